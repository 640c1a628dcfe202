"""One result interface: every result has summary() -> str, to_dict() (JSON-safe), to_frame() where
tabular, plot(path=None, ax=None) -> Figure and _repr_html_; one parametrised test checks them all."""

import json
import warnings

import numpy as np
import pytest
from matplotlib.figure import Figure

import roastlab
from roastlab.report.result import Result

TABULAR = {"simulation", "fit", "validation", "whatif", "transfer", "closed loop", "comparison", "fleet report"}


def _batch():
    ds = roastlab.read_dataset(roastlab.default_dataset_root() / "dataset-I")
    return ds.batches[0]


def make_simulation():
    t = np.arange(0, 901, 30.0)
    return roastlab.simulate("120kg", t, np.full_like(t, 0.4), np.full_like(t, 450.0))


def make_fit():
    return roastlab.fit([_batch()], "120kg", fix={"Pbm": 0.5793}, bounds={"hgm": (0.01, 0.35)}, seed=0, starts=1)


def make_validation():
    return roastlab.FittedModel.paper("120kg").validate([_batch()])


def make_whatif():
    from roastlab.workflows.whatif import whatif

    return whatif(roastlab.FittedModel.paper("120kg"), _batch(), Tb0_C=40.0)


def make_transfer():
    from roastlab.workflows.transfer import transfer

    return transfer(roastlab.FittedModel.paper("120kg"), _batch(), "360kg", interval_s=30.0)


def _control():
    from roastlab.control import standard_reference

    return roastlab.FittedModel.paper("120kg"), standard_reference(30.0)


def make_closed_loop():
    from roastlab.control import run_closed_loop

    model, ref = _control()
    return run_closed_loop(model, ref, "pid")


def make_comparison():
    from roastlab.control import compare, standard_scenarios

    model, ref = _control()
    return compare(model, ref, standard_scenarios()[:2], ("replay", "pid"))


def make_fleet_report(tmp_path_factory):
    pytest.importorskip("duckdb")
    from roastlab.fleet import fit_fleet, fleet_report, ingest
    from roastlab.fleet.synthetic import make_fleet

    folder = tmp_path_factory.mktemp("fleet")
    make_fleet(folder / "data", 40, seed=3)  # synthetic, seeded
    db = folder / "f.duckdb"
    ingest(db, folder / "data" / "manifest.csv")
    fit_fleet(db)
    return fleet_report(db)


MAKERS = {
    "simulation": make_simulation,
    "fit": make_fit,
    "validation": make_validation,
    "whatif": make_whatif,
    "transfer": make_transfer,
    "closed loop": make_closed_loop,
    "comparison": make_comparison,
    "fleet report": make_fleet_report,
}


@pytest.fixture(scope="module", params=sorted(MAKERS))
def result(request, tmp_path_factory):
    make = MAKERS[request.param]
    r = make(tmp_path_factory) if request.param == "fleet report" else make()
    return request.param, r


def test_every_result_has_the_one_interface(result, tmp_path):
    kind, r = result
    assert isinstance(r, Result), kind
    text = r.summary()
    assert isinstance(text, str) and text.strip(), kind
    doc = r.to_dict()
    json.dumps(doc, allow_nan=False)  # JSON-safe: raises on NaN or NumPy types
    if kind in TABULAR:
        frame = r.to_frame()
        assert len(frame) > 0 and len(frame.columns) > 0, kind
    fig = r.plot()
    assert isinstance(fig, Figure) and fig.axes, kind
    path = tmp_path / "f.png"
    assert isinstance(r.plot(path), Figure) and path.stat().st_size > 5_000, kind
    outer = Figure()
    ax = outer.add_subplot(1, 1, 1)
    assert r.plot(ax=ax) is outer and (ax.lines or ax.patches), kind
    html = r._repr_html_()
    assert text.splitlines()[0][:40].replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;") in html


def test_comparison_summary_still_indexes_as_before_with_a_warning():
    r = make_comparison()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = r.summary()["mean_rmse_C"]
    assert old == r.statistics()["mean_rmse_C"]
    assert any(issubclass(w.category, DeprecationWarning) for w in caught)


def test_validation_reports_the_model_beans_at_each_logs_first_crack_mark():
    """Where a log marks first crack, validation gives the model's bean temperature then (the one
    check of the beans a probe-only log allows), in its table and its JSON; a log without a mark
    adds nothing."""
    import dataclasses

    from roastlab.model.constants import FIRST_CRACK_BEAN_C

    batch = _batch()
    model = roastlab.FittedModel.paper("120kg")
    plain = model.validate([batch])
    assert plain.first_crack_beans_C == {} and "first-crack" not in plain.table()
    marked = dataclasses.replace(batch, events={"FCs": 400.0})
    v = model.validate([marked])
    res = model.predict(marked)
    assert v.first_crack_beans_C[batch.name] == pytest.approx(float(np.interp(400.0, res.time_s, res.Tb_C)))
    assert f"coffee cracks at about {FIRST_CRACK_BEAN_C:.0f} °C" in v.table()
    assert v.to_json_dict()["first_crack_beans_C"] == v.first_crack_beans_C
