"""Every kind of bad input: one line on stderr naming the file and the problem, exit code 2,
no traceback, no output file (not even a partial or temporary one)."""

import ast
import functools
import json
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest

from roastlab.io.files import MAX_INPUT_BYTES
from roastlab.workflows.reproduce import default_dataset_root

DATA = default_dataset_root()
HEADER = "time_s,Gg_kg_s,Tgi_C,Ta_C\n"
GOOD_ROWS = "".join(f"{t},0.4,450,{30 + t / 10}\n" for t in range(0, 301, 30))
GOOD_ALOG = repr(
    {
        "mode": "C",
        "timex": [1.5 * i for i in range(80)],  # 1:49 from CHARGE to DROP: a roast init sets up (over a minute)
        "temp1": [150.0 + 0.5 * i for i in range(80)],
        "temp2": [120.0 + 0.25 * i for i in range(80)],
        "timeindex": [2, 0, 0, 0, 0, 0, 75, 0],
        "weight": [200, 0, "g"],
    }
)
SKY_MAP = '[Ta]\ncolumn = "BT"\n[Tgi]\ncolumn = "ET"\n[Gg]\nidentify = true\n'


def simulate_with(tmp_path, name, content):
    f = tmp_path / name
    f.write_text(content) if isinstance(content, str) else f.write_bytes(content)
    return ["simulate", "--plant", "120kg", "--inputs", f, "--out", tmp_path / "out.csv"]


def import_with(tmp_path, name, content, map_text=SKY_MAP):
    f = tmp_path / name
    f.write_text(content) if isinstance(content, str) else f.write_bytes(content)
    m = tmp_path / "map.toml"
    m.write_text(map_text)
    return ["import", f, "--map", m, "--out", tmp_path / "out.csv"]


def theta_with(tmp_path, payload):
    good = tmp_path / "good.csv"
    good.write_text(HEADER + GOOD_ROWS)
    t = tmp_path / "theta.json"
    t.write_text(payload)
    return ["simulate", "--plant", "120kg", "--inputs", good, "--out", tmp_path / "out.csv", "--theta", t]


def plant_with(tmp_path, toml):
    good = tmp_path / "good.csv"
    good.write_text(HEADER + GOOD_ROWS)
    p = tmp_path / "plant.toml"
    p.write_text(toml)
    return ["simulate", "--plant", p, "--inputs", good, "--out", tmp_path / "out.csv"]


PLANT = "Mb_kg = 120\nDch_m = 1.24\nLch_m = 1.335\nHflap_m = 0.3\nSflap_m = 0.1\nMm_kg = 2000\n"

CASES = {
    # batch CSVs
    "empty file": (lambda d: simulate_with(d, "b.csv", ""), "b.csv", "empty file"),
    "header only": (lambda d: simulate_with(d, "b.csv", HEADER), "b.csv", "header only"),
    "missing column": (
        lambda d: simulate_with(d, "b.csv", "time_s,Gg_kg_s\n0,0.4\n"),
        "b.csv",
        "missing column(s) Tgi_C",
    ),
    "duplicated column": (
        lambda d: simulate_with(d, "b.csv", "time_s,Gg_kg_s,Tgi_C,Tgi_C\n0,0.4,450,450\n"),
        "b.csv",
        "duplicated column 'Tgi_C'",
    ),
    "non-numeric cell": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,450,30\n30,0.4,hot,30\n"),
        "b.csv",
        "line 3, column Tgi_C: not a number",
    ),
    "NaN": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,450,30\n30,NaN,450,30\n"),
        "b.csv",
        "line 3, column Gg_kg_s: non-finite",
    ),
    "inf": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,inf,30\n30,0.4,450,30\n"),
        "b.csv",
        "column Tgi_C: non-finite",
    ),
    "empty cell": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,450,30\n30,,450,30\n"),
        "b.csv",
        "line 3, column Gg_kg_s: empty cell",
    ),
    "time decreasing": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,450,30\n30,0.4,450,30\n20,0.4,450,30\n"),
        "b.csv",
        "row 3, column time_s: time not strictly increasing (decreasing",
    ),
    "time duplicated": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,450,30\n0,0.4,450,30\n"),
        "b.csv",
        "time not strictly increasing (duplicated",
    ),
    "negative flow": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,450,30\n30,-0.1,450,30\n"),
        "b.csv",
        "row 2, column Gg_kg_s: Gg_kg_s (inlet gas mass flow) = -0.1 kg/s outside the plausible range",
    ),
    "zero flow": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0,450,30\n30,0.4,450,30\n"),
        "b.csv",
        "Gg_kg_s (inlet gas mass flow) = 0 kg/s outside",
    ),
    "temperature too high": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,1450,30\n30,0.4,450,30\n"),
        "b.csv",
        "column Tgi_C: Tgi_C (inlet gas temperature) = 1450 degC outside",
    ),
    "temperature too low": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,450,-80\n30,0.4,450,30\n"),
        "b.csv",
        "column Ta_C: Ta_C (bean-probe temperature) = -80 degC outside",
    ),
    "truncated row": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,450,30\n30,0.4"),
        "b.csv",
        "line 3: row has 2 cells",
    ),
    "binary file": (lambda d: simulate_with(d, "b.csv", b"\x00\x01\x02PK\x03\x04" * 50), "b.csv", "binary file"),
    "Mb_kg metadata out of range": (
        lambda d: simulate_with(d, "b.csv", "# Mb_kg = -3\n" + HEADER + GOOD_ROWS),
        "b.csv",
        "line 1: Mb_kg (green batch mass) = -3 kg outside",
    ),
    # logs and maps
    "degF data declared as degC": (
        lambda d: import_with(
            d,
            "f.csv",
            "time_s,Ta_C,Tgi_C\n" + "".join(f"{t},{250 + t / 2},{500}\n" for t in range(0, 601, 30)),
            "[Gg]\nconstant_kg_s = 0.4\n",
        ),
        "f.csv",
        "at DROP is above 300",
    ),
    "truncated alog": (
        lambda d: import_with(d, "t.alog", GOOD_ALOG[: len(GOOD_ALOG) // 2]),
        "t.alog",
        "truncated Artisan profile",
    ),
    "alog containing code": (
        lambda d: import_with(d, "evil.alog", "{'timex': __import__('os').system('touch /tmp/roastlab_pwned')}"),
        "evil.alog",
        "code is never run",
    ),
    "alog wrong JSON types": (
        lambda d: import_with(d, "w.alog", json.dumps({"timex": "0,1,2", "temp1": [1, 2, 3], "temp2": [1, 2, 3]})),
        "w.alog",
        "key timex: expected a list of numbers",
    ),
    "alog lengths differ": (
        lambda d: import_with(
            d, "l.alog", repr({"timex": [0.0, 1.5, 3.0], "temp1": [150.0, 151.0, 152.0], "temp2": [120.0, 121.0]})
        ),
        "l.alog",
        "key temp2: has 2 values but timex has 3",
    ),
    "alog not a dict": (lambda d: import_with(d, "n.alog", "[1, 2, 3]"), "n.alog", "not an Artisan profile"),
    "alog DROP before CHARGE": (
        lambda d: import_with(
            d, "x.alog", GOOD_ALOG.replace("[2, 0, 0, 0, 0, 0, 75, 0]", "[60, 0, 0, 0, 0, 0, 20, 0]")
        ),
        "x.alog",
        "key timeindex: DROP (sample 20, 30 s) is marked at or before CHARGE (sample 60, 90 s)",
    ),
    "map unknown key": (
        lambda d: import_with(d, "g.alog", GOOD_ALOG, "colour = 'red'\n" + SKY_MAP),
        "map.toml",
        "unknown key(s) colour",
    ),
    "map unknown key in a table": (
        lambda d: import_with(d, "g.alog", GOOD_ALOG, SKY_MAP + "colour = 'red'\n"),
        "map.toml",
        "[Gg]: unknown key(s) colour",
    ),
    "map channel missing from log": (
        lambda d: import_with(d, "g.alog", GOOD_ALOG, SKY_MAP.replace('"ET"', '"Inlet"')),
        "g.alog",
        "no channel 'Inlet'",
    ),
    "map two flow sources": (
        lambda d: import_with(d, "g.alog", GOOD_ALOG, SKY_MAP + "constant_kg_s = 0.1\n"),
        "map.toml",
        "exactly one of",
    ),
    # parameters and plants
    "unknown plant preset": (
        lambda d: (
            simulate_with(d, "b.csv", HEADER + GOOD_ROWS)[:2]
            + ["999kg"]
            + simulate_with(d, "b.csv", HEADER + GOOD_ROWS)[3:]
        ),
        "999kg",
        "unknown plant preset",
    ),
    "negative geometry": (
        lambda d: plant_with(d, PLANT.replace("Lch_m = 1.335", "Lch_m = -1.335")),
        "plant.toml",
        "Lch_m (chamber length) = -1.335 m outside the plausible range 0.02..20 m",
    ),
    "plant missing key": (
        lambda d: plant_with(d, PLANT.replace("Mm_kg = 2000\n", "")),
        "plant.toml",
        "missing key(s) Mm_kg",
    ),
    "plant bad TOML": (lambda d: plant_with(d, "Mb_kg = = 3"), "plant.toml", "not valid TOML"),
    "plant unknown process constant": (
        lambda d: plant_with(d, PLANT + "[process]\nwarp = 9\n"),
        "plant.toml",
        "unknown process constant 'warp'",
    ),
    "Pbm outside (0, 1) in THETA.json": (
        lambda d: theta_with(d, '{"hgm": 0.01, "hbm": 0.02, "Pbm": 1.3}'),
        "theta.json",
        "Pbm (bean area touching the metal, section 3.1) = 1.3 - outside the plausible range",
    ),
    "missing theta keys": (lambda d: theta_with(d, '{"hgm": 0.01}'), "theta.json", "missing key(s) hbm, Pbm"),
    "theta wrong JSON type": (
        lambda d: theta_with(d, '{"hgm": "0.01", "hbm": 0.02, "Pbm": 0.6}'),
        "theta.json",
        "parameters.hgm: must be a number",
    ),
    "theta not JSON": (lambda d: theta_with(d, "hgm = 0.01"), "theta.json", "not valid JSON"),
    "Pbm outside (0, 1) on the command line": (
        lambda d: simulate_with(d, "b.csv", HEADER + GOOD_ROWS) + ["--pbm", "0"],
        "command line",
        "Pbm must be in (0, 1)",
    ),
    "inverted bounds": (
        lambda d: [
            "identify",
            "--plant",
            "120kg",
            DATA / "dataset-I",
            "--out",
            d / "out.csv",
            "--bounds",
            "hbm=0.3:0.1",
        ],
        "command line",
        "inverted or empty bounds",
    ),
    "inverted bounds in a fit spec": (
        lambda d: _spec(d, "[free]\nhgm = [0.3, 0.1, 0.2]\n"),
        "fit.toml",
        "free.hgm: bounds of hgm inverted",
    ),
    "fit spec unknown parameter": (
        lambda d: _spec(d, "[free]\nwarp = [0, 1, 0.5]\n"),
        "fit.toml",
        "free.warp: unknown parameter",
    ),
    "fit spec weights an unknown output": (
        lambda d: _spec(d, "[free]\nhgm = [0.001, 1, 0.02]\n[weights]\nBT2 = 1.0\n"),
        "fit.toml",
        "weights.BT2: unknown output (allowed: Ta, Tb2, ET)",
    ),
    "fit spec weights ET on logs without ET": (
        lambda d: _spec(d, "[free]\nhgm = [0.001, 1, 0.02]\n[weights]\nET = 1.0\n"),
        "fit.toml",
        "the ET output has a weight but no batch has an ET reading",
    ),
    "fit spec weights an output by a word it does not know": (
        lambda d: _spec(d, '[free]\nhgm = [0.001, 1, 0.02]\n[weights]\nET = "auto"\n'),
        "fit.toml",
        "weights.ET: must be a number or \"residual\" (set from a first fit's residuals), got 'auto'",
    ),
    "fit spec weights the probe by its own residuals": (
        lambda d: _spec(d, '[free]\nhgm = [0.001, 1, 0.02]\n[weights]\nTa = "residual"\n'),
        "fit.toml",
        "weights.Ta: the probe is what weights from the residuals are relative to",
    ),
    "fit spec weights ET by its residuals on logs without ET": (
        lambda d: _spec(d, '[free]\nhgm = [0.001, 1, 0.02]\n[weights]\nET = "residual"\n'),
        "fit.toml",
        "the ET output has a weight but no batch has an ET reading",
    ),
    "fit spec with a negative weight": (
        lambda d: _spec(d, "[free]\nhgm = [0.001, 1, 0.02]\n[weights]\nTb2 = -1\n"),
        "fit.toml",
        "weights.Tb2: must be >= 0",
    ),
    "fit spec weights every output 0": (
        lambda d: _spec(d, "[free]\nhgm = [0.001, 1, 0.02]\n[weights]\nTa = 0\n"),
        "fit.toml",
        "every output weight is 0",
    ),
    "fit spec weights a second reading the logs lack": (
        lambda d: _spec(d, "[free]\nhgm = [0.001, 1, 0.02]\n[weights]\nTb2 = 1\n"),
        "fit.toml",
        "no batch has a second bean reading",
    ),
    "--weight of an unknown output": (
        lambda d: ["identify", "--plant", "120kg", DATA / "dataset-I", "--out", d / "m.json", "--weight", "BT=1"],
        "command line",
        "unknown output 'BT' to weight",
    ),
    # files and paths
    "missing input file": (
        lambda d: ["simulate", "--plant", "120kg", "--inputs", d / "nope.csv", "--out", d / "out.csv"],
        "nope.csv",
        "file not found",
    ),
    "output path equal to input": (lambda d: _same_path(d), "b.csv", "is an input of this run"),
    "missing output folder": (
        lambda d: simulate_with(d, "b.csv", HEADER + GOOD_ROWS)[:-1] + [d / "no" / "such" / "out.csv"],
        "out.csv",
        "output folder does not exist",
    ),
    "file over the size limit": (lambda d: _huge(d), "huge.csv", "over the 16 MB limit"),
    "huge alog": (lambda d: _huge(d, "huge.alog", import_=True), "huge.alog", "over the 16 MB limit"),
}


def _spec(d, text):
    spec = d / "fit.toml"
    spec.write_text(text)
    return ["identify", "--plant", "120kg", DATA / "dataset-I", "--out", d / "out.csv", "--spec", spec]


def _same_path(d):
    f = d / "b.csv"
    f.write_text(HEADER + GOOD_ROWS)
    return ["simulate", "--plant", "120kg", "--inputs", f, "--out", f]


def _huge(d, name="huge.csv", import_=False):
    f = d / name
    with open(f, "wb") as fh:  # sparse: 201 MB on paper, nothing on disk
        fh.truncate(MAX_INPUT_BYTES + 1)
    if import_:
        m = d / "map.toml"
        m.write_text(SKY_MAP)
        return ["import", f, "--map", m, "--out", d / "out.csv"]
    return ["simulate", "--plant", "120kg", "--inputs", f, "--out", d / "out.csv"]


def _dataset_and_plant(d):
    """A dataset of two good batches, a plant file, a map and a spec in folder d."""
    for k in (1, 2):
        (d / f"b{k}.csv").write_text(HEADER + GOOD_ROWS)
    (d / "dataset.toml").write_text('plant = "120kg"\n[[batch]]\nfile = "b1.csv"\n[[batch]]\nfile = "b2.csv"\n')
    (d / "plant.toml").write_text(PLANT)
    (d / "map.toml").write_text('[Ta]\ncolumn = "Ta_C"\n')
    (d / "spec.toml").write_text("[free]\nhbm = [0.01, 0.35, 0.02]\n")
    return d


def _identify_out(d, target):
    _dataset_and_plant(d)
    return ["identify", "--plant", d / "plant.toml", "--spec", d / "spec.toml", d / "b1.csv", "--out", d / target]


def _fifo(d, as_input):
    good = d / "good.csv"
    good.write_text(HEADER + GOOD_ROWS)
    fifo = d / "pipe"
    os.mkfifo(fifo)
    if as_input:
        return ["simulate", "--plant", "120kg", "--inputs", fifo, "--out", d / "o.csv"]
    return ["simulate", "--plant", "120kg", "--inputs", good, "--out", fifo]


def _with_model(d, text, extra=()):
    good = d / "good.csv"
    good.write_text(HEADER + GOOD_ROWS)
    m = d / "model.json"
    m.write_text(text)
    return ["simulate", "--plant", "120kg", "--model", m, "--inputs", good, "--out", d / "o.csv", *extra]


def _good_sim(d, *extra):
    good = d / "good.csv"
    good.write_text(HEADER + GOOD_ROWS)
    return ["simulate", "--plant", "120kg", "--inputs", good, "--out", d / "o.csv", *extra]


def _map_case(d, map_text):
    log = d / "log.csv"
    log.write_text(HEADER + GOOD_ROWS)
    m = d / "m.toml"
    m.write_text(map_text)
    return ["import", log, "--map", m, "--out", d / "o.csv"]


def _fit_spec(d, spec_text):
    _dataset_and_plant(d)
    (d / "spec.toml").write_text(spec_text)
    return ["identify", "--plant", "120kg", "--spec", d / "spec.toml", d / "b1.csv", "--out", d / "m.json"]


HOSTILE = {
    # 1. outputs that are inputs of the same run, or special files
    "output over the plant file": (lambda d: _identify_out(d, "plant.toml"), "plant.toml", "is an input of this run"),
    "output over the fit spec": (lambda d: _identify_out(d, "spec.toml"), "spec.toml", "is an input of this run"),
    "output over a dataset index": (
        lambda d: ["identify", _dataset_and_plant(d), "--out", d / "dataset.toml"],
        "dataset.toml",
        "is an input of this run",
    ),
    "output over the model file": (
        lambda d: _with_model(d, '{"hgm": 0.01, "hbm": 0.02, "Pbm": 0.6}')[:-2] + ["--out", d / "model.json"],
        "model.json",
        "is an input of this run",
    ),
    "output replaces a FIFO": (lambda d: _fifo(d, False), "pipe", "not a regular file"),
    # 2. unbounded resources
    "input from /dev/zero": (
        lambda d: ["simulate", "--plant", "120kg", "--inputs", "/dev/zero", "--out", d / "o.csv"],
        "/dev/zero",
        "not a regular file",
    ),
    "input from a FIFO (no hang)": (lambda d: _fifo(d, True), "pipe", "not a regular file"),
    "map resample step of a nanosecond": (
        lambda d: _map_case(d, "resample_s = 1e-9\n"),
        "m.toml",
        "must be 0 (off) or 0.1..600 s",
    ),
    # 3. numbers that used to raise
    "model nested 100 deep": (lambda d: _with_model(d, "[" * 100 + "]" * 100), "model.json", "nested deeper"),
    "model with NaN": (lambda d: _with_model(d, '{"hgm": NaN, "hbm": 0.02, "Pbm": 0.6}'), "model.json", "NaN"),
    "model with a 400-digit integer": (
        lambda d: _with_model(d, '{"hgm": 1' + "0" * 400 + ', "hbm": 0.02, "Pbm": 0.6}'),
        "model.json",
        "number out of range",
    ),
    "TOML nested 2000 deep": (lambda d: _map_case(d, "x = " + "[" * 2000 + "]" * 2000 + "\n"), "m.toml", "m.toml"),
    "spec fixes a zero metal mass": (
        lambda d: _fit_spec(d, "[free]\nhbm = [0.01, 0.35, 0.02]\n[fixed]\nMm = 0.0\n"),
        "spec.toml",
        "Mm (drum metal mass in thermal contact, eq. 12) = 0 kg outside",
    ),
    "spec frees a capacity down to zero": (
        lambda d: _fit_spec(d, "[free]\ncm = [0.0, 1.0, 0.4]\n"),
        "spec.toml",
        "lower bound: cm (metal specific heat, eq. 12) = 0 kJ/(kg K) outside the plausible range",
    ),
    "negative moisture": (lambda d: _good_sim(d, "--x0", "-0.1"), "--x0", "X0 (green moisture, dry basis) = -0.1"),
    "absolute-zero drum": (lambda d: _good_sim(d, "--tm0", "-273.15"), "--tm0", "outside the plausible range"),
    "negative seed": (
        lambda d: ["identify", _dataset_and_plant(d), "--seed", "-1", "--out", d / "m.json"],
        "--seed",
        "must be in 0..",
    ),
    "figure with an unknown extension (no CSV written)": (
        lambda d: _good_sim(d, "--plot", d / "fig.xyz"),
        "fig.xyz",
        "unknown figure format",
    ),
    # 4. silently absurd
    "flow of 1e17 kg/s": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,1e17,450,30\n30,0.4,450,30\n"),
        "b.csv",
        "outside the plausible range",
    ),
    "flow of 1e308 kg/s": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,1e308,450,30\n30,0.4,450,30\n"),
        "b.csv",
        "outside the plausible range",
    ),
    "a gap of 11 days": (
        lambda d: simulate_with(d, "b.csv", HEADER + "0,0.4,450,30\n1e6,0.4,450,30\n"),
        "b.csv",
        "outside the plausible range",
    ),
    "extreme initial bean temperature": (lambda d: _good_sim(d, "--tb0", "1e300"), "--tb0", "outside the plausible"),
    # 8. messages that help
    "an Artisan log given as a batch CSV": (
        lambda d: simulate_with(d, "b.csv", "{'timex': [0, 1], 'temp1': [1, 2]}"),
        "b.csv",
        "roastlab import",
    ),
    "a baseline file given as a model": (
        lambda d: _with_model(d, '{"baseline": "first-order", "tau_s": 100, "offset_C": 0}'),
        "model.json",
        "--baseline first-order",
    ),
}
RT_MAP = (
    'format = "roastime"\n[Ta]\ncolumn = "beanTemperature"\n[Tgi]\nconstant_C = 22\n[Gg]\nidentify = true\n'
    '[heater]\ncolumn = "heater"\nunit = "level"\n'
)
RT = '{"sampleRate": 2, "weightGreen": "490", "beanTemperature": [150, 140, 130, 135], "actions": {"actionTimeList": [{"index": 0, "value": 6, "ctrlType": 0}]}}'
ROASTIME = {
    "RoasTime with a zero sample rate": (
        lambda d: import_with(d, "r.json", RT.replace('"sampleRate": 2', '"sampleRate": 0'), RT_MAP),
        "r.json",
        "key sampleRate",
    ),
    "RoasTime with no sample rate nor roast length": (
        lambda d: import_with(d, "r.json", RT.replace('"sampleRate": 2, ', ""), RT_MAP),
        "r.json",
        "no totalRoastTime to tell the sample rate from",
    ),
    "RoastWorld action at a second far past the roast": (
        lambda d: import_with(
            d,
            "r.json",
            RT.replace('"sampleRate": 2', '"totalRoastTime": 1.5').replace(
                '{"actionTimeList": [{"index": 0, "value": 6, "ctrlType": 0}]}',
                '[{"type": "Power", "second": 1e308, "setting": 6}]',
            ),
            RT_MAP,
        ),
        "r.json",
        "second 1e+308 or setting 6 out of range",
    ),
    "RoastWorld action of no number": (
        lambda d: import_with(
            d,
            "r.json",
            RT.replace('"sampleRate": 2', '"totalRoastTime": 1.5').replace(
                '{"actionTimeList": [{"index": 0, "value": 6, "ctrlType": 0}]}',
                '[{"type": "Power", "second": "six", "setting": 6}]',
            ),
            RT_MAP,
        ),
        "r.json",
        "second must be a finite number",
    ),
    "RoasTime truncated": (lambda d: import_with(d, "r.json", RT[:60], RT_MAP), "r.json", "r.json"),
    "RoasTime heater level of 600": (
        lambda d: import_with(d, "r.json", RT.replace('"value": 6', '"value": 600'), RT_MAP),
        "r.json",
        "outside 0..20 for unit 'level'",
    ),
    "map with an unknown setting unit": (
        lambda d: import_with(d, "r.json", RT, RT_MAP.replace('unit = "level"', 'unit = "watts"')),
        "map.toml",
        "must be one of percent, level, tens, kW",
    ),
    "map Tgi with both a column and a constant": (
        lambda d: import_with(d, "r.json", RT, RT_MAP.replace("constant_C = 22", 'constant_C = 22\ncolumn = "x"')),
        "map.toml",
        "column or constant_C",
    ),
}
SMALL_PLANT = "Mb_kg = 0.2\nDch_m = 0.16\nLch_m = 0.2\nHflap_m = 0.02\nSflap_m = 0.1\nMm_kg = 1.5\n"
ALOG_MAP = '[Ta]\ncolumn = "BT"\n[Tgi]\ncolumn = "ET"\n[Gg]\nconstant_kg_s = 0.4\n'


@functools.cache
def _model_text() -> str:
    """A model file fitted once on the small Artisan log (for the commands that need one)."""
    from roastlab.cli import main

    d = Path(tempfile.mkdtemp(prefix="roastlab-model-"))
    try:
        (d / "log.alog").write_text(GOOD_ALOG)
        (d / "map.toml").write_text(ALOG_MAP)
        (d / "small.toml").write_text(SMALL_PLANT)
        (d / "spec.toml").write_text("[free]\nhbm = [0.01, 0.35, 0.02]\n")
        argv = ["identify", "--plant", d / "small.toml", "--map", d / "map.toml", d / "log.alog"]
        assert main([*map(str, argv), "--spec", str(d / "spec.toml"), "--out", str(d / "m.json"), "--starts", "1"]) == 0
        return (d / "m.json").read_text()
    finally:
        shutil.rmtree(d)


def _newer(d, *argv, log=GOOD_ALOG):
    """The small log, its map, a small plant and a model in ``d``; argv with {d} filled in."""
    (d / "log.alog").write_text(log)
    (d / "map.toml").write_text(ALOG_MAP)
    (d / "small.toml").write_text(SMALL_PLANT)
    (d / "model.json").write_text(_model_text())
    return [a.format(d=d) if isinstance(a, str) else a for a in argv]


_NO_BT = repr({k: v for k, v in ast.literal_eval(GOOD_ALOG).items() if k != "temp2"})

#: The commands added since the first rounds: what-if, transfer, control, model comparison,
#: prediction bands, init and fit-roaster (fleet: tests/test_fleet.py; page uploads: test_app.py).
NEWER = {
    "whatif on a log without BT": (
        lambda d: _newer(
            d, "whatif", "{d}/log.alog", "--model", "{d}/model.json", "--map", "{d}/map.toml", "--tgi", "10", log=_NO_BT
        ),
        "log.alog",
        "temp2",
    ),
    "whatif --set that is not SETTING=VALUE@TIME": (
        lambda d: _newer(
            d,
            "whatif",
            "{d}/log.alog",
            "--model",
            "{d}/model.json",
            "--map",
            "{d}/map.toml",
            "--set",
            "heater=abc@1:00",
        ),
        "--set",
        "SETTING=VALUE@TIME",
    ),
    "whatif changes a setting the log has not": (
        lambda d: _newer(
            d, "whatif", "{d}/log.alog", "--model", "{d}/model.json", "--map", "{d}/map.toml", "--heater", "+1@1:00"
        ),
        "log.alog",
        "no heater setting",
    ),
    "whatif --tgi beyond the plausible inlet": (
        lambda d: _newer(
            d, "whatif", "{d}/log.alog", "--model", "{d}/model.json", "--map", "{d}/map.toml", "--tgi", "5000"
        ),
        "--tgi",
        "plausible",
    ),
    "transfer reference going back in time": (
        lambda d: (
            _newer(d, "transfer", "--model", "{d}/model.json", "--reference", "{d}/ref.csv", "--out", "{d}/p.csv")
            if (d / "ref.csv").write_text(HEADER + GOOD_ROWS.replace("60,0.4", "20,0.4"))
            else None
        ),
        "ref.csv",
        "not strictly increasing",
    ),
    "transfer limit of 1e300": (
        lambda d: (
            _newer(
                d,
                "transfer",
                "--model",
                "{d}/model.json",
                "--reference",
                "{d}/ref.csv",
                "--out",
                "{d}/p.csv",
                "--tgi-max",
                "1e300",
            )
            if (d / "ref.csv").write_text(HEADER + GOOD_ROWS)
            else None
        ),
        "--tgi-max",
        "plausible",
    ),
    "control scenario with an unknown key": (
        lambda d: (
            _newer(
                d,
                "control",
                "--model",
                "{d}/model.json",
                "--plant",
                "{d}/small.toml",
                "--reference",
                "{d}/ref.csv",
                "--scenario",
                "{d}/sc.toml",
                "--controller",
                "pid",
                "--out",
                "{d}/t.csv",
            )
            if (d / "ref.csv").write_text(HEADER + GOOD_ROWS) and (d / "sc.toml").write_text('name = "q"\nbogus = 3\n')
            else None
        ),
        "sc.toml",
        "unknown key(s) bogus",
    ),
    "compare-models with an unknown law": (
        lambda d: _newer(
            d,
            "compare-models",
            "--plant",
            "{d}/small.toml",
            "--map",
            "{d}/map.toml",
            "{d}/log.alog",
            "--variant",
            "contact=bogus",
        ),
        "--variant",
        "unknown contact law",
    ),
    "validate --band of 1.5": (
        lambda d: _newer(
            d, "validate", "--model", "{d}/model.json", "--map", "{d}/map.toml", "{d}/log.alog", "--band", "1.5"
        ),
        "--band",
        "in (0, 1)",
    ),
    "init on a log without BT": (
        lambda d: _newer(d, "init", "{d}/log.alog", "--out", "{d}/cfg", "--batch-kg", "0.2", log=_NO_BT),
        "log.alog",
        "temp2",
    ),
    "fit-roaster without init": (
        lambda d: _newer(d, "fit-roaster", "{d}/nocfg", "{d}/log.alog"),
        "nocfg",
        "roastlab init",
    ),
}

CASES.update(HOSTILE)
CASES.update(ROASTIME)
CASES.update(NEWER)


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_input(cli, tmp_path, case):
    build, names, needle = CASES[case]
    args = build(tmp_path)
    before = {
        p: p.read_bytes() if p.stat().st_size < 1e6 else p.stat().st_size for p in tmp_path.rglob("*") if p.is_file()
    }
    code, out, err = cli(*args)
    assert code == 2, (case, code, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert names in err and needle in err, err
    after = {p for p in tmp_path.rglob("*") if p.is_file()}
    assert after == set(before), f"{case}: files appeared {after - set(before)}"
    for p, content in before.items():  # inputs never modified
        assert (p.read_bytes() if isinstance(content, bytes) else p.stat().st_size) == content
    assert not os.path.exists("/tmp/roastlab_pwned")


def test_unwritable_output_folder(cli, tmp_path):
    good = tmp_path / "good.csv"
    good.write_text(HEADER + GOOD_ROWS)
    target = "/proc/roastlab-out.csv"  # /proc refuses new files even for root
    code, _, err = cli("simulate", "--plant", "120kg", "--inputs", good, "--out", target)
    assert code == 2 and "roastlab-out.csv" in err and err.count("\n") == 1, err
    assert not os.path.exists(target)


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"Gg_kg_s": np.full(5, 0.4)}, "Gg_kg_s has 5 values, time_s has 31"),
        ({"time_s": np.array([]), "Gg_kg_s": np.array([]), "Tgi_C": np.array([])}, "at least 2 time samples"),
        ({"Tgi_C": np.full((31, 2), 450.0)}, "one-dimensional"),
        ({"Gg_kg_s": np.full(31, np.nan)}, "outside the plausible range"),
    ],
)
def test_python_simulate_checks_shapes_before_the_kernel(kwargs, needle):
    import roastlab

    t = np.arange(0, 901, 30.0)
    args = {"time_s": t, "Gg_kg_s": np.full_like(t, 0.4), "Tgi_C": np.full_like(t, 450.0), **kwargs}
    with pytest.raises(roastlab.ParameterError, match=needle):
        roastlab.simulate("120kg", **args)


def test_python_simulate_returns_copies():
    import roastlab

    t = np.arange(0, 301, 30.0)
    g = np.full_like(t, 0.4)
    r = roastlab.simulate("120kg", t, g, np.full_like(t, 450.0))
    r.Gg_kg_s[:] = 9.0
    assert np.all(g == 0.4)


@pytest.mark.parametrize("dt", [0.0, -5.0, float("nan")])
def test_simulator_step_refuses_bad_dt(dt):
    import roastlab

    sim = roastlab.Simulator("120kg")
    with pytest.raises(roastlab.ParameterError, match="dt_s"):
        sim.step(dt, 0.4, 450.0)
    assert sim.t_s == 0.0


def test_newline_in_a_log_name_stays_a_comment(cli, tmp_path):
    """A log named 'x\\nMb_kg = 5.csv' must not write a metadata line the reader obeys."""
    log = tmp_path / "x\nMb_kg = 5.csv"
    log.write_text(HEADER + GOOD_ROWS)
    out = tmp_path / "o.csv"
    code, _, err = cli("import", log, "--out", out)
    assert code == 0, err
    from roastlab.io.batch import read_batch_csv

    assert read_batch_csv(out).Mb_kg is None
    assert all(line.startswith(("##", "time_s")) or line[0].isdigit() for line in out.read_text().splitlines())
