"""roastlab compare-models: variants fitted and cross-validated by batch size (workflows.compare).

The logs here are SYNTHETIC (seeded below): 120 kg plant batches of three sizes simulated with
the wall-contact law and a half-covered probe, with probe noise."""

import json
import subprocess
import sys

import numpy as np
import pytest

from roastlab import InitialState, simulate
from roastlab.errors import InputError
from roastlab.io.batch import Batch
from roastlab.model.bed import CROSS_VALIDATED
from roastlab.model.plant import as_plant
from roastlab.workflows.compare import compare_models, size_groups

TRUTH = "contact=wall"
THETA = (0.02, 0.2, 0.4)


def synthetic_sizes(seed=5):
    """Two batches each of 60, 120 and 180 kg on the 120 kg plant, simulated with the wall law."""
    import dataclasses

    rng = np.random.default_rng(seed)
    base = as_plant("120kg")
    out = []
    for mass in (60.0, 120.0, 180.0):
        for k in range(2):
            t = np.arange(0.0, 901.0, 10.0)
            Gg = np.full(t.size, 0.4 * rng.uniform(0.9, 1.1))
            Tgi = np.full(t.size, 450.0 + rng.uniform(-20, 20))
            plant = dataclasses.replace(base, Mb_kg=mass)
            r = simulate(plant, t, Gg, Tgi, theta=THETA, initial=InitialState(Ta0_C=30.0), bed=TRUTH)
            Ta = r.Ta_C + rng.normal(0.0, 0.5, t.size)
            out.append(Batch(f"synthetic_{mass:.0f}kg_{k}", t, Gg, Tgi, Ta, Mb_kg=mass))
    return out


def test_size_groups():
    batches = synthetic_sizes()
    labels, step = size_groups(batches)
    assert step == pytest.approx(12.0)
    assert labels == ["60 kg", "60 kg", "120 kg", "120 kg", "180 kg", "180 kg"]
    labels, _ = size_groups(batches, step_kg=200.0)
    assert set(labels) == {"60 kg", "120-180 kg"}  # 60/200 rounds to 0, 120/200 and 180/200 to 1


def test_the_law_that_made_the_data_wins_on_cross_validation():
    """Data made with the wall law: its variant predicts each unseen size better than the paper's
    (which fits Abm proportional to the mass); the JSON and the summary carry every figure."""
    batches = synthetic_sizes()
    result = compare_models(batches, "120kg", None, ["paper", TRUTH], starts=2)
    assert result.best.name == TRUTH
    scores = {s.name: s for s in result.scores}
    assert scores[TRUTH].cv_FIT > scores["paper"].cv_FIT + 1.0
    assert scores[TRUTH].cv_FIT > 95.0
    assert set(scores[TRUTH].cv_by_group) == {"60 kg", "120 kg", "180 kg"}
    doc = result.to_dict()
    assert doc["best"] == TRUTH and doc["variants"][0]["k_free"] == 3
    text = result.summary()
    assert "best by leave-one-size-out FIT: contact=wall" in text and "AIC" in text


def test_variants_carry_parameter_overrides():
    """A variant holds a parameter at a value or frees it within the quantity table's bounds: the
    profile of a parameter only a change of batch size determines (h_probe_m on the Bullet)."""
    from roastlab.errors import ParameterError
    from roastlab.model.quantities import quantity
    from roastlab.workflows.compare import FREE, Variant

    held = Variant.parse("contact=wall,probe=tumbling,h_probe_m=0.2")
    assert held.laws.name == "contact=wall,probe=tumbling" and held.overrides == (("h_probe_m", 0.2),)
    assert held.name == "contact=wall,probe=tumbling,h_probe_m=0.2"
    spec = held.spec(None)
    assert spec.fixed["h_probe_m"] == 0.2 and "h_probe_m" not in {f.name for f in spec.free}
    freed = Variant.parse("h_probe_m=free").spec(spec)  # a held value freed again
    (h,) = [f for f in freed.free if f.name == "h_probe_m"]
    assert (h.lower, h.upper) == quantity("h_probe_m").bounds and "h_probe_m" not in freed.fixed
    assert (
        Variant.parse("paper").spec(spec) is spec and Variant.parse(f"h_probe_m={FREE}").name == "paper,h_probe_m=free"
    )
    for bad, words in [("h_probe_m=deep", "needs a number"), ("depth=1", "neither a bed option"),
                       ("h_probe_m=-1", "h_probe_m")]:  # fmt: skip
        with pytest.raises(ParameterError, match=words):
            Variant.parse(bad)


def test_a_held_parameter_changes_what_is_fitted():
    batches = synthetic_sizes()
    result = compare_models(batches, "120kg", None, [TRUTH, f"{TRUTH},hbm=0.05"], starts=1)
    scores = {s.name: s for s in result.scores}
    assert scores[TRUTH].k_free == 3 and scores[f"{TRUTH},hbm=0.05"].k_free == 2
    assert scores[f"{TRUTH},hbm=0.05"].overrides == {"hbm": 0.05}


def test_one_size_is_refused():
    batches = [b for b in synthetic_sizes() if b.Mb_kg == 60.0]
    with pytest.raises(InputError, match="at least two batch sizes"):
        compare_models(batches, "120kg", None, ["paper"], starts=1)


def test_cli(tmp_path):
    from roastlab.io.batch import write_batch_csv

    paths = []
    for b in synthetic_sizes()[::2] + synthetic_sizes()[1::2][:1]:
        path = tmp_path / f"{b.name}.csv"
        write_batch_csv(path, b)
        paths.append(str(path))
    # the variants' laws are the paper's and the Bullet example's, whose lanes ``make test`` compiles
    # before the suite (another set of laws would cost a worker half a minute of compiling)
    example = CROSS_VALIDATED.name
    cmd = [sys.executable, "-m", "roastlab", "compare-models", "--plant", "120kg", "--variant", "paper",
           "--variant", example, "--starts", "1", "--json", "c.json", "--plot", "c.png", *paths]  # fmt: skip
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "LOSO FIT" in out.stdout
    doc = json.loads((tmp_path / "c.json").read_text())
    assert {v["name"] for v in doc["variants"]} == {"paper", example}
    assert (tmp_path / "c.png").stat().st_size > 10000
    bad = subprocess.run(
        [*cmd[:4], "--plant", "120kg", "--variant", "probe=up", *paths], capture_output=True, text=True
    )
    assert bad.returncode == 2 and "unknown probe law" in bad.stderr and "Traceback" not in bad.stderr


def test_leave_one_roaster_out_predicts_each_unit_from_the_others():
    """group_by="unit": each roaster's logs predicted by the variant fitted on the other roasters'
    logs, the same figure as fitting on them by hand; the summary, JSON and figure name it so."""
    import dataclasses

    import roastlab

    batches = synthetic_sizes()
    units = ["2779", "2054", "2779", "1447", "2054", "2779"]  # SYNTHETIC serial numbers, sizes mixed
    batches = [dataclasses.replace(b, unit=u) for b, u in zip(batches, units)]
    result = compare_models(batches, "120kg", None, [TRUTH], group_by="unit", starts=1)
    assert result.groups == {
        "unit 1447": ["synthetic_120kg_1"],
        "unit 2054": ["synthetic_60kg_1", "synthetic_180kg_0"],
        "unit 2779": ["synthetic_60kg_0", "synthetic_120kg_0", "synthetic_180kg_1"],
    }
    (score,) = result.scores
    train = [b for b in batches if b.unit != "2054"]
    by_hand = roastlab.fit(train, "120kg", bed=TRUTH, starts=1).model.validate([b for b in batches if b.unit == "2054"])
    assert score.cv_by_group["unit 2054"] == pytest.approx(by_hand.average["FIT"], abs=1e-6)
    assert "best by leave-one-roaster-out FIT" in result.summary() and "LORO FIT" in result.summary()
    doc = result.to_json_dict()
    assert doc["group_by"] == "unit" and doc["step_kg"] is None and "loro_FIT" in doc["variants"][0]
    with pytest.raises(InputError, match="names no roaster"):
        compare_models(synthetic_sizes(), "120kg", None, [TRUTH], group_by="unit", starts=1)
    one = [dataclasses.replace(b, unit="2779") for b in synthetic_sizes()]
    with pytest.raises(InputError, match="at least logs of two roasters"):
        compare_models(one, "120kg", None, [TRUTH], group_by="unit", starts=1)
    with pytest.raises(InputError, match="group logs by one of size, unit, log"):
        compare_models(batches, "120kg", None, [TRUTH], group_by="day", starts=1)


def test_leave_one_log_out_scores_each_roast_and_its_band():
    """group_by="log": each log predicted by the variant fitted on all the others; its FIT and the
    share of its samples inside that model's band are those of fitting without it by hand."""
    import roastlab
    from roastlab.evaluate.bands import band_coverage
    from roastlab.workflows.compare import log_groups

    batches = synthetic_sizes()[:4]
    result = compare_models(batches, "120kg", None, [TRUTH], group_by="log", starts=1)
    assert list(result.groups) == [b.name for b in batches]
    (score,) = result.scores
    held = batches[1]
    by_hand = roastlab.fit([b for b in batches if b is not held], "120kg", bed=TRUTH, starts=1).model
    assert score.cv_by_group[held.name] == pytest.approx(by_hand.validate([held]).average["FIT"], abs=1e-6)
    (row,) = band_coverage(by_hand, [held])
    assert score.cv_band_by_group[held.name] == pytest.approx(row["inside"], abs=1e-9)
    assert 0.0 <= score.cv_band_inside <= 1.0 and score.cv_band_width_C > 0.0
    text = result.summary()
    assert "LOLO FIT" in text and "LOLO band in" in text and "best by leave-one-log-out FIT" in text
    doc = result.to_json_dict()
    assert doc["group_by"] == "log" and doc["variants"][0]["lolo_band_inside"] == pytest.approx(score.cv_band_inside)
    assert log_groups([batches[0], batches[0], batches[1]]) == [
        batches[0].name,
        f"{batches[0].name} #2",
        batches[1].name,
    ]
    with pytest.raises(InputError, match="at least two logs"):
        compare_models(batches[:1], "120kg", None, [TRUTH], group_by="log", starts=1)
    assert score.cv_band_parameters_only == []
    two = compare_models(batches[:2], "120kg", None, [TRUTH], group_by="log", starts=1)  # each fit on one log
    assert two.scores[0].cv_band_parameters_only == [b.name for b in batches[:2]]
    assert "the fit had one log, so its band is the parameters' alone" in two.summary()


def test_the_lowest_aic_is_weighed_against_the_best_by_one_standard_error():
    """The paired per-group FIT difference of two variants and its standard error, by hand; a
    difference within one standard error is said to be no difference."""
    from roastlab.model.bed import BedLaws
    from roastlab.workflows.compare import ModelComparison, VariantScore

    def score(name, aic, by_group):
        return VariantScore(name, BedLaws(), {}, 1.0, 100, 3, aic, aic, [], 80.0, float(np.mean(list(by_group.values()))),
                            by_group)  # fmt: skip

    groups = {"a": ["x"], "b": ["y"], "c": ["z"]}
    best = score("best", 110.0, {"a": 80.0, "b": 70.0, "c": 75.0})
    close = score("close", 100.0, {"a": 70.0, "b": 76.0, "c": 78.0})  # differences +10, -6, -3: mean 1/3
    far = score("far", 100.0, {"a": 70.0, "b": 60.0, "c": 66.0})  # +10, +10, +9
    diff, se = ModelComparison([best, close], groups, 1.0).cv_difference(best, close)
    assert diff == pytest.approx(1 / 3) and se == pytest.approx(np.std([10, -6, -3], ddof=1) / np.sqrt(3))
    text = ModelComparison([best, close], groups, 1.0).summary()
    assert "within one standard error of best, 0.3 ± 4.9 points over 3 groups" in text and "prefer" not in text
    text = ModelComparison([best, far], groups, 1.0).summary()
    assert "predicts unseen sizes worse by 9.7 ± 0.3 points over 3 groups: prefer best" in text


def test_a_roast_given_twice_is_left_out_once():
    """SYNTHETIC: a roast given twice (a renamed copy keeps the second its recording started) would be
    fitted in one copy and held out in the other; compare-models keeps the first and says so."""
    import dataclasses

    batches = [dataclasses.replace(b, started_epoch_s=1.7e9 + 3600.0 * k) for k, b in enumerate(synthetic_sizes()[:3])]
    copy = dataclasses.replace(batches[1], name="renamed_copy")
    result = compare_models([*batches, copy], "120kg", None, [TRUTH], group_by="log", starts=1)
    assert list(result.groups) == [b.name for b in batches]
    why = f"renamed_copy is a copy of {batches[1].name} (recorded from the same second: one roast)"
    assert result.left_out == {"renamed_copy": why}
    assert f"left out: {why}" in result.summary() and result.to_json_dict()["left_out"] == result.left_out


def test_a_fit_given_one_roast_twice_says_so():
    """SYNTHETIC: identify keeps what it is given (the fit is the user's), but a roast given twice
    weighs twice, and the fit's warnings say which."""
    import dataclasses

    import roastlab

    a, b = (dataclasses.replace(x, started_epoch_s=1.7e9 + 60.0 * k) for k, x in enumerate(synthetic_sizes()[:2]))
    copy = dataclasses.replace(a, name="a_copy")
    warned = roastlab.fit([a, b, copy], "120kg", bed=TRUTH, starts=1).warnings
    assert any(
        f"one roast given twice, so it weighs twice in the fit: a_copy is a copy of {a.name}" in w for w in warned
    )
    assert not any("given twice" in w for w in roastlab.fit([a, b], "120kg", bed=TRUTH, starts=1).warnings)


@pytest.mark.parametrize("n", [3, 10, 14, 25])
def test_every_variant_has_its_own_colour_in_the_figure(n):
    """The bar chart gives each variant a colour no other has (matplotlib's ten-colour cycle repeats
    from the eleventh: at 14 variants two pairs of bars were one colour), and up to ten variants the
    colours are the usual cycle's."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import colors

    from roastlab.workflows.compare import variant_colours

    got = [colors.to_hex(c) for c in variant_colours(n)]
    assert len(set(got)) == n
    if n <= 10:
        assert got == [colors.to_hex(f"C{i}") for i in range(n)]
