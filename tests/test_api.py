"""The fitted-model object and file: one application path for every command and the Python API."""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import roastlab
from roastlab.io.batch import Batch

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "skywalker"
DATA = roastlab.default_dataset_root()


@pytest.fixture(scope="module")
def sky_model(tmp_path_factory):
    """A model fitted on two Skywalker logs with the example's map and spec (what a user runs)."""
    from conftest import REAL_DATA

    folder = REAL_DATA / "skywalker"
    if not folder.is_dir():
        pytest.skip("../shared/data/real is absent")
    logs = sorted(folder.glob("*.alog"))[3:]  # from October 2025 on, ET reads the drum's air (the map)
    batches = [roastlab.load_log(p, EXAMPLE / "map.toml") for p in logs[0:4:2]]
    from roastlab.io.importers import load_map

    result = roastlab.fit(
        batches, EXAMPLE / "plant.toml", EXAMPLE / "fit.toml", column_map=load_map(EXAMPLE / "map.toml"), starts=2
    )
    path = tmp_path_factory.mktemp("model") / "sky.json"
    result.model.save(path)
    return path, logs[1]


def test_the_packages_names_are_one_list_three_ways():
    """``roastlab``'s public names load on first use: the table that loads them (``_LAZY``), ``__all__``
    and the imports static tools read (under TYPE_CHECKING) name the same objects, and each loads."""
    import ast
    import inspect

    tree = ast.parse(inspect.getsource(roastlab))
    block = next(n for n in tree.body if isinstance(n, ast.If) and getattr(n.test, "id", "") == "TYPE_CHECKING")
    static = {
        a.asname or a.name: f"{n.module}" + (f":{a.name}" if a.asname else "") for n in block.body for a in n.names
    }
    assert static == roastlab._LAZY
    assert sorted(roastlab.__all__) == sorted(roastlab._LAZY)
    for name in roastlab.__all__:
        assert getattr(roastlab, name) is not None


def test_whatif_is_the_same_through_every_path(cli, sky_model, tmp_path):
    """simulate --model, validate --model --predictions and model.predict agree to 1e-6 degC."""
    model_path, log = sky_model
    batch_csv = tmp_path / "b.csv"
    assert cli("import", log, "--map", EXAMPLE / "map.toml", "--out", batch_csv)[0] == 0
    model = roastlab.load_model(model_path)
    batch = roastlab.load_log(batch_csv)
    for offset in (0.0, 20.0):
        sim_out, pred_dir = tmp_path / f"sim{offset:g}.csv", tmp_path / f"pred{offset:g}"
        pred_dir.mkdir()
        args = ("--model", model_path, "--tgi-offset", offset)
        assert cli("simulate", *args, "--inputs", batch_csv, "--out", sim_out)[0] == 0
        code, _, err = cli("validate", *args, batch_csv, "--predictions", pred_dir)
        assert code == 0, err
        api = model.predict(batch, Tgi_offset_C=offset).Ta_C
        via_sim = pd.read_csv(sim_out)["Ta_C"].to_numpy()
        via_val = pd.read_csv(pred_dir / "b.csv")["Ta_pred_C"].to_numpy()
        # the CSVs carry 6 decimals: 5e-7 of rounding is the whole allowed difference
        assert np.max(np.abs(via_sim - api)) <= 1e-6 and np.max(np.abs(via_val - api)) <= 1e-6
    # the raw log through the model's own map gives the same curve as its imported CSV (4 decimals)
    raw = model.predict(log).Ta_C
    assert np.max(np.abs(raw - model.predict(batch).Ta_C)) < 1e-3


def test_fit_prediction_equals_identification(sky_model):
    """The model file, applied by FittedModel, reproduces the identification's own SSR."""
    model_path, _ = sky_model
    model = roastlab.load_model(model_path)
    doc = json.loads(model_path.read_text())
    logs = [Path(i["path"]) for i in doc["provenance"]["inputs"] if i["role"] == "batch"]
    val = model.validate([roastlab.load_log(p, model.column_map) for p in logs])
    ssr = sum(r["SSR"] for r in val.rows)
    outputs = doc["fit"]["outputs"]  # the example weighs ET too: the fit's SSR sums the weighted outputs
    assert ssr == pytest.approx(outputs["Ta"]["SSR"], rel=1e-9)
    assert sum(o["weight"] * o["SSR"] for o in outputs.values()) == pytest.approx(doc["fit"]["SSR"], rel=1e-9)


def test_model_file_round_trip_and_contents(tmp_path):
    ds = roastlab.read_dataset(DATA / "dataset-I")
    result = roastlab.fit(ds.batches[:2], "120kg", estimate_tm0=True, seed=1, starts=2)
    path = result.model.save(tmp_path / "m.json")
    doc = json.loads(path.read_text())
    assert doc["format"] == "roastlab-model/1" and doc["plant"]["Dch_m"] == 1.24
    assert doc["initial"]["Tm0_C"]["how"] == "fitted per batch" and set(doc["initial"]["Tm0_C"]["per_batch"]) == {
        "batch1",
        "batch2",
    }
    again = roastlab.load_model(path)
    a = result.model.predict(ds.batches[0]).Ta_C
    assert np.array_equal(a, again.predict(ds.batches[0]).Ta_C)
    # a batch not in the fit set takes the median fitted Tm0 and says so
    r = again.predict(ds.batches[3])
    assert any("not in the fit set" in n for n in r.meta["notes"])


def test_legacy_theta_json_loads(tmp_path):
    old = tmp_path / "theta.json"
    old.write_text(json.dumps({"hgm": 0.02, "hbm": 0.03, "Pbm": 0.6, "SSR": 1.0, "plant": "120kg"}))
    m = roastlab.load_model(old)
    assert m.theta.as_tuple() == (0.02, 0.03, 0.6) and m.plant.name == "120kg"


@pytest.mark.parametrize(
    "content, needle",
    [
        ({"baseline": "first-order", "tau_s": 100.0, "offset_C": 0.0}, "--baseline first-order"),
        ({"mode": "per-batch", "batches": []}, "not a model"),
        ({"format": "roastlab-model/9"}, "unknown model format"),
    ],
)
def test_wrong_kind_of_file_says_what_it_is(tmp_path, content, needle):
    f = tmp_path / "x.json"
    f.write_text(json.dumps(content))
    with pytest.raises(roastlab.InputError, match=needle.replace("-", r"\-")):
        roastlab.load_model(f)


def test_transfer_to_another_plant_names_what_carried_over():
    ds = roastlab.read_dataset(DATA / "dataset-I")
    result = roastlab.fit(ds.batches[:2], "120kg", estimate_tm0=True, seed=0, starts=2)
    v = result.model.validate(roastlab.read_dataset(DATA / "dataset-V").batches, plant="360kg")
    (note,) = [n for n in v.notes if "applied to 360kg" in n]
    assert "carried over hgm, hbm, Pbm" in note and "dropped plant-specific Tm0_C" in note


def test_a_log_outside_a_per_batch_fit_runs_from_its_own_drum_reading_and_says_only_what_it_uses():
    """SYNTHETIC dataset-I: the drum start fitted per batch on two batches. A third batch with no
    reading of its own runs from the fitted batches' median and a note says so; with its own reading
    (what a map's [initial] gives) it runs from that, as a change to it would, and no note claims the median."""
    import dataclasses

    ds = roastlab.read_dataset(DATA / "dataset-I")
    model = roastlab.fit(ds.batches[:2], "120kg", estimate_tm0=True, seed=0, starts=1).model
    assert model.initial["Tm0_C"]["how"] == "fitted per batch"
    new = ds.batches[2]
    assert any("median of the fitted batches" in n for n in model.validate([new]).notes)
    own = dataclasses.replace(new, initial={**new.initial, "Tm0_C": 150.0})
    v = model.validate([own])
    assert not any("median of the fitted batches" in n for n in v.notes)
    np.testing.assert_allclose(model.predict(own).Ta_C, model.predict(new, Tm0_C=150.0).Ta_C, atol=1e-9)


def test_a_value_left_on_its_bound_to_rounding_reads_as_the_bound_in_the_table():
    """A fitted value 1e-16 on a floor of 0 (the Bullet's shell loss in fit-roaster's table read
    1.0803e-16) reads 0; one a step inside its bound keeps its digits."""
    doc = roastlab.FittedModel.paper().to_document()
    doc["parameters"]["U_shell_kW_m2K"] = {"value": 1.08e-16, "how": "fitted", "stderr": None, "bounds": [0.0, 0.1]}
    doc["parameters"]["hgm"] = {"value": 0.0010004, "how": "fitted", "stderr": None, "bounds": [0.001, 1.0]}
    rows = {r[0]: r[1] for r in roastlab.FittedModel(doc).table()}
    assert rows["U_shell_kW_m2K"] == "0" and rows["hgm"] == "0.0010004"
    doc["parameters"]["U_shell_kW_m2K"]["bounds"] = ["a", None]  # a user's file: bounds are not trusted
    assert {r[0]: r[1] for r in roastlab.FittedModel(doc).table()}["U_shell_kW_m2K"] == "1.08e-16"


def test_results_display_and_plot_without_pyplot():
    import matplotlib.pyplot as plt

    ds = roastlab.read_dataset(DATA / "dataset-I")
    result = roastlab.fit(ds.batches[:2], "120kg", seed=0, starts=2)
    assert repr(result).startswith("<FitResult <FittedModel 120kg") and "<table" in result._repr_html_()
    assert "hgm" in result.report() and "std. error" in result.report()
    before = plt.get_fignums()
    fig = result.plot()
    sim_fig = result.model.predict(ds.batches[0]).plot()
    assert plt.get_fignums() == before  # not registered: Jupyter shows it once
    assert len(fig.axes) == 6 and len(sim_fig.axes) == 4  # per batch: BT with its RoR axis, residual
    # one legend for the panels, below them, not one in each panel over its curves
    (legend,) = fig.legends
    assert not any(ax.get_legend() for ax in fig.axes[::3]) and not any(ax.get_legend() for ax in fig.axes[2::3])
    assert [t.get_text() for t in legend.get_texts()] == [
        "BT predicted (model Ta)", "BT measured (Ta)", "RoR predicted", "RoR measured"]  # fmt: skip
    frame = result.validation.to_frame()
    assert list(frame.index) == ["batch1", "batch2"] and "FIT" in frame


def test_progress_is_a_callback_and_the_library_never_prints(capsys):
    ds = roastlab.read_dataset(DATA / "dataset-I")
    calls = []
    roastlab.fit(ds.batches[:1], "120kg", seed=0, starts=2, progress=lambda *a: calls.append(a))
    assert calls and calls[-1][0] == calls[-1][1]
    out = capsys.readouterr()
    assert out.out == "" and out.err == ""


def test_unknown_change_is_refused():
    m = roastlab.FittedModel.paper("120kg")
    t = np.arange(0, 301, 30.0)
    b = Batch("b", t, np.full_like(t, 0.4), np.full_like(t, 450.0))
    with pytest.raises(roastlab.ParameterError, match="unknown change"):
        m.predict(b, burner=3)
    with pytest.raises(roastlab.ParameterError, match="no heater setting"):
        m.predict(b, heater=3)  # a real change, but this batch logs no heater


def test_placeholder_flow_without_a_spec_is_refused():
    t = np.arange(0, 301, 30.0)
    b = Batch("b", t, np.ones_like(t), np.full_like(t, 450.0), np.linspace(30, 150, len(t)))
    with pytest.raises(roastlab.InputError, match="placeholder"):
        roastlab.fit([b], "120kg")


def _api_misuse_cases():
    import roastlab
    from roastlab.io.batch import read_batch_csv
    from roastlab.model.rhs import pack_params
    from roastlab.workflows.model import FittedModel, load_model

    b = read_batch_csv(Path(roastlab.__file__).parent / "datasets" / "paper-synthetic" / "dataset-I" / "batch1.csv")
    m = FittedModel.paper("120kg")
    return {
        "load_model(None)": lambda: load_model(None),
        "fit of a missing path": lambda: roastlab.fit(["x"], "120kg"),
        "fit of a number": lambda: roastlab.fit([3], "120kg"),
        "fit with a negative seed": lambda: roastlab.fit([b], "120kg", seed=-1),
        "predict with an array initial state": lambda: m.predict(b, Tm0_C=np.array([1.0, 2.0])),
        "predict with NaN hgm": lambda: m.predict(b, hgm=float("nan")),
        "theta of two values": lambda: roastlab.simulate("120kg", b.time_s, b.Gg_kg_s, b.Tgi_C, theta=(0.01, 0.02)),
        "pack_params of a name": lambda: pack_params("120kg", (0.01, 0.0254, 0.5793), 0.1),
        "pack_params with NaN X0": lambda: pack_params(m.plant, (0.01, 0.0254, 0.5793), float("nan")),
        "complex inlet temperatures": lambda: roastlab.simulate("120kg", b.time_s, b.Gg_kg_s, b.Tgi_C + 0j),
    }


@pytest.mark.parametrize("case", sorted(_api_misuse_cases()))
def test_api_misuse_raises_the_projects_own_errors(case):
    """The API's promise (issue 27): ordinary misuse is a RoastlabError with a clear message,
    never a TypeError/ValueError/AttributeError from inside, nor a silent NaN."""
    from roastlab.errors import RoastlabError

    with pytest.raises(RoastlabError) as exc:
        _api_misuse_cases()[case]()
    assert len(str(exc.value)) > 10


#: Wrong values of every kind: none, NaN, complex, a wrong shape, a string, a negative number,
#: a list, a mapping, an all-NaN array and a Boolean.
WRONG = [None, float("nan"), 1 + 2j, np.array([[1.0, 2.0]]), "abc", -1, [1, 2], {"a": 1}, np.full(3, np.nan), True]


def _public_calls():
    """Each public function and class of ``roastlab`` with good arguments."""
    import roastlab

    b = roastlab.read_batch_csv(
        Path(roastlab.__file__).parent / "datasets" / "paper-synthetic" / "dataset-I" / "batch1.csv"
    )
    p = roastlab.pack_params(roastlab.load_plant("120kg"), (0.01, 0.0254, 0.5793), 0.1)
    return {
        "simulate": ("120kg", b.time_s, b.Gg_kg_s, b.Tgi_C),
        "pack_params": (roastlab.load_plant("120kg"), (0.01, 0.0254, 0.5793), 0.1),
        "rhs": (0.0, np.array([30.0, 120, 0.1, 0, 30]), np.array([0.4, 450.0]), p),
        "load_plant": ("120kg",),
        "load_model": ("missing.json",),
        "load_log": ("missing.alog",),
        "read_batch_csv": ("missing.csv",),
        "read_dataset": ("missing",),
        "InitialState": (25.0,),
        "Theta": (0.01, 0.02, 0.5),
        "Simulator": ("120kg",),
        "fit": ([b], "120kg"),
    }


@pytest.mark.parametrize("name", sorted(_public_calls()))
def test_every_public_function_refuses_wrong_arguments_with_its_own_error(name):
    """Each argument of each public function, in turn, given each kind of wrong value: the call
    returns or raises the project's own error, never a TypeError, AttributeError or ValueError
    from inside (issue 27, the API's promise)."""
    import roastlab
    from roastlab.errors import RoastlabError

    good = _public_calls()[name]
    func = getattr(roastlab, name)
    for i in range(len(good)):
        for wrong in WRONG:
            args = list(good)
            args[i] = wrong
            try:
                func(*args)
            except RoastlabError as exc:
                assert len(str(exc)) > 10
            except Exception as exc:  # noqa: BLE001 - the point of the test
                pytest.fail(f"{name} argument {i} = {wrong!r}: {type(exc).__name__}: {exc}")


def test_whatif_band_is_the_changed_curves_and_a_model_without_one_says_why(cli, sky_model, tmp_path):
    """whatif --band: the band is centred on the changed prediction (the same band the validate
    command scores, through prediction_bands with the same changes); a model file with neither
    covariance nor spread refuses it in one line naming the file, exit 2."""
    from roastlab.evaluate.bands import prediction_bands

    model_path, log = sky_model
    out_json = tmp_path / "w.json"
    code, out, err = cli("whatif", log, "--model", model_path, "--tgi", "15", "--band", "--json", out_json)
    assert code == 0, err
    doc = json.loads(out_json.read_text())["band"]
    model = roastlab.load_model(model_path)
    batch = roastlab.load_log(log, model.column_map)
    b = prediction_bands(model, [batch], 0.9, Tgi_offset_C=15.0)[0]
    assert doc["level"] == 0.9 and doc["median_width_C"] == pytest.approx(float(np.median(b.width_C)), abs=0.01)
    assert doc["DROP_lower_C"] < model.predict(batch, Tgi_offset_C=15.0).Ta_C[-1] < doc["DROP_upper_C"]
    assert "90 % prediction band of the changed probe BT" in out
    bare = tmp_path / "bare.json"
    m = json.loads(model_path.read_text())
    m["fit"].pop("correlation", None)
    m["fit"].pop("spread", None)
    bare.write_text(json.dumps(m))
    code, _, err = cli("whatif", log, "--model", bare, "--band")
    errors = [line for line in err.splitlines() if not line.startswith("note: ")]
    assert code == 2 and len(errors) == 1 and "no band" in errors[0] and str(bare) in errors[0]


def test_simulate_band_columns_hold_the_prediction(cli, sky_model, tmp_path):
    model_path, log = sky_model
    out = tmp_path / "s.csv"
    code, text, err = cli("simulate", "--model", model_path, "--inputs", log, "--out", out, "--band", "0.8")
    assert code == 0, err
    df = pd.read_csv(out)
    assert np.all(df["Ta_lower_C"] <= df["Ta_C"] + 1e-6) and np.all(df["Ta_C"] <= df["Ta_upper_C"] + 1e-6)
    assert (df["Ta_upper_C"] - df["Ta_lower_C"]).median() > 0.5 and "80 % prediction band" in text
    code, _, err = cli("simulate", "--plant", EXAMPLE / "plant.toml", "--inputs", log, "--map", EXAMPLE / "map.toml",
                       "--out", tmp_path / "p.csv", "--band")  # fmt: skip
    assert code == 2 and "carries no band" in err


def test_whatif_on_the_fan_moves_the_roast_and_a_model_deaf_to_it_says_so(sky_model):
    """The Skywalker's Air setting sets the flow (the example frees Gg_fan_kg_s; here a gain that
    doubles the fitted flow at full fan): more air from 5:00 cools the roast to DROP. A model whose fan
    gain is 0, or the 1e-44 a fit leaves on the gain's floor of 0 (two logs' fit does), changes nothing
    and the table says why, instead of a silent "+0.0" a roaster would read as "the fan does not
    matter"."""
    from roastlab.workflows.whatif import parse_setting_change, whatif

    model_path, log = sky_model
    fitted = roastlab.load_model(model_path)
    model = fitted.with_values(Gg_fan_kg_s=fitted.values["Gg_kg_s"] / 100)
    batch = roastlab.load_log(log, model.column_map)
    more_air = [parse_setting_change("fan", "+20@5:00")]
    moved = whatif(model, batch, more_air)
    drop = next(r for r in moved.rows if r["reading"] == "probe" and r["key"] == "DROP_C")
    assert drop["changed"] < drop["as_run"] - 0.5 and not moved.inert
    for gain in (0.0, 1.4e-44):
        deaf = whatif(model.with_values(Gg_fan_kg_s=gain), batch, more_air)
        drop = next(r for r in deaf.rows if r["reading"] == "probe" and r["key"] == "DROP_C")
        assert drop["changed"] == pytest.approx(drop["as_run"], abs=1e-6)
        assert any("does not respond to the fan (Gg_fan_kg_s = 0" in w for w in deaf.warnings())
    assert "does not respond" not in "\n".join(
        whatif(model, batch, [parse_setting_change("heater", "+5@5:00")]).warnings()
    )


def test_a_shift_past_the_knobs_end_says_where_the_log_is_there_already(sky_model):
    """The heater shifted up where the log runs it at the top of its range changes nothing there; a note
    says when (a Bullet log runs P9 from 1:00 to 8:00, and "+1 from 4:00" there first acts at 8:00), and
    of a change that nothing is left for, that it changes nothing, rather than a table of zeros a
    roaster would read as "the heater does not matter". The page shows the notes (``warnings``)."""
    import dataclasses

    from roastlab.metrics.profile import mmss
    from roastlab.workflows.whatif import parse_setting_change, whatif

    model_path, log = sky_model
    model = roastlab.load_model(model_path)
    batch = roastlab.load_log(log, model.column_map)
    t = batch.time_s
    top = dataclasses.replace(batch, heater=np.where((t >= 180.0) & (t < 360.0), 100.0, 60.0))
    moved = whatif(model, top, [parse_setting_change("heater", "+10@2:00")])
    assert moved.changes == ["heater +10 from 2:00 (held within 0 %-100 %)"]
    last = t[t < 360.0][-1]
    assert (
        f"heater +10 from 2:00: the log is at 100 % there 3:00-{mmss(last)}, the end of its range, so the change acts "
        "only outside those times"
    ) in moved.warnings()
    drop = next(r for r in moved.rows if r["reading"] == "probe" and r["key"] == "DROP_C")
    assert drop["changed"] > drop["as_run"] + 0.5  # it acts outside those minutes
    full = whatif(
        model, dataclasses.replace(batch, heater=np.full(t.size, 100.0)), [parse_setting_change("heater", "+10")]
    )
    assert (
        "heater +10: the log is at 100 % wherever it applies, the end of its range, so it changes nothing"
        in full.warnings()
    )
    assert np.array_equal(full.changed.Ta_C, full.as_run.Ta_C)
    plain = whatif(model, batch, [parse_setting_change("heater", "+5@5:00")])
    assert plain.held_at_end == [] and not any("end of its range" in w for w in plain.warnings())


def test_transfer_deciding_a_heater_the_model_is_deaf_to_says_so(sky_model):
    """A program decided on the heater of a model whose heater gains are all 0 (SETTING_GAINS, the
    one table whatif reads too) is refused with the gains named, not optimised over a flat response."""
    from roastlab.errors import InputError
    from roastlab.workflows.transfer import transfer

    model_path, log = sky_model
    model = roastlab.load_model(model_path).with_values(Qe_gain_kW=0.0, Tgi_gain_C=0.0)
    with pytest.raises(InputError, match=r"the heater has no effect on .*\(Qe_gain_kW, Tgi_gain_C\) are 0"):
        transfer(model, roastlab.load_log(log, model.column_map), None, None)


def test_whatif_figure_shows_the_first_crack_mark_and_no_mark_past_the_curves(sky_model):
    """The Skywalker's one bean reading, its FCs mark read as the beans at FIRST_CRACK_BEAN_C, is drawn
    as a marker at the mark and named so (a single dot among a channel's went unseen), and an event
    well past the curves (COOL, minutes after DROP) gets no label outside the axes."""
    from matplotlib.text import Annotation

    from roastlab.model.actuators import Actuator
    from roastlab.model.constants import FIRST_CRACK_BEAN_C
    from roastlab.report.figures import plot_whatif
    from roastlab.workflows.whatif import parse_setting_change, whatif

    model_path, log = sky_model
    model = roastlab.load_model(model_path)
    batch = roastlab.load_log(log, model.column_map)
    batch.events["COOL"] = batch.time_s[-1] + 120.0
    fig = plot_whatif(whatif(model, batch, [parse_setting_change("heater", "+5@3:00")]))
    ax = fig.axes[0]
    (mark,) = [ln for ln in ax.get_lines() if ln.get_label().startswith("beans at first crack")]
    assert mark.get_ydata().tolist() == [FIRST_CRACK_BEAN_C] and mark.get_marker() == "D"
    assert abs(mark.get_xdata()[0] * 60.0 - batch.events["FCs"]) <= 2.5
    labels = [c.get_text() for c in ax.get_children() if isinstance(c, Annotation)]
    assert any(s.startswith("FCs ") for s in labels) and any(s.startswith("DRY ") for s in labels)
    assert not any(s.startswith("COOL ") for s in labels)
    # the settings in one unit share an axis in it; in two units (a heater in kPa, the fan in %) each
    # its own scale, the fan on the right (a kPa under 100 % sat flat along the floor)
    assert len(fig.axes) == 3 and fig.axes[2].get_ylabel() == "setting [%]"
    w = whatif(model, batch, [parse_setting_change("heater", "+5@3:00")])
    w.actuators["heater"] = Actuator("heater", "kPa", 0.0, 3.5)
    fig = plot_whatif(w)
    assert [a.get_ylabel() for a in fig.axes[2:]] == ["heater [kPa]", "fan [%]"]


def _in_fahrenheit(doc: dict) -> None:
    """An Artisan profile recorded in degF: its mode, BT, ET and room in degF (the same roast)."""
    f = lambda c: c if c == -1 else c * 9.0 / 5.0 + 32.0  # noqa: E731 - Artisan's -1: no sample
    doc["mode"], doc["temp1"], doc["temp2"] = "F", [f(v) for v in doc["temp1"]], [f(v) for v in doc["temp2"]]
    if doc.get("ambientTemp"):
        doc["ambientTemp"] = f(doc["ambientTemp"])


def test_whatif_speaks_the_unit_the_log_was_recorded_in(cli, sky_model, tmp_path):
    """The same roast logged in degF: whatif's table, figure and Artisan background are in degF without
    being told (the figure's temperatures on a degF scale), --units C gives the table in degC, and the
    numbers are the same roast's either way."""
    from conftest import rewritten_alog

    model_path, log = sky_model
    f_log = rewritten_alog(log, tmp_path / "in_F.alog", _in_fahrenheit)
    bg = tmp_path / "next.alog"
    argv = ["whatif", f_log, "--model", model_path, "--heater", "+5@3:00", "--plot", tmp_path / "f.png", "--alog", bg]
    code, out_f, err = cli(*argv)
    assert code == 0, err
    code, out_c, err = cli("whatif", f_log, "--model", model_path, "--heater", "+5@3:00", "--units", "C")
    assert code == 0, err
    assert "temperature at DROP [°F]" in out_f and "[°C]" not in out_f and "temperature at DROP [°C]" in out_c

    def at_drop(text):
        line = next(ln for ln in text.splitlines() if ln.strip().startswith("temperature at DROP"))
        return float(line.split()[-3])  # the changed column

    assert at_drop(out_f) == pytest.approx(at_drop(out_c) * 9 / 5 + 32, abs=0.06)
    from roastlab.report.figures import plot_whatif
    from roastlab.workflows.whatif import parse_setting_change, whatif

    model = roastlab.load_model(model_path)
    w = whatif(model, roastlab.load_log(f_log, model.column_map), [parse_setting_change("heater", "+5@3:00")])
    fig = plot_whatif(w, units=w.batch.temp_unit)
    labels = [a.get_ylabel() for ax in fig.axes for a in (ax, *ax.child_axes)]  # the degF scales: child axes
    assert "temperature [°F]" in labels and any(s.startswith("RoR [°F/min]") for s in labels)
    assert (tmp_path / "f.png").stat().st_size > 20_000
    # the Artisan background in the roaster's own mode (degF), the same changed curve read back in degC
    import ast

    from roastlab.io.importers.artisan import read_alog

    assert ast.literal_eval(bg.read_text())["mode"] == "F"
    assert np.max(np.abs(read_alog(bg).channels["BT"] - w.changed.Ta_C)) <= 0.005


def test_a_validation_figure_speaks_degf_on_every_scale(sky_model, tmp_path):
    """plot_fit in degF (fit-roaster's held-out figure for a roaster logging in degF): BT, its rate of
    rise on the right and the residual each on a degF scale, each panel's MAE in degF (9/5 of the degC
    one), the curves the same degC numbers."""
    from conftest import rewritten_alog
    from roastlab.report.figures import plot_fit

    model_path, log = sky_model
    model = roastlab.load_model(model_path)
    batch = roastlab.load_log(rewritten_alog(log, tmp_path / "in_F.alog", _in_fahrenheit), model.column_map)
    result = model.validate([batch])
    fig = plot_fit(result, units="F")
    labels = [a.get_ylabel() for ax in fig.axes for a in (ax, *ax.child_axes)]
    assert "BT [°F]" in labels and "RoR [°F/min]" in labels and "residual\nBT meas − pred [°F]" in labels
    assert not any("°C" in text for text in labels)
    title = next(ax.get_title() for ax in fig.axes if ax.get_title())
    assert f"MAE {9 / 5 * result.rows[0]['MAE']:.2f} °F" in title
    ror = next(a for ax in fig.axes for a in ax.child_axes if a.get_ylabel() == "RoR [°F/min]")
    assert ror.get_yaxis().get_ticks_position() == "right"  # beside the RoR's curves, not over BT's scale
    celsius = plot_fit(result)
    assert "BT [°C]" in [ax.get_ylabel() for ax in celsius.axes] and not any(ax.child_axes for ax in celsius.axes)


def test_transfer_speaks_the_unit_the_log_was_recorded_in(cli, sky_model, tmp_path):
    """transfer from a roast logged in degF: its summary's errors, tolerance and band in degF (9/5 of the
    degC ones, the same program), --units C back in degC; the program file is the same either way."""
    from conftest import rewritten_alog

    model_path, log = sky_model
    f_log = rewritten_alog(log, tmp_path / "in_F.alog", _in_fahrenheit)
    runs = {}
    for units in (None, "C"):
        out = tmp_path / f"program-{units}.csv"
        argv = ["transfer", "--model", model_path, "--reference", f_log, "--batch-kg", "0.22", "--out", out]
        code, text, err = cli(*argv, *(["--units", units] if units else []))
        assert code == 0, err
        runs[units] = text, out.read_text()
    (f_text, f_prog), (c_text, c_prog) = runs[None], runs["C"]
    # the Artisan background in the mode the reference was recorded in, whatever --units shows
    import ast

    bg = tmp_path / "bg.alog"
    argv = ["transfer", "--model", model_path, "--reference", f_log, "--batch-kg", "0.22", "--out", tmp_path / "p.csv"]
    assert cli(*argv, "--units", "C", "--alog", bg)[0] == 0
    assert ast.literal_eval(bg.read_text())["mode"] == "F"
    assert "RMSE °F" in f_text and "°C" not in f_text and "RMSE °C" in c_text and f_prog == c_prog

    def rmse(text):
        return float(next(ln for ln in text.splitlines() if ln.startswith("runnable")).split()[-2])

    assert rmse(f_text) == pytest.approx(rmse(c_text) * 9 / 5, abs=2e-3)
    assert "(max |e| <= 3.6 °F)" in f_text or "(max |e| > 3.6 °F)" in f_text


@pytest.mark.parametrize(
    ("text", "delta", "want"),
    [("204", False, 204.0), ("400F", False, 204.444), ("400 °F", False, 204.444), ("204c", False, 204.0),
     ("72f", False, 22.222), ("36F", True, 20.0), ("+18F", True, 10.0), ("-10", True, -10.0)],
)  # fmt: skip
def test_a_temperature_option_takes_degf_written_as_such(text, delta, want):
    """--tm0/--tb0/--tgi: degC as a bare number, degF with an F after it (a roaster who reads degF); an
    offset converts without the 32 degF."""
    from roastlab.cli.common import temperature_arg

    assert temperature_arg("--tm0", delta)(text) == pytest.approx(want, abs=1e-3)


def test_whatif_takes_the_drum_in_degf(cli, sky_model, tmp_path):
    """whatif --tm0 400F is the drum at 204.4 degC: the same answer as --tm0 204.444."""
    model_path, log = sky_model
    runs = [
        cli("whatif", log, "--model", model_path, "--tm0", tm0, "--json", tmp_path / f"{k}.json")
        for k, tm0 in enumerate(["400F", "204.444444"])
    ]
    assert all(code == 0 for code, _, _ in runs), runs
    a, b = (json.loads((tmp_path / f"{k}.json").read_text())["rows"] for k in range(2))
    assert [r["changed"] for r in a] == pytest.approx([r["changed"] for r in b], rel=1e-6)
    code, _, err = cli("whatif", log, "--model", model_path, "--tm0", "400X")
    assert code == 2 and "--tm0 must be a number, got '400X'" in err


def _whatif_written(cli, sky_model, heater: str, option: str, path):
    """``roastlab whatif LOG --heater HEATER OPTION PATH`` on the Skywalker model (exit 0), and the same
    what-if as a library call, to compare the written file with."""
    from roastlab.workflows.whatif import parse_setting_change, whatif

    model_path, log = sky_model
    code, _, err = cli("whatif", log, "--model", model_path, "--heater", heater, option, path)
    assert code == 0, err
    model = roastlab.load_model(model_path)
    return whatif(model, roastlab.load_log(log, model.column_map), [parse_setting_change("heater", heater, "percent")])


def test_whatif_writes_the_changed_roast_as_an_artisan_background(cli, sky_model, tmp_path):
    """whatif --alog: Artisan's format read back by the project's own importer gives the changed
    probe prediction as BT, the model's drum (the Skywalker's ET) as ET, the changed heater as Burner
    events, DRY and first crack where the table's changed probe reaches them, DROP at the log's."""
    from roastlab.io.importers.artisan import read_alog

    bg = tmp_path / "next.alog"
    w = _whatif_written(cli, sky_model, "+10@4:00", "--alog", bg)
    back = read_alog(bg)
    assert np.max(np.abs(back.channels["BT"] - w.changed.Ta_C)) <= 0.005
    assert np.max(np.abs(back.channels["ET"] - w.changed.Tm_C)) <= 0.005
    np.testing.assert_allclose(back.channels["Burner"], w.changed.heater, atol=1e-9)
    probe = {r["key"]: r["changed"] for r in w.rows if r["reading"] == "probe"}
    t = w.changed.time_s
    step = float(np.max(np.diff(t)))
    assert abs(back.events["FCs"] - probe["FCs_s"]) <= step and abs(back.events["DRY"] - probe["DRY_s"]) <= step
    assert back.events["DROP"] == pytest.approx(t[-1] - t[0]) and back.weight_in_kg == pytest.approx(w.batch_kg)


def test_whatif_writes_the_changed_settings_as_artisan_alarms(cli, sky_model, tmp_path):
    """whatif --alarms: an alarm per change of the changed heater and fan, at its time after CHARGE (a
    setting at CHARGE at 0:01), moving the Burner or Air slider to the percentage; replayed step by step
    the alarms give back the changed settings the prediction ran with."""
    import json

    from roastlab.io.background import alarm_slider_action

    alrm = tmp_path / "next.alrm"
    w = _whatif_written(cli, sky_model, "-10@4:00", "--alarms", alrm)
    alarms = json.loads(alrm.read_text())
    t = w.changed.time_s - w.changed.time_s[0]
    for setting, etype in (("heater", "Burner"), ("fan", "Air")):
        rows = [(s, v) for s, a, v in zip(alarms["alarmoffsets"], alarms["alarmactions"], alarms["alarmstrings"])
                if a == alarm_slider_action(etype)]  # fmt: skip
        assert rows, etype
        replay = np.full(len(t), np.nan)
        for at_s, text in rows:
            replay[t >= (0 if at_s == 1 else at_s)] = float(text.split(" # ")[0])
        np.testing.assert_allclose(replay, getattr(w.changed, setting), atol=1e-9, err_msg=setting)
