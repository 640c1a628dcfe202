"""The one uncertainty rule (roastlab.fit.uncertainty) against independent numbers, and the two
fitters agreeing on the same batch because they share it."""

import math

import numpy as np
import pytest

import roastlab
from roastlab.fit import uncertainty
from roastlab.fit.batchfit import identify_each
from roastlab.fit.identify import build_free_parameters, identify
from roastlab.model.parameters import THETA_START
from roastlab.sim.population import pack_batches


def line_fit(seed):
    """A seeded synthetic straight line y = 1.5 + 0.7 x + noise fitted by least squares: x, the
    design matrix X (the Jacobian), the coefficients, the residuals (model - measured) and the SSR."""
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 10.0, 25)
    y = 1.5 + 0.7 * x + rng.normal(0.0, 0.3, x.size)
    X = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = X @ coef - y
    ssr = float(r @ r)
    return x, X, coef, r, ssr


def test_linear_regression_known_answer():
    """A straight-line fit y = a + b x: the covariance is s^2 (X'X)^-1 with s^2 = SSR / (n - 2),
    computed here by hand from the closed-form sums (no pseudo-inverse involved)."""
    x, X, coef, r, ssr = line_fit(0)
    u = uncertainty.from_jacobian(X, coef, [-10, -10], [10, 10], ssr, ["a", "b"])
    n = x.size
    s2 = ssr / (n - 2)
    sxx = np.sum((x - x.mean()) ** 2)
    se_b = math.sqrt(s2 / sxx)  # textbook slope standard error
    se_a = math.sqrt(s2 * (1.0 / n + x.mean() ** 2 / sxx))
    assert u.stderr[0] == pytest.approx(se_a, rel=1e-10)
    assert u.stderr[1] == pytest.approx(se_b, rel=1e-10)
    assert u.correlation[0, 1] == pytest.approx(-x.mean() / math.sqrt(np.mean(x**2)), rel=1e-10)
    # lmfit's definitions: n ln(chi2 / n) + 2 k and + ln(n) k
    assert u.aic == pytest.approx(n * math.log(ssr / n) + 4.0)
    assert u.bic == pytest.approx(n * math.log(ssr / n) + 2.0 * math.log(n))


def test_bound_flat_and_no_dof_get_no_standard_error():
    J = np.array([[1.0, 0.0, 2.0], [1.0, 0.0, 1.0], [1.0, 0.0, 0.5], [1.0, 0.0, 3.0]])
    lo, hi = np.zeros(3), np.ones(3)
    u = uncertainty.from_jacobian(J, [1.0 - 1e-5, 0.5, 0.5], lo, hi, 2.0, ["on_bound", "flat", "free"])
    assert np.isnan(u.stderr[0]) and np.isnan(u.stderr[1]) and u.stderr[2] > 0
    assert list(u.on_bound) == [True, False, False] and list(u.flat) == [False, True, False]
    # the same parameter a hair further inside (2e-4 of the span) is determined again
    assert np.isfinite(uncertainty.from_jacobian(J, [1.0 - 2e-4, 0.5, 0.5], lo, hi, 2.0, list("abc")).stderr[0])
    # two residuals, two determined parameters: no degrees of freedom, no standard error
    u2 = uncertainty.from_jacobian(J[:2, [0, 2]], [0.5, 0.5], lo[:2], hi[:2], 1.0, ["a", "b"])
    assert np.all(np.isnan(u2.stderr))
    words = " ".join(u.warnings())
    assert "upper bound" in words and "no effect" in words


def test_several_values_on_bounds_and_several_correlated_pairs_are_one_line_each():
    """Five parameters, two held by their bounds and two pairs nearly collinear: two warnings, each
    naming every parameter or pair (a fit-roaster's terminal read seven lines for these before)."""
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=40), rng.normal(size=40)
    J = np.column_stack([a, a + 1e-3 * rng.normal(size=40), b, b - 1e-3 * rng.normal(size=40), rng.normal(size=40)])
    J = np.column_stack([J, rng.normal(size=(40, 2))])
    lo, hi = np.zeros(7), np.ones(7)
    names = ["p", "q", "r", "s", "t", "low", "high"]
    u = uncertainty.from_jacobian(J, [0.5] * 5 + [1e-7, 1.0 - 1e-7], lo, hi, 2.0, names)
    w = u.warnings()
    assert len(w) == 2, w
    assert w[0].startswith("2 values are on a bound: low (its lower bound 0), high (its upper bound 1)")
    assert w[1].startswith("2 pairs are correlated: p and q (-1.000), r and s (-1.000); the data pin down")
    one = uncertainty.from_jacobian(
        J[:, [0, 1, 4, 5]], [0.5, 0.5, 0.5, 1e-7], lo[:4], hi[:4], 2.0, ["p", "q", "t", "low"]
    )
    assert [x.split(":")[0] for x in one.warnings()] == [
        "low is on its lower bound 0",
        "p and q are correlated (-1.000)",
    ]


def test_a_range_over_decades_is_judged_near_its_bound_in_the_logarithm():
    """A rate factor in [1e5, 1e10] at 1e6, a decade above its floor, is determined by the data; in
    the value it lay within 1e-4 of the span (1e6) of the floor and got no standard error."""
    J = np.array([[1.0, 2.0], [1.0, 1.0], [1.0, 0.5], [1.0, 3.0]])
    lo, hi = np.array([1e5, 0.0]), np.array([1e10, 1.0])
    u = uncertainty.from_jacobian(J, [1e6, 0.5], lo, hi, 2.0, ["A", "b"])
    assert not u.on_bound[0] and np.isfinite(u.stderr[0])
    assert (1e6 - lo[0]) <= uncertainty.ON_BOUND_REL * (hi[0] - lo[0])  # what the value's rule called it
    # on its floor to the rule's margin in the logarithm (1e-4 of ln 1e5, 0.12 %) it is held
    held = uncertainty.from_jacobian(J, [1e5 * 1.001, 0.5], lo, hi, 2.0, ["A", "b"])
    assert held.at_lower[0] and np.isnan(held.stderr[0])
    # the two fitters' coordinate: both judge in it (the per-batch fitter imports it from here)
    from roastlab.fit import batchfit, identify

    assert identify.log_sampled is uncertainty.log_sampled is batchfit.log_sampled


@pytest.fixture(scope="module")
def one_batch():
    ds = roastlab.read_dataset(roastlab.default_dataset_root() / "dataset-I")
    return pack_batches(ds.batches[:1], "120kg", (THETA_START.hgm, THETA_START.hbm, 0.5793))


@pytest.mark.parametrize("hgm_bounds", [None, (0.01, 0.1)], ids=["interior", "hgm-held-by-its-upper-bound"])
def test_the_two_fitters_agree_on_the_same_batch(one_batch, hgm_bounds):
    """identify() (SciPy, many batches) and identify_each() (compiled, per batch) on one batch:
    the same values, the same standard errors within 10 % (their Jacobians differ: SciPy's steps
    vs the compiled fitter's), and the same verdict on which parameter a bound holds."""
    bounds = {} if hgm_bounds is None else {"hgm": hgm_bounds}  # unbounded, hgm lands at ~0.16
    each = identify_each(one_batch, names=["hgm", "hbm"], bounds=bounds)
    free, fixed = build_free_parameters({"Pbm": 0.5793}, bounds)
    one = identify(one_batch, free, fixed, seed=0, n_starts=2)
    for j, name in enumerate(["hgm", "hbm"]):
        assert each.theta[0, j] == pytest.approx(one.values[name], rel=2e-3)
        if one.stderr[name] is None:
            assert np.isnan(each.stderr[0, j]), name
        else:
            assert each.stderr[0, j] == pytest.approx(one.stderr[name], rel=0.1)
    held = [k for k, v in one.stderr.items() if v is None]
    assert held == ([] if hgm_bounds is None else ["hgm"])
    assert one.uncertainty is not None and np.isfinite(one.aic) and np.isfinite(one.bic)
    doc = one.to_json_dict()
    assert doc["AIC"] == pytest.approx(one.aic) and len(doc["covariance"]) == 2


def test_standard_errors_do_not_depend_on_the_parameters_units():
    """A parameter measured in units that make it 1e9 (the reaction's pre-exponential factor A
    beside a flow in kg/s) keeps its own standard error: the straight line's slope expressed in
    units 1e-9 times as large has a standard error 1e9 times as large, with the same correlation.
    A plain pseudo-inverse cut that direction (singular values below 1e-15 of the largest) and
    gave it a variance of about 0; the held-out residuals, which invert the same matrix, stay put."""
    _, X, coef, r, ssr = line_fit(1)
    u = uncertainty.from_jacobian(X, coef, [-10, -10], [10, 10], ssr, ["a", "b"])
    k = 1e-9  # the slope in units 1e-9 times as large: the value x 1e9, the Jacobian column x 1e-9
    Xs = X * np.array([1.0, k])
    us = uncertainty.from_jacobian(Xs, coef / [1.0, k], [-10, -1e10], [10, 1e10], ssr, ["a", "b"])
    assert us.stderr[0] == pytest.approx(u.stderr[0], rel=1e-8)
    assert us.stderr[1] == pytest.approx(u.stderr[1] / k, rel=1e-8)
    assert us.correlation[0, 1] == pytest.approx(u.correlation[0, 1], rel=1e-8)
    groups = np.repeat(np.arange(5), 5)
    held = uncertainty.held_out_residuals(X, r, groups, np.ones(2, bool))
    assert np.allclose(uncertainty.held_out_residuals(Xs, r, groups, np.ones(2, bool)), held, atol=1e-9)


def test_held_out_residuals_given_the_model_are_refits_without_each_group(monkeypatch):
    """Given the model, each group's held-out residuals are those of the fit redone without it, for a
    model curved in its parameters (a * exp(b x)), checked against converged refits from scratch on
    seeded synthetic data; a group far from the others (x in [2, 3], reading 60 % high) is where one
    linearised step errs most, and the refit does not. Bounds hold in the refit too: there
    Gauss-Newton's steps leave them and SciPy's trust region refits (within the bounds, Gauss-Newton
    alone)."""
    import scipy.optimize
    from scipy.optimize import least_squares

    scipy_calls = []

    def counted(*args, **kwargs):
        scipy_calls.append(1)
        return least_squares(*args, **kwargs)

    rng = np.random.default_rng(5)
    groups = np.repeat(np.arange(4), 8)
    x = np.concatenate([np.linspace(0.0, 1.0, 8)] * 3 + [np.linspace(2.0, 3.0, 8)])

    def residuals_many(Z):  # (m, 2) -> (m, n): a * exp(b x) - y
        Z = np.atleast_2d(Z)
        return Z[:, :1] * np.exp(Z[:, 1:2] * x[None, :]) - y[None, :]

    def jacobian(z):
        return np.column_stack([np.exp(z[1] * x), z[0] * x * np.exp(z[1] * x)])

    y = np.exp(0.8 * x) * (1 + 0.05 * rng.normal(size=x.size)) + 0.3 * rng.normal(size=4)[groups]
    y[groups == 3] *= 1.6
    lo, hi = np.array([0.01, -3.0]), np.array([10.0, 3.0])
    tight = dict(xtol=1e-14, ftol=1e-14, gtol=1e-14)

    def refit(keep, z0, lo, hi):
        f = least_squares(
            lambda q: residuals_many(q)[0][keep], z0, jac=lambda q: jacobian(q)[keep], bounds=(lo, hi), **tight
        )
        return residuals_many(f.x)[0]

    z = least_squares(lambda q: residuals_many(q)[0], [1.0, 0.5], jac=jacobian, bounds=(lo, hi), **tight).x
    r, J, det = residuals_many(z)[0], jacobian(z), np.ones(2, bool)
    linear = uncertainty.held_out_residuals(J, r, groups, det)
    monkeypatch.setattr(scipy.optimize, "least_squares", counted)  # where the refits find it
    held = uncertainty.held_out_residuals(J, r, groups, det, z, lo, hi, residuals_many, jacobian)
    assert not scipy_calls
    for g in range(4):
        out = groups == g
        truth = refit(~out, z, lo, hi)[out]
        assert np.allclose(held[out], truth, atol=1e-4), g
    far = groups == 3
    assert np.abs(linear[far] - refit(~far, z, lo, hi)[far]).max() > 0.5  # one step does not follow the curve
    # a bound the refit meets holds it there: without the far group b falls, here onto a floor
    # just below the full fit's value
    lo_b = np.array([0.01, z[1] - 0.01])
    held_b = uncertainty.held_out_residuals(J, r, groups, det, z, lo_b, hi, residuals_many, jacobian)
    assert scipy_calls
    assert np.allclose(held_b[far], refit(~far, z, lo_b, hi)[far], atol=1e-4)
    assert not np.allclose(held_b[far], held[far], atol=1e-3)

    # a refit SciPy refuses (it raises ValueError where the products overflow) keeps the step
    def refused(Z):
        raise ValueError("overflow")

    kept = uncertainty.held_out_residuals(J, r, groups, det, z, lo, hi, refused, jacobian)
    assert np.array_equal(kept, linear)


def test_a_refit_simulates_the_batches_it_fits_and_ends_at_the_optimum_without_its_batch():
    """Each held-out refit on dataset-I simulates only the batches it fits (``by_group``), never the
    one left out in a Jacobian, and ends where SciPy's trust region, run to its end with tolerances
    of 1e-14 on every batch, ends: the held-out residuals agree to 0.005 degC (they differ by 0.0009
    degC at most, where the two ends lie 1e-8 of the cost apart on a flat ridge). Gauss-Newton's steps
    (``_newton_refit``) do it with fewer sensitivity runs than SciPy's trust region at
    ``REFIT_TOL`` (two to four a refit, the first the fit's own), and without calling SciPy."""
    import importlib

    import scipy.optimize
    from scipy.optimize import least_squares

    from roastlab.io.batch import read_dataset
    from roastlab.workflows.reproduce import default_dataset_root

    ident = importlib.import_module("roastlab.fit.identify")
    ds = read_dataset(default_dataset_root() / "dataset-I")
    free, fixed = build_free_parameters()
    obj = ident.Objective(pack_batches(ds.batches, ds.plant, THETA_START), free, fixed)
    z, ssr, r, J, _ = ident._polish(obj, obj.start)
    det = uncertainty.from_jacobian(J, z, obj.lower, obj.upper, ssr, list(obj.names)).determined
    groups, nb = obj.batch_of_residual, obj.packed.n_batches
    asked, scipy_calls = [], []

    def jacobian(zz, groups=None):
        asked.append(groups)
        return obj.jacobian(zz, groups)

    def counted(*args, **kwargs):
        scipy_calls.append(1)
        return least_squares(*args, **kwargs)

    scipy.optimize.least_squares, saved = counted, scipy.optimize.least_squares
    try:
        held = uncertainty.held_out_residuals(
            J, r, groups, det, z, obj.lower, obj.upper, obj.residuals_many, jacobian, by_group=True
        )
    finally:
        scipy.optimize.least_squares = saved
    assert not scipy_calls  # every refit ended on Gauss-Newton's steps
    assert asked and all(len(g) == nb - 1 for g in asked)  # never the batch left out

    def full(x):
        zz = z.copy()
        zz[det] = x
        return zz

    scipy_jacobians = 0
    for g in range(nb):
        keep = groups != g
        common = dict(jac=lambda x, keep=keep: obj.jacobian(full(x))[keep][:, det], method="trf", x_scale="jac",
                      bounds=(obj.lower[det], obj.upper[det]))  # fmt: skip
        fun = lambda x, keep=keep: obj.residuals(full(x))[keep]  # noqa: E731
        tight = least_squares(fun, z[det], ftol=1e-14, xtol=1e-14, gtol=1e-14, max_nfev=200, **common)
        assert np.abs(held[~keep] - obj.residuals(full(tight.x))[~keep]).max() < 0.005, g
        tol = uncertainty.REFIT_TOL
        end = least_squares(fun, z[det], ftol=tol, xtol=tol, gtol=tol, max_nfev=uncertainty.REFIT_MAX_NFEV, **common)
        scipy_jacobians += end.njev - 1  # its first is the fit's
    assert len(asked) < scipy_jacobians, (len(asked), scipy_jacobians)


def test_a_refit_whose_step_is_not_borne_out_is_scipys():
    """Where a Gauss-Newton step of the refit leaves the bounds or does not lower the cost by a
    quarter of what it predicted, the refit is SciPy's trust region from the full fit's optimum:
    ``_newton_refit`` gives None (held_out_residuals then calls SciPy: the bound case of
    test_held_out_residuals_given_the_model_are_refits_without_each_group)."""
    x = np.linspace(0.0, 1.0, 10)
    y = np.exp(0.5 * x)

    def fun(q):  # a * exp(b x) - y
        return q[0] * np.exp(q[1] * x) - y

    def jac(q):
        return np.column_stack([np.exp(q[1] * x), q[0] * x * np.exp(q[1] * x)])

    everywhere = np.ones(x.size, bool)
    det = np.ones(2, bool)
    lo, hi = np.array([0.0, -5.0]), np.array([5.0, 5.0])
    # from near the optimum (1, 0.5) the steps contract to it
    end = uncertainty._newton_refit(fun, jac, np.array([1.05, 0.45]), jac([1.05, 0.45]), everywhere, det, lo, hi)
    assert end is not None and np.allclose(end, [1.0, 0.5], atol=1e-6)
    # a bound between the start and the optimum: the first step leaves it
    tight_lo = np.array([1.02, -5.0])
    assert uncertainty._newton_refit(fun, jac, np.array([1.05, 0.45]), jac([1.05, 0.45]), everywhere, det,
                                     tight_lo, hi) is None  # fmt: skip
    # far from the optimum the linearisation's step overshoots: the cost falls by less than it predicted
    far = np.array([0.05, 4.0])
    assert uncertainty._newton_refit(fun, jac, far, jac(far), everywhere, det, lo, hi) is None


def test_held_out_residuals_equal_refits_without_each_group_for_a_linear_model():
    """The linearised leave-one-group-out rule is exact when the model is linear in its parameters:
    checked against refitting (numpy lstsq) without each group, on seeded synthetic data."""
    rng = np.random.default_rng(3)
    groups = np.repeat(np.arange(5), 12)
    J = np.column_stack([np.ones(groups.size), rng.normal(size=groups.size), rng.normal(size=groups.size)])
    y = J @ np.array([1.0, -2.0, 0.5]) + rng.normal(size=groups.size) + 0.7 * rng.normal(size=5)[groups]
    z = np.linalg.lstsq(J, y, rcond=None)[0]
    r = J @ z - y  # model - measured, as the objective's residuals
    held = uncertainty.held_out_residuals(J, r, groups, np.ones(3, bool))
    for g in range(5):
        keep = groups != g
        zg = np.linalg.lstsq(J[keep], y[keep], rcond=None)[0]
        assert np.allclose(held[~keep], J[~keep] @ zg - y[~keep], atol=1e-12)
    assert np.sqrt(np.mean(held**2)) > np.sqrt(np.mean(r**2))  # a log predicted without it errs more
    # a parameter a bound holds stays where it is: only the determined columns move
    only_mean = uncertainty.held_out_residuals(J, r, groups, np.array([True, False, False]))
    for g in range(5):
        rows = groups == g
        assert np.allclose(only_mean[rows], r[rows] + (r[rows].sum() / (~rows).sum()), atol=1e-12)


def test_a_value_the_data_leave_open_is_said_so_and_not_printed_as_a_number():
    """A column of J nearly zero (a term all but switched off at the fitted value: the probe's depth scale
    near 0 on a few logs gave a standard error of 4e+57 m on a 0-0.5 m range, printed as such): the
    warning says the data leave it open and the model's table shows no number; one of a correlated pair
    is the pair's warning instead."""
    from roastlab import FittedModel

    rng = np.random.default_rng(1)
    J = np.column_stack([rng.normal(size=30), 1e-30 * rng.normal(size=30)])
    u = uncertainty.from_jacobian(J, [0.5, 1e-3], np.zeros(2), np.array([1.0, 0.5]), 2.0, ["hbm", "h_probe_m"])
    assert u.unpinned.tolist() == [False, True]
    assert any(w.startswith("h_probe_m = 0.001 is not determined by these data") for w in u.warnings())
    model = FittedModel.paper()
    model.parameters["h_probe_m"] = {"value": 1e-3, "stderr": float(u.stderr[1]), "bounds": [0.0, 0.5],
                                     "how": "fitted", "unit": "m"}  # fmt: skip
    row = next(r for r in model.table() if r[0] == "h_probe_m")
    assert row[2] == "wider than its range"
