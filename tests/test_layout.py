"""The architecture as a test: imports point one way, privates stay home, arguments are documented.

Layers, lowest first: errors -> model -> metrics -> io -> report -> sim -> evaluate -> fit -> workflows -> fleet -> control -> cli.
A module may import from its own subpackage and from lower layers only, and never a private
(underscore) name from another subpackage. Imports inside functions count too.
"""

import ast
import inspect
import re
from pathlib import Path

import pytest

import roastlab

SRC = Path(roastlab.__file__).parent
LAYERS = [
    "errors",
    "model",
    "metrics",
    "io",
    "report",
    "sim",
    "evaluate",
    "fit",
    "workflows",
    "fleet",
    "control",
    "app",  # the roaster's page (a web layer over the library)
    "cli",
    "apps",  # the deprecated location of the command line (a shim onto cli)
]
RANK = {name: i for i, name in enumerate(LAYERS)}


def _modules():
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC)
        if rel.parts[0] in ("__init__.py", "__main__.py"):
            continue
        yield path, rel.parts[0].removesuffix(".py")


def _imports(path: Path):
    """(line, target subpackage, imported names) for every roastlab import in a file."""
    tree = ast.parse(path.read_text())
    pkg_parts = ("roastlab",) + path.relative_to(SRC).parent.parts
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg_parts[: len(pkg_parts) - node.level + 1]
                full = list(base) + (node.module.split(".") if node.module else [])
            elif node.module and node.module.startswith("roastlab"):
                full = node.module.split(".")
            else:
                continue
            target = full[1] if len(full) > 1 else None
            names = [a.name for a in node.names]
            if target is None:  # "from .. import x": x is the subpackage
                for n in names:
                    yield node.lineno, n, []
            else:
                yield node.lineno, target, names
        elif isinstance(node, ast.Import):
            for a in node.names:
                parts = a.name.split(".")
                if parts[0] == "roastlab" and len(parts) > 1:
                    yield node.lineno, parts[1], []


def violations():
    out = []
    for path, layer in _modules():
        for line, target, names in _imports(path):
            if target == "__version__" or target == layer:
                continue
            if target not in RANK:
                out.append(f"{path.relative_to(SRC)}:{line} imports unknown roastlab.{target}")
            elif RANK[target] > RANK[layer]:
                out.append(f"{path.relative_to(SRC)}:{line}: {layer} imports upward from {target}")
            for n in names:
                if n.startswith("_"):
                    out.append(f"{path.relative_to(SRC)}:{line}: private {n} imported from {target}")
    return out


def test_imports_point_one_way_and_privates_stay_home():
    assert violations() == []


def test_the_checker_catches_a_violation(tmp_path, monkeypatch):
    """The layout test itself can fail: an upward import and a private import are both found."""
    bad = SRC / "model" / "_layout_probe.py"
    bad.write_text("from ..sim.kernels import integrate_into\nfrom ..io.files import _READ\n")
    try:
        found = violations()
    finally:
        bad.unlink()
    assert any("model imports upward from sim" in v for v in found)
    assert any("private _READ" in v for v in found)


def _public_functions():
    for name in roastlab.__all__:
        obj = getattr(roastlab, name)
        if inspect.isfunction(obj):
            yield name, obj
        elif inspect.isclass(obj) and obj.__module__.startswith("roastlab"):
            for meth_name, meth in vars(obj).items():
                if inspect.isfunction(meth) and not meth_name.startswith("_"):
                    yield f"{name}.{meth_name}", meth
    yield "FittedModel.__init__", roastlab.FittedModel.__init__


def undocumented(fn) -> list[str]:
    """Arguments of ``fn`` that its docstring (or its class's) does not mention by name."""
    doc = inspect.getdoc(fn) or ""
    owner = getattr(inspect.getmodule(fn), fn.__qualname__.split(".")[0], None)
    if inspect.isclass(owner):
        doc += "\n" + (inspect.getdoc(owner) or "")
    missing = []
    for p in inspect.signature(fn).parameters.values():
        if p.name in ("self", "cls") or p.kind in (p.VAR_POSITIONAL,):
            continue
        if not re.search(rf"(?<![A-Za-z0-9_]){re.escape(p.name)}(?![A-Za-z0-9_])", doc):
            missing.append(p.name)
    return missing


PUBLIC = dict(_public_functions())


@pytest.mark.parametrize("name", sorted(PUBLIC))
def test_public_arguments_are_documented(name):
    assert undocumented(PUBLIC[name]) == [], f"{name}: document these arguments in its docstring"


def test_the_documentation_check_can_fail():
    def f(a, b):
        """Uses a only."""

    assert undocumented(f) == ["b"]


def _module_name(path: Path) -> str:
    rel = path.relative_to(SRC).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(("roastlab",) + parts)


def module_graph() -> dict[str, set[str]]:
    """Module -> the roastlab modules it imports (imports inside functions included)."""
    modules = {_module_name(p): p for p in SRC.rglob("*.py") if p.name != "__main__.py"}
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for name, path in modules.items():
        pkg = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = pkg[: len(pkg) - node.level + 1]
                    full = base + (node.module.split(".") if node.module else [])
                elif node.module and node.module.startswith("roastlab"):
                    full = node.module.split(".")
                else:
                    continue
                for a in node.names:  # "from . import x": x may be a module
                    target = ".".join(full + [a.name])
                    graph[name].add(target if target in modules else ".".join(full))
            elif isinstance(node, ast.Import):
                graph[name] |= {a.name for a in node.names if a.name.startswith("roastlab.")}
        graph[name] = {t for t in graph[name] if t in modules and t != name and t != "roastlab"}
    return graph


def import_cycles(graph) -> list[list[str]]:
    """Every strongly connected group of more than one module (Tarjan's algorithm)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                out.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles_between_modules():
    """Not only between packages: no two modules import each other, directly or around a loop
    (package __init__ re-exports excluded: a package may re-export what its modules define)."""
    graph = {m: {t for t in ts if not t.endswith("__init__")} for m, ts in module_graph().items()}
    pkgs = {m for m in graph if (SRC / Path(*m.split(".")[1:]) / "__init__.py").exists()}
    graph = {m: ts - pkgs for m, ts in graph.items() if m not in pkgs}
    assert import_cycles(graph) == []


def test_the_cycle_finder_finds_a_cycle():
    assert import_cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_the_old_command_line_location_still_works_with_a_warning():
    import importlib
    import sys

    sys.modules.pop("roastlab.apps.cli", None)
    with pytest.warns(DeprecationWarning, match="roastlab.cli"):
        old = importlib.import_module("roastlab.apps.cli")
    from roastlab.cli import main

    assert old.main is main


def test_the_package_and_its_command_line_import_no_heavy_library():
    """``import roastlab`` and the command line's parser leave SciPy's optimize and stats, pandas,
    matplotlib, SymPy, DuckDB and CasADi to the functions that call them: every command pays its
    imports, and SciPy's optimize and stats alone took a cold ``roastlab simulate`` from 2.7 s to
    3.5 s (medians of 5, 2026-11-30's VM). A fresh interpreter, as a command starts."""
    import subprocess
    import sys

    heavy = ["scipy.optimize", "scipy.stats", "pandas", "matplotlib", "sympy", "duckdb", "casadi"]
    code = f"import sys, roastlab, roastlab.cli.main; print([m for m in {heavy!r} if m in sys.modules])"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]", out
