"""Terminal output that a file cannot take over: control characters in printed text are shown escaped.

A column name, a file name or any other text that came from a file may hold ANSI escape sequences (``ESC [ 31 m``
turns the terminal red; others move the cursor, rewrite lines or set the window title) or bidirectional
overrides that reorder what is shown.  :class:`SafeConsole` is a :class:`rich.console.Console` whose output
shows every such character as ``\\xNN`` / ``\\uNNNN`` (:func:`visible`); rich's own styling and cursor control
(its control segments and styles) are added after, untouched.  The CLI's consoles are SafeConsoles.
"""

from __future__ import annotations

import re

from rich.console import Console
from rich.segment import Segment

__all__ = ["SafeConsole", "visible"]

#: C0 controls but tab and line feed, DEL, C1 controls, bidirectional embeddings/overrides/isolates.
_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")


def _esc(m: re.Match) -> str:
    c = ord(m.group(0))
    return f"\\x{c:02x}" if c < 0x100 else f"\\u{c:04x}"


def visible(text: str) -> str:
    r"""``text`` with control characters written out (``\x1b``), printable as is.

    Examples
    --------
    >>> visible("\x1b[31mgz\x1b[0m")
    '\\x1b[31mgz\\x1b[0m'
    >>> visible("gz [deg/s]\tok")
    'gz [deg/s]\tok'
    """
    return _CONTROL.sub(_esc, text)


class SafeConsole(Console):
    """A rich Console that prints text segments through :func:`visible` (see the module docstring)."""

    def _render_buffer(self, buffer) -> str:
        return super()._render_buffer(seg if seg.control or not _CONTROL.search(seg.text) else
                                      Segment(visible(seg.text), seg.style, seg.control) for seg in buffer)
