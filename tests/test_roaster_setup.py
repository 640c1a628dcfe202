"""roastlab init and fit-roaster: a roaster from its logs with no hand-written files."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from conftest import REAL_DATA
from test_importers import fake_alog


def test_init_detects_an_artisan_layout_and_writes_commented_files(cli, tmp_path):
    """SYNTHETIC Artisan logs (test_importers.fake_alog) with Burner and Air events and a weight."""
    extra = {
        "specialevents": [10, 40],
        "specialeventstype": [3, 0],
        "specialeventsvalue": [8.0, 4.0],  # Burner 70 %, Air 30 % in Artisan's encoding
        "etypes": ["Air", "Drum", "Damper", "Burner", "--"],
        "roastertype": "Hottop KN-8828B-2K+",
    }
    logs = []
    for k in range(2):
        p = tmp_path / f"r{k}.alog"
        p.write_text(fake_alog(extra=extra))
        logs.append(p)
    before = [p.read_bytes() for p in logs]
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    text = {n: (tmp_path / "cfg" / f"{n}.toml").read_text() for n in ("map", "plant", "fit")}
    assert 'column = "Burner"' in text["map"] and 'column = "Air"' in text["map"] and 'unit = "percent"' in text["map"]
    assert "catalogue: Hottop" in text["plant"] and "Mm_kg = 0.75" in text["plant"]  # 3 kg per kg of 0.25 kg
    assert "Qe_gain_kW" in text["fit"] and "Tgi_gain_C" in text["fit"] and "h_probe_m" not in text["fit"]
    assert "Hottop" in out and [p.read_bytes() for p in logs] == before  # logs never modified


@pytest.mark.parametrize(
    "case, words",
    [
        ("no weight", "--batch-kg"),
        ("mixed machines", "different roasters"),
        ("no BT", "bean temperature"),
        ("nothing drives the model", "neither a heater setting nor ET"),
    ],
)
def test_init_bad_input_is_one_line_saying_what_to_pass(cli, tmp_path, case, words):
    a = tmp_path / "a.alog"
    b = tmp_path / "b.alog"
    if case == "no weight":
        a.write_text(fake_alog(extra={"weight": [0, 0, "g"]}))
        b.write_text(fake_alog())
    elif case == "mixed machines":
        a.write_text(fake_alog(extra={"roastertype": "Hottop"}))
        b.write_text(fake_alog(extra={"roastertype": "Behmor"}))
    elif case == "no BT":
        a.write_text(fake_alog(extra={"temp2": [-1] * 120}))
        b.write_text(fake_alog())
    else:  # no heater events and no ET
        a.write_text(fake_alog(et=[-1.0] * 120))
        b.write_text(fake_alog(et=[-1.0] * 120))
    code, _, err = cli("init", a, b, "--out", tmp_path / "cfg")
    assert code == 2 and words in err and err.count("\n") == 1, err
    assert not (tmp_path / "cfg").exists()


@pytest.mark.slow
@pytest.mark.parametrize("machine, pattern", [("skywalker", "*.alog"), ("bullet", "*_49[0]g.json *_500g.json")])
def test_init_and_fit_roaster_reach_the_hand_written_examples_on_the_shared_logs(cli, tmp_path, machine, pattern):
    """No hand edits: the held-out FIT is within 2 points of the hand-written example's files
    (examples/<machine>/) fitted and held out on the same split, and beats the first-order baseline."""
    folder = REAL_DATA / machine
    if not folder.is_dir():
        pytest.skip("../shared/data/real is absent")
    logs = sorted({p for pat in pattern.split() for p in folder.glob(pat)})
    assert cli("init", *logs, "--out", tmp_path / "cfg")[0] == 0
    example = tmp_path / "example"
    example.mkdir()
    for name in ("map.toml", "plant.toml", "fit.toml"):
        shutil.copy(Path(__file__).resolve().parents[1] / "examples" / machine / name, example / name)
    held = {}
    for cfg in ("cfg", "example"):
        code, out, err = cli("fit-roaster", tmp_path / cfg, *logs)
        assert code == 0, err
        held[cfg] = float(out.split("held out: FIT ")[1].split(" %")[0])
        base = float(out.split("baseline: ")[1].split(" %")[0])
    assert abs(held["cfg"] - held["example"]) <= 2.0 and held["cfg"] > base + 20, held
    doc = json.loads((tmp_path / "cfg" / "model.json").read_text())
    assert doc["format"] == "roastlab-model/1"
    report = (tmp_path / "cfg" / "report.md").read_text()
    assert "sorted by date" in report and "held out" in report
    assert (tmp_path / "cfg" / "heldout.png").stat().st_size > 20_000
