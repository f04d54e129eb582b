"""``tests/deliberate_bugs.py`` stays live: every entry's text is in its source file exactly once, the bugged file
still compiles, the bug changes the text, and the tests named to catch it exist (a stale entry would otherwise make
the hand-run report "NOT CAUGHT" or stop at an assertion, long after the code moved)."""

import ast
import re
import runpy
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MODULE = runpy.run_path(str(ROOT / "tests" / "deliberate_bugs.py"))  # not "__main__": nothing is applied or run


def _entries():
    out = []
    for block, value in MODULE.items():
        if block.isupper() and isinstance(value, list) and value and all(isinstance(e, tuple) for e in value):
            out += [pytest.param(e, id=f"{block}:{e[0][:60]}") for e in value]
    return out


ENTRIES = _entries()


def test_the_blocks_are_found():
    assert len(ENTRIES) >= 50  # BUGS, H_TESTS24, H_TESTS36, H_TESTS35, H_TESTS35_FUSED


@pytest.mark.parametrize("entry", ENTRIES)
def test_deliberate_bug_still_applies(entry):
    what, rel, old, new, command = entry
    path = ROOT / rel
    assert path.is_file(), f"{what}: {rel} is gone"
    text = path.read_text(encoding="utf-8")
    assert text.count(old) == 1, f"{what}: the text to replace is in {rel} {text.count(old)} times, not once"
    assert new != old
    ast.parse(text.replace(old, new), filename=rel)  # the bug is a one-line slip, not a syntax error
    tests = [a for a in command if a.endswith(".py")]
    assert tests and all((ROOT / t).is_file() for t in tests), f"{what}: a test file of {tests} is gone"
    if "-k" in command:
        words = [w for w in re.findall(r"\w+", command[command.index("-k") + 1]) if w not in ("and", "or", "not")]
        names = [n for t in tests for n in re.findall(r"^(?:async )?def (test_\w+)|^class (Test\w+)",
                                                     (ROOT / t).read_text(encoding="utf-8"), re.M) for n in n if n]
        assert any(w in n for w in words for n in names), f"{what}: no test of {tests} matches -k {words}"
