"""The bed laws (roastlab.model.bed): geometry by hand, limits where they are the paper's, files and options."""

import dataclasses
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from reference_model import bed_segment
from roastlab.errors import InputError, ParameterError
from roastlab.model import rhs
from roastlab.model.bed import PAPER_BED, VARIANTS, BedLaws
from roastlab.model.constants import GREEN_BULK_DENSITY_KG_M3
from roastlab.model.layout import P
from roastlab.model.plant import as_plant
from test_physics import steady_probe_run


def test_wall_contact_area_by_hand():
    """A half-full drum wets half the mantle and half of each end disc; a full one all of it;
    any fill agrees with the reference's own bisection; the area grows more slowly than the mass."""
    plant = as_plant("120kg")
    R, L = plant.Dch_m / 2, plant.Lch_m
    full = GREEN_BULK_DENSITY_KG_M3 * math.pi * R**2 * L
    half = dataclasses.replace(plant, Mb_kg=full / 2)
    assert half.wall_contact_area_m2 == pytest.approx(math.pi * R * L + math.pi * R**2, rel=1e-12)
    whole = dataclasses.replace(plant, Mb_kg=full)
    assert whole.wall_contact_area_m2 == pytest.approx(2 * math.pi * R * L + 2 * math.pi * R**2, rel=1e-9)
    per_kg = []
    for share in (0.02, 0.1, 0.25, 0.6):
        p = dataclasses.replace(plant, Mb_kg=share * full)
        t, h, area = bed_segment(p.Mb_kg, p.Dch_m, p.Lch_m)
        assert p.bed_angle_rad == pytest.approx(t, rel=1e-9)
        assert p.bed_depth_m == pytest.approx(h, rel=1e-9)
        assert p.wall_contact_area_m2 == pytest.approx(area, rel=1e-9)
        per_kg.append(p.wall_contact_area_m2 / p.Mb_kg)
    assert all(a > b for a, b in zip(per_kg, per_kg[1:]))  # a deeper bed wets less wall per kilogram


def test_paper_bed_packs_the_paper_and_codes_each_law():
    plant = as_plant("120kg")
    theta = (0.01, 0.0254, 0.5793)
    paper = rhs.pack_params(plant, theta)
    assert np.array_equal(paper, rhs.pack_params(plant, theta, bed="paper"))
    assert [paper[P[k]] for k in ("contact_law", "probe_law", "probe_gas_law")] == [0.0, 0.0, 0.0]
    both = rhs.pack_params(plant, theta, bed="contact=wall,probe=tumbling,probe_gas=mean")
    assert [both[P[k]] for k in ("contact_law", "probe_law", "probe_gas_law")] == [1.0, 1.0, 1.0]
    assert both[P["A_wall"]] == pytest.approx(plant.wall_contact_area_m2)
    Agb, Abm = rhs.bed_areas_m2(both, 1.0)
    assert Abm == pytest.approx(0.5793 * plant.wall_contact_area_m2)
    assert Agb == pytest.approx(plant.Ab_m2 - Abm)
    assert rhs.bed_areas_m2(paper, 1.0) == rhs.bean_areas_m2(plant.Ab_m2, 0.5793)


def test_tumbling_probe_reads_its_covered_mix_and_is_eq17_without_a_depth():
    """Steady state: Ta = c Tb + (1 - c) Tgo with c = 1 - exp(-h_bed/h_probe); with h_probe 0 the
    tumbling law is eq. 17 bit for bit, like the law at rest."""
    plant = as_plant("120kg")
    h = plant.bed_depth_m
    r = steady_probe_run(plant, "probe=tumbling", h_probe_m=h)
    c = 1.0 - math.exp(-1.0)
    assert r.Tb_C[-1] - r.Tgo_C[-1] > 50
    assert r.Ta_C[-1] == pytest.approx(c * r.Tb_C[-1] + (1 - c) * r.Tgo_C[-1], abs=1e-3)
    assert np.array_equal(steady_probe_run(plant, "probe=tumbling").states, steady_probe_run(plant).states)


def test_mean_gas_is_the_mean_of_the_exchanger_profile():
    """The probe's gas under probe_gas=mean is the path average of Tgi -> T* as exp(-NTU s)
    (numerical quadrature here), between the outlet and the inlet temperature."""
    from scipy.integrate import quad

    plant = as_plant("120kg")
    p = rhs.pack_params(plant, (0.02, 0.05, 0.6), bed="probe_gas=mean")
    Tb, Tm, X, Gg, Tgi = 150.0, 220.0, 0.05, 30.0, 400.0
    Tgo = rhs.heat_flows(Tb, Tm, X, 0.0, Gg, Tgi, p)[0]
    T_star, NTU = rhs.exchanger(Tb, Tm, X, 1.0, Gg, Tgi, p)[:2]
    by_quad = quad(lambda s: T_star + (Tgi - T_star) * math.exp(-NTU * s), 0.0, 1.0)[0]
    mean = rhs.probe_gas_C(Tgi, Tgo, T_star, NTU, p)
    assert mean == pytest.approx(by_quad, rel=1e-12)
    assert Tgo < mean < Tgi
    outlet = rhs.pack_params(plant, (0.02, 0.05, 0.6))
    assert rhs.probe_gas_C(Tgi, Tgo, T_star, NTU, outlet) == Tgo


def test_wall_contact_makes_the_batch_response_flatter():
    """Per kilogram, the wall law gives a small batch more metal contact than the paper's law does
    relative to a large one: the ratio of Abm per kg small/large is > 1 under the wall law, 1 under the paper's."""
    plant = as_plant("120kg")
    small, large = dataclasses.replace(plant, Mb_kg=40.0), dataclasses.replace(plant, Mb_kg=160.0)

    def abm_per_kg(pl, bed):
        return rhs.bed_areas_m2(rhs.pack_params(pl, (0.01, 0.03, 0.5), bed=bed), 1.0)[1] / pl.Mb_kg

    assert abm_per_kg(small, None) == pytest.approx(abm_per_kg(large, None))
    assert abm_per_kg(small, "contact=wall") / abm_per_kg(large, "contact=wall") > 1.5


@pytest.mark.parametrize(
    "text, problem",
    [("probe=wobbly", "unknown probe law"), ("colour=green", "unknown bed option"), ("probe", "not option=law")],
)
def test_bad_laws_are_one_clear_error(text, problem):
    with pytest.raises(ParameterError, match=problem):
        BedLaws.parse(text)


def test_variants_and_names():
    assert VARIANTS["paper"] is PAPER_BED
    assert BedLaws.parse({"probe": "tumbling"}).name == "probe=tumbling"
    for name, laws in VARIANTS.items():
        assert BedLaws.parse(name) == laws


def test_fit_spec_and_model_file_carry_the_laws(tmp_path):
    from roastlab.io.fitspec import load_fit_spec
    from roastlab.io.modelfile import read_model_document

    spec = tmp_path / "fit.toml"
    spec.write_text('[free]\nhbm = [0.01, 0.3, 0.05]\n[bed]\nprobe = "tumbling"\n')
    assert load_fit_spec(spec).bed == BedLaws(probe="tumbling")
    spec.write_text('[free]\nhbm = [0.01, 0.3, 0.05]\n[bed]\nprobe = "sideways"\n')
    with pytest.raises(InputError, match="fit.toml.*bed.*unknown probe law"):
        load_fit_spec(spec)
    doc = {
        "format": "roastlab-model/1",
        "plant": "120kg",
        "parameters": {k: {"value": v} for k, v in (("hgm", 0.01), ("hbm", 0.0254), ("Pbm", 0.5793))},
        "bed": {"contact": "sideways"},
    }
    path = tmp_path / "m.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError, match="m.json.*bed.*unknown contact law"):
        read_model_document(path)


def test_a_fitted_model_keeps_its_laws(tmp_path):
    """fit(bed=...) writes the laws into the model file; the loaded model predicts with them."""
    import roastlab
    from roastlab.workflows.datasets import make_batch

    rng = np.random.default_rng(3)  # synthetic batches of the 120 kg plant (workflows.datasets)
    batches = [make_batch(rng, "120kg", i, False)[0] for i in range(2)]
    result = roastlab.fit(batches, "120kg", fix={"hgm": 0.01}, bed="contact=wall", starts=1)
    path = result.model.save(tmp_path / "m.json")
    assert json.loads(path.read_text())["bed"]["contact"] == "wall"
    loaded = roastlab.load_model(path)
    assert loaded.bed == BedLaws(contact="wall")
    a, b = result.model.predict(batches[0]), loaded.predict(batches[0])
    assert np.array_equal(a.Ta_C, b.Ta_C)
    paper = result.model.with_values()
    paper.bed = PAPER_BED
    assert np.max(np.abs(paper.predict(batches[0]).Ta_C - a.Ta_C)) > 0.1  # the law is in force


def test_cli_bad_bed_is_exit_2(tmp_path):
    out = subprocess.run(
        [sys.executable, "-m", "roastlab", "identify", "--plant", "120kg", "--bed", "probe=wobbly", "x.csv"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert out.returncode == 2
    assert "unknown probe law" in out.stderr and "Traceback" not in out.stderr


def test_bed_surface_and_wall_radiation_by_hand():
    """The bed's free surface is its chord along the drum (the diameter when half full, nothing when
    full); the radiation a drum wall at 300 degC sends to beans at 200 degC is eps sigma A (T1^4 - T2^4),
    computed here in watts from CODATA's sigma; it is the paper's model at eps_rad 0; per kilogram a small
    batch gets more of it than a large one."""
    plant = as_plant("120kg")
    R, L = plant.Dch_m / 2, plant.Lch_m
    full = GREEN_BULK_DENSITY_KG_M3 * math.pi * R**2 * L
    assert dataclasses.replace(plant, Mb_kg=full / 2).bed_surface_area_m2 == pytest.approx(2 * R * L, rel=1e-12)
    assert dataclasses.replace(plant, Mb_kg=full).bed_surface_area_m2 == pytest.approx(0.0, abs=1e-9)
    small = dataclasses.replace(plant, Mb_kg=0.05 * full)
    t, _, _ = bed_segment(small.Mb_kg, small.Dch_m, small.Lch_m)
    assert small.bed_surface_area_m2 == pytest.approx(2 * R * math.sin(t / 2) * L, rel=1e-9)
    p = rhs.pack_params(small, (0.01, 0.03, 0.5))
    assert rhs.wall_radiation_kW(200.0, 300.0, 1.0, p) == 0.0  # eps_rad 0: the paper
    p[P["eps_rad"]] = 0.8
    watts = 0.8 * 5.670374419e-8 * small.bed_surface_area_m2 * (573.15**4 - 473.15**4)
    assert rhs.wall_radiation_kW(200.0, 300.0, 1.0, p) == pytest.approx(watts / 1000.0, rel=1e-12)
    large = dataclasses.replace(plant, Mb_kg=0.3 * full)
    assert small.bed_surface_area_m2 / small.Mb_kg > 2.5 * large.bed_surface_area_m2 / large.Mb_kg


def test_gas_area_at_the_bed_surface_by_hand():
    """k_flight > 0: Agb = k_flight A_surf whatever the contact law and Pbm, Abm the contact law's;
    k_flight 0 is the contact law's Agb; per kilogram a small batch meets more gas than a large one."""
    plant = as_plant("120kg")
    for bed in ("paper", "contact=wall"):
        p = rhs.pack_params(plant, (0.01, 0.03, 0.5), bed=bed)
        Agb0, Abm0 = rhs.bed_areas_m2(p, 1.0)
        p[P["k_flight"]] = 4.0
        Agb, Abm = rhs.bed_areas_m2(p, 1.0)
        assert Agb == pytest.approx(4.0 * plant.bed_surface_area_m2, rel=1e-12) and Abm == Abm0
        p[P["Pbm"]] = 0.7
        assert rhs.bed_areas_m2(p, 1.0)[0] == Agb  # the gas's area no longer depends on Pbm
        assert Agb0 != Agb
    small, large = (dataclasses.replace(plant, Mb_kg=m) for m in (40.0, 200.0))
    per_kg = [rhs.bed_areas_m2(rhs.pack_params(q, (0.01, 0.03, 0.5)), 1.0)[0] / q.Mb_kg for q in (small, large)]
    assert per_kg[0] == pytest.approx(per_kg[1])  # the paper: the same gas area per kilogram
    with_surface = []
    for q in (small, large):
        p = rhs.pack_params(q, (0.01, 0.03, 0.5))
        p[P["k_flight"]] = 4.0
        with_surface.append(rhs.bed_areas_m2(p, 1.0)[0] / q.Mb_kg)
    assert with_surface[0] > 2.0 * with_surface[1]


def test_swollen_beans_scale_the_bed_as_their_size():
    """bean_swell (roastlab.model.rhs.swell_factor): 0 is the paper's beans exactly; with the reactions
    complete (He = Het) a volume gain of 1 doubles each bean's volume, so its size is 2^(1/3) and the
    beans' area, the probe's bed depth, the wetted arc and the free surface scale as s^2, s^2, s and s.
    The shallow bed's depth law against the exact segment: doubling the bed's volume (twice the batch
    at rest, computed by the plant's own segment geometry) deepens it by 2^(2/3) within 4 %."""
    plant = as_plant("120kg")
    p = rhs.pack_params(plant, (0.02, 0.05, 0.6), bed="probe=tumbling")
    p[P["h_probe"]] = plant.bed_depth_m
    Het = p[P["Het"]]
    assert rhs.swell_factor(Het, p) == 1.0  # bean_swell 0: the paper
    p[P["bean_swell"]] = 1.0
    assert rhs.swell_factor(0.0, p) == 1.0  # green beans
    s = rhs.swell_factor(Het, p)
    assert s == pytest.approx(2.0 ** (1.0 / 3.0), rel=1e-14)
    assert rhs.swell_factor(Het / 2.0, p) == pytest.approx(1.5 ** (1.0 / 3.0), rel=1e-14)
    assert rhs.bed_areas_m2(p, s) == pytest.approx(rhs.bean_areas_m2(plant.Ab_m2 * s * s, 0.6), rel=1e-14)
    assert rhs.probe_coverage(p, s) == pytest.approx(1.0 - math.exp(-(s * s)), rel=1e-14)  # h_bed s^2 over h_bed
    wall = rhs.pack_params(plant, (0.02, 0.05, 0.6), bed="contact=wall")
    assert rhs.bed_areas_m2(wall, s)[1] == pytest.approx(0.6 * plant.wall_contact_area_m2 * s, rel=1e-14)
    wall[P["eps_rad"]] = 0.8
    assert rhs.wall_radiation_kW(150.0, 250.0, s, wall) == pytest.approx(
        s * rhs.wall_radiation_kW(150.0, 250.0, 1.0, wall), rel=1e-14
    )
    for Mb in (0.2 * plant.Mb_kg, plant.Mb_kg, 1.5 * plant.Mb_kg):  # fills of 3-18 %
        green = dataclasses.replace(plant, Mb_kg=Mb)
        doubled = dataclasses.replace(plant, Mb_kg=2.0 * Mb)
        assert doubled.bed_depth_m / green.bed_depth_m == pytest.approx(2.0 ** (2.0 / 3.0), rel=0.04)
