"""Prediction bands (roastlab.evaluate.bands) on SYNTHETIC logs (tests/test_compare.py's seeded
generator: 120 kg plant batches with 0.5 degC probe noise and roast-to-roast input changes)."""

import subprocess
import sys

import numpy as np
import pytest

import roastlab
from roastlab.errors import ParameterError
from roastlab.evaluate.bands import (
    _new_roast_quantile,
    band_coverage,
    parameter_covariance,
    prediction_bands,
    roast_spread,
)
from test_compare import synthetic_sizes


@pytest.fixture(scope="module")
def fitted():
    batches = [b for b in synthetic_sizes(seed=8) + synthetic_sizes(seed=9) if b.Mb_kg == 120.0]
    result = roastlab.fit(batches[:3], "120kg", bed="contact=wall", starts=2)
    return result.model, batches, result.identification


def test_spread_is_stored_and_is_the_rms_by_time():
    t = np.arange(0.0, 301.0, 10.0)
    s = roast_spread([t, t, t[:11]], [t * 0 + 1, t * 0 - 1, t[:11] * 0 + 3])
    assert s["time_s"][0] == 0.0 and s["logs"] == 3 and s["held_out"]
    assert s["rms_C"][0] == pytest.approx(
        np.sqrt((1 + 1 + 9) / 3), abs=1e-4
    )  # stored to 4 decimals  # three logs reach t = 0
    # past 100 s the third log has ended: it counts with its error at DROP, +3, not as a log that never was
    assert s["rms_C"][-1] == pytest.approx(np.sqrt((1 + 1 + 9) / 3), abs=1e-4)
    assert s["time_s"][-1] == t[-1] and len(s["rms_C"]) == len(s["time_s"])  # to the longest log
    assert roast_spread([t], [t]) is None  # one log says nothing about the spread between roasts


def test_spread_is_each_log_predicted_without_it(fitted):
    model, batches, identification = fitted
    spread = model.doc["fit"]["spread"]
    assert spread["held_out"]
    v = model.validate(batches[:3])  # the fit set's own errors
    own = [np.asarray(p) - np.asarray(m) for m, p in zip(v.measured, v.predicted)]
    assert roast_spread(v.time_s, own)["time_s"] == spread["time_s"]
    # rebuilt from the identification's held-out errors: each log errs more than in the fit
    # (slightly here: two determined parameters over ~100 samples a log learn little from one log)
    held = identification.held_out_Ta
    for b, e in enumerate(own):
        h = held[b, : e.size]
        assert np.sqrt(np.nanmean(h**2)) > np.sqrt(np.nanmean(e**2))
        assert np.nanmax(np.abs(h - e)) < 0.1  # and by what one log moves the fit: a little


def test_band_holds_about_its_level_on_a_held_out_log(fitted):
    model, batches, _ = fitted
    assert model.doc["fit"]["spread"]["logs"] == 3
    rows = band_coverage(model, batches[3:], level=0.9)
    inside = np.mean([r["inside"] for r in rows])
    assert 0.8 <= inside <= 1.0, rows
    assert all(0.5 < r["median_width_C"] < 10.0 for r in rows)
    narrow = band_coverage(model, batches[3:], level=0.5)
    assert np.mean([r["inside"] for r in narrow]) < inside  # a lower level is a narrower band
    band = prediction_bands(model, batches[3:4])[0]
    assert np.all(band.lower_C <= band.predicted_C) and np.all(band.predicted_C <= band.upper_C)
    assert band.sigma_parameters_C.max() > 0  # the fitted parameters' covariance propagates


def test_parameter_part_is_the_covariance_through_difference_quotients(fitted):
    """sigma_p(t) = sqrt(g' C g) with g = dTa/dz: the band's exact sensitivities against central
    differences of two re-simulations per parameter (FittedModel.with_values), and C from the
    file's correlation and standard errors (hgm and hbm, correlated -0.99; Pbm on its bound)."""
    model, batches, _ = fitted
    names, C = parameter_covariance(model)
    se = [model.parameters[n]["stderr"] for n in names]
    assert names == ["hgm", "hbm"] and np.allclose(np.sqrt(np.diag(C)), se)
    r = model.doc["fit"]["correlation"]["matrix"][0][1]
    assert C[0, 1] == pytest.approx(r * se[0] * se[1])
    batch = batches[3]
    band = prediction_bands(model, [batch])[0]
    g = []
    for n, s_n in zip(names, se):
        v, h = model.parameters[n]["value"], 0.01 * s_n
        up = model.with_values(**{n: v + h}).predict(batch).Ta_C
        down = model.with_values(**{n: v - h}).predict(batch).Ta_C
        g.append((up - down) / (2 * h))
    g = np.array(g).T  # (samples, 2)
    by_differences = np.sqrt(np.einsum("tk,kl,tl->t", g, C, g))
    assert band.sigma_parameters_C.max() > 0.01
    assert np.allclose(band.sigma_parameters_C, by_differences, rtol=0.02, atol=1e-3)
    # the correlation matters: the data pin a combination of hgm and hbm, so the band is narrower
    # than if their errors were independent
    independent = np.sqrt(np.einsum("tk,k,tk->t", g, np.diag(C), g))
    assert np.median(band.sigma_parameters_C) < 0.5 * np.median(independent)


def test_levels_and_quantile():
    assert _new_roast_quantile(0.9, 1000) == pytest.approx(1.645, abs=0.01)
    assert _new_roast_quantile(0.9, 3) > 2.3  # three logs: wide


@pytest.mark.parametrize("n_logs", [2, 3, 9])
def test_new_roast_factor_covers_its_level_by_simulation(n_logs):
    """A new zero-mean error falls inside +-factor x RMS(n earlier errors about zero) at the band's level."""
    rng = np.random.default_rng(7)
    trials = 200_000
    rms = np.sqrt(np.mean(rng.standard_normal((trials, n_logs)) ** 2, axis=1))
    new = rng.standard_normal(trials)
    inside = np.mean(np.abs(new) <= _new_roast_quantile(0.9, n_logs) * rms)
    assert inside == pytest.approx(0.9, abs=0.004)
    with pytest.raises(ParameterError, match="band level"):
        prediction_bands(None, [], level=1.5)


def test_validate_band_cli(fitted, tmp_path):
    from roastlab.io.batch import write_batch_csv

    model, batches, _ = fitted
    model.save(tmp_path / "m.json")
    write_batch_csv(tmp_path / "b.csv", batches[3])
    cmd = [sys.executable, "-m", "roastlab", "validate", "--model", "m.json", "b.csv", "--band", "--json", "v.json"]
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "90% prediction band" in out.stdout and "median width" in out.stdout
    bad = subprocess.run(cmd[:-3] + ["--band", "2"], capture_output=True, text=True, cwd=tmp_path)
    assert bad.returncode == 2 and "band level" in bad.stderr
    # a band with a changed initial state is refused before the validation prints anything
    changed = subprocess.run(cmd[:-2] + ["--tm0", "200"], capture_output=True, text=True, cwd=tmp_path)
    assert changed.returncode == 2 and "--band scores the model as fitted" in changed.stderr
    assert changed.stdout == "" and changed.stderr.count("\n") == 1


def test_validate_band_reports_each_batch_size(fitted, tmp_path):
    """Logs of two sizes: a line and a JSON entry per size, its share the samples-weighted share of its logs,
    and its mean FIT and MAE over the held-out logs (the batch-size question, asked of any model)."""
    import json

    from roastlab.io.batch import write_batch_csv
    from test_compare import synthetic_sizes

    model, batches, _ = fitted
    model.save(tmp_path / "m.json")
    other = [b for b in synthetic_sizes(seed=10) if b.Mb_kg == 180.0]
    names = []
    for k, b in enumerate([batches[3], *other]):
        write_batch_csv(tmp_path / f"b{k}.csv", b)
        names.append(f"b{k}.csv")
    cmd = [sys.executable, "-m", "roastlab", "validate", "--model", "m.json", *names, "--band", "--json", "v.json"]
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "size 120 kg (1 log)" in out.stdout and "size 180 kg (2 logs)" in out.stdout
    band = json.loads((tmp_path / "v.json").read_text())["band"]
    heavy = [r for r in band["batches"] if r["Mb_kg"] == 180.0]
    by_size = {g["size"]: g for g in band["by_size"]}
    assert by_size["180 kg"]["logs"] == 2 and by_size["180 kg"]["n"] == sum(r["n"] for r in heavy)
    want = sum(r["n"] * r["inside"] for r in heavy) / sum(r["n"] for r in heavy)
    assert by_size["180 kg"]["inside"] == pytest.approx(want)
    # and the metrics by size, of the logs held out from the fit (every log where none was fitted on)
    doc = json.loads((tmp_path / "v.json").read_text())
    scored = [r for r in doc["batches"] if r["name"] not in doc.get("not_held_out", {})]
    fit_of = {g["size"]: g for g in doc["by_size"]}
    heavy_fit = [r["FIT"] for r in scored if r["name"] in ("b1", "b2")]
    assert fit_of["180 kg"]["logs"] == 2 and fit_of["180 kg"]["FIT"] == pytest.approx(np.mean(heavy_fit))
    line = next(ln for ln in out.stdout.splitlines() if ln.startswith("size 180 kg (2 logs)") and "FIT" in ln)
    assert f"FIT {np.mean(heavy_fit):>6.1f} %" in line and line.endswith(" °C")


def test_a_validation_figure_of_several_sizes_shows_each_size_in_turn(fitted):
    """Logs of two sizes, the heavier listed first: the panels take a log of each size in turn, lightest
    first, each titled with its batch, and the title says how they were chosen (validate --plot)."""
    from roastlab.evaluate.validate import each_size_in_turn, panels_by_size
    from roastlab.report.figures import plot_fit
    from test_compare import synthetic_sizes

    model, batches, _ = fitted
    heavy = [b for b in synthetic_sizes(seed=10) if b.Mb_kg == 180.0]
    logs = [*heavy, batches[3]]  # 180, 180, 120 kg
    result = model.validate(logs)
    masses = [b.Mb_kg for b in logs]
    assert each_size_in_turn(masses) == [2, 0, 1] and each_size_in_turn(masses, scored={0, 1}) == [0, 1]
    panels = panels_by_size(result.names, masses)
    fig = plot_fit(result, max_panels=2, **panels)
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert [t.split(":")[0] for t in titles] == [f"{result.names[2]} (120 kg)", f"{result.names[0]} (180 kg)"]
    assert fig.get_suptitle() == "(each size's logs in turn: 2 of 3 batches)"
    # validate's: some logs were fitted on, so the held-out ones; one size: the first panels, as before
    assert panels_by_size(result.names, masses, scored={0, 2})["which"] == (
        [2, 0],
        "each size's held-out logs in turn:",
    )
    assert panels_by_size(result.names[:2], masses[:2]) == {}


def test_a_band_says_when_a_batch_size_lies_outside_the_fitted_ones():
    """The spread keeps the fitted green weights' range; a batch outside it gets a note, inside none."""
    from types import SimpleNamespace

    from roastlab.evaluate.bands import sizes_outside

    t = [np.arange(0.0, 300.0, 5.0)] * 3
    e = [np.full(60, 2.0), np.full(60, -1.0), np.full(60, 0.5)]
    spread = roast_spread(t, e, batch_kg=[0.49, 0.5, 0.49])
    assert spread["batch_kg"] == [0.49, 0.5]
    model = SimpleNamespace(doc={"fit": {"spread": spread}})
    assert sizes_outside(model, [0.49, 0.5, 0.495, 0.48]) is None  # one size, as compare-models groups them
    note = sizes_outside(model, [0.35, 0.49, 0.8, 0.35])
    assert note.startswith("0.35 kg, 0.8 kg lie outside") and "0.49-0.5 kg" in note
    assert sizes_outside(SimpleNamespace(doc={"fit": {"spread": roast_spread(t, e)}}), [0.35]) is None  # older file


def test_a_band_says_when_a_log_comes_from_another_roaster_of_the_make():
    """The spread keeps the roasters its logs name (serial numbers); a log of another unit gets a
    note, joined with the size note by band_note; logs that name none, or a file without units, none."""
    from types import SimpleNamespace

    from roastlab.evaluate.bands import band_note, units_outside

    t = [np.arange(0.0, 300.0, 5.0)] * 3
    e = [np.full(60, 2.0), np.full(60, -1.0), np.full(60, 0.5)]
    spread = roast_spread(t, e, batch_kg=[0.49, 0.5, 0.49], units=["2779", "2779", ""])
    assert spread["units"] == ["2779"]
    model = SimpleNamespace(doc={"fit": {"spread": spread}}, plant=None)
    assert units_outside(model, ["2779", ""]) is None
    note = units_outside(model, ["2054", "2779", "1447"])
    assert note.startswith("units 1447, 2054 are not the roaster") and "(2779)" in note
    assert units_outside(SimpleNamespace(doc={"fit": {"spread": roast_spread(t, e)}}), ["2054"]) is None
    assert "units" not in roast_spread(t, e, units=["", "", ""])
    batch = SimpleNamespace(Mb_kg=0.2, unit="2054")
    both = band_note(model, [batch])
    assert both.startswith("0.2 kg lies outside") and " and unit 2054 is not the roaster" in both
    assert "holds neither the error of a batch-size change nor the difference between two drums" in both
    assert band_note(model, [batch], batch_kg=0.5).startswith("unit 2054")  # a what-if's weight replaces the log's
    assert band_note(model, [SimpleNamespace(Mb_kg=0.49, unit="2779")]) is None


def test_a_band_of_a_model_fitted_on_one_log_says_it_holds_no_spread(fitted):
    """One log says nothing about the spread between roasts: the band is the parameters' alone and
    its note says so (fit-roaster on two logs held 4 % of the held-out log's samples before it did),
    joined with the other notes; a model with a spread gets none of it."""
    from types import SimpleNamespace

    from roastlab.evaluate.bands import band_note, band_report

    model, batches, _ = fitted
    one = roastlab.fit(batches[:1], "120kg", bed="contact=wall", starts=2).model
    report = band_report(one, batches[3:4])[0]
    from roastlab.workflows.roaster import band_sentence

    assert not report["spread"] and report["note"].startswith("the model was fitted on one log")
    assert "(parameters only;" in band_sentence(report)
    assert "does not hold the spread between roasts" in report["note"]
    assert band_report(model, batches[3:4])[0]["spread"] and band_report(model, batches[3:4])[0]["note"] is None
    three = band_note(
        SimpleNamespace(doc={"fit": {}}, plant=None), [SimpleNamespace(Mb_kg=0.2, unit="2054")]
    )  # no spread, so no sizes or units to compare either
    assert three.startswith("the model was fitted on one log") and "nor" not in three


def test_a_transfer_programs_band_is_around_its_predicted_curve(fitted):
    """transfer --band: the program's batch (TransferResult.program_batch, what PROGRAM.csv holds) applied
    by the model gives the program's predicted BT as the band's centre; the band is the model's, on plant B."""
    from roastlab.fit.program import ProgramLimits
    from roastlab.workflows.transfer import transfer

    model, batches, _ = fitted
    ref = batches[-1]  # held out of the fit
    r = transfer(model, ref, "120kg", "120kg", limits=ProgramLimits(150.0, 550.0, 120.0), batch_kg=100.0,
                 interval_s=10.0, band_level=0.9)  # fmt: skip
    b = r.band
    np.testing.assert_allclose(b.predicted_C, r.program.Ta_pred_C, atol=1e-6)
    assert np.all(b.lower_C <= b.predicted_C) and np.all(b.predicted_C <= b.upper_C) and b.median_width_C > 0.1
    assert r.metrics["band"]["level"] == 0.9 and r.metrics["band"]["median_width_C"] == round(b.median_width_C, 2)
    assert "90 % prediction band of the predicted BT" in r.summary()
    # a model file with neither covariance nor spread carries no band: said before any work
    with pytest.raises(ParameterError, match="no band"):
        transfer(roastlab.FittedModel.paper("120kg"), ref, "120kg", "120kg", batch_kg=100.0, band_level=0.9)
