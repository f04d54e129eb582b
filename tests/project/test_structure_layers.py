"""The package's layers: every module sits on one floor, and no import -- module-level, deferred or type-only --
points to a floor above its own; no type-only circle; no private name imported across packages.

The floors, lowest first (:data:`LAYERS`):

0. **core** -- errors, units, formatting helpers, atomic output, the interrupt guard, document limits;
1. **io** -- readers and the signal description (sampling, units per channel), temperature logs, datasheets;
2. **statistics** -- the Allan family, the noise processes and their identification, GMWM, the lifting wavelet,
   the record screen and its findings, the simulators;
3. **models** -- the drift models (grey, Elman, grey-Elman, Kalman) and their registry;
4. **evaluation** -- heading error, artefacts, verdicts, the two estimators compared, consistency;
5. **report / export** -- rendering of results (HTML, figures, tables) and the navigation-filter exports;
6. **workflows** -- one run per command (``workflows/``, the pipeline, the model bundle, compensation, planning);
   a workflow's ``write_<cmd>`` renders through the report, so the report sits below the workflows;
7. **interfaces** -- the CLI and the fleets, which only call the workflows.

A module belongs to the floor of its top-level name (a package or a loose module of ``fogdrift``).  The checker
itself is proved on a fake package (an upward import, a type-only circle and a private import are each found).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))  # the graph reader of tests/project/test_structure_imports.py
from test_structure_imports import PACKAGE, SRC, import_cycles, import_edges  # noqa: E402

LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("core", ("fogdrift", "errors", "_util", "units", "interrupt", "documents", "output", "constraints")),
    ("io", ("io", "signal", "temperature", "spec")),
    ("statistics", ("allan", "noise", "gmwm", "lifting", "metrics", "outliers", "simulate", "screen",
                    "screen_kinds", "health", "selfnoise", "segments", "plausibility")),
    ("models", ("models",)),
    ("evaluation", ("evaluation",)),
    ("report/export", ("report", "export")),
    ("workflows", ("workflows", "pipeline", "bundle", "plan", "compensate")),
    ("interfaces", ("cli", "fleet", "__main__")),
)


def _top(module: str, package: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else package


def floors(layers=LAYERS) -> dict[str, int]:
    """Top-level name -> floor number."""
    out = {}
    for i, (_, names) in enumerate(layers):
        for n in names:
            assert n not in out, f"{n} is on two floors"
            out[n] = i
    return out


def upward_imports(src: Path, package: str, layers=LAYERS) -> list[str]:
    """``"importer -> target (line L): floor a -> floor b"`` for every import pointing to a higher floor."""
    floor = floors(layers)
    mods, edges = import_edges(src, package, type_checking=True)
    out = []
    for e in edges:
        a, b = floor[_top(e.importer, package)], floor[_top(e.target, package)]
        if b > a:
            out.append(f"{e.importer} -> {e.target} (line {e.line}): {layers[a][0]} -> {layers[b][0]}")
    return sorted(set(out))


def unplaced(src: Path, package: str, layers=LAYERS) -> list[str]:
    floor = floors(layers)
    mods, _ = import_edges(src, package)
    return sorted({_top(m, package) for m in mods} - set(floor))


def private_imports(src: Path, package: str) -> list[str]:
    """``from a.b import _name`` where ``a.b`` lies in another top-level package than the importer (dunder names
    such as ``__version__`` are public)."""
    out = []
    for path in sorted((src / package).rglob("*.py")):
        parts = list(path.relative_to(src).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        mod = ".".join(parts)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = parts if is_pkg else parts[:-1]
                base = base[:len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != package or _top(target, package) == _top(mod, package):
                continue
            for a in node.names:
                if a.name.startswith("_") and not a.name.startswith("__"):
                    out.append(f"{mod} imports {target}.{a.name} (line {node.lineno})")
    return out


def test_every_module_sits_on_a_floor():
    assert unplaced(SRC, PACKAGE) == []


def test_no_import_points_up_a_floor():
    assert upward_imports(SRC, PACKAGE) == []


def test_no_circle_even_through_type_only_imports():
    mods, edges = import_edges(SRC, PACKAGE, type_checking=True)
    assert import_cycles(mods, edges) == []


def test_no_private_name_is_imported_across_packages():
    assert private_imports(SRC, PACKAGE) == []


# ---- the checker on a fake package ------------------------------------------------------------------------------
def _fake(tmp_path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        p = tmp_path / "lay" / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return tmp_path


FAKE_LAYERS = (("low", ("lay", "base")), ("high", ("top",)))


def test_the_checker_finds_an_upward_import_even_a_deferred_or_type_only_one(tmp_path):
    src = _fake(tmp_path, {"__init__.py": "", "top.py": "from .base import f\n",
                           "base.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .top import T\n"
                                      "def f():\n    from . import top\n"})
    assert upward_imports(src, "lay", FAKE_LAYERS) == ["lay.base -> lay.top (line 3): low -> high",
                                                       "lay.base -> lay.top (line 5): low -> high"]
    mods, edges = import_edges(src, "lay", type_checking=True)
    assert import_cycles(mods, edges) == [["lay.base", "lay.top"]]
    mods, edges = import_edges(src, "lay")  # without the type-only edge the deferred one still closes it
    assert import_cycles(mods, edges) == [["lay.base", "lay.top"]]


def test_the_checker_finds_a_type_only_circle_and_a_private_import(tmp_path):
    src = _fake(tmp_path, {"__init__.py": "", "base.py": "from .top import _T\n",
                           "top.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .base import X\n"
                                     "_T = 1\n"})
    mods, edges = import_edges(src, "lay")
    assert import_cycles(mods, edges) == []
    mods, edges = import_edges(src, "lay", type_checking=True)
    assert import_cycles(mods, edges) == [["lay.base", "lay.top"]]
    assert private_imports(src, "lay") == ["lay.base imports lay.top._T (line 1)"]
    assert unplaced(src, "lay", (("low", ("lay", "base")),)) == ["top"]
