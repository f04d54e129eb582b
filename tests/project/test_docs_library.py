"""The "Using the library" block of docs/library.md runs as written (issues 33 and 38): the front door
(``fogdrift.read``, ``fogdrift.run_allan``, ``fogdrift.fit_noise``) and the estimators below it."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _library_block() -> str:
    text = (ROOT / "docs" / "library.md").read_text(encoding="utf-8")
    section = text.split("# Using the library", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1, "the section holds one python block"
    return blocks[0]


def test_the_library_block_of_the_docs_runs(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)  # its paths are relative to the repository, as a reader runs it
    namespace: dict = {}
    exec(compile(_library_block(), "docs/library.md", "exec"), namespace)  # noqa: S102 - our own docs
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("gz ") and out[1] == "deg/sqrt(h) " + namespace["fit"].terms["N"].status
    run = namespace["run"]
    assert [a.name for a in run.results] == ["gx", "gy", "gz"]
    assert namespace["yhat"].shape == namespace["drift"][1470:].shape
