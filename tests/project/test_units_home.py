"""One home per unit relation: 1 h = 3600 s and 1 deg = pi/180 rad are written only in ``fogdrift.units``.

Every other module names :data:`fogdrift.units.S_PER_H`, :data:`~fogdrift.units.RAD_PER_DEG`,
:data:`~fogdrift.units.DEG_PER_RAD` (or :data:`~fogdrift.units.ARCSEC_PER_DEG`) instead of the number, so the code
scanned here (comments and string literals excepted, f-string expressions included) holds no ``3600`` literal and
no ``pi / 180`` or ``180 / pi`` -- which also rules out a module of its own defining ``DEG = math.pi / 180``.

One door per floor to the unit parser: besides ``fogdrift.units`` itself, at most one module of each floor of
:data:`test_structure_layers.LAYERS` reaches :func:`fogdrift.units.parse_unit`; the rest of the floor parses
through that module (the io floor through :func:`fogdrift.signal.channel_unit`) or carries the parsed
:class:`~fogdrift.units.UnitSpec`.
"""

from __future__ import annotations

import ast
import io
import math
import tokenize
from pathlib import Path

import sys

import pytest

from fogdrift import units

sys.path.insert(0, str(Path(__file__).parent))  # the floors of tests/project/test_structure_layers.py
from test_structure_layers import LAYERS, _top, floors  # noqa: E402

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


def reaches_parse_unit(source: str) -> bool:
    """Whether the code (docstrings and comments aside) calls ``parse_unit``: by name, as an attribute
    (``units.parse_unit``) or through an import of the name (an alias is a call all the same)."""
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Name) and node.id == "parse_unit":
            return True
        if isinstance(node, ast.Attribute) and node.attr == "parse_unit":
            return True
        if isinstance(node, ast.ImportFrom) and any(a.name == "parse_unit" for a in node.names):
            return True
    return False


def parse_unit_callers(src: Path, package: str, layers=LAYERS) -> dict[str, list[str]]:
    """Floor name -> the modules on it that call ``parse_unit`` (``<package>.units``, its home, left out)."""
    floor = floors(layers)
    out: dict[str, list[str]] = {}
    for path in sorted((src / package).rglob("*.py")):
        parts = path.relative_to(src).with_suffix("").parts
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        if module != f"{package}.units" and reaches_parse_unit(path.read_text(encoding="utf-8")):
            out.setdefault(layers[floor[_top(module, package)]][0], []).append(module)
    return out


def test_one_parse_unit_caller_per_floor():
    """Each floor has at most one module that calls the unit parser; the others go through it."""
    callers = parse_unit_callers(SRC.parent, "fogdrift")
    crowded = {name: mods for name, mods in callers.items() if len(mods) > 1}
    assert crowded == {}, ("more than one module of a floor calls fogdrift.units.parse_unit (parse through the "
                           f"floor's one caller, e.g. fogdrift.signal.channel_unit on the io floor): {crowded}")
    assert callers.get("io") == ["fogdrift.signal"]


def test_the_caller_count_sees_a_second_module_on_a_floor(tmp_path):
    """A second io module calling the parser is found, by name or attribute; a docstring mention is not a call."""
    files = {"__init__.py": "", "units.py": "def parse_unit(u, q=None):\n    return u\n",
             "io/__init__.py": "", "io/a.py": "from ..units import parse_unit as pu\nx = pu('deg/s')\n",
             "io/b.py": "from .. import units\nx = units.parse_unit('g', None)\n",
             "io/c.py": '"""Parsed by parse_unit("deg/s")."""\n# parse_unit(u)\ns = "parse_unit(u)"\n',
             "top.py": "from .units import parse_unit\n"}
    for name, text in files.items():
        (tmp_path / "lay" / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "lay" / name).write_text(text)
    layers = (("core", ("lay", "units")), ("io", ("io",)), ("high", ("top",)))
    assert parse_unit_callers(tmp_path, "lay", layers) == {"io": ["lay.io.a", "lay.io.b"], "high": ["lay.top"]}
