"""Property-based fuzzing: every loader either returns or raises the project's own error.

Inputs are random bytes, random text and mutations (cut, insert, replace) of valid files, so
the fuzzer spends its time near the formats rather than on noise alone.
"""

import json
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from roastlab.errors import RoastlabError
from roastlab.fleet.store import read_manifest
from roastlab.io.batch import read_batch_csv, read_dataset
from roastlab.io.fitspec import load_fit_spec
from roastlab.io.importers import import_log, load_map
from roastlab.io.importers.artisan import read_alog, read_artisan_csv
from roastlab.io.importers.mapping import map_from_mapping
from roastlab.io.importers.roastime import read_roastime
from roastlab.io.modelfile import read_model_document
from roastlab.io.plants import load_plant
from roastlab.io.scenario import load_scenario

VALID = {
    ".csv": "# Mb_kg = 0.2\ntime_s,Gg_kg_s,Tgi_C,Ta_C\n0,0.4,450,30\n30,0.41,449,40\n60,0.4,447,55\n",
    ".alog": repr(
        {
            "mode": "F",
            "timex": [0.0, 1.5, 3.0, 4.5],
            "temp1": [300.0, 301.0, -1, 303.0],
            "temp2": [250.0, 251.0, 252.0, 253.0],
            "timeindex": [1, 0, 0, 0, 0, 0, 3, 0],
            "weight": [200, 0, "g"],
            "specialevents": [1, 2],
            "specialeventstype": [3, 0],
            "specialeventsvalue": [8.0, 5.5],
            "etypes": ["Air", "Drum", "Damper", "Burner", "--"],
            "extratimex": [[0.0, 1.5, 3.0, 4.5]],
            "extraname1": ["Inlet"],
            "extratemp1": [[600.0, 610.0, 620.0, 630.0]],
            "extraname2": ["Fan"],
            "extratemp2": [[1, 2, 3, 4]],
            "extraNoneTempHint2": [True],
        }
    ),
    ".export.csv": "Date:01.01.2026\tUnit:F\tCHARGE:00:02\tDROP:00:08\nTime1\tTime2\tET\tBT\tEvent\n00:00\t\t300\t250\t\n00:02\t00:00\t301\t240\t\n00:05\t00:03\t302\t245\t\n00:08\t00:06\t303\t250\t\n",
    ".map.toml": 'format = "auto"\nresample_s = 2\n[time]\ncolumn = "time_s"\nunit = "s"\n[Ta]\ncolumn = "Ta_C"\nunit = "F"\n[Tgi]\ncolumn = "Tgi_C"\noffset_C = 5\n[Gg]\ncolumn = "Gg_kg_s"\nunit = "kg/h"\n',
    ".plant.toml": 'name = "x"\nMb_kg = 1\nDch_m = 0.3\nLch_m = 0.4\nHflap_m = 0.02\nSflap_m = 0.1\nMm_kg = 20\n[process]\nKt = 0.02\n"Ha/R" = 5000\n',
    ".json": json.dumps({"hgm": 0.02, "hbm": 0.03, "Pbm": 0.6, "SSR": 1.0, "Tm0_C": [100, 120], "batches": ["a", "b"]}),
    ".roastime.json": json.dumps(
        {
            "sampleRate": 2,
            "roastStartIndex": 0,
            "roastEndIndex": 6,
            "beanTemperature": [150, 140, 120, 110, 115, 120],
            "drumTemperature": [240, 25, 60, 80, 95, 105],
            "weightGreen": "490",
            "drumChargeTemperature": 240,
            "indexFirstCrackStart": 4,
            "actions": {
                "actionTimeList": [{"index": 1, "value": 6, "ctrlType": 0}, {"index": 2, "value": 2, "ctrlType": 1}]
            },
        }
    ),
    ".fit.toml": "[free]\nhgm = [0.001, 1.0, 0.02]\nTm0_C = { lower = 60, upper = 300, start = 170, per_batch = true }\n[fixed]\nKt = 0.02\n[initial]\nTb0_C = 22\n[weights]\nTa = 1\nTb2 = 0.5\n",
    ".manifest.csv": "path,machine,plant,started_at,map\nlogs/a.alog,m1,120kg,2024-01-01T08:00:00,map.toml\n"
    "b.csv,m2,360kg,2024-01-02 09:30+02:00,\n",
    ".scenario.toml": 'name = "s"\n[plant]\nmass_factor = 1.2\nTm0_offset_C = -30\ntheta_factor = { hgm = 0.8 }\n'
    "[sensor]\nnoise_C = 0.5\ndelay_s = 2\nseed = 7\n[actuator]\nTgi_min_C = 150\nTgi_max_C = 550\nsample_s = 5\n",
}


ROASTIME_MAP = map_from_mapping(
    {
        "format": "roastime",
        "Ta": {"column": "beanTemperature"},
        "Tgi": {"constant_C": 22.0},
        "Gg": {"identify": True},
        "heater": {"column": "heater", "unit": "level"},
        "fan": {"column": "fan", "unit": "level"},
        "Tb2": {"column": "drumTemperature", "start_s": 1.0},
        "initial": {"Tm0_C": "drumChargeTemperature"},
    },
    "fuzz map",
)


def mutated(kind):
    base = VALID[kind]
    return st.tuples(
        st.integers(0, len(base)),
        st.integers(0, 40),
        st.text(max_size=30),
        st.sampled_from(["cut", "insert", "replace", "truncate"]),
    ).map(lambda a: _mutate(base, *a))


def _mutate(base, i, n, text, how):
    if how == "cut":
        return base[:i] + base[i + n :]
    if how == "insert":
        return base[:i] + text + base[i:]
    if how == "replace":
        return base[:i] + text + base[i + len(text) :]
    return base[:i]


# Structured inputs: well-formed documents with the right keys and values of any type, so the
# loaders' type and range checks are exercised, not only their parsers.
SCALARS = st.one_of(
    st.booleans(),
    st.integers(-(10**6), 10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    # huge numbers: beyond float range, beyond int64, at the edges of float
    st.integers(10**18, 10**400),
    st.sampled_from([1e308, -1e308, 5e-324, -0.0, 2**63, -(2**63) - 1]),
)
VALUES = st.recursive(
    SCALARS, lambda c: st.lists(c, max_size=6) | st.dictionaries(st.text(max_size=6), c, max_size=4), max_leaves=12
)
NUMBER_LISTS = st.lists(st.one_of(st.floats(-1e4, 1e4), st.integers(-5, 500), st.just(-1)), max_size=12)

KEYS = {
    ".map.toml": {
        "format": VALUES,
        "resample_s": VALUES,
        "keep_after_drop": VALUES,
        "time": st.fixed_dictionaries({}, optional={"column": VALUES, "unit": VALUES}),
        "Ta": st.fixed_dictionaries({}, optional={"column": VALUES, "unit": VALUES, "offset_C": VALUES}),
        "Tgi": st.fixed_dictionaries({}, optional={"column": VALUES, "unit": VALUES, "offset_C": VALUES}),
        "Gg": st.fixed_dictionaries(
            {},
            optional={
                "column": VALUES,
                "unit": VALUES,
                "density_kg_m3": VALUES,
                "constant_kg_s": VALUES,
                "identify": VALUES,
                "pitot": st.dictionaries(
                    st.sampled_from(["dp_column", "T_column", "section_m2", "rho0_kg_m3", "T_unit"]), VALUES
                ),
            },
        ),
    },
    ".plant.toml": {
        k: st.one_of(VALUES, st.floats(-10, 10))
        for k in ("name", "Mb_kg", "Dch_m", "Lch_m", "Hflap_m", "Sflap_m", "Mm_kg")
    }
    | {"process": st.dictionaries(st.sampled_from(["A", "cm", "Kt", "Ha/R", "lambda", "warp"]), VALUES, max_size=3)},
    ".scenario.toml": {
        "name": VALUES,
        "plant": st.dictionaries(
            st.sampled_from(["mass_factor", "X0", "Tm0_C", "Tm0_offset_C", "Gg_factor", "theta", "warp"]),
            VALUES,
            max_size=3,
        ),
        "sensor": st.dictionaries(st.sampled_from(["noise_C", "delay_s", "seed", "warp"]), VALUES, max_size=3),
        "actuator": st.dictionaries(
            st.sampled_from(["decide", "Tgi_min_C", "Tgi_max_C", "sample_s", "heater_min", "warp"]), VALUES, max_size=3
        ),
    },
    ".fit.toml": {
        "free": st.dictionaries(st.sampled_from(["hgm", "Pbm", "Tm0_C", "Gg_kg_s", "warp"]), VALUES, max_size=3),
        "fixed": st.dictionaries(st.sampled_from(["Kt", "hbm", "warp"]), VALUES, max_size=2),
        "initial": st.dictionaries(st.sampled_from(["Tb0_C", "X0", "warp"]), VALUES, max_size=2),
        "weights": st.one_of(VALUES, st.dictionaries(st.sampled_from(["Ta", "Tb2", "warp"]), VALUES, max_size=2)),
    },
    ".json": {
        "hgm": VALUES,
        "hbm": VALUES,
        "Pbm": st.one_of(VALUES, st.floats(-1, 2)),
        "SSR": VALUES,
        "batches": VALUES,
    },
    ".roastime.json": {
        "sampleRate": st.one_of(VALUES, st.floats(-1, 1e4)),
        "roastStartIndex": st.one_of(VALUES, st.integers(-3, 10)),
        "roastEndIndex": st.one_of(VALUES, st.integers(-3, 10)),
        "beanTemperature": st.one_of(VALUES, NUMBER_LISTS),
        "drumTemperature": st.one_of(VALUES, NUMBER_LISTS),
        "weightGreen": st.one_of(VALUES, st.sampled_from(["0", "490", "-5", "1e999", ""])),
        "ibtsTemperature": st.one_of(VALUES, NUMBER_LISTS),  # RoastWorld's export: the IR, no sampleRate
        "totalRoastTime": st.one_of(VALUES, st.floats(-1, 1e6)),
        "ambient": VALUES,
        "drumChargeTemperature": VALUES,
        "indexFirstCrackStart": VALUES,
        "actions": st.one_of(
            VALUES,
            st.lists(  # RoastWorld's export: [{type, second, setting}]
                st.fixed_dictionaries(
                    {},
                    optional={
                        "type": st.one_of(VALUES, st.sampled_from(["Power", "Blower", "Drum", "fan", ""])),
                        "second": st.one_of(VALUES, st.floats(-5, 1e5), st.sampled_from([1e308, -1e308, 1e20])),
                        "setting": VALUES,
                    },
                ),
                max_size=4,
            ),
            st.fixed_dictionaries(
                {
                    "actionTimeList": st.lists(
                        st.fixed_dictionaries(
                            {},
                            optional={
                                "index": VALUES,
                                "value": VALUES,
                                "ctrlType": st.one_of(VALUES, st.integers(0, 3)),
                            },
                        ),
                        max_size=4,
                    )
                }
            ),
        ),
    },
    ".alog": {
        "mode": st.one_of(VALUES, st.sampled_from(["C", "F"])),
        "timex": st.one_of(VALUES, NUMBER_LISTS),
        "temp1": st.one_of(VALUES, NUMBER_LISTS),
        "temp2": st.one_of(VALUES, NUMBER_LISTS),
        "timeindex": st.one_of(VALUES, st.lists(st.integers(-2, 15), max_size=8)),
        "weight": VALUES,
        "etypes": VALUES,
        "specialevents": st.one_of(VALUES, NUMBER_LISTS),
        "specialeventstype": st.one_of(VALUES, NUMBER_LISTS),
        "specialeventsvalue": st.one_of(VALUES, NUMBER_LISTS),
        "extratimex": VALUES,
        "extraname1": VALUES,
        "extratemp1": VALUES,
        "extraNoneTempHint1": VALUES,
    },
}


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if v != v else ("inf" if v == float("inf") else ("-inf" if v == float("-inf") else repr(v)))
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return "{ " + ", ".join(f"{json.dumps(k)} = {_toml_value(x)}" for k, x in v.items()) + " }"


def _toml(doc: dict) -> str:
    return "".join(f"{json.dumps(k)} = {_toml_value(v)}\n" for k, v in doc.items())


def structured(kind):
    doc = st.fixed_dictionaries({}, optional=KEYS[kind])
    if kind.endswith(".toml"):
        return doc.map(_toml)
    if kind == ".json":
        return doc.map(lambda d: json.dumps(d, allow_nan=True))
    return st.one_of(doc.map(repr), doc.map(lambda d: json.dumps(d, allow_nan=True)))


def deeply_nested(kind):
    """A valid file with a deep nest of brackets, braces or tuples inserted somewhere."""
    base = VALID[kind]
    return st.tuples(
        st.integers(0, len(base)), st.integers(1, 5000), st.sampled_from(["[", '{"a": ', "(", "[{'a': "])
    ).map(lambda a: base[: a[0]] + a[2] * a[1] + base[a[0] :])


def huge_number_text(kind):
    """A valid file with a number of hundreds of digits (or an exponent far out of range) inserted."""
    base = VALID[kind]
    return st.tuples(
        st.integers(0, len(base)),
        st.sampled_from(["9" * 5000, "1e999999", "-1e-999999", "0x" + "f" * 400, "1" + "0" * 400 + ".5"]),
    ).map(lambda a: base[: a[0]] + a[1] + base[a[0] :])


def content(kind):
    options = [
        mutated(kind),
        mutated(kind),
        st.text(max_size=400),
        st.binary(max_size=400),
        deeply_nested(kind),
        huge_number_text(kind),
    ]
    if kind in KEYS:
        options += [structured(kind)] * 3
    return st.one_of(*options)


def run_loader(kind, data, loader):
    with tempfile.TemporaryDirectory() as tmp:
        suffix = {
            ".export.csv": ".csv",
            ".map.toml": ".toml",
            ".plant.toml": ".toml",
            ".fit.toml": ".toml",
            ".scenario.toml": ".toml",
            ".roastime.json": ".json",
            ".manifest.csv": ".csv",
        }.get(kind, kind)
        path = Path(tmp) / f"fuzz{suffix}"
        if isinstance(data, bytes):
            path.write_bytes(data)
        else:
            path.write_text(data, encoding="utf-8", errors="surrogatepass") if _encodable(data) else path.write_bytes(
                data.encode("utf-8", "replace")
            )
        try:
            loader(path)
        except RoastlabError:
            pass


def _encodable(text):
    try:
        text.encode("utf-8")
        return True
    except UnicodeEncodeError:
        return False


FUZZ = settings(max_examples=300, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])


LOADERS = {
    ".csv": [read_batch_csv, lambda p: import_log(p, None)],
    ".alog": [read_alog, lambda p: import_log(p, None)],
    ".export.csv": [read_artisan_csv],
    ".map.toml": [load_map],
    ".plant.toml": [load_plant],
    ".json": [read_model_document],
    ".fit.toml": [load_fit_spec],
    ".scenario.toml": [load_scenario],
    ".roastime.json": [read_roastime, lambda p: import_log(p, ROASTIME_MAP)],
    ".manifest.csv": [read_manifest],
}


@pytest.mark.parametrize("kind", sorted(LOADERS))
def test_fuzz_loader(kind):
    """Each loader, on 300 generated files of its format, returns or raises RoastlabError."""

    @FUZZ
    @given(content(kind))
    def check(data):
        for loader in LOADERS[kind]:
            run_loader(kind, data, loader)

    check()


@settings(max_examples=60, deadline=None, derandomize=True)
@given(content(".plant.toml"))
def test_fuzz_dataset_folder(data):
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "dataset.toml").write_text(
            'plant = "120kg"\n[[batch]]\nfile = "b.csv"\n' if isinstance(data, bytes) else data[:200], errors="replace"
        )
        (folder / "b.csv").write_text(VALID[".csv"])
        try:
            read_dataset(folder)
        except RoastlabError:
            pass


SPECIAL = ["fifo", "/dev/zero", "/dev/null", "directory", "symlink to /dev/zero", "dangling symlink"]


@pytest.mark.parametrize("special", SPECIAL)
@pytest.mark.parametrize("kind", sorted(LOADERS))
def test_special_files_are_refused_without_hanging(kind, special, tmp_path):
    """Pipes, devices, folders and odd links given as any input: one RoastlabError, at once."""
    import os
    import signal

    path = tmp_path / f"x{kind}"
    if special == "fifo":
        os.mkfifo(path)
    elif special == "directory":
        path.mkdir()
    elif special == "symlink to /dev/zero":
        path.symlink_to("/dev/zero")
    elif special == "dangling symlink":
        path.symlink_to(tmp_path / "nowhere")
    else:
        path = Path(special)

    def hang(*_):
        raise AssertionError(f"{kind} loader hung on {special}")

    old = signal.signal(signal.SIGALRM, hang)
    signal.alarm(10)
    try:
        for loader in LOADERS[kind]:
            with pytest.raises(RoastlabError):
                loader(path)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


NAME_CHARS = st.characters(blacklist_characters="/\x00", blacklist_categories=("Cs",))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.text(NAME_CHARS, min_size=1, max_size=24).filter(lambda n: n not in (".", "..")))
def test_fuzz_control_characters_in_names_stay_data(name):
    """A log named with newlines, tabs, escapes or any Unicode imports into a batch CSV whose
    header and rows are the same as for a plain name: the name never becomes structure."""
    from roastlab.cli import main
    from roastlab.io.batch import read_batch_csv as read

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "map.toml").write_text('[Ta]\ncolumn = "BT"\n[Tgi]\ncolumn = "ET"\n[Gg]\nconstant_kg_s = 0.01\n')
        outs = []
        for stem in ("plain", name):
            log = folder / f"{stem}.alog"
            try:
                log.write_text(VALID[".alog"])
            except OSError:  # a name the file system refuses (too long in bytes)
                return
            out = folder / f"out-{len(outs)}.csv"
            assert main(["import", str(log), "--map", str(folder / "map.toml"), "--out", str(out)]) == 0
            outs.append(out)
        a, b = read(outs[0]), read(outs[1])
        assert np.array_equal(a.time_s, b.time_s) and np.array_equal(a.Ta_C, b.Ta_C)
        lines = [ln for ln in outs[1].read_text().splitlines() if not ln.startswith("#")]
        assert lines == [ln for ln in outs[0].read_text().splitlines() if not ln.startswith("#")]


PARQUET_MAP = map_from_mapping(
    {
        "format": "parquet",
        "time": {"column": "t"},
        "Ta": {"column": "bt"},
        "Tgi": {"column": "et"},
        "Gg": {"column": "flow"},
    },
    "fuzz map",
)


@pytest.fixture(scope="module")
def parquet_bytes():
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    import io

    buf = io.BytesIO()
    n = 40
    table = pa.table(
        {
            "t": np.arange(n) * 2.0,
            "bt": np.linspace(150, 200, n),
            "et": np.full(n, 300.0),
            "flow": np.full(n, 0.01),
            "note": ["x"] * n,
        }
    )
    pq.write_table(table, buf)
    return buf.getvalue()


def test_fuzz_parquet(parquet_bytes):
    """A Parquet log with bytes flipped, cut or inserted (footer and pages alike): a batch or a
    RoastlabError, never a crash or a pyarrow exception."""

    @FUZZ
    @given(
        st.lists(st.tuples(st.integers(0, len(parquet_bytes) - 1), st.integers(0, 255)), min_size=1, max_size=8),
        st.one_of(st.none(), st.integers(8, len(parquet_bytes))),
    )
    def check(flips, cut):
        raw = bytearray(parquet_bytes)
        for i, b in flips:
            raw[i] = b
        if cut is not None:
            raw = raw[:cut] + raw[-8:]  # keep the magic and footer length, lose the middle
        run_loader(".parquet", bytes(raw), lambda p: import_log(p, PARQUET_MAP))

    check()


#: The text options of the newer commands, each with the function that reads it.
def _option_readers():
    import argparse

    from roastlab.cli.common import bed_arg, count_arg, float_arg, level_arg
    from roastlab.workflows.whatif import parse_set, parse_setting_change

    return {
        "whatif --set": parse_set,
        "whatif --heater": lambda t: parse_setting_change("heater", t, "level"),
        "--bed / --variant": bed_arg,
        "validate --band": level_arg,
        "fleet --wait": count_arg("--wait", 0, 86_400),
        "transfer --tgi-rate": float_arg("--tgi-rate"),
    }, argparse.ArgumentTypeError


OPTION_TEXT = st.one_of(
    st.text(max_size=40),
    st.from_regex(r"(heater|fan|x)?=?[+\-x*]?[0-9.eE+\-]{0,12}(@[0-9:.\-]{0,8})?", fullmatch=True),
    st.from_regex(
        r"(contact|probe|probe_gas)=(paper|wall|rest|tumbling|mean|outlet|\w{0,5})(,.{0,12})?", fullmatch=True
    ),
)


@pytest.mark.parametrize("option", sorted(_option_readers()[0]))
def test_fuzz_option_text(option):
    """Any text given to a newer command's option is read or refused with the project's error (or
    argparse's one line), never a ValueError, an overflow or a traceback."""
    readers, arg_error = _option_readers()
    read = readers[option]

    @FUZZ
    @given(OPTION_TEXT)
    def check(text):
        try:
            read(text)
        except (RoastlabError, arg_error):
            pass

    check()


def _damaged(doc: dict, rng) -> dict:
    """``doc`` (a real log's dict) with one to three keys damaged as logs get damaged: a key gone, a
    value of another type or out of range, a series cut short, lengthened, scaled or with one sample
    replaced or two swapped, a field inside a nested dict replaced."""
    import copy

    odd = [None, "", "x", -1, 0, 1e308, [], {}, [1, 2], "12", True, -5.5, [None, "a"], 10**30]
    doc = copy.deepcopy(doc)
    for _ in range(int(rng.integers(1, 4))):
        key = list(doc)[int(rng.integers(len(doc)))]
        value, op = doc[key], int(rng.integers(8))
        series = isinstance(value, list) and len(value) > 1
        if op == 0:
            del doc[key]
        elif op == 1:
            doc[key] = odd[int(rng.integers(len(odd)))]
        elif op == 2 and series:
            doc[key] = value[: int(rng.integers(len(value)))]
        elif op == 3 and series:
            value[int(rng.integers(len(value)))] = odd[int(rng.integers(len(odd)))]
        elif op == 4 and series:
            i, j = rng.integers(len(value), size=2)
            value[i], value[j] = value[j], value[i]
        elif op == 5 and series and all(isinstance(v, (int, float)) for v in value[:5]):
            scale = [-1, 0, 1e6, 1 / 3, 9.0, -300][int(rng.integers(6))]
            doc[key] = [v * scale if isinstance(v, (int, float)) else v for v in value]
        elif op == 6 and series:
            doc[key] = value + value[: int(rng.integers(len(value)))]
        elif op == 7 and isinstance(value, dict) and value:
            value[list(value)[int(rng.integers(len(value)))]] = odd[int(rng.integers(len(odd)))]
    return doc


@pytest.mark.slow
def test_damaged_real_logs_are_set_up_or_refused_in_one_line_naming_them(cli, tmp_path):
    """80 real logs of both machines, each damaged at the level of its keys and series (where the
    byte-level fuzzing above rarely reaches: the survey of channels, events and weights), through
    ``roastlab init`` alone in a folder: it sets the log up or exits 2 with one line that names it;
    never a traceback, a warning or another exit code."""
    import ast

    from conftest import REAL_DATA

    logs = sorted((REAL_DATA / "skywalker").glob("*.alog")) + sorted((REAL_DATA / "bullet").glob("*.json"))
    if not logs:
        pytest.skip("../shared/data/real is absent")
    docs = {p: ast.literal_eval(p.read_text()) if p.suffix == ".alog" else json.loads(p.read_text()) for p in logs}
    rng = np.random.default_rng(20261130)
    refused = 0
    for k in range(80):
        path = logs[int(rng.integers(len(logs)))]
        doc = _damaged(docs[path], rng)
        folder = tmp_path / f"log{k}"
        folder.mkdir()
        log = folder / path.name
        log.write_text(repr(doc) if path.suffix == ".alog" else json.dumps(doc))
        code, _, err = cli("init", folder, "--out", tmp_path / f"cfg{k}")
        assert code in (0, 2), (log, code, err[-500:])
        if code == 2:
            lines = err.strip().splitlines()
            assert len(lines) == 1 and log.name in lines[0], (log, err[-500:])
            refused += 1
    assert 0 < refused < 80  # the damage both refuses logs and leaves some readable
