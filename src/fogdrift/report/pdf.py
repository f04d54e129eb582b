"""``report.pdf``: the HTML report printed by headless Chromium.

Why Chromium and not a PDF library: the test suite already renders the report in headless Chromium, so the
PDF is the very rendering the browser test checks (same layout, fonts and figures), and fogdrift gains no
dependency.  The page is fogdrift's own self-contained HTML (no script, nothing fetched), so it is printed with
``--no-sandbox`` (containers often lack the namespaces Chromium's sandbox needs) and a throw-away profile
(parallel runs do not share a profile lock).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from ..errors import ConfigError, FogdriftError
from ..output import atomic_path

__all__ = ["BROWSERS", "find_chromium", "write_pdf"]

#: Executable names looked up on PATH, in order; ``$FOGDRIFT_CHROMIUM`` (a path) comes first.
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome")


def find_chromium() -> str:
    """The Chromium executable: ``$FOGDRIFT_CHROMIUM`` if set, else the first of :data:`BROWSERS` on PATH.

    Raises
    ------
    ConfigError
        None found; the message says how to install one (one line, naming ``{opt:pdf}``).
    """
    env = os.environ.get("FOGDRIFT_CHROMIUM")
    if env:
        path = shutil.which(env)
        if path is None:
            raise ConfigError(f"FOGDRIFT_CHROMIUM={env!r} is not an executable; {{opt:pdf}} needs headless "
                              "Chromium (Debian/Ubuntu: apt install chromium)")
        return path
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    raise ConfigError("{opt:pdf} needs headless Chromium and none was found on PATH (looked for "
                      f"{', '.join(BROWSERS)}): install it (Debian/Ubuntu: apt install chromium; macOS: brew install "
                      "--cask chromium) or set FOGDRIFT_CHROMIUM to its path, or leave out {opt:pdf}")


def write_pdf(html_path, pdf_path, *, browser: str | None = None, timeout_s: float = 180.0) -> Path:
    """Print ``html_path`` to ``pdf_path`` with headless Chromium, written atomically (complete or absent).

    Raises
    ------
    ConfigError
        No Chromium (see :func:`find_chromium`).
    FogdriftError
        Chromium failed or wrote no PDF (its last error lines are in the message).
    """
    browser = browser or find_chromium()
    html_path, pdf_path = Path(html_path).absolute(), Path(pdf_path)
    with atomic_path(pdf_path) as tmp, tempfile.TemporaryDirectory(prefix="fogdrift-chromium-") as profile:
        cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
               f"--user-data-dir={profile}", "--no-pdf-header-footer", "--print-to-pdf-no-header",
               f"--print-to-pdf={Path(tmp).absolute()}", html_path.as_uri()]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
        except subprocess.TimeoutExpired:
            raise FogdriftError(f"Chromium did not print {html_path.name} within {timeout_s:g} s") from None
        ok = Path(tmp).is_file() and Path(tmp).read_bytes()[:5] == b"%PDF-"
        if proc.returncode != 0 or not ok:
            tail = " | ".join(line for line in (proc.stderr or "").splitlines()[-3:] if line.strip())
            raise FogdriftError(f"Chromium ({browser}) could not print {html_path.name} to PDF (exit "
                                f"{proc.returncode}): {tail or 'no output'}")
    return pdf_path
