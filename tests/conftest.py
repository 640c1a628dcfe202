import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
REAL_DATA = SHARED / "data" / "real"


@pytest.fixture
def real_data():
    folder = REAL_DATA / "skywalker"
    if not folder.is_dir():
        pytest.skip("../shared/data/real is absent")
    return folder


@pytest.fixture
def cli(tmp_path):
    """Run the CLI in-process; returns (exit code, stdout, stderr)."""
    from roastlab.cli import main

    def run(*args, capsys=None):
        import contextlib
        import io

        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main([str(a) for a in args])
            except SystemExit as exc:
                code = exc.code
        return code, out.getvalue(), err.getvalue()

    return run


os.environ.setdefault("MPLBACKEND", "Agg")
