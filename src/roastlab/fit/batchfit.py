"""Per-batch identification, compiled: every batch gets its own theta, all fitted at once.

For many batches (a fleet of roasters, months of logs) the question is often not one theta
for all but the spread of theta across batches: drift, outliers, machine-to-machine
differences. :func:`identify_each` fits theta_b for every batch b independently, but runs
the batches in lock-step so that each iteration is one compiled, parallel population call:

1. score ``n_trial`` trial points (plus the paper's theta0) on every batch, spread over the bounds
   as :func:`roastlab.fit.identify.trial_points` spreads the global search's, and start each batch
   from its best one (a one-start GlobalSearch);
2. projected Levenberg-Marquardt per batch: central-difference Jacobians (6 runs), a damped
   Gauss-Newton step clipped to the bounds, accepted if the batch's SSR falls, damping
   adapted; it stops when a step gains less than ``gain_tol`` (1e-10) of the SSR or moves
   less than 1e-6 of the bounds' span. A parameter whose bounds span two decades or more is
   moved in its logarithm, as the global search samples it (:func:`roastlab.fit.uncertainty.log_sampled`).

Any parameter-vector entry or initial state (except X0, which also sets the dry mass) can be
free, not only theta: a fleet fit spec may free, say, Kt or Tm0_C per batch. Standard errors
come from the Jacobian at each batch's optimum by the one rule of :mod:`roastlab.fit.uncertainty`
(the same as :mod:`.identify`'s).

Each batch's whole fit is one compiled routine, and batches run in parallel over the cores
(numba ``prange``): the work per batch does not depend on how many batches there are, so the
wall time scales linearly. SciPy has no batched bounded least-squares solver; the step here is the textbook
Levenberg-Marquardt update (Nocedal & Wright, Numerical Optimization, section 10.3) and the
tests check it against ``scipy.optimize.least_squares`` batch by batch.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field

import numpy as np
from numba import parallel_chunksize, prange

from ..errors import InputError
from ..evaluate.metrics import fit_percent
from ..model.layout import S_TA
from ..model.limits import check_value
from ..model.parameters import REGISTRY, STATE0, THETA_NAMES, THETA_START
from ..model.rhs import P
from ..sim.cache import compiled
from ..sim.kernels import H0_S, N_OUT, integrate_into
from ..sim.population import PackedBatches, predict_ta
from . import uncertainty
from .identify import FD_STEP, on_bounds, trial_points, trial_unit
from .uncertainty import log_sampled, sampling_coordinate

#: Where a free value goes: a parameter-vector entry or an initial state.
KIND_PARAM, KIND_STATE = 0, 1


def free_slots(names) -> tuple[np.ndarray, np.ndarray]:
    """(kinds, slots) of registry ``names`` for the compiled fitter; InputError for a name it cannot move."""
    kinds, slots = [], []
    for name in names:
        q = REGISTRY.get(name)
        if q is None or name == "X0" or (q.slot not in P and q.slot not in STATE0):
            allowed = ", ".join(n for n in REGISTRY if n != "X0")
            raise InputError(f"{name!r} cannot be fitted per batch (allowed: {allowed})")
        if q.slot in P:
            kinds.append(KIND_PARAM)
            slots.append(P[q.slot])
        else:
            kinds.append(KIND_STATE)
            slots.append(STATE0[q.slot])
    return np.array(kinds, dtype=np.int64), np.array(slots, dtype=np.int64)


@dataclass
class FleetResult:
    """Per-batch values (nb, k) of the free ``params``, their standard errors (NaN on a bound),
    SSR (nb,), FIT (nb,), samples per batch, iterations and timing."""

    names: list[str]
    theta: np.ndarray
    SSR: np.ndarray
    FIT: np.ndarray
    max_iterations: int
    simulations: int
    wall_s: float
    params: list[str] = field(default_factory=lambda: list(THETA_NAMES))
    stderr: np.ndarray | None = None
    n_samples: np.ndarray | None = None
    MAE: np.ndarray | None = None
    sims: np.ndarray | None = None

    def summary(self, max_rows: int = 20) -> str:
        """A table of the per-batch values (up to ``max_rows`` batches) and their statistics."""
        lines = []
        if len(self.names) <= max_rows:
            lines.append(f"{'batch':<20}" + "".join(f"{p:>9}" for p in self.params) + f"{'SSR':>12}{'FIT %':>9}")
            for name, th, ssr, fit in zip(self.names, self.theta, self.SSR, self.FIT):
                lines.append(f"{name[:20]:<20}" + "".join(f"{v:>9.4f}" for v in th) + f"{ssr:>12.3f}{fit:>9.2f}")
        stats = self.statistics()
        for name in self.params:
            v = stats[name]
            lines.append(f"{name}: mean {v['mean']:.4f}, std {v['std']:.4f}, range [{v['min']:.4f}, {v['max']:.4f}]")
        lines.append(f"FIT: mean {stats['FIT']['mean']:.2f} %, worst {stats['FIT']['min']:.2f} %")
        return "\n".join(lines)

    def statistics(self) -> dict:
        """Mean, standard deviation and range of each fitted value over the batches; mean and worst FIT."""
        out = {}
        for j, name in enumerate(self.params):
            col = self.theta[:, j]
            out[name] = {
                "mean": float(col.mean()),
                "std": float(col.std(ddof=1)) if len(col) > 1 else 0.0,
                "min": float(col.min()),
                "max": float(col.max()),
            }
        out["FIT"] = {"mean": float(self.FIT.mean()), "min": float(self.FIT.min())}
        return out

    def to_json_dict(self) -> dict:
        return {
            "mode": "per-batch",
            "batches": [
                {"name": n, **{k: float(v) for k, v in zip(self.params, th)}, "SSR": float(s), "FIT": float(f)}
                for n, th, s, f in zip(self.names, self.theta, self.SSR, self.FIT)
            ],
            "summary": self.statistics(),
            "max_iterations": self.max_iterations,
            "simulations": self.simulations,
            "wall_s": round(self.wall_s, 3),
        }


@compiled(inline="always")
def _set_free(z, lo, span, logs, kinds, slots, p, x0):
    """Scaled z in [0, 1]^k -> the free values in their slots of p (model.rhs.PARAM_NAMES) or x0.

    ``lo + z span`` is the value, or its logarithm where ``logs`` (the search's sampling coordinate,
    :func:`roastlab.fit.identify.trial_points`: a parameter over decades is searched in its logarithm).
    """
    for j in range(z.shape[0]):
        v = lo[j] + z[j] * span[j]
        if logs[j]:
            v = np.exp(v)
        if kinds[j] == 0:
            p[slots[j]] = v
        else:
            x0[slots[j]] = v


@compiled
def _residual_vec(z, lo, span, logs, kinds, slots, t, Gg, Tgi, Q, F, n, Ta, x0, p, zoh, h_max, scratch, out):
    """Residuals T^a - Ta for scaled parameters z in [0, 1]^k, into out[:n]."""
    _set_free(z, lo, span, logs, kinds, slots, p, x0)
    integrate_into(t, Gg, Tgi, Q, F, n, x0, p, zoh, h_max, scratch, H0_S, False)
    for i in range(n):
        out[i] = scratch[i, S_TA] - Ta[i]


@compiled
def _ssr_of(z, lo, span, logs, kinds, slots, t, Gg, Tgi, Q, F, n, Ta, x0, p, zoh, h_max, scratch, r):
    """SSR of the probe reading (a failed simulation counts as 1e300); r is a work buffer."""
    _residual_vec(z, lo, span, logs, kinds, slots, t, Gg, Tgi, Q, F, n, Ta, x0, p, zoh, h_max, scratch, r)
    s = 0.0
    for i in range(n):
        s += r[i] * r[i]
    if not (s == s):
        return 1e300
    return s


@compiled
def _jacobian(
    z, lo, span, logs, kinds, slots, free, t, Gg, Tgi, Q, F, n, Ta, x0, p, zoh, h_max, scratch, r0, rp, rm, zt, J
):
    """Residuals r0 at z and their central-difference Jacobian J (n, k) in scaled units; returns sims."""
    k = z.shape[0]
    _residual_vec(z, lo, span, logs, kinds, slots, t, Gg, Tgi, Q, F, n, Ta, x0, p, zoh, h_max, scratch, r0)
    sims = 1
    for j in range(k):
        if not free[j]:
            for i in range(n):
                J[i, j] = 0.0
            continue
        zt[:] = z
        zp = min(z[j] + FD_STEP, 1.0)
        zm = max(z[j] - FD_STEP, 0.0)
        zt[j] = zp
        _residual_vec(zt, lo, span, logs, kinds, slots, t, Gg, Tgi, Q, F, n, Ta, x0, p, zoh, h_max, scratch, rp)
        zt[j] = zm
        _residual_vec(zt, lo, span, logs, kinds, slots, t, Gg, Tgi, Q, F, n, Ta, x0, p, zoh, h_max, scratch, rm)
        sims += 2
        for i in range(n):
            J[i, j] = (rp[i] - rm[i]) / (zp - zm)
    return sims


@compiled
def _normal(J, r0, n, A, g):
    """A = J'J and g = J'r over the first n residuals."""
    k = A.shape[0]
    for a in range(k):
        g[a] = 0.0
        for i in range(n):
            g[a] += J[i, a] * r0[i]
        for c in range(k):
            acc = 0.0
            for i in range(n):
                acc += J[i, a] * J[i, c]
            A[a, c] = acc


@compiled
def _fit_one(
    t,
    Gg,
    Tgi,
    Q,
    F,
    n,
    Ta,
    x0_in,
    p_in,
    search,
    z_out,
    jtj_out,
):
    """Score the trial points, then projected Levenberg-Marquardt from the best; returns (SSR, sims).

    ``search`` is what every batch's search shares: (kinds, slots, lo, span, logs, trial, zoh, h_max,
    max_iter, gain_tol). z_out gets the scaled optimum, jtj_out the Gauss-Newton matrix J'J there
    (scaled units).
    """
    kinds, slots, lo, span, logs, trial, zoh, h_max, max_iter, gain_tol = search
    k = lo.shape[0]
    p = p_in.copy()
    x0 = x0_in.copy()
    scratch = np.empty((t.shape[0], N_OUT))
    rs = np.empty(n)
    best = 1e300
    z = np.empty(k)
    sims = 0
    for m in range(trial.shape[0]):
        s = _ssr_of(trial[m], lo, span, logs, kinds, slots, t, Gg, Tgi, Q, F, n, Ta, x0, p, zoh, h_max, scratch, rs)
        sims += 1
        if s < best:
            best = s
            z[:] = trial[m]
    free = np.empty(k, dtype=np.bool_)
    for j in range(k):
        free[j] = span[j] > 0.0
    r0 = np.empty(n)
    rp = np.empty(n)
    rm = np.empty(n)
    J = np.empty((n, k))
    A = np.empty((k, k))
    g = np.empty(k)
    M = np.empty((k, k))
    b = np.empty(k)
    zt = np.empty(k)
    step = np.zeros(k)
    pinned = np.empty(k, dtype=np.bool_)
    fixed_step = np.empty(k)
    lam = 1e-3
    ssr = best
    need_jac = True
    done = False
    # one pass more than max_iter steps: the last only refreshes J'J at the optimum (for the errors)
    for _it in range(max_iter + 1):
        if need_jac:
            sims += _jacobian(
                z,
                lo,
                span,
                logs,
                kinds,
                slots,
                free,
                t,
                Gg,
                Tgi,
                Q,
                F,
                n,
                Ta,
                x0,
                p,
                zoh,
                h_max,
                scratch,
                r0,
                rp,
                rm,
                zt,
                J,
            )
            _normal(J, r0, n, A, g)
            need_jac = False
        if done or _it == max_iter:
            break
        # damped normal equations (M = A + lam diag(A)). Fixed parameters, those on a bound whose
        # gradient pushes outward, and those whose step would cross a bound are pinned (the last
        # at the bound they hit) and the others re-solved given that move: clipping a step
        # computed as if the bound were not there is what makes projected Gauss-Newton crawl.
        for a in range(k):
            pinned[a] = (not free[a]) or (z[a] <= 0.0 and g[a] > 0.0) or (z[a] >= 1.0 and g[a] < 0.0)
            fixed_step[a] = 0.0
        for _pass in range(k):
            for a in range(k):
                for c in range(k):
                    M[a, c] = A[a, c]
                M[a, a] += lam * A[a, a] + 1e-12
                b[a] = -g[a]
            for a in range(k):  # move the pinned displacements to the right-hand side
                if pinned[a]:
                    for c in range(k):
                        if not pinned[c]:
                            b[c] -= M[c, a] * fixed_step[a]
            for a in range(k):
                if pinned[a]:
                    for c in range(k):
                        M[a, c] = 0.0
                        M[c, a] = 0.0
                    M[a, a] = 1.0
                    b[a] = fixed_step[a]
            step = np.linalg.solve(M, b)
            crossed = False
            for j in range(k):
                if not pinned[j] and (z[j] + step[j] < 0.0 or z[j] + step[j] > 1.0):
                    pinned[j] = True
                    fixed_step[j] = (0.0 if z[j] + step[j] < 0.0 else 1.0) - z[j]
                    crossed = True
            if not crossed:
                break
        for j in range(k):
            zt[j] = min(max(z[j] + step[j], 0.0), 1.0)
        s = _ssr_of(zt, lo, span, logs, kinds, slots, t, Gg, Tgi, Q, F, n, Ta, x0, p, zoh, h_max, scratch, rs)
        sims += 1
        if s < ssr:
            gain = (ssr - s) / max(ssr, 1e-300)
            moved = 0.0
            for j in range(k):
                moved = max(moved, abs(zt[j] - z[j]))
            z[:] = zt
            ssr = s
            lam = max(lam / 3.0, 1e-12)
            need_jac = True
            # converged: the SSR barely moves, or the step (in units of the bounds) is tiny,
            # which ends the slow crawl along a valley of correlated parameters
            if gain < gain_tol or moved < 1e-6:
                done = True
        else:
            lam *= 4.0
            done = lam > 1e10
    jtj_out[:, :] = A
    z_out[:] = z
    return ssr, sims


@compiled(parallel=True)
def _fit_population(
    T,
    GG,
    TGI,
    QQ,
    FF,
    N,
    TA,
    X0,
    PB,
    search,
    Z,
    SSR,
    SIMS,
    JTJ,
):
    for b in prange(N.shape[0]):
        ssr, sims = _fit_one(
            T[b],
            GG[b],
            TGI[b],
            QQ[b],
            FF[b],
            N[b],
            TA[b],
            X0[b],
            PB[b],
            search,
            Z[b],
            JTJ[b],
        )
        SSR[b] = ssr
        SIMS[b] = sims


@functools.cache
def _sobol_points(seed: int, n: int, k: int) -> np.ndarray:
    """Scrambled Sobol points in [0, 1)^k, cached: building the generator costs ~1 ms a call."""
    # imported where called: SciPy's optimize and stats cost every command ~1 s (tests/test_layout.py)
    from scipy.stats import qmc

    pts = qmc.Sobol(k, scramble=True, seed=np.random.default_rng(seed)).random(n)
    pts.setflags(write=False)
    return pts


def trial_set(start, lo: np.ndarray, hi: np.ndarray, seed: int, n_trial: int) -> np.ndarray:
    """The trial points every batch scores, in the fitter's scaled units (0 at ``lo``, 1 at ``hi``, evenly
    in the value or, over two decades or more, in its logarithm: :func:`roastlab.fit.identify.trial_unit`):
    ``start`` first, then ``n_trial`` scrambled Sobol points spread as the global search spreads its own
    (the outer tenth of each range on its bound, :func:`roastlab.fit.identify.on_bounds`). A fixed
    component (``lo == hi``) is 0 in every row.
    """
    free = hi > lo
    unit = on_bounds(_sobol_points(seed, n_trial, len(lo)))
    start_unit = trial_unit(np.clip(start, lo, hi)[None, :], np.where(free, lo, 0.0), np.where(free, hi, 1.0))
    return np.where(free, np.clip(np.vstack([start_unit, unit]), 0.0, 1.0), 0.0)


def standard_errors(jtj, values, lo, hi, ssr, n, c_span, logs) -> np.ndarray:
    """Per-batch standard errors (nb, k) of the ``values`` from J'J in the fitter's scaled units (z in
    [0, 1] along each parameter's sampling coordinate, ``c_span`` wide), by the one rule of
    :mod:`roastlab.fit.uncertainty`: NaN on a bound (judged on the value, as :mod:`.identify` judges
    it), fixed (``lo == hi``), without effect or with no degrees of freedom left. An error in the
    coordinate is carried to the value: times ``c_span``, and times the value where the coordinate
    is its logarithm (d exp(c) = exp(c) dc)."""
    nb, k = values.shape
    out = np.full((nb, k), np.nan)
    names = [str(j) for j in range(k)]
    for b in range(nb):
        out[b] = uncertainty.from_normal(jtj[b], values[b], lo, hi, ssr[b], n[b], names).stderr * c_span
    return np.where(logs, values * out, out)


def identify_each(
    packed: PackedBatches,
    bounds: dict | None = None,
    fix: dict | None = None,
    seed: int = 0,
    n_trial: int = 32,
    max_iter: int = 100,
    gain_tol: float = 1e-10,
    progress=None,
    chunk: int = 256,
    names=THETA_NAMES,
    start: dict | None = None,
) -> FleetResult:
    """Fit the free ``names`` (default theta) separately for every batch of ``packed``.

    ``bounds`` changes the registry's default bounds by name, ``fix`` holds components at a
    value, ``start`` is the first trial point by name (default: theta0 for theta components,
    the bounds' middle for others); ``progress(done, total, text)`` is called after every ``chunk`` batches when given.
    """
    t0 = time.perf_counter()
    names = list(names)
    kinds, slots = free_slots(names)
    k = len(names)
    bounds = {**{n: REGISTRY[n].bounds for n in names}, **(bounds or {})}
    fix = {n: check_value(n, v, "fixed value") for n, v in (fix or {}).items()}  # the quantity table's range
    stray = sorted(set(fix) - set(names))
    if stray:
        raise InputError(
            f"fix {', '.join(stray)}: not among the fitted names {', '.join(names)} (set it in the packed batches)"
        )
    lo = np.array([fix.get(n, bounds[n][0]) for n in names], dtype=float)
    hi = np.array([fix.get(n, bounds[n][1]) for n in names], dtype=float)
    # the fitter moves z in [0, 1] along the search's sampling coordinate (a parameter over decades
    # in its logarithm, identify.trial_points): c = c_lo + z c_span, the value c or exp(c)
    logs = log_sampled(lo, hi)
    c_lo = sampling_coordinate(lo, logs)
    c_span = sampling_coordinate(hi, logs) - c_lo
    nb = packed.n_batches
    if np.any(~np.isfinite(packed.TA[packed.mask()])):
        raise InputError("per-batch identification needs a measured Ta at every sample")
    theta0 = THETA_START.as_dict()
    start = {**{n: theta0.get(n, 0.5 * (lo[j] + hi[j])) for j, n in enumerate(names)}, **(start or {})}
    trial = trial_set([start[n] for n in names], lo, hi, seed, n_trial)
    Z = np.zeros((nb, k))
    SSR = np.zeros(nb)
    SIMS = np.zeros(nb, dtype=np.int64)
    JTJ = np.zeros((nb, k, k))
    TA = np.where(packed.mask(), packed.TA, 0.0)
    chunk = max(1, min(nb, chunk)) if progress is not None else nb
    # what every batch's search shares, one argument through the parallel loop (_fit_one unpacks it)
    search = (kinds, slots, c_lo, c_span, logs, trial, packed.zoh, packed.h_max_s, max_iter, gain_tol)
    for a in range(0, nb, chunk):
        sl = slice(a, min(a + chunk, nb))
        # batches differ several-fold in work: hand them out one at a time, not in equal blocks
        with parallel_chunksize(1):
            _fit_population(
                *(a[sl] for a in packed.inputs),
                TA[sl],
                packed.x0[sl],
                packed.PB[sl],
                search,
                Z[sl],
                SSR[sl],
                SIMS[sl],
                JTJ[sl],
            )
        if progress is not None:
            progress(sl.stop, nb, "batches fitted")
    values = trial_points(Z, lo, hi)
    # the scalar integrator, as the fit itself: a batch's figures must not depend on how many batches
    # share the call (a fleet's chunks, Dask or in-process)
    ta = predict_ta(packed, names, values[None], use_lanes=False)[0]
    fits = np.array([fit_percent(packed.TA[b, :n], ta[b, :n]) for b, n in enumerate(packed.N)])
    mae = np.nanmean(np.abs(np.where(packed.mask(), ta - packed.TA, np.nan)), axis=1)
    stderr = standard_errors(JTJ, values, lo, hi, SSR, packed.N, c_span, logs)
    return FleetResult(
        list(packed.names),
        values,
        SSR,
        fits,
        max_iter,
        int(SIMS.sum()) + nb,
        time.perf_counter() - t0,
        names,
        stderr,
        packed.N.copy(),
        mae,
        SIMS + 1,
    )
