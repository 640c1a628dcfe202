"""Bounded memory: the largest input each reader accepts is parsed under a hard memory cap.

Each case writes a worst-case file just under its format's size limit (as many values as
fit, so the parser builds as many objects as it can), then loads it in a child process whose
address space is capped with ``resource.setrlimit(RLIMIT_AS)``. The child must finish (a
result or the project's own one-line error, never MemoryError or a kill) and its peak
resident memory must stay under :data:`RSS_BOUND_MB`.

Before this test, a Python-literal ``.alog`` just under the old 200 MB limit needed ~18 GB
(``ast.literal_eval`` builds a syntax tree of every number).
"""

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from roastlab.io.files import CONFIG_MAX_BYTES, MAX_INPUT_BYTES

resource = pytest.importorskip("resource")

#: Address-space cap of the child [bytes]: importing NumPy, SciPy and numba alone maps ~0.5 GB.
ADDRESS_SPACE_CAP = 2 * 1024**3
#: Peak resident memory allowed for parsing the largest accepted file of any format [MB].
RSS_BOUND_MB = 640


def _fill(head: str, item: str, sep: str, tail: str, limit: int) -> str:
    """``head + item sep item ... + tail`` with as many items as fit under ``limit`` bytes."""
    n = (limit - len(head) - len(tail) - 64) // (len(item) + len(sep))
    return head + sep.join([item] * n) + tail


def _rows(header: str, row, limit: int) -> str:
    """A CSV text of ``header`` and rows ``row(i)`` up to ``limit`` bytes."""
    parts, size, i = [header], len(header), 0
    while True:
        r = row(i)
        if size + len(r) > limit - 64:
            return "".join(parts)
        parts.append(r)
        size += len(r)
        i += 1


def _alog_python(limit):
    """A valid profile: three series of n samples (time up to 7 digits, temperatures '1.5')."""
    n = (limit - 200) // (len("1234567, ") + 2 * len("1.5, "))
    body = ", ".join(str(i) for i in range(n))  # strictly increasing time
    temps = ", ".join(["1.5"] * n)
    return "{'mode': 'C', 'timex': [" + body + "], 'temp1': [" + temps + "], 'temp2': [" + temps + "]}"


def _alog_day(limit):
    """A day-long profile sampled every 0.1 s up to the size limit (import resamples it)."""
    n = min((limit - 200) // (len("12345.6, ") + 2 * len("150.5, ")), 864_000)
    timex = ", ".join(f"{86_400 * i / (n - 1):.1f}" for i in range(n))
    temps = ", ".join(["150.5"] * n)
    return (
        "{'mode': 'C', 'timeindex': [0, 0, 0, 0, 0, 0, 0, 0], 'timex': ["
        + timex
        + "], 'temp1': ["
        + temps
        + "], 'temp2': ["
        + temps
        + "]}"
    )


def _alog_strings(limit):
    return _fill(
        "{'mode': 'C', 'timex': [0, 1], 'temp1': [1, 2], 'temp2': [1, 2], 'etypes': [", "'a\\'b'", ", ", "]}", limit
    )


def _roastime_series(limit):
    """A RoasTime log whose two temperature series fill the size limit."""
    n = (limit - 300) // (2 * len("150.5,"))
    temps = ",".join(["150.5"] * n)
    head = f'{{"sampleRate": 2, "weightGreen": "500", "roastStartIndex": 0, "roastEndIndex": {n}, '
    return head + f'"beanTemperature": [{temps}], "drumTemperature": [{temps}]}}'


def _roastime_actions(limit):
    """A RoasTime log of a few samples and as many operator actions as fit (one object each)."""
    return _fill(
        '{"sampleRate": 2, "weightGreen": 500, "beanTemperature": [20, 21, 22], "actions": {"actionTimeList": [',
        '{"ctrlType":0,"index":1,"value":5}',
        ",",
        "]}}",
        limit,
    )


def _parquet(path):
    """A Parquet log declaring the largest accepted row count (compressible columns: the file is small
    but decodes to the most memory any accepted Parquet file can)."""
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    from roastlab.io.importers.mapping import MAX_PARQUET_ROWS

    n = MAX_PARQUET_ROWS
    time = np.arange(n, dtype=float) * 0.04  # 2 million samples within a day
    table = pa.table({"t": time, "bt": np.full(n, 150.0), "et": np.full(n, 300.0), "flow": np.full(n, 0.01)})
    pq.write_table(table, path)
    return n


def _parquet_bomb(kind):
    """A small Parquet log whose ``bt`` column decodes to gigabytes: 2 million rows of 100-number
    lists (1.6 GB) or of 3,000-character strings (6 GB), written as repeated row groups that
    compress to a few MB. Refused from its footer, before a page is decoded."""

    def build(path):
        pa = pytest.importorskip("pyarrow")
        pq = pytest.importorskip("pyarrow.parquet")
        n, reps = 10_000, 200
        if kind == "lists":
            offsets = pa.array(np.arange(0, 100 * n + 1, 100, dtype=np.int32))
            bt = pa.ListArray.from_arrays(offsets, pa.array(np.full(100 * n, 150.0)))
        else:
            bt = pa.array(["x" * 3000] * n)
        table = pa.table({"t": np.arange(n, dtype=float), "bt": bt, "et": np.full(n, 300.0), "flow": np.full(n, 0.01)})
        with pq.ParquetWriter(path, table.schema) as writer:
            for _ in range(reps):
                writer.write_table(table)
        return n * reps

    return build


_PARQUET_LOADER = (
    "from roastlab.io.importers.mapping import import_log, map_from_mapping\n"
    "MAP = {'format': 'parquet', 'time': {'column': 't'}, 'Ta': {'column': 'bt'}, 'Tgi': {'column': 'et'},"
    " 'Gg': {'column': 'flow'}}\n"
    "load = lambda p: import_log(p, map_from_mapping(MAP, 'map'))"
)

CASES = {
    # name: (file name, text builder, loader source run in the child)
    "Aillio RoasTime JSON (series)": (
        "series.json",
        lambda: _roastime_series(MAX_INPUT_BYTES),
        "from roastlab.io.importers.roastime import read_roastime as load",
    ),
    "Aillio RoasTime JSON (actions)": (
        "actions.json",
        lambda: _roastime_actions(MAX_INPUT_BYTES),
        "from roastlab.io.importers.roastime import read_roastime as load",
    ),
    "Parquet log at the row limit (import)": ("big.parquet", _parquet, _PARQUET_LOADER),
    "Parquet bomb: 2 M rows of lists (refused)": ("bomb-lists.parquet", _parquet_bomb("lists"), _PARQUET_LOADER),
    "Parquet bomb: 2 M long strings (refused)": ("bomb-strings.parquet", _parquet_bomb("strings"), _PARQUET_LOADER),
    "batch CSV": (
        "big.csv",
        lambda: _rows("time_s,Gg_kg_s,Tgi_C,Ta_C\n", lambda i: f"{i / 20:.2f},0.4,400,30\n", MAX_INPUT_BYTES),
        "from roastlab.io.batch import read_batch_csv as load",
    ),
    "Artisan .alog (Python literal, numbers)": (
        "big.alog",
        lambda: _alog_python(MAX_INPUT_BYTES),
        "from roastlab.io.importers.artisan import read_alog as load",
    ),
    "Artisan .alog (Python literal, strings)": (
        "strings.alog",
        lambda: _alog_strings(MAX_INPUT_BYTES),
        "from roastlab.io.importers.artisan import read_alog as load",
    ),
    "Artisan .alog (JSON)": (
        "big-json.alog",
        lambda: _fill(
            '{"mode": "C", "timex": [0, 1], "temp1": [1, 2], "temp2": [1, 2], "x": [', "1", ",", "]}", MAX_INPUT_BYTES
        ),
        "from roastlab.io.importers.artisan import read_alog as load",
    ),
    "Artisan CSV export": (
        "export.csv",
        lambda: _rows(
            "Date:01.01.2026\tUnit:C\tCHARGE:00:00\tDROP:00:09\nTime1\tTime2\tET\tBT\tEvent\n",
            lambda i: f"{i // 60:02d}:{i % 60:02d}\t\t1\t1\t\n",
            MAX_INPUT_BYTES,
        ),
        "from roastlab.io.importers.artisan import read_artisan_csv as load",
    ),
    "model JSON": (
        "model.json",
        lambda: _fill('{"format": "roastlab-model/1", "x": [', "1", ",", "]}", MAX_INPUT_BYTES),
        "from roastlab.io.modelfile import read_model_document as load",
    ),
    "map TOML": (
        "map.toml",
        lambda: _fill('format = "auto"\nx = [', "1", ",", "]\n", CONFIG_MAX_BYTES),
        "from roastlab.io.importers import load_map as load",
    ),
    "scenario TOML": (
        "scenario.toml",
        lambda: _fill("[plant]\ntheta = { ", "hgm = 1", ", ", " }\n", CONFIG_MAX_BYTES),
        "from roastlab.io.scenario import load_scenario as load",
    ),
    "plant TOML (many tables)": (
        "plant.toml",
        lambda: _rows('name = "x"\n', lambda i: f"[t{i}]\n", CONFIG_MAX_BYTES),
        "from roastlab.io.plants import load_plant as load",
    ),
    "import with the finest resampling over a day": (
        "day.alog",
        lambda: _alog_day(MAX_INPUT_BYTES),
        "from roastlab.io.importers.mapping import import_log, map_from_mapping\n"
        "MAP = {'format': 'alog', 'resample_s': 0.1, 'Ta': {'column': 'BT'}, 'Tgi': {'column': 'ET'},"
        " 'Gg': {'constant_kg_s': 0.01}}\n"
        "load = lambda p: import_log(p, map_from_mapping(MAP, 'map'))",
    ),
}

CHILD = textwrap.dedent(
    """
    import json, resource, sys
    {loader}
    from roastlab.errors import RoastlabError
    resource.setrlimit(resource.RLIMIT_AS, ({cap}, {cap}))
    try:
        load(sys.argv[1])
        outcome = "loaded"
    except RoastlabError as exc:
        outcome = "refused: " + str(exc).split(": ", 1)[-1][:200]
    # VmHWM is the peak of this process image only; ru_maxrss would carry over the peak of the
    # pytest process that forked us (Linux keeps it across exec), which depends on test order.
    with open("/proc/self/status") as status:
        hwm_kb = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
    rss_mb = hwm_kb / 1024
    print(json.dumps({{"outcome": outcome, "rss_mb": rss_mb}}))
    """
)


@pytest.mark.parametrize("case", sorted(CASES))
def test_largest_accepted_input_parses_in_bounded_memory(case, tmp_path):
    name, build, loader = CASES[case]
    path = tmp_path / name
    if name.endswith(".parquet"):  # limited by its declared rows, not its (compressed) bytes
        build(path)
        size = path.stat().st_size
        assert size <= MAX_INPUT_BYTES
    else:
        path.write_text(build())
        size = path.stat().st_size
        limit = CONFIG_MAX_BYTES if name.endswith(".toml") else MAX_INPUT_BYTES
        assert limit * 0.9 < size <= limit, (case, size)  # the case really is at the limit
    proc = subprocess.run(
        [sys.executable, "-c", CHILD.format(loader=loader, cap=ADDRESS_SPACE_CAP), str(path)],
        capture_output=True,
        text=True,
        timeout=300,
        env={"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "PATH": "/usr/bin:/bin"},
    )
    assert proc.returncode == 0, (case, proc.stderr[-2000:])
    result = json.loads(proc.stdout.strip().splitlines()[-1])
    assert "MemoryError" not in result["outcome"], result
    assert result["rss_mb"] <= RSS_BOUND_MB, (case, result)
    if name.startswith("bomb"):
        assert result["outcome"].startswith("refused") and "not one number per row" in result["outcome"], result
    print(f"{case}: {size / 1e6:.1f} MB file, peak RSS {result['rss_mb']:.0f} MB, {result['outcome'][:80]}")
