"""Fitting a real roaster whose logs lack Tgi and Gg (examples/skywalker), and the baseline."""

import json
from pathlib import Path

import numpy as np
import pytest

from roastlab.fit.baseline import first_order_response, fit_first_order
from roastlab.io.batch import Batch

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "skywalker"


def test_first_order_response_is_exact_for_a_ramp():
    # tau y' = u + c - y with u = a t: y = a t + c - a tau + (y0 - c + a tau) exp(-t/tau)
    t = np.linspace(0, 600, 41)
    a, c, tau, y0 = 0.3, 5.0, 90.0, 20.0
    y = first_order_response(t, a * t, y0, tau, c)
    exact = a * t + c - a * tau + (y0 - c + a * tau) * np.exp(-t / tau)
    np.testing.assert_allclose(y, exact, rtol=1e-12, atol=1e-10)


def test_first_order_fit_recovers_parameters():
    t = np.arange(0, 601, 5.0)
    batches = []
    for k in range(3):
        et = 150 + 0.1 * t + 10 * np.sin(t / (60 + 20 * k))
        bt = first_order_response(t, et, 120.0 + k, 140.0, 12.0)
        batches.append(Batch(f"b{k}", t, np.ones_like(t), et, bt))
    fit = fit_first_order(batches)
    assert fit["tau_s"] == pytest.approx(140.0, rel=1e-5) and fit["offset_C"] == pytest.approx(12.0, abs=1e-4)


def test_first_order_fit_with_settings_recovers_the_gains():
    """The baseline fed the actuator map's inputs (room-air Tgi, heater and fan settings)."""
    from roastlab.fit.baseline import validate_first_order

    t = np.arange(0, 601, 5.0)
    batches = []
    for k in range(3):
        heater = np.where(t < 200 + 50 * k, 8.0, 5.0)
        fan = np.where(t < 300, 2.0, 4.0 + k)
        drive = 22.0 + 30.0 * heater - 6.0 * fan
        bt = first_order_response(t, drive, 100.0 + k, 250.0, -15.0)
        batches.append(Batch(f"b{k}", t, np.ones_like(t), np.full_like(t, 22.0), bt, heater=heater, fan=fan))
    fit = fit_first_order(batches)
    assert fit["tau_s"] == pytest.approx(250.0, rel=1e-4)
    assert fit["heater_gain_C"] == pytest.approx(30.0, rel=1e-4)
    assert fit["fan_gain_C"] == pytest.approx(-6.0, rel=1e-4)
    _, rows = validate_first_order(batches, fit)
    assert min(r["FIT"] for r in rows) > 99.9


def test_skywalker_fit_and_validate(cli, real_data, tmp_path):
    logs = sorted(real_data.glob("*.alog"))
    fit_logs, val_logs = logs[0:4:2], logs[1:4:2]
    theta = tmp_path / "theta.json"
    common = ["--plant", EXAMPLE / "plant.toml", "--map", EXAMPLE / "map.toml"]
    code, out, err = cli(
        "identify", *common, "--spec", EXAMPLE / "fit.toml", *fit_logs, "--out", theta, "--starts", "2"
    )
    assert code == 0, err
    doc = json.loads(theta.read_text())
    for key in ("hgm", "hbm", "Pbm", "Gg_kg_s", "Kt", "Qe_gain_kW", "Tgi_gain_C", "tau_heater_s"):
        assert doc["parameters"][key]["how"] == "fitted", key
    assert doc["initial"]["Tm0_C"] == {"how": "from log", "field": "ET"} and doc["map"]["Gg"] == {"identify": True}
    assert doc["map"]["heater"] == {"column": "Burner", "unit": "percent", "step": 5.0}
    metrics = tmp_path / "m.json"
    code, out, err = cli("validate", *common, "--model", theta, *val_logs, "--json", metrics)
    assert code == 0, err
    m = json.loads(metrics.read_text())
    assert len(m["batches"]) == 2 and m["average"]["MAE"] < 25
    # the model carries its map: the raw logs need no --map, and give the same metrics
    code, _, err = cli("validate", "--model", theta, *val_logs, "--json", tmp_path / "m1.json")
    assert code == 0, err
    assert json.loads((tmp_path / "m1.json").read_text())["average"] == m["average"]
    # a model without its fitted flow cannot be applied to placeholder-flow logs: an error, not a guess
    doc["parameters"].pop("Gg_kg_s")
    stripped = tmp_path / "stripped.json"
    stripped.write_text(json.dumps(doc))
    code, _, err = cli("validate", *common, "--model", stripped, *val_logs, "--json", tmp_path / "m2.json")
    assert code == 2 and "placeholder" in err and not (tmp_path / "m2.json").exists()
    # the first-order baseline through the same commands
    base = tmp_path / "base.json"
    code, _, err = cli("identify", *common, "--baseline", "first-order", *fit_logs, "--out", base)
    assert code == 0, err
    code, out, err = cli("validate", *common, "--baseline", "first-order", "--model", base, *val_logs)
    assert code == 0 and "first-order baseline" in out, err


BULLET = Path(__file__).resolve().parents[1] / "examples" / "bullet"


@pytest.fixture
def bullet_data(real_data):
    folder = real_data.parent / "bullet"
    if not folder.is_dir():
        pytest.skip("../shared/data/real/bullet is absent")
    return folder


def test_roastime_import_reads_settings_events_and_weight(bullet_data):
    from roastlab.io.importers import import_log, load_map

    log = bullet_data / "bullet_2020-07-31_0152_490g.json"
    b = import_log(log, load_map(BULLET / "map.toml"))
    assert b.Mb_kg == pytest.approx(0.49)
    assert b.heater is not None and set(np.unique(b.heater)) <= set(range(0, 10))
    assert b.fan is not None and b.fan.min() >= 0 and b.fan.max() <= 12
    assert "FCs" in b.events and 0 < b.events["FCs"] < b.time_s[-1]
    assert b.initial["Tm0_C"] == pytest.approx(245.1)  # drumChargeTemperature of that log
    assert np.isnan(b.Tb2_C[0]) and np.isfinite(b.Tb2_C[5:]).all()  # IR counts once the beans are in view


def test_roastime_without_weight_is_refused_with_the_way_out(cli, bullet_data, tmp_path):
    code, _, err = cli(
        "import",
        bullet_data / "bullet_2020-08-16_2334_noweight.json",
        "--map",
        BULLET / "map.toml",
        "--out",
        tmp_path / "o.csv",
    )
    assert code == 2 and "no green weight" in err and "batch_kg" in err and err.count("\n") == 1


def test_bullet_fit_and_whatif(cli, bullet_data, tmp_path):
    """The example fits in seconds, beats nothing by luck (held-out FIT > 70 %), and whatif answers."""
    logs = sorted(p for p in bullet_data.glob("*_49*g.json"))[:6]
    model = tmp_path / "bullet.json"
    common = ["--plant", BULLET / "plant.toml", "--map", BULLET / "map.toml"]
    code, _, err = cli("identify", *common, "--spec", BULLET / "fit.toml", *logs[0::2], "--out", model)
    assert code == 0, err
    code, _, err = cli("validate", "--model", model, *logs[1::2], "--json", tmp_path / "v.json")
    assert code == 0, err
    metrics = json.loads((tmp_path / "v.json").read_text())
    assert metrics["average"]["FIT"] > 70
    # the spec fits both bean readings: the IR channel is scored against the model's Tb, per output
    second = metrics["outputs"]["Tb2"]
    assert len(second["batches"]) == 3 and second["average"]["FIT"] > 70
    doc = json.loads(model.read_text())
    assert set(doc["fit"]["outputs"]) == {"Ta", "Tb2"}
    # the probe-immersion term is pinned by the data: the covering depth sits inside its bounds,
    # a little above the bed depth of a 490 g batch (part of the probe is in the air)
    h = doc["parameters"]["h_probe_m"]
    assert h["stderr"] is not None and 0.03 < h["value"] < 0.06
    code, out, err = cli(
        "whatif",
        logs[1],
        "--model",
        model,
        "--heater",
        "+1",
        "--plot",
        tmp_path / "w.png",
        "--json",
        tmp_path / "w.json",
    )
    assert code == 0, err
    rows = json.loads((tmp_path / "w.json").read_text())["rows"]
    assert rows[0]["changed"] > rows[0]["as_run"]  # more heat, hotter at DROP
    assert all(r["changed"] < r["as_run"] for r in rows[1:] if r["changed"] is not None and r["as_run"] is not None)
    assert (tmp_path / "w.png").stat().st_size > 10_000


def test_skywalker_whatif_set_and_tm0(cli, real_data, tmp_path):
    logs = sorted(real_data.glob("*.alog"))[:3]
    model = tmp_path / "sky.json"
    common = ["--plant", EXAMPLE / "plant.toml", "--map", EXAMPLE / "map.toml"]
    assert cli("identify", *common, "--spec", EXAMPLE / "fit.toml", *logs[:2], "--out", model, "--starts", "2")[0] == 0
    code, out, err = cli(
        "whatif", logs[2], "--model", model, "--set", "heater=0@60", "--tm0", "150", "--json", tmp_path / "w.json"
    )
    assert code == 0, err
    rows = json.loads((tmp_path / "w.json").read_text())["rows"]
    assert rows[0]["changed"] < rows[0]["as_run"]  # heater off after a minute: colder at DROP
    code, _, err = cli("whatif", logs[2], "--model", model, "--set", "burner=5")
    assert code == 2 and "SETTING=VALUE@SECONDS" in err
