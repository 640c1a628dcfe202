"""Profile transfer (roastlab transfer): the program, its file, its baselines and its bad input."""

import ast
import json

import numpy as np
import pandas as pd
import pytest

from roastlab.errors import InputError
from roastlab.fit.program import ProgramLimits, limit_spans
from roastlab.io.batch import read_batch_csv, write_batch_csv
from roastlab.io.importers.artisan import read_alog
from roastlab.model.plant import as_plant
from roastlab.model.rhs import P, pack_params
from roastlab.sim.kernels import H_MAX_S, simulate_one
from roastlab.sim.sensitivity import ta_input_jacobian
from roastlab.workflows.datasets import random_reference
from roastlab.workflows.transfer import transfer


def assert_simulates_back(cli, model_path, program_path, ta_pred):
    """``roastlab simulate`` of PROGRAM.csv on the 120 kg plant gives the program's predicted BT."""
    out = program_path.with_name("sim.csv")
    code, _, err = cli(
        "simulate", "--model", str(model_path), "--plant", "120kg", "--inputs", str(program_path), "--out", str(out)
    )
    assert code == 0, err
    sim = pd.read_csv(out, comment="#")
    assert np.max(np.abs(sim["Ta_C"] - np.asarray(ta_pred))) < 1e-3


@pytest.mark.parametrize("zoh, which", [(False, 0), (True, 0), (False, 1)])
def test_restarting_jacobian_matches_full_reruns(zoh, which):
    """Each column restarts from the stored state; a full re-run from CHARGE must agree."""
    p = pack_params(as_plant("120kg"), (0.01, 0.0254, 0.5793), 0.1)
    p[P["Qe_gain"]] = 0.5  # the heater heats the metal, so its column is not zero
    t = np.arange(0.0, 301.0, 10.0)
    n = len(t)
    Gg, Tgi = np.full(n, 0.4), np.linspace(450.0, 380.0, n)
    Q, F = np.full(n, 20.0), np.zeros(n)
    x0 = np.array([25.0, 121.0, 0.1, 0.0, 25.0, 20.0])
    out = simulate_one(t, Gg, Tgi, Q, F, x0, p, zoh, H_MAX_S)
    jac = np.empty((n, n))
    ta_input_jacobian(
        t, Gg, Tgi, Q, F, which, np.ascontiguousarray(out[:, :6]), out[:, 4].copy(), p, zoh, H_MAX_S, 1.0, jac
    )
    for k in (0, 5, 17, n - 1):
        T2, Q2 = Tgi.copy(), Q.copy()
        (T2 if which == 0 else Q2)[k] += 1.0
        full = simulate_one(t, Gg, T2, Q2, F, x0, p, zoh, H_MAX_S)[:, 4]
        np.testing.assert_allclose(jac[:, k], full - out[:, 4], atol=2e-3)
    assert np.abs(jac).max() > 0.003  # the inputs really move the probe (30x the tolerance)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_same_plant_same_batch_matches_as_well_as_the_references_own_inputs(seed):
    model, ref = random_reference(np.random.default_rng(seed), "120kg")
    r = transfer(model, ref, "120kg", "120kg")
    own = r.metrics["reference_own_inputs_on_A"]["rmse_C"]
    assert own < 1e-6  # the noise-free reference is the model's own run
    assert r.metrics["rmse_C"] < 0.05 and r.metrics["max_abs_C"] < 0.2
    assert r.metrics["feasible"]
    lim = r.limits
    assert np.all((r.program.Tgi_C >= lim.low - 1e-9) & (r.program.Tgi_C <= lim.high + 1e-9))
    assert np.all(np.abs(np.diff(r.program.Tgi_C)) <= lim.rate_per_min / 60 * 5.0 + 1e-9)


def test_the_models_own_miss_of_the_reference_is_scored_and_said():
    """A reference whose BT the model misses (its own run plus a ramp that grows to 6 degC at DROP, a late
    rise the model cannot follow): "A's inputs on A" scores the model's own run against it, in the JSON and
    in the summary, and that is the ramp's own size, independent of the transfer's program."""
    import dataclasses

    model, ref = random_reference(np.random.default_rng(5), "120kg")
    t = np.asarray(ref.time_s, float)
    ramp = 6.0 * (t / t[-1]) ** 2
    missed = dataclasses.replace(ref, Ta_C=np.asarray(ref.Ta_C, float) + ramp)
    r = transfer(model, missed, "120kg", "120kg", batch_kg=100.0)
    own = r.metrics["reference_own_inputs_on_A"]
    grid = np.arange(0.0, t[-1] + 1e-9, 5.0)  # the program's knots
    want = np.interp(grid, t, ramp)
    assert own["rmse_C"] == pytest.approx(np.sqrt(np.mean(want**2)), rel=1e-3)
    assert own["max_abs_C"] == pytest.approx(6.0, abs=1e-3)
    row = next(line for line in r.summary().splitlines() if line.startswith("A's inputs on A "))
    assert f"{own['rmse_C']:.3f}" in row and f"{own['max_abs_C']:.3f}" in row
    assert "misses the target by this much" in r.summary()


def test_scale_up_beats_both_baselines_and_is_deterministic():
    model, ref = random_reference(np.random.default_rng(11), "120kg")
    a = transfer(model, ref, "120kg", "360kg")
    b = transfer(model, ref, "120kg", "360kg")
    assert a.program_csv_text() == b.program_csv_text()
    m = a.metrics
    assert m["rmse_C"] <= 0.5 and m["max_abs_C"] <= 2.0
    better = min(m["baseline_same_inputs"]["rmse_C"], m["baseline_retimed"]["rmse_C"])
    assert better >= 5 * m["rmse_C"]


def test_a_transfer_states_the_heat_dose_of_target_and_programs_as_artisans_auc():
    """SYNTHETIC 120 -> 360 kg scale-up: the summary gives each curve's AUC above the target's BT at its
    turning point (Artisan's, roastlab.metrics.profile), the program's within 1 % of the target's where it
    follows the curve to 0.5 degC, and in degF 9/5 as many degree-minutes."""
    from roastlab.metrics.profile import area_under_curve_C_min, turning_point

    model, ref = random_reference(np.random.default_rng(11), "120kg")
    r = transfer(model, ref, "120kg", "360kg")
    m, t = r.metrics, r.time_s
    tp_s, tp_C = turning_point(t, r.target_C)
    base = round(tp_C, 1)  # the target's BT at its turning point, to 0.1 degC (metrics.profile.auc_base_C)
    assert m["AUC_base_C"] == base and m["target_AUC_C_min"] == pytest.approx(
        area_under_curve_C_min(t, r.target_C, tp_s, base)
    )
    assert m["AUC_C_min"] == pytest.approx(m["target_AUC_C_min"], rel=0.01)
    same = m["baseline_same_inputs"]["AUC_C_min"]
    assert same == pytest.approx(
        area_under_curve_C_min(
            t, r.baselines["A's inputs unchanged"], turning_point(t, r.baselines["A's inputs unchanged"])[0], base
        )
    )
    line = next(x for x in r.summary().splitlines() if x.startswith("target"))
    assert line.split()[-1] == f"{m['target_AUC_C_min']:.0f}" and "AUC °C·min" in r.summary()
    r.units = "F"
    assert (
        next(x for x in r.summary().splitlines() if x.startswith("target")).split()[-1]
        == f"{9 / 5 * m['target_AUC_C_min']:.0f}"
    )


def test_unreachable_target_returns_the_best_program_and_says_why():
    model, ref = random_reference(np.random.default_rng(4), "120kg")
    r = transfer(model, ref, "120kg", "360kg", limits=ProgramLimits(150.0, 330.0, 120.0))
    m = r.metrics
    assert not m["feasible"] and m["max_abs_C"] > 2.0
    assert any("330 degC ceiling" in s["limit"] for s in m["on_limits"])
    assert any("ceiling" in line and "cannot heat that fast" in line for line in m["explanation"])
    assert r.program.Tgi_C.max() <= 330.0 + 1e-9


def test_a_miss_is_also_said_from_the_targets_turning_point_on():
    """SYNTHETIC reference with a charge dip the probe cannot follow (40 degC above the model's run at
    CHARGE, fading in 10 s): the verdict stays on the whole roast, and the miss from the target's turning
    point on (metrics.profile.turning_point) is said apart, recomputed here from the program's curve."""
    import dataclasses

    from roastlab.metrics.profile import turning_point

    model, ref = random_reference(np.random.default_rng(1), "120kg")
    ref = dataclasses.replace(ref, Ta_C=ref.Ta_C + 40.0 * np.exp(-ref.time_s / 10.0))
    r = transfer(model, ref, "120kg", "120kg")
    m, t = r.metrics, r.time_s
    tp = turning_point(t, r.target_C)[0]
    after = np.abs(r.program.Ta_pred_C - r.target_C)[t >= tp].max()
    assert not m["feasible"] and 0 < tp == m["turning_point_s"] < 60
    assert m["max_abs_from_turning_point_C"] == pytest.approx(after) and after <= m["max_abs_C"]
    assert f"from the target's turning point (0:{tp:02.0f}) on: max |e| {after:.1f} °C" in r.summary()


def test_a_miss_no_setting_can_move_is_said_to_be_the_charges_not_a_limits():
    """SYNTHETIC charge dip of the test above (the probe 40 degC above the model's run at CHARGE, fading
    in 10 s): in its first seconds the inlet over its whole range barely moves the probe, so the miss is
    said to be the charge's, with that reach, and not blamed on a limit. The reach is recomputed here
    through the model's own predict on the program's batch, the inlet held at its floor and at its
    ceiling, not through the optimiser's simulator call."""
    import dataclasses

    model, ref = random_reference(np.random.default_rng(1), "120kg")
    ref = dataclasses.replace(ref, Ta_C=ref.Ta_C + 40.0 * np.exp(-ref.time_s / 10.0))
    r = transfer(model, ref, "120kg", "120kg")
    t, e, lim = r.time_s, r.program.Ta_pred_C - r.target_C, r.limits
    batch = r.program_batch()
    ends = [model.predict(dataclasses.replace(batch, Tgi_C=np.full(len(t), level)), plant="120kg").Ta_C
            for level in (lim.low, lim.high)]  # fmt: skip
    reach = ends[1] - ends[0]
    # every program's probe lies between the input held at its floor and at its ceiling: the reach bounds it
    assert np.all(ends[0] <= r.program.Ta_pred_C + 1e-6) and np.all(r.program.Ta_pred_C <= ends[1] + 1e-6)
    assert reach[0] == pytest.approx(0.0, abs=1e-9) and np.all(reach[1:] > 0)  # more inlet heat, a hotter probe
    first = r.metrics["explanation"][0]
    end = next(k for k in range(1, len(t)) if abs(e[k]) <= 2.0 < abs(e[k - 1]))  # after the first miss
    worst = int(np.argmax(np.abs(e[:end])))
    assert 0 < t[worst] <= r.metrics["turning_point_s"] and abs(reach[worst]) < abs(e[worst])
    assert (
        f"no program closes it: the Tgi over its whole range (150 degC against 550 degC from CHARGE on) moves the "
        f"predicted BT at 0:{t[worst]:02.0f} by at most {abs(reach[worst]):.1f} °C; before the turning point the "
        "charge sets it (the drum's heat at CHARGE, the probe's fall onto the beans)"
    ) in first
    assert "ceiling" not in first and "floor" not in first


def test_limit_spans_name_levels_and_rates():
    t = np.arange(0.0, 60.0, 5.0)
    u = np.array([150, 150, 160, 170, 180, 180, 180, 550, 550, 550, 540, 540], dtype=float)
    spans = limit_spans(t, u, ProgramLimits(150.0, 550.0, 120.0))
    names = {s["limit"] for s in spans}
    assert "Tgi at its 150 degC floor" in names and "Tgi at its 550 degC ceiling" in names
    assert "Tgi rising at its 120 degC/min rate limit" in names  # 10 degC per 5 s = 120 degC/min


def test_cli_program_file_reproduces_with_simulate_and_alog_loads(cli, tmp_path):
    model, ref = random_reference(np.random.default_rng(5), "120kg")
    model.save(tmp_path / "model.json")
    write_batch_csv(tmp_path / "ref.csv", ref, comment="SYNTHETIC reference for a test")
    before = (tmp_path / "ref.csv").read_bytes()
    code, out, err = cli(
        "transfer", "--model", f"{tmp_path}/model.json", "--from", "120kg", "--to", "120kg",
        "--batch-kg", "84", "--reference", f"{tmp_path}/ref.csv", "--out", f"{tmp_path}/prog.csv",
        "--json", f"{tmp_path}/m.json", "--alog", f"{tmp_path}/bg.alog", "--plot", f"{tmp_path}/t.png", "--tm0", "free",
    )  # fmt: skip
    assert code == 0, err
    assert "feasible" in out and (tmp_path / "ref.csv").read_bytes() == before
    m = json.loads((tmp_path / "m.json").read_text())
    for key in ("rmse_C", "max_abs_C", "feasible", "solve_s", "baseline_same_inputs", "baseline_retimed", "on_limits"):
        assert key in m
    assert m["rmse_C"] <= 0.5 and m["batch_kg"] == 84.0
    prog = read_batch_csv(tmp_path / "prog.csv")
    assert prog.Mb_kg == 84.0 and "Tm0_C" in prog.initial and "Ta0_C" in prog.initial
    pred = pd.read_csv(tmp_path / "prog.csv", comment="#")
    assert_simulates_back(cli, tmp_path / "model.json", tmp_path / "prog.csv", pred["Ta_pred_C"])
    # the background profile: a Python literal as Artisan writes it, read back by the importer
    text = (tmp_path / "bg.alog").read_text()
    profile = ast.literal_eval(text)
    for key in ("timex", "temp1", "temp2", "timeindex", "specialevents", "specialeventstype", "specialeventsvalue",
                "specialeventsStrings", "etypes", "mode", "samplinginterval", "weight", "title"):  # fmt: skip
        assert key in profile
    log = read_alog(tmp_path / "bg.alog")
    np.testing.assert_allclose(log.channels["BT"], pred["Ta_pred_C"], atol=0.01)
    assert "DROP" in log.events and np.isfinite(log.channels["Burner"]).any()
    burner = log.channels["Burner"]
    assert np.nanmin(burner) >= 0 and np.nanmax(burner) <= 100


@pytest.mark.parametrize(
    "extra, needle",
    [
        (["--tgi-min", "500", "--tgi-max", "400"], "inverted"),
        (["--tgi-rate", "0"], "plausible range"),
        (["--interval-s", "200"], "shorter than two"),
        (["--gg", "0.4", "--gg-min", "0.1", "--gg-max", "1"], "one or the other"),
        (["--gg-min", "0.1"], "both Gg limits"),
        (["--tm0", "hot"], "'free'"),
        (["--tm0", "free", "--tm0-range", "300:100"], "LO < HI"),
        (["--decide", "heater"], "heater setting"),
        (["--alarms", "never-written.alrm"], "heater slider"),  # an inlet-temperature program moves no slider
    ],
)
def test_bad_transfer_input_is_one_line_and_exit_2(cli, tmp_path, extra, needle):
    model, ref = random_reference(np.random.default_rng(6), "120kg", minutes=5.0)
    model.save(tmp_path / "model.json")
    write_batch_csv(tmp_path / "ref.csv", ref)
    code, _, err = cli(
        "transfer", "--model", f"{tmp_path}/model.json", "--reference", f"{tmp_path}/ref.csv",
        "--out", f"{tmp_path}/p.csv", *extra,
    )  # fmt: skip
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert needle in err, err
    assert not (tmp_path / "p.csv").exists()


def test_reference_without_probe_curve_is_refused(cli, tmp_path):
    model, _ = random_reference(np.random.default_rng(6), "120kg", minutes=2.0)
    model.save(tmp_path / "model.json")
    (tmp_path / "ref.csv").write_text("time_s,Gg_kg_s,Tgi_C\n0,0.4,450\n60,0.4,450\n120,0.4,450\n")
    code, _, err = cli(
        "transfer",
        "--model",
        f"{tmp_path}/model.json",
        "--reference",
        f"{tmp_path}/ref.csv",
        "--out",
        f"{tmp_path}/p.csv",
    )
    assert code == 2 and "ref.csv" in err and "Ta_C" in err, err


def test_heater_program_on_a_heated_drum_reproduces_and_simulates_back(cli, tmp_path):
    """The actuator extension: the program decides the heater setting (Qe into the metal)."""
    from roastlab.io.batch import Batch
    from roastlab.workflows.model import FittedModel

    model = FittedModel.paper("120kg").with_values(Qe_gain_kW=4.0, tau_heater_s=20.0)
    t = np.arange(0.0, 601.0, 5.0)
    heater = np.where(t < 240, 60.0, np.where(t < 420, 40.0, 50.0))
    ref0 = Batch("heated", t, np.full(len(t), 0.4), np.full(len(t), 300.0), heater=heater, fan=np.zeros(len(t)))
    ta = model.predict(ref0, Ta0_C=25.0).Ta_C
    ref = Batch("heated", t, ref0.Gg_kg_s, ref0.Tgi_C, ta.copy(), heater=heater, fan=np.zeros(len(t)))
    limits = ProgramLimits(0.0, 100.0, 60.0, decide="heater")
    r = transfer(model, ref, "120kg", "120kg", limits=limits, batch_kg=100.0)
    assert r.metrics["rmse_C"] < 0.1 and r.metrics["feasible"]
    same = r.metrics["baseline_same_inputs"]["rmse_C"]
    assert same > 10 * r.metrics["rmse_C"]  # 100 kg with the 120 kg program is off; the program is not
    assert np.all(np.abs(np.diff(r.program.heater)) <= 5.0 + 1e-9)  # 60 per min = 5 per 5 s
    model.save(tmp_path / "m.json")
    (tmp_path / "prog.csv").write_text(r.program_csv_text())
    assert_simulates_back(cli, tmp_path / "m.json", tmp_path / "prog.csv", r.program.Ta_pred_C)


@pytest.mark.parametrize("rate", [2.0, 5.0, 11.0, 17.0, 20.0, 23.0, 77.0])
def test_any_plausible_rate_limit_solves(rate):
    """The start program's increments can exceed an odd rate bound by a rounding error; the
    optimiser projects its start into the bounds instead of refusing it (issue 27)."""
    model, ref = random_reference(np.random.default_rng(4), "120kg")
    r = transfer(model, ref, "120kg", "120kg", limits=ProgramLimits(150.0, 550.0, rate), batch_kg=100.0)
    steps = np.abs(np.diff(r.program.Tgi_C))
    assert np.all(steps <= rate / 60.0 * 5.0 * (1 + 1e-9) + 1e-9)


@pytest.mark.parametrize(
    "option, value, words",
    [("--tgi-max", "1e300", "--tgi-max"), ("--tgi-rate", "0", "--tgi-rate"), ("--tgi-min", "-400", "--tgi-min")],
)
def test_transfer_limits_are_checked_against_the_plausible_table(cli, tmp_path, option, value, words):
    model, ref = random_reference(np.random.default_rng(5), "120kg")
    model.save(tmp_path / "m.json")
    write_batch_csv(tmp_path / "ref.csv", ref)
    code, _, err = cli(
        "transfer", "--model", tmp_path / "m.json", "--reference", tmp_path / "ref.csv", "--out", tmp_path / "p.csv",
        option, value,
    )  # fmt: skip
    assert code == 2 and words in err and "plausible range" in err and err.count("\n") == 1, err
    assert not (tmp_path / "p.csv").exists()


def test_a_feasible_programs_limits_are_summed_up_by_limit():
    # a stepped program meets its rate limit at every step: said once per limit, not once per step
    from roastlab.workflows.transfer import _spans_in_words

    rising = [{"limit": "heater rising at its 6 levels/min rate limit", "from_s": 60.0 * k, "to_s": 60.0 * k + 10.0}
              for k in range(1, 6)]  # fmt: skip
    ceiling = [{"limit": "heater at its P9 ceiling", "from_s": 90.0, "to_s": 150.0}]
    text = _spans_in_words(sorted(rising + ceiling, key=lambda s: s["from_s"]))
    assert text == (
        "heater rising at its 6 levels/min rate limit 5 times from 1:00 to 5:10 (0:50 in all); "
        "heater at its P9 ceiling 1:30-2:30"
    )
    assert _spans_in_words(rising[:2]) == "heater rising at its 6 levels/min rate limit 1:00-1:10, 2:00-2:10"


def test_a_heater_program_in_levels_becomes_artisan_alarms_that_move_the_burner_slider():
    """transfer --alarms: one alarm per change of the runnable program, at its time after CHARGE, moving
    the Burner slider to the level in tens (Artisan's Aillio setups: P6 is 60); Artisan's table layout."""
    from roastlab.io.background import ALARM_FROM_CHARGE, ALARM_NO_SOURCE, alarm_slider_action, setting_events
    from roastlab.io.batch import Batch
    from roastlab.model.actuators import Actuator
    from roastlab.workflows.model import FittedModel

    model = FittedModel.paper("120kg").with_values(Qe_gain_kW=40.0, tau_heater_s=20.0)
    t = np.arange(0.0, 601.0, 5.0)
    heater = np.where(t < 240, 6.0, np.where(t < 420, 4.0, 5.0))
    ref0 = Batch("levels", t, np.full(len(t), 0.4), np.full(len(t), 300.0), heater=heater, fan=np.zeros(len(t)))
    ref = Batch("levels", t, ref0.Gg_kg_s, ref0.Tgi_C, model.predict(ref0, Ta0_C=25.0).Ta_C, heater=heater,
                fan=np.zeros(len(t)))  # fmt: skip
    act = Actuator("heater", "level", 0.0, 9.0, 1.0, 12.0)
    r = transfer(model, ref, "120kg", "120kg", limits=ProgramLimits.for_actuator(act), batch_kg=100.0)
    alarms = json.loads(r.alarms_text())
    n = len(alarms["alarmflags"])
    assert n >= 2 and all(len(v) == n for v in alarms.values())
    events = setting_events(r.program.time_s, r.setting_series())
    assert [e[1] for e in events] == ["Burner"] * n  # the fan is no machine slider here: not moved
    assert alarms["alarmactions"] == [alarm_slider_action("Burner")] * n == [6] * n
    assert alarms["alarmoffsets"] == [max(1, round(r.program.time_s[e[0]])) for e in events]
    assert alarms["alarmoffsets"][0] == 1  # the setting at CHARGE: 0:00 would be no time condition
    assert set(alarms["alarmtimes"]) == {ALARM_FROM_CHARGE} and set(alarms["alarmsources"]) == {ALARM_NO_SOURCE}
    for (_, _, level, label), text in zip(events, alarms["alarmstrings"]):
        value, comment = text.split(" # ", 1)
        assert float(value) == 10.0 * level and comment.startswith(label) and label == f"P{level:g}"
    # the same program from a model whose inlet temperature is decided moves no slider: refused
    model_t, ref_t = random_reference(np.random.default_rng(6), "120kg", minutes=3.0)
    with pytest.raises(InputError, match="heater slider"):
        transfer(model_t, ref_t, "120kg", "120kg", limits=ProgramLimits(150.0, 550.0, 120.0)).alarms_text()


def test_a_target_from_another_roast_is_followed_from_the_references_inputs(cli, tmp_path):
    """transfer --target: the curve is the target's BT over the target's span (SYNTHETIC: a 12-minute roast
    the model made with other inputs); the reference (15 minutes) gives the start and the charge state; the
    reference's own inputs as the baseline are held where the target runs past them."""
    from roastlab.workflows.transfer import aim_at

    model, ref = random_reference(np.random.default_rng(5), "120kg")
    _, other = random_reference(np.random.default_rng(11), "120kg", minutes=12.0)
    aimed = aim_at(ref, other)
    assert aimed.time_s[-1] == 720.0 and aimed.Ta_C is not other.Ta_C
    np.testing.assert_array_equal(aimed.Ta_C, other.Ta_C)
    np.testing.assert_allclose(aimed.Tgi_C, np.interp(other.time_s, ref.time_s, ref.Tgi_C))
    assert aimed.Mb_kg == ref.Mb_kg and aimed.initial == ref.initial and "curve to follow" in aimed.notes[0]
    model.save(tmp_path / "model.json")
    write_batch_csv(tmp_path / "ref.csv", ref, comment="SYNTHETIC reference for a test")
    write_batch_csv(tmp_path / "target.csv", other, comment="SYNTHETIC target for a test")
    code, out, err = cli(
        "transfer", "--model", tmp_path / "model.json", "--reference", tmp_path / "ref.csv",
        "--target", tmp_path / "target.csv", "--out", tmp_path / "p.csv", "--json", tmp_path / "m.json",
    )  # fmt: skip
    assert code == 0, err
    assert "the curve to follow is target's BT (12:00 from CHARGE to DROP)" in err
    prog = pd.read_csv(tmp_path / "p.csv", comment="#")
    assert prog["time_s"].iloc[-1] == pytest.approx(720.0)
    assert json.loads((tmp_path / "m.json").read_text())["rmse_C"] < 2.0  # the model's own curve: reachable
    code, _, err = cli("transfer", "--model", tmp_path / "model.json", "--reference", tmp_path / "ref.csv",
                       "--target", tmp_path / "none.csv", "--out", tmp_path / "q.csv")  # fmt: skip
    assert code == 2 and "none.csv" in err and err.count("\n") == 1


def test_a_logged_readouts_noise_is_no_event_and_its_moves_are():
    """A heater logged by a readout (a gas pressure in kPa, continuous) replayed as events (whatif's
    background and alarms): its noise (0.01 kPa) is no event, a roaster's move (2.4 -> 1.8 kPa) is one,
    labelled in its unit; a stepped setting keeps every change it has."""
    from roastlab.io.background import setting_events
    from roastlab.model.actuators import Actuator

    t = np.arange(0.0, 300.0, 5.0)
    rng = np.random.default_rng(3)
    gas = np.where(t < 150.0, 2.4, 1.8) + np.round(rng.normal(0.0, 0.01, t.size), 2)
    events = setting_events(t, [("heater", gas, Actuator("heater", "kPa", 0.0, 3.0), False)])
    assert len(events) == 2 and events[1][0] == int(np.argmax(t >= 150.0))
    assert events[1][3] == f"Burner {round(gas[events[1][0]], 2):g} kPa"
    steps = np.where(t < 150.0, 60.0, 55.0)
    stepped = setting_events(t, [("heater", steps, Actuator("heater", "percent", 0.0, 100.0, 5.0), False)])
    assert [e[2] for e in stepped] == [60.0, 55.0] and stepped[1][3] == "Burner 55"
