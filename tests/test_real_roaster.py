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
    assert doc["map"]["heater"] == {"column": "Burner", "unit": "percent"}
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
