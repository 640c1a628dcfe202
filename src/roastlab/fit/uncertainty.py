"""The one uncertainty rule of every fit: bounds, covariance, standard errors, AIC and BIC.

Both fitters (:func:`roastlab.fit.identify.identify` over many batches, and the compiled
per-batch fitter :func:`roastlab.fit.batchfit.identify_each`) call this module, so the same
batch gets the same verdict from either path.

The linearised covariance at the optimum of a least-squares fit (lmfit's and SciPy's
``curve_fit`` reading) is

    cov = s^2 (J'J)^+,  s^2 = SSR / (n - k)

over the k parameters the data determine, where J is the Jacobian of the residuals, n the
number of residuals and ^+ the pseudo-inverse. A parameter is *not* determined by the data,
and gets no standard error (NaN, ``None`` in JSON), when

* it is held by a bound: within :data:`ON_BOUND_REL` of its bounds' span from a bound (the
  constraint holds it there, not the data; including it would distort the others), the span
  measured in the coordinate the fit searches (the logarithm for a range over two decades,
  :func:`log_sampled`), or
* the residuals do not move with it (its column of J is zero: a term switched off there), or
* there are no degrees of freedom left (n <= k).

Information criteria for least squares with Gaussian errors of unknown variance (as lmfit
reports them; Burnham & Anderson 2002, eq. 2.13):

    AIC = n ln(SSR / n) + 2 k,   BIC = n ln(SSR / n) + k ln n

with k the number of free parameters (those on a bound included: they were free to move).
Lower is better; differences of a few units matter, the absolute value does not.

>>> import numpy as np
>>> J = np.array([[1.0, 0.0], [1.0, 1.0], [1.0, 2.0]])
>>> u = from_jacobian(J, z=np.array([0.5, 0.5]), lower=np.zeros(2), upper=np.ones(2), ssr=3.0, names=["a", "b"])
>>> [round(float(v), 4) for v in u.stderr]
[1.5811, 1.2247]
>>> round(u.aic, 3), round(u.bic, 3)
(4.0, 2.197)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

import numpy as np

#: A parameter within this share of its bounds' span from a bound is held by the bound.
ON_BOUND_REL = 1e-4
#: Pairs correlated above this (in absolute value) get a warning: the data pin a combination.
CORRELATION_WARN = 0.95


#: A parameter whose bounds span at least this ratio (two decades) is sampled evenly in its
#: logarithm by the global search's trial points, and judged there when it nears a bound: a coefficient in [0.001, 1] kW/(m2 K) or a rate
#: factor A in [1e5, 1e10] is as likely a decade from its floor as near its ceiling, while evenly in
#: the value 99 % of the trial points would lie above a tenth of the ceiling.
LOG_SAMPLED_SPAN = 100.0


def log_sampled(lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Which parameters the trial points sample in their logarithm (:data:`LOG_SAMPLED_SPAN`).

    >>> log_sampled(np.array([0.001, 0.05, 0.0, 5000.0]), np.array([1.0, 0.95, 0.1, 13000.0])).tolist()
    [True, False, False, False]
    """
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    return (lower > 0) & (upper >= LOG_SAMPLED_SPAN * lower)


def sampling_coordinate(z, logs: np.ndarray) -> np.ndarray:
    """Values as the trial points spread them: the logarithm where ``logs``, else the value."""
    z = np.asarray(z, dtype=float)
    return np.where(logs, np.log(np.where(logs, z, 1.0)), z)


def at_bounds(z, lower, upper) -> tuple[np.ndarray, np.ndarray]:
    """(at_lower, at_upper): where ``z`` is held by its lower or upper bound: within
    :data:`ON_BOUND_REL` of the bounds' span, both measured in the :func:`sampling_coordinate`.

    In the value, a rate factor A in [1e5, 1e10] would be "on its floor" anywhere below 1.1e6, eleven
    times the floor; in its logarithm the margin is 0.12 % of the floor, as it is 0.01 % of the span
    for a range the fit searches in the value.

    Works elementwise on any shape; a fixed component (lower == upper) counts as held by both.

    >>> lo, hi = np.array([1e5, 0.05]), np.array([1e10, 0.95])
    >>> [a.tolist() for a in at_bounds(np.array([1e6, 0.0502]), lo, hi)]
    [[False, False], [False, False]]
    >>> [a.tolist() for a in at_bounds(np.array([1.0001e5, 0.95]), lo, hi)]
    [[True, False], [False, True]]
    """
    z, lower, upper = (np.asarray(a, dtype=float) for a in (z, lower, upper))
    logs = log_sampled(lower, upper)
    c_lo, c_hi = sampling_coordinate(lower, logs), sampling_coordinate(upper, logs)
    c = sampling_coordinate(np.clip(z, lower, upper), logs)
    tol = ON_BOUND_REL * (c_hi - c_lo)
    return c - c_lo <= tol, c_hi - c <= tol


def scaled_pinv(a: np.ndarray) -> np.ndarray:
    """The pseudo-inverse of a symmetric positive semi-definite matrix ``a`` (a normal matrix J'J),
    taken in units where each parameter's column of J has length 1: a^+ = D (D a D)^+ D with
    D = diag(a)^-1/2 (1 where the diagonal is 0).

    Equal to ``np.linalg.pinv(a)`` when ``a`` is invertible, but independent of the parameters'
    units: a plain pseudo-inverse cuts singular values below 1e-15 of the largest, so a parameter
    whose magnitude is 1e8 (the reaction's pre-exponential factor A beside a flow in kg/s) loses
    its direction and gets a variance of 0 instead of its own.

    >>> a = np.diag([1e12, 1e-12])
    >>> scaled_pinv(a).diagonal().tolist()
    [1e-12, 1000000000000.0]
    >>> np.linalg.pinv(a).diagonal().tolist()
    [1e-12, 0.0]
    """
    d = np.sqrt(np.abs(np.diag(a)))
    d = np.where(d > 0.0, 1.0 / np.where(d > 0.0, d, 1.0), 1.0)
    return np.linalg.pinv(a * np.outer(d, d)) * np.outer(d, d)


def covariance(jtj: np.ndarray, ssr: float, n_residuals: int, determined: np.ndarray) -> np.ndarray:
    """cov = s^2 (J'J)^+ over the ``determined`` parameters, s^2 = SSR / (n - k); NaN rows and
    columns elsewhere (and everywhere when n <= k). The pseudo-inverse is :func:`scaled_pinv`."""
    k_all = jtj.shape[0]
    cov = np.full((k_all, k_all), np.nan)
    idx = np.flatnonzero(determined)
    dof = int(n_residuals) - idx.size
    if idx.size == 0 or dof <= 0 or not np.all(np.isfinite(jtj[np.ix_(idx, idx)])):
        return cov
    cov[np.ix_(idx, idx)] = scaled_pinv(jtj[np.ix_(idx, idx)]) * (float(ssr) / dof)
    return cov


def standard_errors(cov: np.ndarray) -> np.ndarray:
    """sqrt(diag(cov)); NaN where the variance is not determined or negative."""
    d = np.diag(cov)
    with np.errstate(invalid="ignore"):
        return np.where(d >= 0.0, np.sqrt(np.where(d >= 0.0, d, 0.0)), np.nan)


def unpinned(stderr, lower, upper) -> np.ndarray:
    """Where a standard error is wider than its parameter's bounds' span (:attr:`Uncertainty.unpinned`).

    >>> unpinned(np.array([0.1, 4e57, np.nan]), np.zeros(3), np.full(3, 0.5)).tolist()
    [False, True, False]
    """
    se, lo, hi = (np.asarray(a, dtype=float) for a in (stderr, lower, upper))
    with np.errstate(invalid="ignore"):
        return np.isfinite(se) & np.isfinite(hi - lo) & (se > hi - lo)


def information_criteria(ssr: float, n_residuals: int, k_free: int) -> tuple[float, float]:
    """(AIC, BIC) of a least-squares fit (module docstring); NaN when SSR or n is 0."""
    n = int(n_residuals)
    if n <= 0 or not ssr > 0.0:
        return math.nan, math.nan
    base = n * math.log(ssr / n)
    return base + 2.0 * k_free, base + k_free * math.log(n)


@dataclass
class Uncertainty:
    """The uncertainty of one fit (see the module docstring for each rule).

    names : parameter labels; values : their fitted values; lower, upper : their bounds;
    stderr : standard errors (NaN where not determined); covariance, correlation : (k, k);
    at_lower, at_upper, flat : why a parameter has no standard error;
    ssr : summed (weighted) squared residual; n_residuals : n.
    """

    names: list[str]
    values: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    stderr: np.ndarray
    covariance: np.ndarray
    correlation: np.ndarray
    at_lower: np.ndarray
    at_upper: np.ndarray
    flat: np.ndarray
    ssr: float
    n_residuals: int

    @property
    def determined(self) -> np.ndarray:
        """Where the data determine the parameter: neither held by a bound nor flat."""
        return ~(self.at_lower | self.at_upper | self.flat)

    @property
    def k_free(self) -> int:
        return len(self.names)

    @property
    def aic(self) -> float:
        return information_criteria(self.ssr, self.n_residuals, self.k_free)[0]

    @property
    def bic(self) -> float:
        return information_criteria(self.ssr, self.n_residuals, self.k_free)[1]

    @property
    def on_bound(self) -> np.ndarray:
        return self.at_lower | self.at_upper

    @property
    def unpinned(self) -> np.ndarray:
        """Determined by the rules above, yet with a standard error wider than its bounds' span and no
        strong correlation that would explain it: the residuals barely move with it there (a term all but
        switched off), so the linearised interval covers the whole range many times over and says only
        that the data leave the value open. (One of a correlated pair is the pair's warning instead: the
        data pin their combination.)"""
        c = np.where(np.eye(self.k_free, dtype=bool), 0.0, np.nan_to_num(self.correlation))
        paired = np.any(np.abs(c) > CORRELATION_WARN, axis=1)
        return unpinned(self.stderr, self.lower, self.upper) & ~paired

    def warnings(self) -> list[str]:
        """Plain-words warnings: parameters on a bound, without effect, or strongly correlated; the
        parameters on a bound in one line, the correlated pairs in another."""
        out = []
        held = []
        for k, lab in enumerate(self.names):
            if self.at_lower[k] or self.at_upper[k]:
                side, bound = ("lower", self.lower[k]) if self.at_lower[k] else ("upper", self.upper[k])
                held.append((lab, side, bound))
            elif self.flat[k]:
                out.append(
                    f"{lab} = {self.values[k]:.6g} has no effect on the fit there (its term is off or saturated): the "
                    "data do not determine it; no standard error (try more starts or another start value)"
                )
            elif self.unpinned[k]:
                out.append(
                    f"{lab} = {self.values[k]:.6g} is not determined by these data: the fit barely moves with it "
                    f"there (its standard error, {self.stderr[k]:.2g}, is wider than its whole range, "
                    f"{self.lower[k]:g} to {self.upper[k]:g}), so its value says little; hold it at a value, or add "
                    "logs that move it"
                )
        why = "the optimum may lie outside; no standard error (held by the bound, not the data)"
        if len(held) == 1:
            lab, side, bound = held[0]
            out.insert(0, f"{lab} is on its {side} bound {bound:g}: {why}")
        elif held:
            listed = ", ".join(f"{lab} (its {side} bound {bound:g})" for lab, side, bound in held)
            out.insert(0, f"{len(held)} values are on a bound: {listed}; for each, {why}")
        c = self.correlation
        pairs = [
            (f"{self.names[a]} and {self.names[b]}", f"{c[a, b]:+.3f}")
            for a in range(self.k_free)
            for b in range(a + 1, self.k_free)
            if np.isfinite(c[a, b]) and abs(c[a, b]) > CORRELATION_WARN
        ]
        if len(pairs) == 1:
            ((both, r),) = pairs
            out.append(f"{both} are correlated ({r}): the data pin down a combination of them, not each")
        elif pairs:
            listed = ", ".join(f"{both} ({r})" for both, r in pairs)
            out.append(
                f"{len(pairs)} pairs are correlated: {listed}; the data pin down a combination of each pair, not each"
            )
        return out

    def to_dict(self) -> dict:
        """JSON-safe: standard errors, correlations (null where not determined), AIC, BIC."""

        def num(v):
            return float(v) if np.isfinite(v) else None

        return {
            "stderr": {lab: num(v) for lab, v in zip(self.names, self.stderr)},
            "correlation": {
                "names": list(self.names),
                "matrix": [
                    [None if not np.isfinite(c) else float(round(c, 6)) for c in row] for row in self.correlation
                ],
                "note": "over parameters not on a bound; null for those on a bound",
            },
            "covariance": [[num(c) for c in row] for row in self.covariance],
            "on_bound": [lab for lab, b in zip(self.names, self.on_bound) if b],
            "AIC": num(self.aic),
            "BIC": num(self.bic),
            "k_free": self.k_free,
            "n_residuals": int(self.n_residuals),
        }


def from_normal(jtj, z, lower, upper, ssr: float, n_residuals: int, names) -> Uncertainty:
    """The :class:`Uncertainty` of a fit from its normal matrix J'J at the optimum ``z``."""
    jtj = np.asarray(jtj, dtype=float)
    z, lower, upper = (np.asarray(a, dtype=float) for a in (z, lower, upper))
    at_lo, at_hi = at_bounds(z, lower, upper)
    flat = ~(np.abs(np.diag(jtj)) > 0.0)  # a zero column of J: the residuals do not move with it
    cov = covariance(jtj, ssr, n_residuals, ~(at_lo | at_hi | flat))
    se = standard_errors(cov)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    return Uncertainty(list(names), z, lower, upper, se, cov, corr, at_lo, at_hi, flat, float(ssr), int(n_residuals))


#: Evaluations of the residuals each held-out refit may use, and its tolerances (SciPy's ftol, xtol,
#: gtol; :func:`held_out_residuals`). A held-out error is wanted to a tenth of a degree, not the fit's
#: own precision: at 1e-6 the Bullet's nine held-out logs' RMS errors agree with converged refits to
#: 0.01 degC.
REFIT_MAX_NFEV = 60
REFIT_TOL = 1e-6
#: Gauss-Newton steps a held-out refit may take before SciPy's trust region redoes it
#: (:func:`_newton_refit`), and the least share of a step's predicted fall in cost that its
#: simulated fall must reach for the step to stand (SciPy's trust region accepts a step at the
#: same ratio and widens its region above it).
REFIT_NEWTON_STEPS = 6
REFIT_NEWTON_RATIO = 0.25


def held_out_residuals(
    J, r, groups, determined, z=None, lower=None, upper=None, residuals_many=None, jacobian=None, by_group=False
) -> np.ndarray:
    """Each residual as it would be had its group (a batch) been left out of the fit: the
    leave-one-group-out (cross-validated) residuals, refitted without each group when the model is
    given, else linearised.

    For a least-squares fit with residuals r (n,) and Jacobian J (n, k) at its optimum, leaving
    group i out moves the parameters by one Gauss-Newton step from the full fit,
    dz = (A - A_i)^+ J_i' r_i with A = J'J and A_i = J_i'J_i over the ``determined`` parameters
    (the full fit's stationarity, sum_j J_j'r_j = 0, gives the right-hand side), so the group's
    residuals become

        r_i^(-i) = r_i + J_i (A - A_i)^+ J_i' r_i      (= (I - H_ii)^-1 r_i, H = J A^-1 J')

    exact for a model linear in its parameters (the grouped PRESS residual; Belsley, Kuh & Welsch
    1980 for one residual). Parameters a bound holds stay held; one only group i determines keeps
    its value (a zero row of A - A_i). ``groups`` (n,) labels each residual's group.

    The step is one of a linearisation. Where the other groups barely determine a parameter it runs
    far past where that holds (three Skywalker logs with the drum-start share free: a step of 354 in
    a share bounded to [0.3, 1], a band 329 degC wide), and a group far from the others (another
    batch size, another drum) is predicted through the model's curvature, which one step does not
    follow. Given the model, at the fit's optimum ``z`` within ``lower``/``upper``
    (``residuals_many``: (m, k) parameter vectors -> (m, n) residuals; ``jacobian``: z -> (n, k)),
    the fit is redone without each group instead, from ``z``, within the bounds, over the determined
    parameters (SciPy's ``least_squares``, trust-region reflective with the exact Jacobian, at most
    :data:`REFIT_MAX_NFEV` evaluations), and the group's residuals are the model's at that refit:
    the leave-one-out the formula stands in for. A local refit, not a new global search: it finds
    the optimum nearest the full fit's, as a fit that lost one roast would. The refit first takes
    Gauss-Newton steps from ``z``, the first of them the linearised step above, each checked by
    simulating where it lands (:func:`_newton_refit`); where one is not borne out (it leaves the
    bounds, or the cost falls by less than :data:`REFIT_NEWTON_RATIO` of what it predicted) the
    refit is SciPy's from ``z`` instead. Where SciPy refuses the
    refit (values whose products overflow), the group keeps the linearised step. With ``by_group``
    the two callables take ``groups=`` (the labels whose rows are wanted; the other rows may hold
    anything), so a refit simulates the groups it fits and, at its end, the one it left out.

    >>> J = np.array([[1.0], [1.0], [1.0], [1.0]])  # a mean fitted to two groups of two
    >>> r = np.array([2.0, 2.0, -2.0, -2.0])
    >>> held_out_residuals(J, r, np.array([0, 0, 1, 1]), np.array([True])).tolist()
    [4.0, 4.0, -4.0, -4.0]

    The same mean bounded to [0, 2] (fitted at z = 1): left out, either group would move the mean by
    2, out of its bounds; refitted, the mean stops on its bound, 1 away:

    >>> model = lambda Z: (Z[:, :1] - 1.0) + r
    >>> held_out_residuals(J, r, np.array([0, 0, 1, 1]), np.array([True]), np.array([1.0]), [0.0], [2.0],
    ...                    model, lambda z: J).round(6).tolist()
    [3.0, 3.0, -3.0, -3.0]
    """
    J = np.asarray(J, dtype=float)
    det = np.asarray(determined, dtype=bool)
    Jd = J[:, det]
    r = np.asarray(r, dtype=float)
    groups = np.asarray(groups)
    out = r.copy()
    if Jd.shape[1] == 0:
        return out
    labels = np.unique(groups)
    rows = {g: groups == g for g in labels}
    A = Jd.T @ Jd

    def linearised(g):  # the group's residuals after the one Gauss-Newton step of the formula above
        Ji = Jd[rows[g]]
        return r[rows[g]] + Ji @ (scaled_pinv(A - Ji.T @ Ji) @ (Ji.T @ r[rows[g]]))

    if residuals_many is None:
        for g in labels:
            out[rows[g]] = linearised(g)
        return out
    z = np.asarray(z, dtype=float)
    lower = np.full(z.shape, -np.inf) if lower is None else np.asarray(lower, dtype=float)
    upper = np.full(z.shape, np.inf) if upper is None else np.asarray(upper, dtype=float)
    for g in labels:
        try:
            if by_group:
                others = labels[labels != g]
                fitted = (partial(residuals_many, groups=others), partial(jacobian, groups=others))
                left_out = partial(residuals_many, groups=np.array([g]))
            else:
                fitted, left_out = (residuals_many, jacobian), None
            out[rows[g]] = _refit_without(~rows[g], z, det, lower, upper, *fitted, J, r, left_out)
        except ValueError:  # SciPy refuses values where the products overflow: the step stands in
            out[rows[g]] = linearised(g)  # (the refit's own first step is this step: not computed twice)
    return out


class _Converged(Exception):
    """Raised by a refit's Jacobian at the point where SciPy's ``ftol`` test has just ended the refit."""


def _refit_without(held_in, z, det, lower, upper, residuals_many, jacobian, J0, r0, left_out=None) -> np.ndarray:
    """The left-out residuals (the rows not ``held_in``) at the end of the fit redone on the
    ``held_in`` residuals alone, from ``z`` (where the Jacobian is ``J0`` and the residuals ``r0``),
    over the ``det`` parameters within the bounds (:func:`held_out_residuals`); from ``left_out``
    where ``residuals_many`` leaves them out (None: ``residuals_many`` gives every row).

    Gauss-Newton's steps first (:func:`_newton_refit`, a solver of its own rather than the
    program optimiser's damped one in :mod:`roastlab.fit.program`: a refit wants a step that
    fails, to hand it to SciPy, not one damped until it passes); where they are not borne out,
    SciPy's trust region from ``z``, as follows.

    SciPy asks for the Jacobian at every point it accepts, the last one too, after its ``ftol`` test
    (the cost fell by less than :data:`REFIT_TOL` of itself) has ended the refit there. That last
    Jacobian is not used, so the refit applies the same test when a Jacobian is asked for and stops
    at that point instead: where SciPy's test ended the refit, the same end with one sensitivity run
    fewer (SciPy also asks that the step's reduction was more than a quarter of the predicted one; a
    refit that meets the test without it stops here, one step before SciPy would have)."""
    from scipy.optimize import least_squares

    def full(x):
        zz = z.copy()
        zz[det] = x
        return zz

    seen = {}  # every residual vector simulated, by its parameters: the answer is one of them

    def fun(x):
        key = x.tobytes()
        if key not in seen:
            seen[key] = residuals_many(full(x)[None, :])[0]
        return seen[key][held_in]

    lo, hi = lower[det], upper[det]
    x0 = np.clip(z[det], lo, hi)
    if np.array_equal(x0, z[det]):
        seen[x0.tobytes()] = np.asarray(r0, dtype=float)
        with np.errstate(over="ignore", invalid="ignore"):  # a step into overflow fails its check
            end = _newton_refit(fun, lambda x: jacobian(full(x)), x0, J0, held_in, det, lo, hi)
        if end is not None:
            return _left_out_at(end, full, fun, seen, held_in, left_out)
    accepted = []  # the cost 0.5 |r|^2 at each point SciPy accepted

    def jac(x):
        r = fun(x)
        cost = 0.5 * float(r @ r)
        if accepted and accepted[-1] - cost < REFIT_TOL * accepted[-1]:
            raise _Converged(x.copy())
        accepted.append(cost)
        J = J0 if np.array_equal(x, x0) else jacobian(full(x))
        return np.asarray(J, dtype=float)[held_in][:, det]

    # far out along a parameter spanning decades (the reaction's A) SciPy's products overflow, as in
    # the fit's own polish (roastlab.fit.identify._polish): the step is rejected, or SciPy raises
    # ValueError and held_out_residuals keeps the linearised step for that group
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            end = least_squares(
                fun,
                x0,
                jac=jac,
                bounds=(lo, hi),
                method="trf",
                x_scale="jac",
                ftol=REFIT_TOL,
                xtol=REFIT_TOL,
                gtol=REFIT_TOL,
                max_nfev=REFIT_MAX_NFEV,
            ).x
    except _Converged as stop:
        end = stop.args[0]
    return _left_out_at(end, full, fun, seen, held_in, left_out)


def _left_out_at(end, full, fun, seen, held_in, left_out) -> np.ndarray:
    """The left-out rows at a refit's ``end``: from ``left_out`` (the rows it fitted are not
    simulated again), or, when ``left_out`` is None, from the simulation of every row (``seen``)."""
    if left_out is not None:
        return left_out(full(end)[None, :])[0][~held_in]
    fun(end)
    return seen[end.tobytes()][~held_in]


def _newton_refit(fun, jacobian, x0, J0, held_in, det, lo, hi) -> np.ndarray | None:
    """The end of Gauss-Newton's steps on the ``held_in`` residuals from ``x0`` (the full fit's
    optimum over the ``det`` parameters, where their Jacobian is ``J0``), or None where a step is
    not borne out. ``fun``: x -> the held-in residuals; ``jacobian``: x -> every row's Jacobian.

    Each step solves the linearised problem at the current point, dx = -(J'J)^+ J'r over the held-in
    rows (:func:`scaled_pinv`; from ``x0`` the linearised leave-one-out step of
    :func:`held_out_residuals`), and predicts the cost 0.5 |r|^2 to fall by 0.5 |J dx|^2. A step
    stands where it stays within [``lo``, ``hi``] and the simulated cost falls by at least
    :data:`REFIT_NEWTON_RATIO` of that; else None, and the caller refits with SciPy's trust
    region. The refit ends

    * one step past the current point, when its step predicts a fall of less than
      :data:`REFIT_TOL` of the cost (the point is stationary to that tolerance; where the steps
      contract slowly, as where the residuals are large, the point is still a step from the optimum,
      so the step is taken, unchecked, unless it leaves the bounds), or
    * after a step that leaves less than that to come: the steps contract at the rate
      theta = |J dx_k| / |J dx_(k-1)|, so what remains after step k is at most
      theta / (1 - theta) |J dx_k| (the stopping rule of a Newton iteration in an implicit ODE
      integrator: Hairer & Wanner, Solving ODEs II, 2nd ed., section IV.8), and no Jacobian is
      computed there.

    Near an optimum the data determine well, the steps contract fast (dataset-I: theta 0.02-0.2),
    so a refit takes one or two Jacobians where SciPy's takes two to four."""
    x, J = x0, np.asarray(J0, dtype=float)[held_in][:, det]
    r = fun(x)
    cost = 0.5 * float(r @ r)
    last = None  # |J dx| of the previous step
    for _ in range(REFIT_NEWTON_STEPS):
        if not np.all(np.isfinite(J)):  # a sensitivity overflowed: SciPy's trust region steps back
            return None
        A = J.T @ J
        dx = -(scaled_pinv(A) @ (J.T @ r))
        fall = 0.5 * float(dx @ A @ dx)  # the cost's fall the linearisation predicts
        if not (np.all(np.isfinite(dx)) and math.isfinite(fall)):
            return None
        xn = x + dx
        outside = np.any(xn < lo) or np.any(xn > hi)
        if fall <= REFIT_TOL * cost:  # stationary to the tolerance: its last step, too small to check, is taken
            return x if outside else xn
        if outside:
            return None
        rn = fun(xn)
        cost_n = 0.5 * float(rn @ rn)
        if not cost - cost_n >= REFIT_NEWTON_RATIO * fall:  # NaN fails too
            return None
        step = math.sqrt(2.0 * fall)
        theta = step / last if last else math.inf
        x, r, cost, last = xn, rn, cost_n, step
        if theta < 1.0 and 0.5 * (theta / (1.0 - theta) * step) ** 2 <= REFIT_TOL * cost:
            return x
        J = np.asarray(jacobian(x), dtype=float)[held_in][:, det]
    return None


def from_jacobian(J, z, lower, upper, ssr: float, names) -> Uncertainty:
    """The :class:`Uncertainty` of a fit from the Jacobian ``J`` (n, k) of its residuals at ``z``."""
    J = np.asarray(J, dtype=float)
    return from_normal(J.T @ J, z, lower, upper, ssr, J.shape[0], names)
