"""Identification of theta = (hgm, hbm, Pbm) on several batches (paper eqs. 18-19).

theta* = argmin sum_j SSR_j(theta) within bounds. Two global strategies:

* ``"global"`` (default), in the spirit of MATLAB's GlobalSearch that the paper used:
  score many scattered trial points (a scrambled Sobol set, seeded; evenly in each parameter,
  or in its logarithm where its bounds span two decades, :data:`LOG_SAMPLED_SPAN`; the outer
  tenth of each range on its bound, :data:`ON_BOUND_SHARE`) in one parallel population call,
  then polish the paper's start theta0 and the best distinct trial points with a bounded
  trust-region least-squares solver (SciPy ``least_squares``, ``trf``). As in GlobalSearch, a
  start inside the basin of an optimum already found is not polished again
  (:data:`BASIN_FACTOR`), and the trial points are only ranked, so they are scored with the
  integrator's tolerances loosened (:data:`SCREENING_TOL_SCALE`);
* ``"de"``: SciPy's differential evolution, evaluating each generation as one population
  call, then the same least-squares polish.

Any component can be fixed or re-bounded, and each batch's initial metal temperature can be
estimated as a nuisance parameter. Uncertainty (standard errors, covariance, correlations,
AIC and BIC, and which parameters a bound holds) follows the one rule of
:mod:`roastlab.fit.uncertainty`, from the Jacobian at the optimum.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..model.limits import check_value
from ..model.parameters import (
    DEFAULT_WEIGHTS,
    FREE_NAMES,
    MODEL_OF_OUTPUT,
    N_STARTS,
    OUTPUTS,
    REGISTRY,
    RESIDUAL_REFERENCE,
    THETA_NAMES,
    THETA_START,
    FreeParameter,
    Theta,
)
from ..model.quantities import default
from ..sim.population import PackedBatches, output_sensitivities, predict_outputs
from . import uncertainty
from .threads import one_blas_thread
from .uncertainty import (  # noqa: F401  (CORRELATION_WARN, LOG_SAMPLED_SPAN: re-exported)
    CORRELATION_WARN,
    LOG_SAMPLED_SPAN,
    Uncertainty,
    log_sampled,
    sampling_coordinate,
)

#: Residual given to a sample whose simulation failed (NaN): a very bad fit, not a crash [degC].
FAILED_RESIDUAL_C = 1e3
#: Central-difference step of the reference Jacobian (:meth:`Objective.jacobian_fd`), in units of each parameter's bound span: large
#: against the adaptive integrator's ~1e-6 relative noise (a smaller step let noise steer the
#: search along flat valleys), small against the curvature of the residuals.
FD_STEP = 1e-3


@dataclass
class IdentificationResult:
    """Outcome of :func:`identify`.

    values : identified value of every free parameter (per-batch ones as lists);
    fixed : values held fixed; SSR : summed squared residual [degC^2] (eq. 19);
    stderr, correlation : from the Jacobian at the optimum; warnings : human-readable;
    n_residuals, nfev, wall_s, method, seed : diagnostics; starts : each start chosen, in order, with
    its polish's end and SSR, or why it was skipped, and ``joined``: the index of the start whose
    optimum its polish reached on the way and stopped at (:data:`JOIN_TOL`);
    outputs : per fitted output {"weight", "n", "SSR" (unweighted, degC^2)};
    held_out_Ta : (nb, nmax) model - measured probe [degC] of each batch as predicted had it been
    left out of the fit (refitted without it, :func:`roastlab.fit.uncertainty.held_out_residuals`), NaN where no
    probe sample was fitted; None when Ta has no weight.
    """

    values: dict
    fixed: dict
    SSR: float
    stderr: dict
    correlation: dict
    warnings: list[str]
    n_residuals: int
    nfev: int
    wall_s: float
    method: str
    seed: int
    starts: list[dict] = field(default_factory=list)
    bounds: dict = field(default_factory=dict)
    batches: list[str] = field(default_factory=list)
    outputs: dict = field(default_factory=dict)
    uncertainty: Uncertainty | None = None
    held_out_Ta: np.ndarray | None = None

    @property
    def aic(self) -> float:
        """Akaike's information criterion of the fit (:mod:`roastlab.fit.uncertainty`)."""
        return self.uncertainty.aic if self.uncertainty is not None else float("nan")

    @property
    def bic(self) -> float:
        """The Bayesian information criterion of the fit (:mod:`roastlab.fit.uncertainty`)."""
        return self.uncertainty.bic if self.uncertainty is not None else float("nan")

    @property
    def covariance(self) -> np.ndarray | None:
        """(k, k) covariance of the free parameters, in :attr:`correlation` ``names`` order (NaN
        where not determined)."""
        return None if self.uncertainty is None else self.uncertainty.covariance

    @property
    def theta(self):
        allv = {**self.fixed, **self.values}
        return Theta(*(float(allv[k]) for k in THETA_NAMES))

    def to_json_dict(self) -> dict:
        allv = {**self.fixed, **self.values}
        out = {k: allv[k] for k in THETA_NAMES}
        out.update({k: v for k, v in allv.items() if k not in THETA_NAMES})
        out.update(
            {
                "SSR": self.SSR,
                "stderr": self.stderr,
                "correlation": self.correlation,
                "fixed": sorted(self.fixed),
                "bounds": self.bounds,
                "warnings": self.warnings,
                "n_residuals": self.n_residuals,
                "evaluations": self.nfev,
                "wall_s": round(self.wall_s, 3),
                "method": self.method,
                "seed": self.seed,
                "batches": self.batches,
                "outputs": self.outputs,
            }
        )
        if self.uncertainty is not None:
            u = self.uncertainty.to_dict()
            out.update({k: u[k] for k in ("covariance", "AIC", "BIC", "k_free")})
        return out


#: Why a fit weighting Tb2 cannot run on batches that lack the second reading.
NO_SECOND_READING = (
    "the Tb2 output has a weight but no batch has a second bean reading: read the logs with a map that has a "
    "[Tb2] column, or drop the weight"
)


#: Why a fit weighting ET cannot run on batches that lack it.
NO_ET_READING = (
    "the ET output has a weight but no batch has an ET reading: read the logs with a map that keeps ET "
    "(Artisan's ET channel, or a map's [ET] column), or drop the weight"
)


def check_weights(weights: dict | None) -> dict[str, float]:
    """The output weights with defaults filled in; unknown names or bad values are refused."""
    out = dict(DEFAULT_WEIGHTS)
    for name, w in (weights or {}).items():
        if name not in OUTPUTS:
            raise ParameterError(f"unknown output {name!r} to weight (allowed: {', '.join(OUTPUTS)})")
        try:
            w = float(w)
        except (TypeError, ValueError):
            raise ParameterError(f"the weight of {name} must be a number, got {w!r}") from None
        if not (np.isfinite(w) and w >= 0.0):
            raise ParameterError(f"the weight of {name} must be a finite number >= 0, got {w:g}")
        out[name] = w
    if not any(w > 0 for w in out.values()):
        raise ParameterError("every output weight is 0: nothing to fit")
    return out


def residual_weights(outputs: dict, names) -> dict[str, float]:
    """Each named output's weight from a fit's residuals: the probe's residual variance over the
    output's, ``(SSR_Ta / n_Ta) / (SSR_k / n_k)`` (``outputs`` as :attr:`IdentificationResult.outputs`,
    from a fit with the output at weight 1).

    Derivation: with each output's errors Gaussian and of its own variance s_k^2, the likelihood is
    largest where sum_k SSR_k / s_k^2 is least, and each s_k^2 is estimated by its output's mean squared
    residual (generalised least squares with per-response variances; Bates and Watts, *Nonlinear
    Regression Analysis*, 1988, ch. 4). Relative to the probe's, the weight of an output the model
    reads less closely (the drum's air through the well-mixed outlet of eq. 15e) falls, so its
    model-structure error does not pull the beans; one the model reads as closely counts alike.
    """
    ta = outputs.get(RESIDUAL_REFERENCE) or {}
    if not ta.get("n") or not ta.get("SSR"):
        raise ParameterError(
            f"a weight from the residuals is relative to the bean probe's ({RESIDUAL_REFERENCE}): fit it as well"
        )
    var_ta = ta["SSR"] / ta["n"]
    out = {}
    for name in names:
        o = outputs.get(name) or {}
        if not o.get("n"):
            raise ParameterError(f"no {name} sample was fitted: its weight cannot come from its residuals")
        out[name] = var_ta / max(o["SSR"] / o["n"], 1e-12 * var_ta)
    return out


class Objective:
    """Weighted residuals of the free parameters over packed batches, evaluated in populations.

    The residual vector stacks sqrt(w_Ta) (T^a - Ta) over the measured probe samples and, when
    ``weights["Tb2"] > 0``, sqrt(w_Tb2) (T^b - Tb2) over the samples of the second bean reading,
    so the summed SSR is the weighted sum of the outputs' SSRs (eq. 19 with one term per output).
    """

    def __init__(
        self, packed: PackedBatches, free: list[FreeParameter], fixed: dict[str, float], weights: dict | None = None
    ):
        self.packed = packed
        self.free = free
        self.fixed = fixed
        nb = packed.n_batches
        self.names = [f.name for f in free] + list(fixed)
        # column j of the flat vector z -> (parameter index, batch or -1 for all)
        self.layout = []
        for j, f in enumerate(free):
            if f.per_batch:
                self.layout += [(j, b) for b in range(nb)]
            else:
                self.layout.append((j, -1))
        self.lower = np.array([free[j].lower for j, _ in self.layout])
        self.upper = np.array([free[j].upper for j, _ in self.layout])
        self.start = np.array([free[j].start for j, _ in self.layout])
        self.weights = check_weights(weights)
        valid = packed.mask()
        measured = {"Ta": packed.TA, "Tb2": packed.TB2, "ET": packed.ET}
        self.masks = {k: valid & np.isfinite(measured[k]) & (self.weights[k] > 0) for k in OUTPUTS}
        if self.weights["Tb2"] > 0 and not self.masks["Tb2"].any():
            raise ParameterError(NO_SECOND_READING)
        if self.weights["ET"] > 0 and not self.masks["ET"].any():
            raise ParameterError(NO_ET_READING)
        self.with_tb = bool(self.masks["Tb2"].any())
        self.with_tgo = bool(self.masks["ET"].any())
        self.measured = np.concatenate([measured[k][self.masks[k]] for k in OUTPUTS])
        counts = {k: int(m.sum()) for k, m in self.masks.items()}
        self.sqrt_w = np.concatenate([np.full(counts[k], np.sqrt(self.weights[k])) for k in OUTPUTS])
        self.output_of_residual = np.repeat(np.arange(len(OUTPUTS)), [counts[k] for k in OUTPUTS])
        self.batch_of_residual = np.concatenate([np.nonzero(self.masks[k])[0] for k in OUTPUTS])
        self.nfev = 0

    @property
    def n_residuals(self) -> int:
        return int(self.measured.size)

    def _predicted(self, Z: np.ndarray, tol_scale: float = 1.0, batches=None) -> np.ndarray:
        """(m, n_residuals) model outputs at the measured samples, in the residuals' order (``batches``:
        the batches to simulate, None: all; the others' outputs are NaN)."""
        out = predict_outputs(
            self.packed, self.names, self.values_array(Z), self.with_tb, self.with_tgo, tol_scale, batches=batches
        )
        model = dict(zip(("Ta", "Tb", "Tgo"), out))
        return np.concatenate(
            [model[MODEL_OF_OUTPUT[k]][:, self.masks[k]] for k in OUTPUTS if self.masks[k].any()], axis=1
        )

    def output_ssr(self, r: np.ndarray) -> dict:
        """Per fitted output: its weight, sample count and unweighted SSR [degC^2], from the weighted
        residuals ``r`` (:meth:`residuals`)."""
        r = r / self.sqrt_w
        return {
            k: {
                "weight": self.weights[k],
                "n": int(n),
                "SSR": float(r[self.output_of_residual == j] @ r[self.output_of_residual == j]),
            }
            for j, k in enumerate(OUTPUTS)
            if (n := self.masks[k].sum())
        }

    def values_array(self, Z: np.ndarray) -> np.ndarray:
        """(m, nz) flat vectors -> (m, nb, n_names) parameter values for the kernel."""
        m, nb = Z.shape[0], self.packed.n_batches
        V = np.empty((m, nb, len(self.names)))
        for k, (j, b) in enumerate(self.layout):
            if b < 0:
                V[:, :, j] = Z[:, k][:, None]
            else:
                V[:, b, j] = Z[:, k]
        for j, name in enumerate(self.fixed, start=len(self.free)):
            V[:, :, j] = self.fixed[name]
        return V

    def residuals_many(self, Z: np.ndarray, tol_scale: float = 1.0, groups=None) -> np.ndarray:
        """(m, n_residuals) weighted residuals (model - measured) for m parameter vectors (a
        sample whose simulation failed counts as a 1e3 degC error); ``tol_scale`` > 1 loosens the
        integrator's tolerances (:data:`SCREENING_TOL_SCALE`); ``groups``: the batches (indices, the
        labels of :attr:`batch_of_residual`) whose residuals are wanted, None: all (the others are NaN)."""
        Z = np.atleast_2d(Z)
        self.nfev += Z.shape[0]
        r = self._predicted(Z, tol_scale, groups) - self.measured[None, :]
        failed = ~np.isfinite(r)
        if groups is not None:
            wanted = np.zeros(self.packed.n_batches, dtype=bool)
            wanted[groups] = True
            failed &= wanted[self.batch_of_residual][None, :]
        r[failed] = FAILED_RESIDUAL_C
        return r * self.sqrt_w[None, :]

    def residuals(self, z: np.ndarray) -> np.ndarray:
        return self.residuals_many(z[None, :])[0]

    def held_out_ta(self, z: np.ndarray, r: np.ndarray, J: np.ndarray, determined: np.ndarray) -> np.ndarray | None:
        """(nb, nmax) probe error (model - measured) [degC] of each batch had it been left out of the
        fit, from the weighted residuals ``r`` and their Jacobian ``J`` at the optimum ``z``
        (:func:`uncertainty.held_out_residuals`, each batch a group, the fit redone without it from
        ``z``; every fitted output's residuals move the parameters); NaN where no probe sample was
        fitted, None when the probe has no weight."""
        if not self.masks["Ta"].any():
            return None
        model = (self.residuals_many, self.jacobian)  # each refit simulates the batches it fits (by_group)
        held = uncertainty.held_out_residuals(
            J, r, self.batch_of_residual, determined, z, self.lower, self.upper, *model, by_group=True
        )
        r = held / self.sqrt_w
        out = np.full(self.packed.TA.shape, np.nan)
        out[self.masks["Ta"]] = r[self.output_of_residual == OUTPUTS.index("Ta")]
        return out

    def failed_batches(self, z: np.ndarray) -> list[str]:
        """Names of the batches whose simulation at ``z`` is not finite (empty when all run)."""
        self.nfev += 1
        bad = ~np.isfinite(self._predicted(np.atleast_2d(z))[0])
        return [self.packed.names[b] for b in np.unique(self.batch_of_residual[bad])]

    def ssr_many(self, Z: np.ndarray, tol_scale: float = 1.0) -> np.ndarray:
        r = self.residuals_many(Z, tol_scale)
        return np.einsum("ij,ij->i", r, r)

    def jacobian(self, z: np.ndarray, groups=None) -> np.ndarray:
        """d residuals / d z, exact: the forward sensitivities of every batch in one population
        call (:func:`roastlab.sim.population.output_sensitivities`). A sample whose simulation
        failed gets a zero row (its residual is the constant :data:`FAILED_RESIDUAL_C`), as do the
        samples of the batches not in ``groups`` (as in :meth:`residuals_many`)."""
        self.nfev += 1
        V = self.values_array(z[None, :])[0]
        res = output_sensitivities(self.packed, self.names, V, self.layout, with_tgo=self.with_tgo, batches=groups)
        parts = [res[MODEL_OF_OUTPUT[k]][1][self.masks[k]] for k in OUTPUTS if self.masks[k].any()]
        J = np.concatenate(parts, axis=0) * self.sqrt_w[:, None]
        return np.where(np.isfinite(J), J, 0.0)

    def jacobian_fd(self, z: np.ndarray) -> np.ndarray:
        """Central differences, all 2 nz perturbed vectors in one population call (the reference
        for :meth:`jacobian`). The step is :data:`FD_STEP` of each parameter's range.
        """
        nz = len(z)
        step = FD_STEP * (self.upper - self.lower)
        Z = np.repeat(z[None, :], 2 * nz, axis=0)
        hi = np.minimum(z + step, self.upper)
        lo = np.maximum(z - step, self.lower)
        for k in range(nz):
            Z[2 * k, k] = hi[k]
            Z[2 * k + 1, k] = lo[k]
        r = self.residuals_many(Z)
        J = np.empty((r.shape[1], nz))
        for k in range(nz):
            J[:, k] = (r[2 * k] - r[2 * k + 1]) / (hi[k] - lo[k])
        return J


def build_free_parameters(
    fix: dict[str, float] | None = None,
    bounds: dict[str, tuple[float, float]] | None = None,
    estimate_tm0: bool = False,
    start: dict[str, float] | None = None,
    extra: list[FreeParameter] | None = None,
):
    """Free parameters and fixed values from the user's --fix / --bounds choices."""
    fix = dict(fix or {})
    bounds = dict(bounds or {})
    start = dict(start or {})
    for name in list(fix) + list(bounds):
        if name not in REGISTRY:
            raise ParameterError(f"unknown parameter {name!r} (allowed: {', '.join(FREE_NAMES)})")
    # a fixed value is a value the user gives: inside its plausible range (the quantity table)
    fix = {name: check_value(name, value, "fixed value") for name, value in fix.items()}
    free, fixed = [], {}
    theta0 = THETA_START.as_dict()
    for name in THETA_NAMES:
        if name in fix:
            fixed[name] = fix[name]
            continue
        lo, hi = bounds.get(name, REGISTRY[name].bounds)
        free.append(FreeParameter(name, lo, hi, start.get(name, theta0[name])))
    if estimate_tm0:
        lo, hi = bounds.get("Tm0_C", REGISTRY["Tm0_C"].bounds)
        free.append(FreeParameter("Tm0_C", lo, hi, start.get("Tm0_C", default("Tm0_C")), per_batch=True))
    for p in extra or []:
        free.append(p)
    for name, value in fix.items():
        if name not in THETA_NAMES:
            fixed[name] = float(value)
    if not free:
        raise ParameterError("every parameter is fixed: nothing to identify")
    return free, fixed


#: The share of each parameter's range, at either end, whose trial points are moved onto the bound:
#: the optima of this model often sit on a bound (the paper's hgm, the Skywalker's hbm and base flow
#: and the Bullet's hgm on their floors), where a scattered point would almost never land, so about
#: one coordinate in five of the trial points lies on a face of the box.
ON_BOUND_SHARE = 0.1


def on_bounds(unit: np.ndarray) -> np.ndarray:
    """Unit-cube trial points with each coordinate within :data:`ON_BOUND_SHARE` of 0 or 1 moved there.

    >>> on_bounds(np.array([[0.05, 0.5, 0.95]])).tolist()
    [[0.0, 0.5, 1.0]]
    """
    return np.where(unit < ON_BOUND_SHARE, 0.0, np.where(unit > 1.0 - ON_BOUND_SHARE, 1.0, unit))


def trial_points(unit: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Points of the unit cube (rows) as parameter values: evenly in the value, or in its logarithm
    for :func:`log_sampled` parameters (the inverse of :func:`trial_unit`); a coordinate of 0 or 1
    is the bound itself, never one rounded past it.

    >>> trial_points(np.array([[0.0, 0.5, 1.0]]), np.array([1e-3, 1e-3, 0.0]), np.array([1.0, 1.0, 2.0])).round(6).tolist()
    [[0.001, 0.031623, 2.0]]
    >>> trial_points(np.array([[0.0, 1.0]]), np.array([1e-4, 1e-4]), np.array([0.03, 0.03])).tolist()
    [[0.0001, 0.03]]
    """
    logs = log_sampled(lower, upper)
    lo, hi = sampling_coordinate(lower, logs), sampling_coordinate(upper, logs)
    c = lo + unit * (hi - lo)
    inside = np.clip(np.where(logs, np.exp(np.where(logs, c, 0.0)), c), lower, upper)
    return np.where(unit <= 0.0, lower, np.where(unit >= 1.0, upper, inside))


def trial_unit(z: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Parameter values (rows) as points of the unit cube of :func:`trial_points`.

    >>> trial_unit(np.array([[0.001, 0.031623, 2.0]]), np.array([1e-3, 1e-3, 0.0]), np.array([1.0, 1.0, 2.0])).round(4).tolist()
    [[0.0, 0.5, 1.0]]
    """
    logs = log_sampled(lower, upper)
    lo, hi = sampling_coordinate(lower, logs), sampling_coordinate(upper, logs)
    return (sampling_coordinate(z, logs) - lo) / (hi - lo)


#: A start closer to an optimum already found than this share of that optimum's basin radius is
#: not polished (MATLAB GlobalSearch's ``DistanceThresholdFactor``, 0.75). A basin's radius is the
#: longest distance a polish travelled to reach its optimum, both in units of the bounds' widths.
BASIN_FACTOR = 0.75
#: Trial points are only ranked, to choose where to polish: they are simulated with the
#: integrator's tolerances 100x looser (local error ~0.01 degC per step, against SSR differences
#: of many degC^2 between trial points; dataset-I's best eight keep their order). Polishes and
#: everything reported use the full accuracy.
SCREENING_TOL_SCALE = 100.0


class _Basins:
    """The optima found so far and their basin radii (:data:`BASIN_FACTOR`), in units of the
    bounds' widths; two polishes whose ends agree to 1e-6 of every width found the same optimum."""

    def __init__(self, lower: np.ndarray, width: np.ndarray):
        self.lower, self.width, self.found = lower, width, []  # found: [[optimum, radius], ...]

    def _unit(self, z) -> np.ndarray:
        return (np.asarray(z, dtype=float) - self.lower) / self.width

    def holds(self, start) -> bool:
        """True when ``start`` lies inside the basin of an optimum already found."""
        u = self._unit(start)
        return any(np.linalg.norm(u - c) < BASIN_FACTOR * r for c, r in self.found)

    def add(self, start, end) -> None:
        """A polish went from ``start`` to ``end``: a new optimum, or a wider basin of a known one."""
        u0, u = self._unit(start), self._unit(end)
        travelled = float(np.linalg.norm(u0 - u))
        same = next((b for b in self.found if np.max(np.abs(u - b[0])) <= 1e-6), None)
        if same is None:
            self.found.append([u, travelled])
        else:
            same[1] = max(same[1], travelled)


#: Why a start was given up: its least-squares polish met values (far out along a parameter that spans
#: several decades, such as the reaction's A) where the sensitivities overflow and SciPy refuses them.
POLISH_OVERFLOW = "its polish met values where the model's sensitivities overflow"


#: A later polish whose accepted iterate comes within this share of every bound's width of an optimum
#: already found, no lower than it, stops there: it is converging on that optimum (its iterates close
#: in on one by orders of magnitude per step at that distance), so its last steps would only find it
#: again. Its end is then that optimum, with the residuals and Jacobian stored with it.
JOIN_TOL = 1e-4


class _Joined(Exception):
    """Raised inside a polish that reached the optimum ``found[index]`` (:data:`JOIN_TOL`)."""

    def __init__(self, index: int):
        super().__init__(index)
        self.index = index


def _polish(obj: Objective, z0: np.ndarray, found=()):
    """A least-squares polish from ``z0``: (end, SSR, residuals, Jacobian at the end, joined), where
    ``joined`` is the index into ``found`` (optima already polished, each (end, SSR, residuals,
    Jacobian)) of the optimum the polish reached on its way (:data:`JOIN_TOL`), or None."""
    # imported where called: SciPy's optimize and stats cost every command ~1 s (tests/test_layout.py)
    from scipy.optimize import least_squares

    scale = obj.upper - obj.lower
    cost = {}  # SSR of each point SciPy evaluated, by its bytes: a Jacobian is asked for at an accepted point

    def residuals(z):
        r = obj.residuals(z)
        cost[z.tobytes()] = float(r @ r)
        return r

    def jacobian(z):
        ssr = cost.get(z.tobytes(), math.inf)
        for i, (end, ssr_found, _, _) in enumerate(found):
            if ssr >= ssr_found and np.max(np.abs(z - end) / scale) <= JOIN_TOL:
                raise _Joined(i)
        return obj.jacobian(z)

    # far out along a parameter spanning decades (A) SciPy's products overflow; the start is then
    # given up (identify catches the ValueError) or the step rejected, so no warning is printed. Its
    # trust-region solver divides by a zero derivative of the step's secular equation on a flat
    # direction (phi / phi_prime, scipy.optimize._lsq.common.solve_lsq_trust_region) and recovers
    # alike (a parameter held by the data to none of its range: exotherm freed on the Skywalker)
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            res = least_squares(
                residuals,
                z0,
                jac=jacobian,
                bounds=(obj.lower, obj.upper),
                method="trf",
                x_scale=scale,
                ftol=1e-12,
                xtol=1e-10,
                gtol=1e-10,
                max_nfev=200,
            )
    except _Joined as joined:
        return (*found[joined.index], joined.index)
    return res.x, float(res.fun @ res.fun), res.fun, res.jac, None


def identify(
    packed: PackedBatches,
    free: list[FreeParameter],
    fixed: dict[str, float] | None = None,
    method: str = "global",
    seed: int = 0,
    n_trial: int = 256,
    n_starts: int = N_STARTS,
    progress=None,
    weights: dict | None = None,
    held_out: bool = True,
) -> IdentificationResult:
    """Minimise the summed SSR (eq. 19) of the packed batches over the free parameters.

    Parameters
    ----------
    packed : batches with measured Ta, from :func:`roastlab.population.pack_batches`
    free, fixed : from :func:`build_free_parameters`
    method : ``"global"`` (scattered trial points + least-squares polish) or ``"de"``
    seed : makes the search deterministic
    n_trial, n_starts : trial points scored and starts chosen for a polish (``"global"``; a start
        inside the basin of an optimum already found is skipped, :data:`BASIN_FACTOR`); with one
        start, the start alone is polished and no trial point is simulated
    progress : callable ``progress(done, total, text)`` called after each polish, or None
    weights : {output: weight} over :data:`OUTPUTS` (default Ta 1, Tb2 0: the probe alone)
    held_out : compute ``held_out_Ta``, each batch's probe error had it been left out (one local
        refit per batch, about a third of a fit's time); False leaves it None

    The solver's SVDs run on one BLAS thread (:func:`roastlab.fit.threads.one_blas_thread`).
    """
    with one_blas_thread():
        return _identify(packed, free, fixed, method, seed, n_trial, n_starts, progress, weights, held_out)


def _identify(packed, free, fixed, method, seed, n_trial, n_starts, progress, weights, held_out):
    """:func:`identify`'s work."""
    # imported where called: SciPy's optimize and stats cost every command ~1 s (tests/test_layout.py)
    from scipy.optimize import differential_evolution
    from scipy.stats import qmc

    if method not in ("global", "de"):
        raise ParameterError(f"unknown method {method!r} (allowed: global, de)")
    fixed = dict(fixed or {})
    t0 = time.perf_counter()
    obj = Objective(packed, free, fixed, weights)
    if obj.n_residuals == 0:
        raise ParameterError("no measured samples to fit (no Ta, or every fitted output's weight is 0)")
    nz = len(obj.start)
    failed = obj.failed_batches(obj.start)
    if failed:
        raise ParameterError(
            f"the model cannot be simulated at the starting values for {len(failed)} batch(es) "
            f"({', '.join(failed[:3])}{', ...' if len(failed) > 3 else ''}): check the initial state, plant and "
            "inputs, or give other starting values in the fit spec"
        )
    rng = np.random.default_rng(seed)
    width = obj.upper - obj.lower
    starts_log = []
    start_unit = trial_unit(obj.start[None, :], obj.lower, obj.upper)
    if method == "global" and n_starts <= 1:  # the start alone: no trial point to rank
        candidates = [trial_points(start_unit, obj.lower, obj.upper)[0]]
    elif method == "global":
        sampler = qmc.Sobol(nz, scramble=True, seed=rng)
        unit = np.vstack([start_unit, on_bounds(sampler.random(n_trial))])
        trial = trial_points(unit, obj.lower, obj.upper)
        ssr = obj.ssr_many(trial, SCREENING_TOL_SCALE)
        order = np.argsort(ssr[1:]) + 1
        chosen = [0]
        for i in order:  # the best trial points that are not near-duplicates of a chosen one
            if len(chosen) >= n_starts:
                break
            if all(np.max(np.abs(unit[i] - unit[c])) > 0.05 for c in chosen):
                chosen.append(int(i))
        candidates = [trial[i] for i in chosen]
    else:

        def f(Z):  # differential_evolution's vectorized form: Z is (nz, S)
            return obj.ssr_many(Z.T)

        de = differential_evolution(
            f,
            list(zip(obj.lower, obj.upper)),
            seed=rng,
            vectorized=True,
            updating="deferred",
            polish=False,
            popsize=15,
            tol=1e-8,
            maxiter=300,
            init="sobol",
            x0=obj.start,
        )
        candidates = [de.x]
    best = None
    basins = _Basins(obj.lower, width)
    found, found_by = [], []  # the optima polished to their end, (end, SSR, residuals, Jacobian), and their starts
    for k, z0 in enumerate(candidates):
        if basins.holds(z0):
            starts_log.append({"start": [float(v) for v in z0], "skipped": "inside the basin of an optimum found"})
        else:
            try:
                z, ssr_k, r_k, J_k, joined = _polish(obj, np.asarray(z0, dtype=float), found)
            except ValueError as exc:  # SciPy refuses a non-finite matrix: the sensitivities overflowed
                if "infs or NaNs" not in str(exc):
                    raise
                starts_log.append({"start": [float(v) for v in z0], "skipped": POLISH_OVERFLOW})
                continue
            entry = {"start": [float(v) for v in z0], "end": [float(v) for v in z], "SSR": ssr_k}
            if joined is None:
                found.append((z, ssr_k, r_k, J_k))
                found_by.append(len(starts_log))
            else:  # reached the optimum this start's polish found, on its way, and stopped there
                entry["joined"] = found_by[joined]
            starts_log.append(entry)
            basins.add(z0, z)
            if best is None or ssr_k < best[1]:
                best = (z, ssr_k, r_k, J_k)
        if progress is not None and best is not None:
            progress(k + 1, len(candidates), f"SSR {best[1]:.6g}, {obj.nfev} simulations")
    if best is None:
        raise ParameterError(
            f"every start of the fit ({len(candidates)}) ran into values where the model overflows: "
            "narrow the bounds of the parameters that span several decades (e.g. A)"
        )
    z, ssr, r, J = best
    failed = obj.failed_batches(z)
    if failed:
        raise ParameterError(
            f"no fitted values found at which every batch can be simulated ({', '.join(failed[:3])} fail): "
            "the bounds admit only values for which the model diverges"
        )
    labels = [free[j].name if b < 0 else f"{free[j].name}[{packed.names[b]}]" for j, b in obj.layout]
    unc = uncertainty.from_jacobian(J, z, obj.lower, obj.upper, ssr, labels)
    values: dict = {}
    for k, (j, b) in enumerate(obj.layout):
        name = free[j].name
        if b < 0:
            values[name] = float(z[k])
        else:
            values.setdefault(name, [None] * packed.n_batches)[b] = float(z[k])
    unc_doc = unc.to_dict()
    return IdentificationResult(
        values=values,
        fixed=fixed,
        SSR=ssr,
        stderr=unc_doc["stderr"],
        correlation=unc_doc["correlation"],
        warnings=unc.warnings(),
        n_residuals=obj.n_residuals,
        nfev=obj.nfev,
        wall_s=time.perf_counter() - t0,
        method=method,
        seed=seed,
        starts=starts_log,
        bounds={lab: [float(obj.lower[k]), float(obj.upper[k])] for k, lab in enumerate(labels)},
        batches=list(packed.names),
        outputs=obj.output_ssr(r),
        uncertainty=unc,
        held_out_Ta=obj.held_out_ta(z, r, J, unc.determined) if held_out else None,
    )
