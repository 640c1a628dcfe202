"""Compiled code cannot go stale: an edit to the right-hand side alone reaches the cached kernels."""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import roastlab
from roastlab.sim import cache

SRC = Path(roastlab.__file__).parent
RUN = (
    "import numpy as np, roastlab; t = np.arange(0, 901, 30.0); "
    "print(repr(float(roastlab.simulate('120kg', t, np.full_like(t, 0.4), np.full_like(t, 450.0)).Tb_C[-1])))"
)


def test_every_compiled_module_uses_the_keyed_cache():
    """numba's own cache=True (keyed on one file) appears nowhere, also not as an overload's
    ``jit_options={"cache": True}``; every module that compiles code or holds code compiled into a
    kernel lies in a subpackage the hash covers."""
    for path in SRC.rglob("*.py"):
        text = path.read_text()
        rel = path.relative_to(SRC)
        if path.name != "cache.py":
            assert not re.search(r"njit\(|[\"']?cache[\"']?\s*[=:]\s*True", text), (
                f"{rel}: use roastlab.sim.cache.compiled"
            )
        if re.search(r"@compiled|register_jitable", text):
            assert rel.parts[0] in cache.COMPILED_SOURCES, rel


def _run(root: Path, cache_home: Path) -> str:
    env = {"PYTHONPATH": str(root), "XDG_CACHE_HOME": str(cache_home), "PATH": "/usr/bin:/bin"}
    proc = subprocess.run([sys.executable, "-c", RUN], capture_output=True, text=True, env=env, timeout=300, cwd=root)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout.strip()


@pytest.mark.slow
def test_an_edit_to_the_right_hand_side_reaches_the_cached_kernels(tmp_path):
    """A copy of the package, run, edited in rhs.py only (the bean solids' heat capacity doubled),
    run again with the same cache folder: the answer changes. With numba's per-file cache the
    kernels in kernels.py would have loaded their stale compiled code and printed the old value."""
    copy = tmp_path / "src"
    shutil.copytree(SRC, copy / "roastlab", ignore=shutil.ignore_patterns("__pycache__"))
    home = tmp_path / "cache"
    before = _run(copy, home)
    again = _run(copy, home)  # unchanged: the same value, from the same cache folder
    assert again == before
    assert len(list((home / "roastlab" / "numba").iterdir())) == 1
    # the same sources at another path (a fresh clone, the installed wheel) load those kernels:
    # numba rewrites a kernel's index when it compiles it, so no file of the cache changes
    files = {p: p.stat().st_mtime_ns for p in (home / "roastlab").rglob("*") if p.is_file()}
    elsewhere = tmp_path / "elsewhere"
    shutil.copytree(copy, elsewhere)
    assert _run(elsewhere, home) == before
    assert {p: p.stat().st_mtime_ns for p in (home / "roastlab").rglob("*") if p.is_file()} == files
    # nothing in numba's per-file cache beside the sources: it would outlive an edit to the layout
    assert not [p.name for p in copy.rglob("*.nb[ic]")]
    rhs = copy / "roastlab" / "model" / "rhs.py"
    text = rhs.read_text()
    assert "cs = 1.099 + 0.007 * Tb" in text
    rhs.write_text(text.replace("cs = 1.099 + 0.007 * Tb", "cs = 2.0 * (1.099 + 0.007 * Tb)"))
    after = _run(copy, home)
    assert float(after) < float(before) - 5.0, (before, after)  # twice the heat capacity: cooler beans
    assert len(list((home / "roastlab" / "numba").iterdir())) == 2


@pytest.mark.parametrize("given, expected", [(None, "PASSIVE"), ("ACTIVE", "ACTIVE")])
def test_numba_threads_sleep_between_calls_unless_the_environment_says_otherwise(given, expected):
    """Importing roastlab sets OpenMP's wait policy for numba's threads (roastlab.sim.OMP_WAIT_POLICY)
    before the OpenMP runtime loads, which reads it once: spinning workers waited for on a core another
    process wants made dataset-I's identification on 2 cores 2.7x slower than on one
    (docs/performance.md). A policy the user's environment names is kept."""
    env = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"}
    if given is not None:
        env["OMP_WAIT_POLICY"] = given
    code = (
        "import os, roastlab; "
        "maps = open('/proc/self/maps').read() if os.path.exists('/proc/self/maps') else ''; "
        "print(os.environ.get('OMP_WAIT_POLICY'), 'libgomp' in maps)"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    policy, loaded = out.stdout.split()
    assert policy == expected
    assert loaded == "False", "OpenMP was loaded before roastlab.sim could set its wait policy"


def test_a_literal_entry_is_kept_per_value_and_per_argument_types():
    """``literal_entry`` compiles once per constant and per the arguments' types, and hands back the
    kept entry when called again with the same (the sensitivities ask for it at every Jacobian)."""
    import numba
    import numpy as np

    @numba.njit
    def scaled(x, k):
        numba.literally(k)
        return x * k

    a = np.ones(3)
    two = cache.literal_entry(scaled, (a, 2), 1)
    assert cache.literal_entry(scaled, (np.zeros(3), 2), 1) is two and two(a, 2)[0] == 2.0
    three = cache.literal_entry(scaled, (a, 3), 1)
    assert three is not two and three(a, 3)[0] == 3.0
    single = cache.literal_entry(scaled, (a.astype(np.float32), 2), 1)
    assert single is not two and single(a.astype(np.float32), 2).dtype == np.float32
    assert len(scaled.overloads) == 3
