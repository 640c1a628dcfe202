"""The README's Python example runs as written and prints MODEL.md's check value."""

import contextlib
import io
import os
import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def _blocks():
    return re.findall(r"```python\n(.*?)```", README.read_text(), re.S)


def test_readme_python_example(tmp_path):
    block = _blocks()[0]
    assert len([ln for ln in block.splitlines() if ln.strip()]) <= 6
    out = io.StringIO()
    cwd = os.getcwd()
    os.chdir(tmp_path)  # the example saves a figure
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(block, "README.md", "exec"), {})  # our own README, not user input
    finally:
        os.chdir(cwd)
    tb, ta = (float(v) for v in out.getvalue().split())
    assert abs(tb - 218.31) < 0.01 and abs(ta - 210.72) < 0.01
    assert (tmp_path / "batch.png").exists()


def test_readme_api_example(tmp_path):
    """The fit / save / load / predict / validate example runs and its what-if moves BT up."""
    block = _blocks()[1]
    out = io.StringIO()
    cwd = os.getcwd()
    os.chdir(tmp_path)  # the example saves model.json
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(block, "README.md", "exec"), {})  # our own README, not user input
    finally:
        os.chdir(cwd)
    lines = out.getvalue().splitlines()
    assert (tmp_path / "model.json").exists() and "std. error" in out.getvalue()
    delta = float(lines[-2])
    assert 0.0 < delta < 20.0  # a hotter ET heats the beans, by less than the ET change
    assert lines[-1].startswith("<ValidationResult 2 batch(es) on 360kg")


def test_every_roastlab_name_the_docs_give_exists():
    """A `roastlab.a.b` the README or docs/*.md names (a module, function or constant) resolves:
    the docs do not point at code that moved or was renamed."""
    import importlib
    import warnings

    root = README.parent
    named = {}
    for path in [README, *sorted((root / "docs").glob("*.md"))]:
        for m in re.finditer(r"`(roastlab(?:\.[A-Za-z_]\w*)+)", path.read_text(encoding="utf-8")):
            named.setdefault(m.group(1), path.name)
    missing = []
    for dotted, where in sorted(named.items()):
        parts = dotted.split(".")
        for i in range(len(parts), 0, -1):  # the longest importable module, then attributes
            try:
                with warnings.catch_warnings():  # a deprecated alias the README names still imports
                    warnings.simplefilter("ignore", DeprecationWarning)
                    obj = importlib.import_module(".".join(parts[:i]))
                break
            except ImportError:
                continue
        for attr in parts[i:]:
            obj = getattr(obj, attr, None)
        if obj is None:
            missing.append(f"{where}: {dotted}")
    assert len(named) > 50 and not missing, missing


def test_every_option_the_docs_give_a_command_exists():
    """`roastlab CMD [SUB] ... --option` in the README or docs/*.md: the option is one of that command's
    (a renamed or dropped flag, or an error message advising one the command lacks, would fail here)."""
    import argparse

    from roastlab.cli.main import build_parser

    def commands(parser):
        return next((a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction)), {})

    root = README.parent
    checked, unknown = 0, []
    for path in [README, *sorted((root / "docs").glob("*.md"))]:
        for m in re.finditer(
            r"roastlab ([a-z][a-z-]*)(?: ([a-z][a-z-]*))?([^`\n;|&]*)", path.read_text(encoding="utf-8")
        ):
            parser = commands(build_parser()).get(m.group(1))
            if parser is None:
                continue
            parser = commands(parser).get(m.group(2), parser)
            known = {s for a in parser._actions for s in a.option_strings}
            for flag in re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", m.group(3)):
                checked += 1
                if flag not in known:
                    unknown.append(f"{path.name}: roastlab {m.group(1)} ... {flag}")
    assert checked > 150 and not unknown, unknown
