"""Exact sensitivities (issue 26): the generated Jacobian of the one right-hand side against
CasADi's and against central differences; the forward sensitivities of the compiled integrator
against central differences of the integrator itself; their users (identification, program
optimisation) against the finite-difference reference."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from roastlab.model.layout import N_INPUTS, N_PARAMS, N_STATES, S_TA, P
from roastlab.model.plant import as_plant
from roastlab.model.rhs import derivatives, pack_params
from roastlab.sim.jacobian import CODE_VALUES, CONTINUOUS, generate_source, load, source_path
from roastlab.sim.kernels import H_MAX_S, N_OUT, integrate_into
from roastlab.sim.sensitivity import integrate_sens_into, program_sensitivity

NS = N_STATES
#: Continuous entries whose value 0 switches their extension off (a kink at 0, where(k > 0, ...), or a
#: branch there whose difference quotient would take a step of 1e-11: the swelling's derivative at 0 is
#: checked where another combination switches it on).
SWITCHES = ("k_flight", "bean_swell")
RHS_JACOBIAN = load()


def _params(codes: dict, rng) -> np.ndarray:
    """The 120 kg plant's parameter vector with every extension switched on at random values and
    the law codes ``codes``, so each Jacobian entry is exercised."""
    p = pack_params(as_plant("120kg"), (0.01, 0.0254, 0.5793))
    p[P["Qe_gain"]] = rng.uniform(1.0, 5.0)
    p[P["Qe_offset"]] = rng.uniform(0.5, 2.0)
    p[P["Tgi_gain"]] = rng.uniform(5.0, 20.0)
    p[P["tau_heater"]] = rng.uniform(10.0, 60.0)
    p[P["Gg_fan"]] = rng.uniform(0.001, 0.01)
    p[P["U_shell"]] = rng.uniform(0.001, 0.01)
    p[P["h_probe"]] = p[P["h_bed"]] * rng.uniform(1.2, 3.0)  # a partly covered probe
    p[P["eps_rad"]] = rng.uniform(0.3, 0.9)  # the wall's radiation to the bed
    # the gas at the bed's surface in half the combinations (the contact laws' own Agb in the rest)
    p[P["k_flight"]] = rng.uniform(2.0, 20.0) if codes.get("probe_gas_law") == 1.0 else 0.0
    # the heater's drive as a power of its setting (a gas burner's pressure) in half the combinations
    p[P["heater_exp"]] = rng.uniform(0.4, 0.9) if codes.get("probe_law") == 1.0 else 1.0
    # the fan's drive as a power of its setting (a draft in Pa) in the other half
    p[P["fan_exp"]] = rng.uniform(0.4, 0.9) if codes.get("probe_law") != 1.0 else 1.0
    # the heater's lag growing as its setting falls (a radiant element) in half the combinations, full
    # power above the settings of _point (1-9) so that the lag's power law, not its floor, is exercised
    p[P["heater_lag_exp"]] = rng.uniform(0.5, 1.0) if codes.get("contact_law") == 1.0 else 0.0
    p[P["heater_full"]] = rng.uniform(9.0, 12.0)
    # the beans swelling with the reactions' extent (bed areas, depth and surface) in the half without k_flight
    p[P["bean_swell"]] = rng.uniform(0.3, 1.0) if codes.get("probe_gas_law") != 1.0 else 0.0
    for name, value in codes.items():
        p[P[name]] = value
    return p


def _point(rng):
    x = np.array([rng.uniform(60, 220), rng.uniform(150, 260), rng.uniform(0.02, 0.12), rng.uniform(0, 80),
                  rng.uniform(50, 210), rng.uniform(1, 8)])  # fmt: skip
    u = np.array([rng.uniform(0.3, 0.6), rng.uniform(250, 480), rng.uniform(1, 9), rng.uniform(1, 9)])
    return x, u


COMBOS = [dict(zip(CODE_VALUES, c)) for c in itertools.product(*CODE_VALUES.values())]


def _generated(x, u, p, want=None):
    f = np.zeros(NS)
    Jx, Ju, Jp = np.zeros((NS, NS)), np.zeros((NS, N_INPUTS)), np.zeros((NS, N_PARAMS))
    RHS_JACOBIAN(*x, *u, p, np.ones(N_PARAMS, dtype=bool) if want is None else want, f, Jx, Ju, Jp)
    return f, Jx, Ju, Jp


@pytest.mark.parametrize("codes", COMBOS[::5], ids=lambda c: ",".join(f"{k}={v:g}" for k, v in c.items()))
def test_the_jacobian_computes_the_parameter_columns_asked_for(codes):
    """Each column of J_p where ``want`` asks for it, the same as with every column asked for, and
    nothing in the others; f, J_x and J_u whatever is asked."""
    rng = np.random.default_rng(11)
    p = _params(codes, rng)
    x, u = _point(rng)
    full = _generated(x, u, p)
    asked = [P[name] for name in ("hgm", "hbm", "Pbm", "bean_swell", "heater_lag_exp")]
    want = np.zeros(N_PARAMS, dtype=bool)
    want[asked] = True
    some = _generated(x, u, p, want)
    for a, b in zip(full[:3], some[:3]):
        assert np.array_equal(a, b)
    assert np.array_equal(some[3][:, asked], full[3][:, asked]) and np.any(full[3][:, asked] != 0)
    others = np.setdiff1d(np.arange(N_PARAMS), asked)
    assert not np.any(some[3][:, others]) and np.any(full[3][:, others])


@pytest.mark.parametrize("codes", COMBOS, ids=lambda c: ",".join(f"{k}={v:g}" for k, v in c.items()))
def test_generated_jacobian_matches_central_differences(codes):
    rng = np.random.default_rng(abs(hash(tuple(codes.values()))) % 2**32)
    p = _params(codes, rng)
    for _ in range(3):
        x, u = _point(rng)
        f, Jx, Ju, Jp = _generated(x, u, p)
        np.testing.assert_allclose(f, derivatives(*x, *u, p), rtol=1e-12, atol=1e-15)

        def g(xx=x, uu=u, pp=p):
            return np.array(derivatives(*xx, *uu, pp))

        xu = np.concatenate([x, u])
        for j, column in enumerate(np.hstack([Jx, Ju]).T):  # d f / d x, then d f / d u
            h = 1e-6 * max(1.0, abs(xu[j]))
            e = np.zeros(xu.size)
            e[j] = h
            plus, minus = xu + e, xu - e
            fd = (g(xx=plus[:NS], uu=plus[NS:]) - g(xx=minus[:NS], uu=minus[NS:])) / (2 * h)
            np.testing.assert_allclose(column, fd, rtol=1e-5, atol=1e-9 * max(1.0, np.abs(fd).max()))
        for name in CONTINUOUS:
            q = P[name]
            if name in SWITCHES and p[q] == 0.0:
                continue  # off: a difference quotient would step across the switch
            h = 1e-5 * max(abs(p[q]), 1e-6)
            pp, pm = p.copy(), p.copy()
            pp[q] += h
            pm[q] -= h
            fd = (g(pp=pp) - g(pp=pm)) / (2 * h)
            scale = max(np.abs(fd).max(), np.abs(Jp[:, q]).max(), 1e-12)
            # central differences carry roundoff ~1e-16 |f| / h: a loose bound (CasADi checks tightly)
            assert np.abs(Jp[:, q] - fd).max() <= 1e-4 * scale, (name, Jp[:, q], fd)


@pytest.mark.parametrize(
    "codes", COMBOS[:: max(1, len(COMBOS) // 4)], ids=lambda c: ",".join(f"{v:g}" for v in c.values())
)
def test_generated_jacobian_matches_casadi(codes):
    """The same right-hand side evaluated on CasADi symbols (the control baseline's route) and
    differentiated by CasADi gives the same state and input Jacobians."""
    ca = pytest.importorskip("casadi")
    from roastlab.model.rhs import rebind

    rng = np.random.default_rng(7)
    p = _params(codes, rng)
    ns = rebind(exp=ca.exp, fmax=ca.fmax, where=ca.if_else)
    xs, us = ca.SX.sym("x", NS), ca.SX.sym("u", N_INPUTS)
    d = ca.vertcat(*ns.derivatives(*[xs[i] for i in range(NS)], *[us[k] for k in range(N_INPUTS)], p))
    jac = ca.Function("J", [xs, us], [ca.jacobian(d, xs), ca.jacobian(d, us)])
    for _ in range(3):
        x, u = _point(rng)
        _, Jx, Ju, _ = _generated(x, u, p)
        Jx_ca, Ju_ca = (np.array(a) for a in jac(x, u))
        np.testing.assert_allclose(Jx, Jx_ca, rtol=1e-10, atol=1e-14)
        np.testing.assert_allclose(Ju, Ju_ca, rtol=1e-10, atol=1e-14)


def test_a_burner_off_has_a_finite_jacobian_under_the_square_root_law():
    """heater_exp 0.5 (a gas burner logged as its pressure) with the lagged setting at 0, the burner
    off, and fan_exp 0.5 with a draft of 0: the square root's slope is infinite there, the drive's
    (linear below a floor) is not, so every Jacobian entry is finite and the program optimiser's
    gradient is a number."""
    rng = np.random.default_rng(5)
    p = _params(COMBOS[0], rng)
    p[P["heater_exp"]] = p[P["fan_exp"]] = 0.5  # and a fan logged as its draft, off
    x, u = _point(rng)
    x[-1], u[2], u[3] = 0.0, 0.0, 0.0
    f, Jx, Ju, Jp = _generated(x, u, p)
    assert np.all(np.isfinite(f)) and np.all(np.isfinite(Jx)) and np.all(np.isfinite(Ju)) and np.all(np.isfinite(Jp))
    assert Jx[1, -1] > 0.0  # more lagged gas heats the drum


def test_generated_source_is_the_cached_one():
    """The cached generated module is what the generator writes for these sources (no stale cache)."""
    path = source_path()
    if path is None:
        pytest.skip("no writable cache folder")
    assert path.read_text() == generate_source()


@pytest.mark.parametrize("key", range(len(COMBOS)), ids=lambda k: ",".join(f"{v:g}" for v in COMBOS[k].values()))
def test_a_combinations_codes_written_in_give_its_jacobian_to_the_bit(key):
    """The generated functions with one combination's codes written in (what the sensitivity kernel
    compiles per combination, so the compiler decides the codes' tests) read no code from ``p`` and
    give the numbers of the function that reads them, bit for bit, every parameter column asked for."""
    from roastlab.sim.jacobian import COMBINATIONS, _source_text, code_key, with_codes

    codes = COMBOS[key]
    assert tuple(codes.values()) == COMBINATIONS[key]
    text = _source_text()
    special = with_codes(text, key)
    for name in CODE_VALUES:
        read = f"p_{name} = p[{P[name]}]"
        assert read in text and read not in special, name
    function = load(key=key)
    rng = np.random.default_rng(100 + key)
    p = _params(codes, rng)
    for _ in range(3):
        x, u = _point(rng)
        want = np.ones(N_PARAMS, dtype=bool)
        got = np.zeros(NS), np.zeros((NS, NS)), np.zeros((NS, N_INPUTS)), np.zeros((NS, N_PARAMS))
        function(*x, *u, p, want, *got)
        for a, b in zip(got, _generated(x, u, p)):
            assert np.array_equal(a, b)
    assert code_key(np.vstack([p, p])) == key


def test_runs_share_a_code_key_only_when_every_code_is_one_of_its_values():
    from roastlab.sim.jacobian import COMBINATIONS, code_key

    p = _params(COMBOS[0], np.random.default_rng(3))
    assert code_key(p[None, :]) == 0 and COMBINATIONS[0] == tuple(COMBOS[0].values())
    q = _params(COMBOS[5], np.random.default_rng(3))
    assert code_key(np.vstack([p, q])) == -1  # runs whose laws differ
    q = p.copy()
    q[P["x_exp"]] = 1.5  # no law's exponent
    assert code_key(q[None, :]) == -1
    assert code_key(np.zeros((0, N_PARAMS))) == -1


def test_the_sensitivity_kernel_for_the_runs_codes_agrees_with_the_one_reading_them():
    """A fit's sensitivities run the kernel compiled for its runs' codes; runs whose codes differ (two
    bed laws in one call) take the kernel that reads them from each run's parameters, and each run's
    numbers are the same to the bit either way."""
    import dataclasses

    from roastlab.io.batch import read_dataset
    from roastlab.model.parameters import THETA_START
    from roastlab.sim.jacobian import code_key
    from roastlab.sim.population import output_sensitivities, pack_batches
    from roastlab.workflows.reproduce import default_dataset_root

    ds = read_dataset(default_dataset_root() / "dataset-I")
    batches = ds.batches[:2]
    paper = pack_batches(batches, ds.plant, THETA_START)
    tumbling = pack_batches(batches, ds.plant, THETA_START, bed="probe=tumbling,probe_gas=mean")
    mixed = dataclasses.replace(paper, PB=np.vstack([paper.PB[0], tumbling.PB[1]]))
    names, values, directions = ["hbm", "Pbm"], np.array([[0.03, 0.5], [0.03, 0.5]]), [(0, -1), (1, -1)]
    one = output_sensitivities(paper, names, values, directions)
    other = output_sensitivities(tumbling, names, values, directions)
    both = output_sensitivities(mixed, names, values, directions)
    for out in ("Ta", "Tb"):
        for k in range(2):  # the value, its derivatives
            assert np.array_equal(both[out][k][0], one[out][k][0], equal_nan=True)
            assert np.array_equal(both[out][k][1], other[out][k][1], equal_nan=True)
    assert code_key(mixed.PB) == -1 and -1 < code_key(paper.PB) != code_key(tumbling.PB) > -1


def test_the_printed_powers_shortcut_only_where_pow_is_exact():
    """A power with an exponent that is not a whole number is printed behind pow's exact cases
    (x**0 = 1, x**1 = x, 1**y = 1): at bases and exponents that hit them, at their neighbours and
    at the non-finite values, the printed expression gives pow's bits, NaN where pow gives NaN."""
    import math

    import sympy as sp

    from roastlab.sim.jacobian import _printer

    x, y = sp.symbols("x y", real=True)
    printer = _printer()
    symbolic = printer.doprint(x**y)
    constant = printer.doprint(x ** sp.Float(1.0 / 3.0))
    assert "== 1.0" in symbolic and "== 0.0" in symbolic and "== 1.0" in constant
    assert printer.doprint(x**2) == "x**2" and printer.doprint(x ** sp.Rational(1, 2)) == "math.sqrt(x)"
    near = [math.nextafter(1.0, 0.0), math.nextafter(1.0, 2.0)]
    values = [0.0, -0.0, 1.0, 2.5, 1e-6, math.inf, math.nan, *near]
    exponents = [0.0, -0.0, 1.0, -1.0, 0.5, 1.0 / 3.0, -2.0 / 3.0, math.inf, -math.inf, math.nan, *near]
    printed = eval(f"lambda x, y: {symbolic}", {"math": math})  # the printer's own text, no user input
    for a, b in itertools.product(values, exponents):
        try:
            want = a**b
        except ZeroDivisionError:  # Python raises where C's pow gives inf (0 to a negative power)
            continue
        got = printed(a, b)
        assert (math.isnan(want) and math.isnan(got)) or (
            got == want and math.copysign(1, got) == math.copysign(1, want)
        ), (a, b)


def _case(zoh, heater=False):
    t = np.arange(0.0, 901.0, 10.0)
    n = t.size
    p = pack_params(as_plant("120kg"), (0.01, 0.0254, 0.5793))
    Q = np.zeros(n)
    if heater:
        p[P["Qe_gain"]], p[P["tau_heater"]] = 3.0, 30.0
        Q = 5.0 + 2.0 * np.sin(t / 150.0)
    Gg = np.full(n, 0.45)
    Tgi = 420.0 + 40.0 * np.sin(t / 200.0)
    x0 = np.array([25.0, 180.0, 0.1, 0.0, 25.0, Q[0]])
    return t, Gg, Tgi, Q, np.zeros(n), x0, p, zoh


def _ta(t, Gg, Tgi, Q, F, x0, p, zoh):
    out = np.empty((t.size, N_OUT))
    integrate_into(t, Gg, Tgi, Q, F, t.size, x0, p, zoh, H_MAX_S, out)
    return out


@pytest.mark.parametrize("zoh", [False, True])
def test_parameter_sensitivities_match_central_differences(zoh):
    t, Gg, Tgi, Q, F, x0, p, zoh = _case(zoh)
    n = t.size
    names = ["hgm", "hbm", "Pbm", "Kt"]
    m = len(names) + 1  # and Tm0
    S0 = np.zeros((NS, m))
    S0[1, m - 1] = 1.0
    pq = np.array([P[k] for k in names], dtype=np.int64)
    pc = np.arange(len(names), dtype=np.int64)
    none = np.zeros(0, dtype=np.int64)
    out = np.empty((n, NS))
    outS = np.empty((n, 1, m))
    integrate_sens_into(t, Gg, Tgi, Q, F, n, x0, p, zoh, H_MAX_S, S0, none, none, none, none, np.zeros(0), pq, pc,
                        np.ones(len(names)), np.array([S_TA]), out, outS)  # fmt: skip
    base = _ta(t, Gg, Tgi, Q, F, x0, p, zoh)
    np.testing.assert_allclose(out, base[:, :NS], rtol=0, atol=1e-9)  # the same steps, the same states
    for c, name in enumerate([*names, "Tm0"]):
        h = 1e-4 * (p[P[name]] if name != "Tm0" else 100.0)
        runs = []
        for sign in (1, -1):
            pp, xx = p.copy(), x0.copy()
            if name == "Tm0":
                xx[1] += sign * h
            else:
                pp[P[name]] += sign * h
            runs.append(_ta(t, Gg, Tgi, Q, F, xx, pp, zoh)[:, S_TA])
        fd = (runs[0] - runs[1]) / (2 * h)
        assert np.abs(outS[:, 0, c] - fd).max() <= 1e-6 * np.abs(fd).max(), name


@pytest.mark.parametrize("zoh,heater", [(False, False), (True, False), (True, True), (False, True)])
def test_program_sensitivities_match_central_differences(zoh, heater):
    t, Gg, Tgi, Q, F, x0, p, zoh = _case(zoh, heater)
    which = 1 if heater else 0
    states, dta = program_sensitivity(t, Gg, Tgi, Q, F, x0, p, zoh, which, ("Gg", "Tm0"))
    n = t.size
    assert dta.shape == (n, n + 2)
    np.testing.assert_allclose(states, _ta(t, Gg, Tgi, Q, F, x0, p, zoh)[:, :NS], atol=1e-9)
    for k in (0, 1, 17, n // 2, n - 1):
        h = 0.5 if which == 0 else 0.05
        runs = []
        for sign in (1, -1):
            T2, Q2, x2 = Tgi.copy(), Q.copy(), x0.copy()
            if which == 0:
                T2[k] += sign * h
            else:
                Q2[k] += sign * h
                if k == 0:
                    x2[5] = Q2[0]  # the lag starts settled at the first setting
            runs.append(_ta(t, Gg, T2, Q2, F, x2, p, zoh)[:, S_TA])
        fd = (runs[0] - runs[1]) / (2 * h)
        assert np.abs(dta[:, k] - fd).max() <= 1e-5 * max(np.abs(fd).max(), 1e-9), k
        reach = k if zoh or k == 0 else k - 1
        assert np.all(dta[: reach + 1, k] == 0.0)  # causality: nothing before the knot's interval
    for c, (which_extra, h) in enumerate((("Gg", 1e-4), ("Tm0", 0.5))):
        runs = []
        for sign in (1, -1):
            g2, x2 = Gg.copy(), x0.copy()
            if which_extra == "Gg":
                g2 += sign * h
            else:
                x2[1] += sign * h
            runs.append(_ta(t, g2, Tgi, Q, F, x2, p, zoh)[:, S_TA])
        fd = (runs[0] - runs[1]) / (2 * h)
        assert np.abs(dta[:, n + c] - fd).max() <= 1e-5 * np.abs(fd).max(), which_extra


def test_identification_jacobian_matches_central_differences():
    """The identification objective's exact Jacobian (theta, the moisture at charge through the
    dry mass, and a per-batch drum temperature) against small central differences."""
    from roastlab.fit.identify import Objective
    from roastlab.io.batch import read_dataset
    from roastlab.model.parameters import THETA_START, FreeParameter
    from roastlab.sim.population import pack_batches
    from roastlab.workflows.reproduce import default_dataset_root

    ds = read_dataset(default_dataset_root() / "dataset-I")
    packed = pack_batches(ds.batches[:3], ds.plant, THETA_START)
    free = [
        FreeParameter("hgm", 0.001, 0.1, 0.02),
        FreeParameter("hbm", 0.001, 0.1, 0.03),
        FreeParameter("Pbm", 0.1, 0.9, 0.5),
        FreeParameter("X0", 0.05, 0.15, 0.1),
        FreeParameter("Tm0_C", 100.0, 300.0, 190.0, per_batch=True),
    ]
    obj = Objective(packed, free, {})
    z = obj.start.copy()
    J = obj.jacobian(z)
    for k in range(z.size):
        h = 1e-5 * (obj.upper[k] - obj.lower[k])
        zp, zm = z.copy(), z.copy()
        zp[k] += h
        zm[k] -= h
        fd = (obj.residuals(zp) - obj.residuals(zm)) / (2 * h)
        assert np.abs(J[:, k] - fd).max() <= 1e-4 * np.abs(fd).max() + 1e-9, k
    # the finite-difference reference (its step is 1e-3 of the range) agrees to its truncation error
    assert np.abs(J - obj.jacobian_fd(z)).max() <= 0.05 * np.abs(J).max()


def test_program_optimiser_exact_and_fd_agree():
    """Profile transfer's optimiser reaches the same program with exact sensitivities as with the
    finite-difference reference, with fewer simulations."""
    from roastlab.fit.program import ProgramLimits, optimise_program

    t, Gg, Tgi, Q, F, x0, p, _ = _case(False)
    target = _ta(t, Gg, Tgi + 15.0 * np.cos(t / 100.0), Q, F, x0, p, False)[:, S_TA]
    limits = ProgramLimits(low=150.0, high=550.0, rate_per_min=60.0)
    res = {
        s: optimise_program(t, target, x0, p, Gg, Tgi, limits, sensitivities=s, max_iterations=60)
        for s in ("exact", "fd")
    }
    for r in res.values():
        assert np.sqrt(np.mean((r.Ta_pred_C - target) ** 2)) < 0.1
    assert np.abs(res["exact"].Tgi_C - res["fd"].Tgi_C).max() < 1.0
    assert res["exact"].simulations < res["fd"].simulations


def test_a_program_optimiser_out_of_evaluations_says_so_in_plain_words():
    """SYNTHETIC target as above, two evaluations allowed: the program is returned with a note in the
    roaster's words, not SciPy's message; with enough evaluations there is none."""
    from roastlab.fit.program import ProgramLimits, optimise_program

    t, Gg, Tgi, Q, F, x0, p, _ = _case(False)
    target = _ta(t, Gg, Tgi + 15.0 * np.cos(t / 100.0), Q, F, x0, p, False)[:, S_TA]
    limits = ProgramLimits(low=150.0, high=550.0, rate_per_min=60.0)
    short = optimise_program(t, target, x0, p, Gg, Tgi, limits, max_iterations=2)
    assert short.notes == [
        "the optimiser used all 2 of its evaluations before it settled: the program is the best it found"
    ]
    assert optimise_program(t, target, x0, p, Gg, Tgi, limits, max_iterations=60).notes == []


def test_outlet_gas_sensitivities_match_central_differences():
    """ET fitted against the outlet gas Tgo: its exact derivative (the generated outlet Jacobian
    applied to the state sensitivities) against central differences of the simulated Tgo."""
    from roastlab.model.parameters import THETA_START
    from roastlab.sim.population import output_sensitivities, pack_batches, predict_outputs

    t, Gg, Tgi, Q, F, x0, p, _ = _case(True, heater=True)
    from roastlab.io.batch import Batch

    batch = Batch("synthetic", t, Gg, Tgi, heater=Q)
    packed = pack_batches([batch], "120kg", THETA_START, hold="zoh")
    names = ["hgm", "hbm", "Tm0_C"]
    values = np.array([[0.02, 0.03, 190.0]])
    res = output_sensitivities(packed, names, values, [(0, -1), (1, -1), (2, -1)], with_tgo=True)
    g, dg = res["Tgo"]
    _, _, tgo = predict_outputs(packed, names, values[None], with_tb=False, with_tgo=True)
    np.testing.assert_allclose(g[0], tgo[0, 0], atol=1e-9)
    for c, h in enumerate((1e-5, 1e-5, 0.01)):
        vp, vm = values.copy(), values.copy()
        vp[0, c] += h
        vm[0, c] -= h
        fd = (predict_outputs(packed, names, vp[None], False, True)[2][0, 0]
              - predict_outputs(packed, names, vm[None], False, True)[2][0, 0]) / (2 * h)  # fmt: skip
        assert np.abs(dg[0, :, c] - fd).max() <= 1e-4 * np.abs(fd).max(), c


def test_drum_start_share_sensitivities_match_central_differences():
    """The drum at CHARGE read through a share of its rise over the room (``Tm0_share``): the
    exact derivatives of the probe with respect to the share, the reading and the room against
    central differences of the simulated probe."""
    from roastlab.io.batch import Batch
    from roastlab.model.parameters import THETA_START
    from roastlab.sim.population import output_sensitivities, pack_batches, predict_outputs

    t, Gg, Tgi, Q, F, x0, p, _ = _case(False, heater=True)
    packed = pack_batches([Batch("synthetic", t, Gg, Tgi, heater=Q)], "120kg", THETA_START)
    names = ["Tm0_share", "Tm0_C", "T_room_C", "Qe_gain_kW"]
    values = np.array([[0.7, 150.0, 25.0, 3.0]])
    res = output_sensitivities(packed, names, values, [(j, -1) for j in range(len(names))])
    ta, dta = res["Ta"]
    np.testing.assert_allclose(ta[0], predict_outputs(packed, names, values[None], False)[0][0, 0], atol=1e-9)
    for c, h in enumerate((1e-4, 0.01, 0.01, 1e-4)):
        vp, vm = values.copy(), values.copy()
        vp[0, c] += h
        vm[0, c] -= h
        fd = (predict_outputs(packed, names, vp[None], False)[0][0, 0]
              - predict_outputs(packed, names, vm[None], False)[0][0, 0]) / (2 * h)  # fmt: skip
        assert np.abs(dta[0, :, c] - fd).max() <= 1e-5 * np.abs(fd).max(), names[c]
