"""Import graph of the package, deferred imports included (issue 21): no cycle, seen or hidden.

``test_structure.py`` imports every module first in a fresh interpreter, which finds the cycles that break at
import time.  A cycle closed by a function-level ("deferred") import never breaks there, and 150 internal
deferred imports hid three (``noise/_kernels`` <-> ``noise/engine``; ``report/__init__`` -> ``report/html`` ->
``report_gmwm`` -> ``report/__init__``; ``evaluation/__init__`` <-> ``evaluation/analysis``).  This test reads
every ``Import``/``ImportFrom`` node anywhere in every module with :mod:`ast` and

* finds the strongly connected components of the whole graph (module-level and deferred edges; importing
  ``a.b.c`` also runs the ``__init__`` of every package on the way that is not the importer's own ancestor);
* allows an internal deferred import only where :data:`DEFERRED` lists it, with a reason: to keep numba, JAX,
  matplotlib, the CLI stack or optional readers lazy -- or as named debt (``DEBT``: nothing heavy behind it, the
  owner moves it to module level).

Imports under ``if TYPE_CHECKING:`` never run and are not edges.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src"
PACKAGE = "fogdrift"


@dataclass(frozen=True)
class Edge:
    importer: str
    target: str
    deferred: bool
    line: int


def _modules(src: Path, package: str) -> dict[str, tuple[Path, bool]]:
    """``{dotted name: (path, is_package)}`` of every module of ``package`` under ``src``."""
    out = {}
    for path in sorted((src / package).rglob("*.py")):
        parts = list(path.relative_to(src).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        out[".".join(parts)] = (path, is_pkg)
    return out


def _is_type_checking(node: ast.AST) -> bool:
    t = getattr(node, "test", None)
    return isinstance(node, ast.If) and ((isinstance(t, ast.Name) and t.id == "TYPE_CHECKING")
                                         or (isinstance(t, ast.Attribute) and t.attr == "TYPE_CHECKING"))


def import_edges(src: Path, package: str, *, type_checking: bool = False) -> tuple[dict, list[Edge]]:
    """Every internal import of ``package`` (module-level and deferred) as :class:`Edge`; with ``type_checking``
    also the imports under ``if TYPE_CHECKING:`` (as deferred edges: they never run, but a type-only circle still
    ties two modules together)."""
    mods = _modules(src, package)
    edges: list[Edge] = []
    for mod, (path, is_pkg) in mods.items():
        def visit(node, deferred):
            for ch in ast.iter_child_nodes(node):
                if _is_type_checking(ch):
                    if type_checking:
                        visit(ch, True)
                    continue
                d = deferred or isinstance(ch, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
                if isinstance(ch, ast.Import):
                    edges.extend(Edge(mod, a.name, d, ch.lineno) for a in ch.names
                                 if a.name.split(".")[0] == package)
                elif isinstance(ch, ast.ImportFrom):
                    if ch.level:
                        base = mod.split(".") if is_pkg else mod.split(".")[:-1]
                        base = base[:len(base) - (ch.level - 1)]
                        target = ".".join(base + ([ch.module] if ch.module else []))
                    else:
                        target = ch.module or ""
                    if target.split(".")[0] != package:
                        continue
                    for a in ch.names:  # "from pkg import sub" imports the submodule
                        sub = f"{target}.{a.name}"
                        edges.append(Edge(mod, sub if sub in mods else target, d, ch.lineno))
                visit(ch, d)

        visit(ast.parse(path.read_text(encoding="utf-8")), False)
    return mods, edges


def _ancestors(name: str) -> list[str]:
    parts = name.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def import_cycles(mods: dict, edges: list[Edge]) -> list[list[str]]:
    """Strongly connected components (more than one module, or a module importing itself), sorted."""
    graph: dict[str, set] = defaultdict(set)
    for e in edges:
        if e.target not in mods:
            continue
        graph[e.importer].add(e.target)
        for parent in _ancestors(e.target):  # the packages on the way run their __init__ first
            if parent in mods and parent != e.importer and parent not in _ancestors(e.importer):
                graph[e.importer].add(parent)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set = set()
    out = []

    def strong(v):  # Tarjan; the package has ~150 modules, recursion depth is no issue
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1 or v in graph[v]:
                out.append(sorted(comp))

    for v in sorted(mods):
        if v not in index:
            strong(v)
    return sorted(out)


def _allowed(allowed: dict, importer: str, target: str) -> bool:
    """``allowed``: importer -> (reason, targets); an importer ``pkg.*`` covers every module under ``pkg``,
    a target ``"*"`` every target."""
    for key, (_, targets) in allowed.items():
        hit = key == importer or (key.endswith(".*") and importer.startswith(key[:-1]))
        if hit and (target in targets or "*" in targets):
            return True
    return False


def unlisted_deferred(edges: list[Edge], allowed: dict) -> list[str]:
    """Deferred internal imports that ``allowed`` (importer -> (reason, targets)) does not list."""
    return sorted({f"{e.importer} -> {e.target} (line {e.line})" for e in edges
                   if e.deferred and not _allowed(allowed, e.importer, e.target)})


# ------------------------------------------------------------------------------------------------------------
# The allow-list.  A reason says what the deferral keeps lazy; DEBT entries have nothing heavy behind them and
# are to be moved to module level by the named owner (an entry that is no longer used must be removed).
# ------------------------------------------------------------------------------------------------------------
NUMBA = "keeps numba lazy: the compiled kernels load (and compile or read their cache) on first use"
CLI = ("CLI start-up: 'fogdrift --help' and each command import only what that command runs "
       "(typer/rich at the root, the analysis stack of the one command)")
BATCH = "batch: a worker imports only the stack of the task kind it runs (pipeline, GMWM, report, compensate)"
ROOT = "the package root stays import-light (fogdrift/__init__ exposes only the version and the errors)"


def DEBT(owner: str) -> str:  # noqa: N802 - reads as a label in the table
    return f"debt (nothing heavy behind it): move to module level; owner {owner}"


DEFERRED: dict[str, tuple[str, tuple[str, ...]]] = {
    "fogdrift": (ROOT, ("fogdrift.errors",)),
    "fogdrift.cli": (CLI + "; main() takes SIGINT over before importing anything (cli/__init__ docstring)", (
        "fogdrift.cli._app", "fogdrift.interrupt")),
    "fogdrift.cli._app": (CLI, ("fogdrift.pipeline",)),
    "fogdrift.cli._spec": (CLI, ("fogdrift.report",)),
    "fogdrift.cli._tables": (CLI, ("fogdrift.noise.terms", "fogdrift.report")),
    "fogdrift.cli.allan": (CLI, ("fogdrift.pipeline", "fogdrift.report", "fogdrift.workflows.allan")),
    "fogdrift.cli.analyze": (CLI, ("fogdrift.cli.compensate", "fogdrift.cli.noise",
        "fogdrift.evaluation.verdicts", "fogdrift.pipeline",
        "fogdrift.report", "fogdrift.report.pdf", "fogdrift.report.summary",
        "fogdrift.workflows.analyze")),
    "fogdrift.cli._screen": (CLI, ("fogdrift.segments",)),
    "fogdrift.cli.batch": (CLI, ("fogdrift.fleet", "fogdrift.fleet.commands", "fogdrift.fleet.summary")),
    "fogdrift.cli.compensate": (CLI, ("fogdrift.compensate", "fogdrift.evaluation")),
    "fogdrift.cli.consistency": (CLI, ("fogdrift.evaluation.consistency", "fogdrift.models.statespace",
                                       "fogdrift.workflows.consistency")),
    "fogdrift.cli.export": (CLI, ("fogdrift.export", "fogdrift.export.targets", "fogdrift.workflows.export")),
    "fogdrift.cli.model": (CLI, ("fogdrift.cli.separate", "fogdrift.evaluation", "fogdrift.pipeline",
        "fogdrift.report", "fogdrift.workflows.model")),
    "fogdrift.cli.noise": (CLI, ("fogdrift.gmwm.analysis", "fogdrift.gmwm.quantity", "fogdrift.noise.periodic", "fogdrift.noise.quantity", "fogdrift.report",
        "fogdrift.report.gmwm", "fogdrift.workflows.allan", "fogdrift.workflows.noise")),
    "fogdrift.cli.separate": (CLI, ("fogdrift.pipeline", "fogdrift.report", "fogdrift.workflows.separate")),
    "fogdrift.cli.plan": (CLI, ("fogdrift.pipeline", "fogdrift.plan", "fogdrift.plan.fleet", "fogdrift.report", "fogdrift.report.plan_figure")),
    "fogdrift.fleet.commands": (BATCH, ("fogdrift.evaluation.verdicts",
        "fogdrift.pipeline", "fogdrift.workflows.allan",
        "fogdrift.workflows.analyze", "fogdrift.workflows.noise")),
    "fogdrift.workflows.consistency": ("GMWM (gmwm.analysis -> scipy.optimize) only for --method gmwm",
                                       ("fogdrift.gmwm.analysis",)),
    "fogdrift.fleet.runner": (BATCH, ("fogdrift.fleet.page", "fogdrift.gmwm.analysis", "fogdrift.pipeline")),
    "fogdrift.io.chunked": ("optional readers: the binary/HDF5 readers and the registry load only for the format opened", (
        "fogdrift.io.readers.binary", "fogdrift.io.registry")),
    "fogdrift.pipeline": ("model modules load on use, through the registry (test_model_registry: importing the "
                          "pipeline imports no model module); GMWM (gmwm.estimator: scipy.optimize's least squares, "
                          "gmwm.simulate: scipy.signal) only for noise_method='gmwm', so allan, separate and model "
                          "never load it (test_speed_imports)", ("fogdrift.gmwm.analysis", "fogdrift.evaluation.gmwm_vs_allan")),
    "fogdrift.io.load": ("optional readers: the reader registry imports a reader module on first use", (
        "fogdrift.io.registry",)),
    "fogdrift.report": ("the HTML report (report.html: the evaluation verdicts, the model registry, the sections) "
                        "loads where a report is written; allan and noise write their files without it",
                        ("fogdrift.report.html",)),
    "fogdrift.lifting._kernels": (NUMBA, ("fogdrift.lifting._numba",)),
    "fogdrift.noise.engine": (NUMBA, ("fogdrift.noise._kernels",)),
}

#: Cycles known today -> the plan that removes them.  A key is the set of modules that identifies the cycle: a
#: found cycle holding all of them is this one (its other members may change while it is worked on).  Keep it
#: empty; an entry is a debt, and an entry no found cycle matches must be removed.
KNOWN_CYCLES: dict[frozenset, str] = {}


def _known(cycle) -> bool:
    return any(key <= set(cycle) for key in KNOWN_CYCLES)


def test_no_import_cycle_including_deferred_imports():
    mods, edges = import_edges(SRC, PACKAGE)
    assert len(mods) > 50 and sum(e.deferred for e in edges) > 50
    cycles = [c for c in import_cycles(mods, edges) if not _known(c)]
    assert cycles == [], "import cycles (module-level and deferred imports):\n" + "\n".join(map(str, cycles))


def test_known_cycles_are_not_stale():
    mods, edges = import_edges(SRC, PACKAGE)
    found = [set(c) for c in import_cycles(mods, edges)]
    stale = [sorted(k) for k in KNOWN_CYCLES if not any(k <= c for c in found)]
    assert stale == [], f"KNOWN_CYCLES entries no cycle matches any more (remove them): {stale}"


def test_deferred_internal_imports_are_listed_with_a_reason():
    mods, edges = import_edges(SRC, PACKAGE)
    missing = unlisted_deferred(edges, DEFERRED)
    assert missing == [], ("deferred internal imports not in DEFERRED (move them to module level, or list them "
                           "with what they keep lazy):\n" + "\n".join(missing))
    used = {(e.importer, e.target) for e in edges if e.deferred}
    stale = sorted(f"{k} -> {t}" for k, (_, ts) in DEFERRED.items() for t in ts if t != "*" and (k, t) not in used)
    assert stale == [], "DEFERRED entries no longer used (remove them):\n" + "\n".join(stale)
    assert all(reason.strip() for reason, _ in DEFERRED.values())


def test_the_known_cycles_of_issue_21_are_gone():
    mods, edges = import_edges(SRC, PACKAGE)
    in_cycles = {m for c in import_cycles(mods, edges) for m in c}
    for m in ("fogdrift.noise._kernels", "fogdrift.noise.engine", "fogdrift.report.gmwm"):
        assert m not in in_cycles
    assert "fogdrift.report_gmwm" not in mods and "fogdrift.allan_chunked" not in mods
    # HUBER_K has one home, read by the NumPy engine and the numba kernels
    from fogdrift.noise import _kernels, engine, huber
    assert engine.HUBER_K is huber.HUBER_K and _kernels.HUBER_K is huber.HUBER_K


def _fake_package(tmp_path, files: dict[str, str]) -> Path:
    pkg = tmp_path / "cyc"
    pkg.mkdir()
    for name, text in files.items():
        (pkg / name).write_text(text)
    return tmp_path


def test_the_checker_reports_a_deferred_import_cycle(tmp_path):
    # a.b at module level, b -> a inside a function: imports fine, so only the graph can see it
    src = _fake_package(tmp_path, {
        "__init__.py": "",
        "a.py": "from .b import g\n\ndef f():\n    return g()\n",
        "b.py": "def g():\n    from .a import f\n    return f\n",
        "c.py": "from . import a\n",
    })
    mods, edges = import_edges(src, "cyc")
    assert import_cycles(mods, edges) == [["cyc.a", "cyc.b"]]
    assert unlisted_deferred(edges, {}) == ["cyc.b -> cyc.a (line 2)"]
    assert unlisted_deferred(edges, {"cyc.b": ("lazy", ("cyc.a",))}) == []
    assert unlisted_deferred(edges, {"cyc.*": ("lazy", ("*",))}) == []
    assert unlisted_deferred(edges, {"cyc.a": ("lazy", ("*",))}) == ["cyc.b -> cyc.a (line 2)"]
    # the same package really imports without error: the import-first check of test_structure.py misses it
    out = subprocess.run([sys.executable, "-c", "import cyc.b, cyc.a; print(cyc.b.g().__name__)"], cwd=src,
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "f"


def test_the_checker_follows_package_inits_and_skips_type_checking(tmp_path):
    # p.x imports q.y: that runs q/__init__, which imports p.x back -> a cycle through a package init;
    # an import under TYPE_CHECKING never runs and closes nothing
    src = _fake_package(tmp_path, {"__init__.py": ""})
    for sub, files in {"p": {"__init__.py": "", "x.py": "def f():\n    from ..q.y import g\n"},
                       "q": {"__init__.py": "from ..p.x import f\n", "y.py": "g = 1\n"},
                       "r": {"__init__.py": "", "z.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
                                                        "    from ..r import z\n"}}.items():
        (src / "cyc" / sub).mkdir()
        for name, text in files.items():
            (src / "cyc" / sub / name).write_text(text)
    mods, edges = import_edges(src, "cyc")
    assert import_cycles(mods, edges) == [["cyc.p.x", "cyc.q"]]
    assert not any(e.importer == "cyc.r.z" for e in edges)
