"""CLI options made from the declared settings (:mod:`fogdrift.constraints`; the rows by name:
:data:`fogdrift.models.settings.SETTINGS`).

:func:`with_settings` adds one option per named row to a command -- the row's flag, type, default and help -- where
the command's signature has its ``settings`` parameter, and hands the command the values as ``settings``
(``{name: value}``, the :class:`~fogdrift.pipeline.AnalysisConfig` keywords; an option written as text,
``--fit-taus 1:300``, is handed on parsed by its row's ``parse``).  A new setting of a stage is one
row: every command that names it gets its option, and ``{opt:NAME}`` in a message is spelled with its flag
(``fogdrift.cli._app.FLAGS``).
"""

from __future__ import annotations

import functools
import inspect
import typing
from typing import Annotated

import typer

from ..models.settings import SETTINGS
from ._app import errors

__all__ = ["with_settings"]


def with_settings(*names: str):
    """Decorator: the options of the settings ``names`` in place of the command's ``settings`` parameter."""
    rows = [SETTINGS[n] for n in names]

    def decorate(func):
        sig = inspect.signature(func)
        if "settings" not in sig.parameters:
            raise TypeError(f"{func.__name__} has no 'settings' parameter to put the options of {names} in")
        hints = typing.get_type_hints(func, include_extras=True)  # resolve string annotations (PEP 563)
        own = [p.replace(annotation=hints.get(p.name, p.annotation)) for p in sig.parameters.values()]
        at = [p.name for p in own].index("settings")
        made = [inspect.Parameter(r.name, own[at].kind, default=r.default if r.parse is None else r.text,
                                  annotation=Annotated[r.rule.type if r.parse is None else str,
                                                       typer.Option(r.flag, help=r.help)]) for r in rows]
        params = own[:at] + made + own[at + 1:]

        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            given = {r.name: kwargs.pop(r.name) for r in rows if r.name in kwargs}
            with errors():  # an option given as text (--fit-taus 1:300): its value, or one line naming the option
                for r in rows:
                    if r.parse is not None and r.name in given:
                        given[r.name] = r.parse(given[r.name])
            return func(*args, settings=given, **kwargs)

        wrapper.__signature__ = sig.replace(parameters=params)
        return wrapper

    return decorate
