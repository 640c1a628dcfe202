import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
REAL_DATA = SHARED / "data" / "real"


def pytest_configure(config):
    """Under pytest-xdist, each worker's numba loops on its share of the cores: ``make test`` runs a
    worker per core, and each worker's parallel loops would otherwise start a thread per core too, so
    2 workers on 2 cores ran 4 busy threads (four fitting tests together took 98 s against 54 s with a
    thread per worker, 2026-11-28). Set in each worker's main thread, where the tests run; a test that
    asks for threads (``fleet --threads``) still gets them."""
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    if workers > 1:
        import numba

        numba.set_num_threads(max(1, numba.config.NUMBA_NUM_THREADS // workers))


#: Artisan's special-event lists (one entry per event).
EVENT_KEYS = ("specialevents", "specialeventstype", "specialeventsvalue", "specialeventsStrings")


def rewritten_alog(src: Path, dst: Path, edit) -> Path:
    """``src`` (an Artisan profile: a Python literal) with ``edit(doc)`` applied, written to ``dst``:
    a shared log changed into the case a test needs, the shared file untouched."""
    import ast

    doc = ast.literal_eval(src.read_text(encoding="utf-8"))
    edit(doc)
    dst.write_text(repr(doc), encoding="utf-8")
    return dst


def event_steps(doc: dict, event_type: int) -> list[float]:
    """The step series ``doc``'s special events of ``event_type`` make, per sample, as the machine would
    report the setting (its external value; before the first change, the first one)."""
    import numpy as np

    from roastlab.io.importers.artisan import events_internal_to_external

    s = np.full(len(doc["timex"]), np.nan)
    for i, t, v in zip(doc["specialevents"], doc["specialeventstype"], doc["specialeventsvalue"]):
        if t == event_type:
            s[i:] = events_internal_to_external(v)
    return [float(x) for x in np.where(np.isnan(s), s[np.isfinite(s)][0], s)]


def drop_events(doc: dict, event_type: int | None = None) -> None:
    """Remove ``doc``'s special events of ``event_type`` (an index into ``etypes``), or all of them."""
    keep = [k for k, t in enumerate(doc["specialeventstype"]) if event_type is not None and t != event_type]
    for key in EVENT_KEYS:
        doc[key] = [doc[key][k] for k in keep]


@pytest.fixture
def real_data():
    folder = REAL_DATA / "skywalker"
    if not folder.is_dir():
        pytest.skip("../shared/data/real is absent")
    return folder


def printed_percent(out: str, label: str) -> float:
    """The percentage a command printed right after ``label`` (fit-roaster's "held out: FIT ",
    "baseline: ", "band:"), read up to its " %"."""
    return float(out.split(label)[1].split(" %")[0])


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
