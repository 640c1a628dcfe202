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
