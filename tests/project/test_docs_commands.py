"""Every shell block of the README and the tutorials runs as written (issue 38): a documented command that fails
fails the build.

Each document's ``sh`` blocks run in order in one scratch folder (a later block may read what an earlier one wrote,
as a reader's would), with ``data/`` linked to the repository's and ``../shared`` to the shared data; ``fogdrift``
is this interpreter's ``python -m fogdrift``.  ``make`` lines are the README's own two commands, which CI runs
itself; they are not run here.  A block needing the shared data is skipped where it is absent.  The time limit per
block is a hang guard, not a speed rule.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared"
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs" / "tutorials").glob("*.md"))]
HANG_GUARD_S = 1800


def shell_blocks(path: Path) -> list[str]:
    """The ``sh`` blocks of a Markdown file, without the ``make`` lines."""
    blocks = re.findall(r"```(?:sh|bash)\n(.*?)```", path.read_text(encoding="utf-8"), flags=re.S)
    out = []
    for b in blocks:
        lines = [ln for ln in b.replace("\\\n", " ").splitlines() if ln.strip() and not ln.lstrip().startswith("make ")]
        if lines:
            out.append("\n".join(lines))
    return out


def test_the_blocks_are_found_and_the_readme_has_the_two_commands():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "make demo" in text and "make test" in text
    assert len(shell_blocks(ROOT / "README.md")) >= 3
    assert all(shell_blocks(p) or "make demo" in p.read_text() for p in DOCS[1:])


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_shell_block_runs(doc, tmp_path):
    blocks = shell_blocks(doc)
    if not blocks:
        pytest.skip(f"{doc.name} has no shell block besides the README's make commands")
    if any("../shared" in b for b in blocks) and not SHARED.is_dir():
        pytest.skip("the shared data (../shared) is not beside this checkout")
    work = tmp_path / "reader"
    work.mkdir()
    (work / "data").symlink_to(ROOT / "data")
    (tmp_path / "shared").symlink_to(SHARED if SHARED.is_dir() else tmp_path / "missing")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT / "src"), os.environ.get("PYTHONPATH")])),
               COLUMNS="120")
    prelude = f'fogdrift() {{ "{sys.executable}" -m fogdrift "$@"; }}\nset -e\n'
    for i, block in enumerate(blocks, 1):
        res = subprocess.run(["bash", "-c", prelude + block], cwd=work, env=env, capture_output=True, text=True,
                             timeout=HANG_GUARD_S)
        assert res.returncode == 0, f"{doc.name} block {i} failed:\n{block}\n--- stderr:\n{res.stderr[-3000:]}"
