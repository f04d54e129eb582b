"""One home per unit relation: 1 h = 3600 s and 1 deg = pi/180 rad are written only in ``fogdrift.units``.

Every other module names :data:`fogdrift.units.S_PER_H`, :data:`~fogdrift.units.RAD_PER_DEG`,
:data:`~fogdrift.units.DEG_PER_RAD` (or :data:`~fogdrift.units.ARCSEC_PER_DEG`) instead of the number, so the code
scanned here (comments and string literals excepted, f-string expressions included) holds no ``3600`` literal and
no ``pi / 180`` or ``180 / pi`` -- which also rules out a module of its own defining ``DEG = math.pi / 180``.
"""

from __future__ import annotations

import ast
import io
import math
import tokenize
from pathlib import Path

import pytest

from fogdrift import units

SRC = Path(__file__).resolve().parents[2] / "src" / "fogdrift"
HOME = SRC / "units.py"


def _number(text: str):
    try:
        return float(text.replace("_", ""))
    except ValueError:  # complex or other literals: not a unit factor
        return None


def _fstring_expressions(literal: str) -> list[str]:
    """The source of every ``{...}`` expression of an f-string literal (Python < 3.12 tokenizes it as one STRING)."""
    try:
        tree = ast.parse(literal, mode="eval")
    except SyntaxError:  # pragma: no cover - a literal the tokenizer accepted
        return []
    return [ast.unparse(node.value) for node in ast.walk(tree) if isinstance(node, ast.FormattedValue)]


def _code_tokens(source: str) -> list[tuple[int, int, str]]:
    """(type, line, text) of the code tokens: no comments, no string literals, but f-string expressions included."""
    out = []
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT or tok.type in (tokenize.NL, tokenize.NEWLINE, tokenize.INDENT,
                                                         tokenize.DEDENT, tokenize.ENDMARKER):
            continue
        if tok.type == tokenize.STRING:
            prefix = tok.string[:tok.string.index(tok.string.lstrip("rRbBuUfF")[0])].lower()
            if "f" in prefix:
                for expr in _fstring_expressions(tok.string):
                    out += [(t, tok.start[0], s) for t, _, s in _code_tokens(expr)]
            continue
        out.append((tok.type, tok.start[0], tok.string))
    return out


def offences(source: str) -> list[str]:
    """Each ``3600`` literal and each ``pi / 180`` or ``180 / pi`` (any ``math.`` / ``np.`` prefix) in the code."""
    toks = _code_tokens(source)
    found = []
    for i, (typ, line, text) in enumerate(toks):
        if typ == tokenize.NUMBER and _number(text) == 3600.0:
            found.append(f"line {line}: {text}")
        if typ == tokenize.OP and text == "/" and 0 < i < len(toks) - 1:
            j = i + 1  # the right operand's last name: ``np.pi`` -> ``pi``
            while j + 2 < len(toks) and toks[j][0] == tokenize.NAME and toks[j + 1][2] == ".":
                j += 2
            left, right = toks[i - 1][2], toks[j][2]
            if (left == "pi" and _number(right) == 180.0) or (_number(left) == 180.0 and right == "pi"):
                found.append(f"line {line}: {left} / {right}")
    return found


def test_the_scan_sees_a_regression():
    """The scan finds each spelling of the factors in code and ignores comments and plain strings."""
    bad = ["x = y / 3600.0", "x = y * 3600", "x = 3600.", "DEG = math.pi / 180.0", "d = 180 / np.pi",
           "DEG = pi/180", "s = f'{t / 3600:.3g} h'", "h = (60.0, 600.0, 3600.0)"]
    for line in bad:
        assert offences(line + "\n"), line
    good = ["x = y / S_PER_H  # 3600 s per hour, pi / 180", "s = 'corrtime x 3600, (pi/180)/60'",
            "x = 36000.0", "n = 1800 * 2", "k = y / 216000.0", "a = math.pi / 2.0", "s = f'{t / S_PER_H:.3g} h'"]
    for line in good:
        assert not offences(line + "\n"), line


def test_units_states_each_factor():
    """The home holds the factors the rest of the package names (bit-exact values)."""
    assert units.S_PER_H == 3600.0 and units.S_PER_MIN == 60.0 and units.ARCSEC_PER_DEG == 3600.0
    assert units.RAD_PER_DEG == math.pi / 180.0 and units.DEG_PER_RAD == 180.0 / math.pi
    assert units.RATE_UNITS["deg/s"] == units.S_PER_H
    assert units.EARTH_RATE_DPH == 7.2921150e-5 * 180.0 / math.pi * 3600.0
    assert offences(HOME.read_text(encoding="utf-8")), "the scan must find the factors in their home"


@pytest.mark.parametrize("path", sorted(p for p in SRC.rglob("*.py") if p != HOME), ids=lambda p: str(p.relative_to(SRC)))
def test_no_unit_factor_outside_units(path):
    """No module but ``fogdrift.units`` writes 3600 or pi/180 in its code (name S_PER_H, RAD_PER_DEG, DEG_PER_RAD)."""
    found = offences(path.read_text(encoding="utf-8"))
    assert not found, f"{path.relative_to(SRC)}: unit factor written out, name it from fogdrift.units: {found}"


def test_code_says_what_and_why_not_which_issue():
    """Comments and docstrings in the package tell what the code does and why, never its history: no "issue N"
    (the issue tracker's numbers mean nothing to a reader of the code; a figure cites bench/RESULTS.md)."""
    import re
    from pathlib import Path

    pkg = Path(__file__).resolve().parents[2] / "src" / "fogdrift"
    found = [f"{p.relative_to(pkg)}:{i}: {line.strip()}" for p in sorted(pkg.rglob("*.py"))
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
             if re.search(r"\bissues? \d+\b", line, re.IGNORECASE)]
    assert found == []
