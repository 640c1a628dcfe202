"""The README's Python example runs as written and prints MODEL.md's check value."""

import contextlib
import io
import os
import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_example(tmp_path):
    text = README.read_text()
    block = re.search(r"```python\n(.*?)```", text, re.S).group(1)
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


def test_readme_names_both_setup_commands():
    text = README.read_text()
    assert "make reproduce" in text and "make test" in text
