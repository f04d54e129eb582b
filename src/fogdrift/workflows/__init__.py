"""The commands as workflows: ``run_<command>(record, ...) -> <Command>Run`` and ``write_<command>(run, out_dir)``.

One module per command.  A workflow is what the command *does*: screen the record, fit, evaluate -- everything but
reading options and printing.  The CLI (options -> workflow -> print), ``fogdrift batch`` (:mod:`fogdrift.fleet`)
and a Python user call the same functions, so a batch folder holds what the single command writes::

    >>> from fogdrift.workflows import WORKFLOWS
    >>> sorted(WORKFLOWS)
    ['allan', 'analyze', 'export', 'model', 'noise', 'separate']

Each run object keeps its inputs (the record, the configuration, the segment plan and the record screen) beside its
results, so that ``write_<command>`` and the printers need nothing else.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..errors import ConfigError

__all__ = ["Workflow", "WORKFLOWS", "workflow"]


@dataclass(frozen=True)
class Workflow:
    """One command's workflow: where its ``run`` and ``write`` functions live (imported on first use)."""

    name: str
    module: str
    description: str

    def _mod(self):
        import importlib

        return importlib.import_module(f"{__name__}.{self.module}")

    @property
    def run(self) -> Callable:
        return getattr(self._mod(), f"run_{self.name}")

    @property
    def write(self) -> Callable:
        return getattr(self._mod(), f"write_{self.name}")


#: The workflows, one row per command (the module is imported when its functions are first asked for).
WORKFLOWS: dict[str, Workflow] = {
    "allan": Workflow("allan", "allan", "Allan variance and IEEE-952 coefficients of every axis"),
    "noise": Workflow("noise", "noise", "GMWM noise model of every axis"),
    "separate": Workflow("separate", "separate", "lifting-wavelet separation of every axis into drift and white noise"),
    "model": Workflow("model", "model", "drift models fitted on the training block, compared on the test block, and "
                                         "the model bundle"),
    "export": Workflow("export", "export", "the noise model in the estimators' own files (Kalibr, OpenVINS, VINS, "
                                            "ORB-SLAM3, KF-GINS, imuSensor, gnss-ins-sim, JSON)"),
    "analyze": Workflow("analyze", "analyze", "the whole method (separation, drift models, compensation) with an "
                                               "HTML report"),
}


def workflow(name: str) -> Workflow:
    """The :data:`WORKFLOWS` row of ``name`` (ConfigError listing them otherwise)."""
    try:
        return WORKFLOWS[name]
    except (KeyError, TypeError):
        raise ConfigError(f"no workflow {name!r}; expected one of {sorted(WORKFLOWS)}") from None
