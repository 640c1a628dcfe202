"""Physical invariants of the model that hold whatever the parameters in bounds."""

import math

import numpy as np
import pytest

from roastlab import InitialState, Simulator, load_plant, pack_params, rhs, simulate
from roastlab.model.rhs import P, gas_heat_capacity_kJ_kgK
from roastlab.sim.kernels import simulate_one

T = np.arange(0.0, 961.0, 30.0)


def burner(plant="120kg"):
    scale = load_plant(plant).Mb_kg / 120.0
    Tgi = np.interp(T, [0, 300, 960], [480.0, 430.0, 380.0])
    return np.full_like(T, 0.4 * scale), Tgi


@pytest.mark.parametrize("plant", ["120kg", "360kg"])
@pytest.mark.parametrize("theta", [(0.01, 0.0254, 0.5793), (0.35, 0.35, 0.8), (0.01, 0.01, 0.5), (0.2, 0.01, 0.7)])
def test_invariants(plant, theta):
    Gg, Tgi = burner(plant)
    r = simulate(plant, T, Gg, Tgi, theta=theta)
    X = r.X_kg_kg
    assert np.all(np.diff(X) <= 0), "moisture must never increase"
    assert np.all(X >= 0)
    assert np.all(r.He_kJ_kg <= load_plant(plant).process.Het)
    assert np.all(np.diff(r.He_kJ_kg) >= 0)
    assert np.all(r.Tb_C < Tgi), "beans cannot get hotter than the gas that heats them"
    assert np.all(r.Tgo_C <= Tgi)
    assert np.all(r.Tm_C < Tgi)


def test_no_metal_coupling_keeps_metal_constant():
    Gg, Tgi = burner()
    r = simulate("120kg", T, Gg, Tgi, theta=(0.0, 0.0, 0.6), initial=InitialState(Tm0_C=137.0))
    assert np.max(np.abs(r.Tm_C - 137.0)) < 1e-12
    assert r.Tb_C[-1] > 150  # the beans still heat from the gas


def test_printed_moisture_law_leaves_X_at_X0():
    Gg, Tgi = burner()
    r = simulate("120kg", T, Gg, Tgi, moisture="printed", initial=InitialState(X0=0.11))
    assert np.max(np.abs(r.X_kg_kg - 0.11)) < 1e-9
    default = simulate("120kg", T, Gg, Tgi, initial=InitialState(X0=0.11))
    assert default.X_kg_kg[-1] < 0.05  # Schwartzberg's law does dry the beans


def test_energy_balance_of_gas():
    """Qgb = Gg cg (Tgi - Tgo) (eq. 9) is consistent with the reported Tgo."""
    Gg, Tgi = burner()
    r = simulate("120kg", T, Gg, Tgi)
    q = r.heat_flows()["Qgb_kW"]
    cg = np.array([gas_heat_capacity_kJ_kgK(v) for v in Tgi])
    np.testing.assert_allclose(q, Gg * cg * (Tgi - r.Tgo_C), rtol=1e-12)


def test_gas_heat_capacity_is_air_like():
    # dry air near 723 K: about 1.08 kJ/(kg K); near 300 K: 1.005
    assert abs(gas_heat_capacity_kJ_kgK(450.0) - 1.08) < 0.01
    assert abs(gas_heat_capacity_kJ_kgK(27.0) - 1.005) < 0.01


def test_rhs_is_pure_and_matches_kernel_step():
    plant = load_plant("120kg")
    p = pack_params(plant, (0.01, 0.0254, 0.5793), 0.1)
    x = np.array([30.0, 121.0, 0.1, 0.0, 30.0])
    u = np.array([0.4, 450.0])
    d1 = rhs(0.0, x, u, p)
    d2 = rhs(123.0, x.copy(), u.copy(), p.copy())
    np.testing.assert_array_equal(d1, d2)
    assert np.all(x == [30.0, 121.0, 0.1, 0.0, 30.0])
    # the compiled integrator over a tiny step moves the state by h * rhs (Euler), to O(h^2)
    h = 1e-3
    zero = np.zeros(2)
    x6 = np.append(x, 0.0)
    out = simulate_one(
        np.array([0.0, h]), np.array([0.4, 0.4]), np.array([450.0, 450.0]), zero, zero, x6, p, False, 30.0
    )
    np.testing.assert_allclose(out[1, :5], x + h * d1, rtol=0, atol=1e-4 * h * np.abs(d1).max())
    assert d1[0] > 0 and d1[2] <= 0 and d1[3] > 0


def test_actuator_terms_enter_the_one_rhs():
    """Heater -> Qe on the metal and Tgi rise through the lag state, fan -> Gg: each term moves
    the derivative it should and nothing else; the compiled step agrees with rhs()."""
    plant = load_plant("120kg")
    p = pack_params(plant, (0.01, 0.0254, 0.5793), 0.1)
    x = np.array([150.0, 200.0, 0.05, 10.0, 140.0, 4.0])
    base = rhs(0.0, x, np.array([0.4, 300.0, 6.0, 2.0]), p)
    assert base[5] == pytest.approx((6.0 - 4.0) / 1.0)  # lag state only; gains 0 = the paper's model
    q = p.copy()
    q[P["Qe_gain"]] = 2.0  # kW per unit: H = 4 gives 8 kW more into the metal
    d = rhs(0.0, x, np.array([0.4, 300.0, 6.0, 2.0]), q)
    assert d[1] - base[1] == pytest.approx(8.0 / (plant.Mm_kg * plant.process.cm))
    np.testing.assert_array_equal(np.delete(d, 1), np.delete(base, 1))
    q = p.copy()
    q[P["Tgi_gain"]] = 5.0  # H = 4 raises the gas by 20 degC: same as logging Tgi 20 degC higher
    np.testing.assert_allclose(
        rhs(0.0, x, np.array([0.4, 300.0, 6.0, 2.0]), q)[:5], rhs(0.0, x, np.array([0.4, 320.0]), p)[:5]
    )
    q = p.copy()
    q[P["Gg_fan"]] = 0.05  # fan 2 adds 0.1 kg/s
    np.testing.assert_allclose(
        rhs(0.0, x, np.array([0.4, 300.0, 6.0, 2.0]), q)[:5], rhs(0.0, x, np.array([0.5, 300.0]), p)[:5]
    )
    q[P["Qe_gain"]], q[P["tau_heater"]] = 2.0, 30.0
    h = 1e-3
    u = [np.full(2, v) for v in (0.4, 300.0, 6.0, 2.0)]
    out = simulate_one(np.array([0.0, h]), *u, x, q, False, 30.0)
    d = rhs(0.0, x, np.array([0.4, 300.0, 6.0, 2.0]), q)
    np.testing.assert_allclose(out[1, :6], x + h * d, rtol=0, atol=1e-4 * h * np.abs(d).max())


def test_heater_energy_balance_at_steady_state():
    """Independent number: at steady state with the reaction spent and the beans dry, all the
    heater's power leaves with the gas, Qe = Gg cg(Tgi) (Tgo - Tgi) (eqs. 9, 12, 15a-b)."""
    from roastlab.model.rhs import gas_heat_capacity_kJ_kgK
    from roastlab.sim.simulate import InitialState, simulate

    t = np.arange(0.0, 40001.0, 50.0)
    n = len(t)
    values = {"Qe_gain_kW": 0.15, "Qe_offset_kW": 0.0, "tau_heater_s": 20.0, "Gg_fan_kg_s": 0.002}
    res = simulate(
        "120kg",
        t,
        np.full(n, 0.3),
        np.full(n, 25.0),
        theta=(0.05, 0.05, 0.6),
        initial=InitialState(Tb0_C=25.0, Tm0_C=25.0, X0=0.0, He0_kJ_kg=232.0),
        heater=np.full(n, 400.0),
        fan=np.full(n, 50.0),
        values=values,
    )
    Qe = 0.15 * 400.0
    Gg = 0.3 + 0.002 * 50.0
    carried = Gg * gas_heat_capacity_kJ_kgK(25.0) * (res.Tgo_C[-1] - 25.0)
    assert abs(res.Tm_C[-1] - res.Tm_C[-20]) < 1e-3  # settled
    assert carried == pytest.approx(Qe, rel=1e-4)
    assert res.heat_flows()["Qe_kW"][-1] == pytest.approx(Qe)


def test_shell_loss_energy_balance_at_steady_state():
    """Independent number: with a shell loss, the heater's power at steady state splits into what
    the gas carries out and U_shell Ashell (Tm - T_room), Ashell = pi D (L + D/2) from the plant."""
    from roastlab.model.rhs import gas_heat_capacity_kJ_kgK
    from roastlab.sim.simulate import InitialState, simulate

    plant = load_plant("120kg")
    t = np.arange(0.0, 40001.0, 50.0)
    n = len(t)
    values = {"Qe_gain_kW": 0.15, "tau_heater_s": 20.0, "U_shell_kW_m2K": 0.01, "T_room_C": 20.0}
    res = simulate(
        plant,
        t,
        np.full(n, 0.3),
        np.full(n, 25.0),
        theta=(0.05, 0.05, 0.6),
        initial=InitialState(Tb0_C=25.0, Tm0_C=25.0, X0=0.0, He0_kJ_kg=232.0),
        heater=np.full(n, 400.0),
        values=values,
    )
    Ashell = math.pi * 1.24 * (1.335 + 1.24 / 2)  # MODEL.md 120 kg drum: D = 1.24 m, L = 1.335 m
    assert plant.Ashell_m2 == pytest.approx(Ashell, rel=1e-3)
    loss = 0.01 * Ashell * (res.Tm_C[-1] - 20.0)
    carried = 0.3 * gas_heat_capacity_kJ_kgK(25.0) * (res.Tgo_C[-1] - 25.0)
    assert abs(res.Tm_C[-1] - res.Tm_C[-20]) < 1e-3  # settled
    assert loss > 0.2 * 60.0  # the loss takes a real share, so the balance tests it
    assert carried + loss == pytest.approx(0.15 * 400.0, rel=1e-4)
    assert res.heat_flows()["Qloss_kW"][-1] == pytest.approx(loss)


def test_derived_geometry_matches_model_md():
    assert math.isclose(load_plant("120kg").Agm_m2, 23.2, abs_tol=0.05)
    assert math.isclose(load_plant("360kg").Agm_m2, 54.4, abs_tol=0.05)
    assert math.isclose(load_plant("120kg").Ab_m2, 147, abs_tol=0.5)
    assert math.isclose(load_plant("360kg").Ab_m2, 441, abs_tol=0.5)
    assert math.isclose(load_plant("120kg").Mbd_kg(0.1), 120 / 1.1)


def test_steppable_simulator_matches_batch_simulation():
    Gg, Tgi = burner()
    batch = simulate("120kg", T, Gg, Tgi, hold="zoh", initial=InitialState(Ta0_C=30.0))
    sim = Simulator("120kg", hold="zoh", initial=InitialState(Ta0_C=30.0))
    states = [sim.x.copy()]
    for k in range(len(T) - 1):
        states.append(sim.step(T[k + 1] - T[k], Gg[k], Tgi[k]))
    np.testing.assert_allclose(np.array(states), batch.states, rtol=0, atol=1e-9)
    lin = simulate("120kg", T, Gg, Tgi, hold="linear", initial=InitialState(Ta0_C=30.0))
    sim = Simulator("120kg", hold="linear", initial=InitialState(Ta0_C=30.0), u0=(Gg[0], Tgi[0]))
    for k in range(len(T) - 1):
        sim.step(T[k + 1] - T[k], Gg[k + 1], Tgi[k + 1])
    np.testing.assert_allclose(sim.x, lin.states[-1], atol=1e-9)


@pytest.mark.parametrize("mass_kg", [0.2, 0.49, 0.9, 60.0, 120.0])
def test_bed_depth_is_the_circular_segment_of_the_fill(mass_kg):
    """Independent number: the segment of height h_bed cut from the drum's circle has the area
    the batch's bulk volume needs per metre of drum, R^2 acos((R-h)/R) - (R-h) sqrt(2Rh - h^2)."""
    import dataclasses

    from roastlab.model.constants import GREEN_BULK_DENSITY_KG_M3

    base = load_plant("120kg" if mass_kg > 10 else "360kg")
    plant = dataclasses.replace(
        base, Mb_kg=mass_kg, Dch_m=0.2 if mass_kg < 10 else base.Dch_m, Lch_m=0.25 if mass_kg < 10 else base.Lch_m
    )
    R, h = plant.Dch_m / 2, plant.bed_depth_m
    segment = R**2 * math.acos((R - h) / R) - (R - h) * math.sqrt(2 * R * h - h * h)
    assert segment * plant.Lch_m == pytest.approx(mass_kg / GREEN_BULK_DENSITY_KG_M3, rel=1e-9)
    half = dataclasses.replace(plant, Mb_kg=GREEN_BULK_DENSITY_KG_M3 * math.pi * R**2 * plant.Lch_m / 2)
    assert half.bed_depth_m == pytest.approx(R, rel=1e-9)  # a half-full drum: the bed reaches the axis


def steady_probe_run(plant, bed=None, **extra):
    """Eleven hours of much air through a drum heated by the heater: at the end the states are
    steady and the gas leaves well below the beans, so the probe's covered share shows."""
    from roastlab.sim.simulate import InitialState, simulate

    t = np.arange(0.0, 40001.0, 50.0)
    n = len(t)
    return simulate(
        plant,
        t,
        np.full(n, 6.0),
        np.full(n, 25.0),
        theta=(0.005, 0.05, 0.6),
        initial=InitialState(Tb0_C=25.0, Tm0_C=25.0, X0=0.0, He0_kJ_kg=232.0, Ta0_C=25.0),
        heater=np.full(n, 400.0),
        values={"Qe_gain_kW": 0.5, "tau_heater_s": 20.0, **extra},
        bed=bed,
    )


def test_probe_immersion_reads_the_covered_mix_at_steady_state():
    """At steady state a probe covered over a share c = h_bed / h_probe reads c Tb + (1 - c) Tgo
    (eq. 17 extended); with h_probe 0 (the paper) or below the bed it reads Tb, bit for bit as eq. 17."""
    plant = load_plant("120kg")

    def run(**extra):
        return steady_probe_run(plant, **extra)

    half = run(h_probe_m=2 * plant.bed_depth_m)
    assert half.Tb_C[-1] - half.Tgo_C[-1] > 50  # the gas is much cooler than the beans, so c matters
    assert half.Ta_C[-1] == pytest.approx(0.5 * half.Tb_C[-1] + 0.5 * half.Tgo_C[-1], abs=1e-3)
    paper, covered = run(), run(h_probe_m=0.5 * plant.bed_depth_m)
    assert paper.Ta_C[-1] == pytest.approx(paper.Tb_C[-1], abs=1e-3)
    assert np.array_equal(paper.states, covered.states)  # c = 1 is eq. 17 exactly
    # the probe never feeds back (only the adaptive step, which also watches Ta, differs)
    assert np.allclose(paper.states[:, :4], half.states[:, :4], rtol=0, atol=1e-4)


def test_drum_at_charge_from_a_share_of_its_rise():
    """The drum at CHARGE from a reading that shows a share of its rise over the room
    (roastlab.model.rhs.drum_at_charge_C), by hand: a probe at 132 degC in a 22 degC room showing
    0.8 of the drum's rise puts the drum at 22 + 110/0.8 = 159.5 degC; share 1 returns the reading
    bit for bit (the paper's and the Bullet's Tm0); the inverse gives the reading back; and a
    simulation from the population path starts there."""
    from roastlab.io.batch import Batch
    from roastlab.model.layout import S_TM
    from roastlab.model.parameters import THETA_START
    from roastlab.model.rhs import drum_at_charge_C, drum_start_reading_C
    from roastlab.sim.population import pack_batches, simulate_population

    assert drum_at_charge_C(132.0, 0.8, 22.0) == pytest.approx(159.5, abs=1e-12)
    assert drum_start_reading_C(159.5, 0.8, 22.0) == pytest.approx(132.0, abs=1e-12)
    assert drum_at_charge_C(131.71, 1.0, 22.0) == 131.71
    t = np.arange(0.0, 61.0, 5.0)
    b = Batch("synthetic", t, np.full(t.size, 0.45), np.full(t.size, 400.0), initial={"Tm0_C": 132.0})
    packed = pack_batches([b], "120kg", THETA_START)
    out = simulate_population(packed, ["Tm0_share", "T_room_C"], np.array([[[0.8, 22.0]]]))
    assert out[0, 0, 0, S_TM] == pytest.approx(159.5, abs=1e-9)
    assert simulate_population(packed)[0, 0, 0, S_TM] == 132.0


def test_a_model_with_a_drum_start_share_reads_logs_and_given_drums_apart():
    """A model whose drum start is a reading (Tm0_share 0.8): a log's reading starts the drum above
    it, while a drum temperature given as a change (what-if, the page, a scenario) starts the drum
    there, not above it."""
    from roastlab import FittedModel
    from roastlab.io.batch import Batch
    from roastlab.model.layout import S_TM

    t = np.arange(0.0, 121.0, 5.0)
    b = Batch("synthetic", t, np.full(t.size, 0.45), np.full(t.size, 400.0), initial={"Tm0_C": 132.0})
    model = FittedModel.paper().with_values(Tm0_share=0.8, T_room_C=22.0)
    assert model.predict(b).states[0, S_TM] == pytest.approx(159.5, abs=1e-9)
    assert model.predict(b, Tm0_C=150.0).states[0, S_TM] == pytest.approx(150.0, abs=1e-9)
    assert FittedModel.paper().predict(b).states[0, S_TM] == 132.0
