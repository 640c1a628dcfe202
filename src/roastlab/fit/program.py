"""Input-program optimisation: the inlet-gas program that makes the model's probe follow a target.

The one optimiser behind profile transfer (:mod:`roastlab.workflows.transfer`) and model
predictive control. The problem, on a time grid t_0..t_{n-1} (the program's knots):

    minimise   sum_i (Ta_i(z) - target_i)^2  +  lam^2 sum_k d_k^2
    over       z = (u_0, d_1..d_{n-1} [, Gg] [, Tm0]),   u_k = u_0 + d_1 + ... + d_k
    subject to |d_k| <= rate (t_k - t_{k-1})      (rate limit: box bounds on the increments)
               u_min <= u_k <= u_max              (level limits: a stiff penalty while solving,
                                                   then the program is clipped, which keeps the
                                                   rate limit since clipping is 1-Lipschitz)

where u is the inlet gas temperature Tgi [degC] (the paper's input) or, with the actuator
extension, the heater setting.

Ta(z) is the compiled model (:func:`roastlab.sim.kernels.integrate_into`, the one right-hand
side) run with Tgi held linearly (or zero-order) between knots. The Jacobian of Ta in the
knots, the optional constant gas flow and the drum start temperature comes from one run of
the forward sensitivities (:func:`roastlab.sim.sensitivity.program_sensitivity`, exact
derivatives of the integrator's steps); finite differences on the compiled integrator
(``sensitivities="fd"``, :func:`roastlab.sim.sensitivity.ta_input_jacobian`) are the
reference. The solver is SciPy's bounded trust-region least squares
(``least_squares(method="trf")``), or for a warm-started receding horizon a box-bounded
damped Gauss-Newton (``solver="gauss-newton"``), started from a given program (for transfer:
the reference's own inputs). Deterministic: no random starts.
"""

from __future__ import annotations

import dataclasses
import time
import types
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..metrics.profile import ror_operator
from ..model.actuators import MIN_HOLD_S, TGI_LIMITS, Actuator
from ..model.layout import N_STATES, S_H, S_TA, S_TM
from ..model.limits import check_value
from ..sim.kernels import H_MAX_S, simulate_one
from ..sim.sensitivity import program_sensitivity, ta_input_jacobian
from .threads import one_blas_thread

#: Most knots a program may have (the Jacobian is dense, n x n).
MAX_KNOTS = 2500
#: Weight of a degree outside the level limits against a degree of tracking error, while solving.
LEVEL_PENALTY = 30.0
#: Default smoothness weight lam [-]: a 1 degC step of the program costs like 0.03 degC of error.
SMOOTHNESS = 0.03


#: The inputs a program can decide, with their unit.
DECISIONS = {"Tgi": "degC", "heater": "setting"}


@dataclass
class ProgramLimits:
    """Limits of the program: the decided input's level and rate (per minute), and an optional
    range for a constant gas flow [kg/s] that the optimiser may then choose.

    ``decide`` is ``"Tgi"`` (inlet gas temperature [degC], the paper's input) or ``"heater"``
    (the heater setting of the actuator extension, in the map's units).
    """

    low: float = TGI_LIMITS[0]
    high: float = TGI_LIMITS[1]
    rate_per_min: float = TGI_LIMITS[2]
    Gg_min_kg_s: float | None = None
    Gg_max_kg_s: float | None = None
    decide: str = "Tgi"
    #: the machine's control when deciding it (its steps make the runnable program); None: continuous
    actuator: Actuator | None = None

    def __post_init__(self) -> None:
        if self.decide not in DECISIONS:
            raise InputError(f"cannot decide {self.decide!r} (allowed: {', '.join(DECISIONS)})", "limits")
        if self.decide == "Tgi":  # levels and rate within the quantity table's plausible ranges
            self.low = check_value("Tgi_C", self.low, "--tgi-min")
            self.high = check_value("Tgi_C", self.high, "--tgi-max")
            self.rate_per_min = check_value("rate_per_min", self.rate_per_min, "--tgi-rate")
        else:
            self.low = check_value("heater", self.low, "--heater-min")
            self.high = check_value("heater", self.high, "--heater-max")
            self.rate_per_min = check_value("rate_per_min", self.rate_per_min, "--heater-rate")
        for name in ("Gg_min_kg_s", "Gg_max_kg_s"):
            if getattr(self, name) is not None:
                setattr(self, name, check_value("Gg_kg_s", getattr(self, name), "--gg-" + name[3:6]))
        if not self.low < self.high:
            raise InputError(f"{self.decide} limits inverted or empty: min {self.low:g} >= max {self.high:g}", "limits")
        a = self.actuator
        if a is not None and (self.low, self.high) != (a.low, a.high):
            # narrower (or wider) limits than the map's: the runnable program's settings obey them
            # too, so they must be settings the machine has
            if a.stepped:
                for v, opt in ((self.low, "--heater-min"), (self.high, "--heater-max")):
                    k = (v - a.low) / a.step
                    if abs(k - round(k)) > 1e-9:
                        raise InputError(f"{a.label(v)} is not a setting of the machine ({a.describe()})", opt)
            self.actuator = dataclasses.replace(a, low=self.low, high=self.high)
        if (self.Gg_min_kg_s is None) != (self.Gg_max_kg_s is None):
            raise InputError("give both Gg limits (min and max) or neither", "limits")
        if self.Gg_min_kg_s is not None and not 0 < self.Gg_min_kg_s < self.Gg_max_kg_s:
            raise InputError(
                f"Gg limits must satisfy 0 < min < max, got {self.Gg_min_kg_s:g}..{self.Gg_max_kg_s:g} kg/s", "limits"
            )

    @classmethod
    def for_actuator(cls, actuator, low=None, high=None, rate_per_min=None, gg_min=None, gg_max=None) -> ProgramLimits:
        """Limits for deciding a machine's control (:class:`roastlab.model.actuators.Actuator`,
        as the map declares it): its range, rate and steps unless overridden, so a program is
        called infeasible because of the machine, not because of a default."""
        if actuator is None:
            raise InputError("deciding the heater needs a model whose map reads a heater setting ([heater])", "limits")
        return cls(
            actuator.low if low is None else low,
            actuator.high if high is None else high,
            actuator.rate_per_min if rate_per_min is None else rate_per_min,
            gg_min,
            gg_max,
            decide=actuator.name,
            actuator=actuator,
        )

    @classmethod
    def for_model(cls, column_map, decide=None, low=None, high=None, rate_per_min=None) -> ProgramLimits:
        """The limits for the control a program decides on the machine a model's ``column_map``
        describes. ``decide`` None: the heater, on the machine's own settings
        (:meth:`for_actuator`), where the map reads a heater and the inlet is room air (an
        induction or electric drum); the inlet gas temperature otherwise (the paper's gas
        roaster). ``low``, ``high``, ``rate_per_min`` override the machine's or the defaults."""
        has_heater = column_map is not None and column_map.heater is not None
        if decide is None:
            decide = "heater" if has_heater and column_map.inlet_is_constant else "Tgi"
        if decide == "heater":
            if not has_heater:
                raise InputError("deciding the heater needs a model whose map reads a heater setting ([heater])")
            return cls.for_actuator(column_map.actuator("heater"), low, high, rate_per_min)
        return cls(
            TGI_LIMITS[0] if low is None else low,
            TGI_LIMITS[1] if high is None else high,
            TGI_LIMITS[2] if rate_per_min is None else rate_per_min,
        )

    @property
    def gg_free(self) -> bool:
        return self.Gg_min_kg_s is not None

    @property
    def unit(self) -> str:
        return self.actuator.unit if self.actuator is not None else DECISIONS[self.decide]


@dataclass
class ProgramResult:
    """The optimised program and what it gives."""

    time_s: np.ndarray
    Tgi_C: np.ndarray
    heater: np.ndarray  # zeros without the actuator extension
    fan: np.ndarray  # as given (zeros without the actuator extension)
    Gg_kg_s: np.ndarray
    Ta_pred_C: np.ndarray
    states: np.ndarray  # (n, N_OUT) the model's run with the program; row 0 is the charge state
    params: np.ndarray  # the parameter vector the program is for
    solve_s: float
    iterations: int
    simulations: int
    notes: list[str] = field(default_factory=list)
    zoh: bool = False

    @property
    def Tm0_C(self) -> float:
        """Drum temperature at CHARGE [degC] (chosen by the optimiser when it was a decision)."""
        return float(self.states[0, S_TM])


def _run(t, Gg, Tgi, Q, F, x0, p, zoh):
    return simulate_one(t, Gg, Tgi, Q, F, x0, p, zoh, H_MAX_S)


def optimise_program(
    t,
    target_C,
    x0,
    p,
    Gg_kg_s,
    Tgi_C,
    limits: ProgramLimits,
    *,
    heater=None,
    fan=None,
    zoh: bool = False,
    tm0_bounds: tuple[float, float] | None = None,
    smoothness: float = SMOOTHNESS,
    weights=None,
    max_iterations: int = 60,
    u_prev: float | None = None,
    Tgi_bias_C: float = 0.0,
    ror_weight: float = 0.0,
    sensitivities: str = "exact",
    solver: str = "trf",
) -> ProgramResult:
    """The program of one input (Tgi or the heater, ``limits.decide``; optionally also a constant
    Gg and the drum start temperature) whose simulated probe follows ``target_C`` on ``t`` [s].

    Parameters
    ----------
    t : (n,) knot times [s], strictly increasing; the program and the target live on them
    target_C : (n,) the probe curve to follow [degC]
    x0 : (NS,) initial state [Tb, Tm, X, He, Ta, H]; Ta should be the target's first reading
    p : parameter vector of the plant the program is for (:func:`roastlab.model.rhs.pack_params`)
    Gg_kg_s : (n,) gas flow [kg/s] (kept when ``limits`` has no Gg range; else the start value)
    Tgi_C, heater : (n,) inlet temperature [degC] and heater setting; the decided one is the
        starting program (projected into the limits first), the other is held as given
    limits : :class:`ProgramLimits`
    fan : (n,) fan setting held as given (zeros when omitted)
    zoh : zero-order hold between knots instead of linear
    tm0_bounds : (lo, hi) [degC] to make the drum temperature at CHARGE a decision
    smoothness : weight lam on the program's increments (see the module docstring)
    weights : (n,) weight of each knot's tracking error (default 1)
    max_iterations : most residual evaluations of the solver (a warm-started receding-horizon
        step needs a few; a transfer from scratch tens)
    u_prev : the decided input applied just before ``t[0]`` (receding-horizon control): the
        rate limit then also holds between it and the first knot, over ``t[1] - t[0]``
    Tgi_bias_C : an inlet-temperature offset the model sees on top of ``Tgi_C`` [degC] (an
        estimated disturbance; the decided program and its limits exclude it)
    ror_weight : weight of the rate-of-rise error [per degC/min] against the level error
        [per degC] (0: track the level only); the RoR is the one of
        :func:`roastlab.metrics.profile.rate_of_rise_C_per_min`, which the control score uses too
    sensitivities : ``"exact"`` (forward sensitivities integrated with the states,
        :func:`roastlab.sim.sensitivity.program_sensitivity`) or ``"fd"`` (finite differences on
        the compiled integrator, the reference)
    solver : ``"trf"`` (SciPy's bounded trust-region least squares) or ``"gauss-newton"`` (a
        box-bounded damped Gauss-Newton, :func:`_projected_gauss_newton`: lighter per
        iteration, for a warm-started receding horizon)
    """
    # imported where called: SciPy's optimize and stats cost every command ~1 s (tests/test_layout.py)
    from scipy.optimize import least_squares

    t0_clock = time.perf_counter()
    if sensitivities not in ("exact", "fd"):
        raise InputError(f"sensitivities must be 'exact' or 'fd', got {sensitivities!r}", "program")
    if solver not in ("trf", "gauss-newton"):
        raise InputError(f"solver must be 'trf' or 'gauss-newton', got {solver!r}", "program")
    t = np.ascontiguousarray(t, dtype=np.float64)
    n = t.shape[0]
    if n < 3:
        raise InputError(f"a program needs at least 3 knots (two intervals), got {n}", "reference")
    if n > MAX_KNOTS:
        raise InputError(f"{n} knots is more than {MAX_KNOTS}: use a longer --interval-s", "reference")
    target = np.asarray(target_C, dtype=np.float64)
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=np.float64)
    Q = np.zeros(n) if heater is None else np.array(heater, dtype=np.float64)
    F = np.zeros(n) if fan is None else np.ascontiguousarray(fan, dtype=np.float64)
    T_in = np.array(Tgi_C, dtype=np.float64)
    which = 0 if limits.decide == "Tgi" else 1
    x0 = np.array(x0, dtype=np.float64)
    dt = np.diff(t)
    step_max = limits.rate_per_min / 60.0 * dt
    lo_T, hi_T = limits.low, limits.high

    # the first knot's range: the level limits, and the rate limit from the input applied before
    first_lo, first_hi = lo_T, hi_T
    if u_prev is not None:
        first_lo = min(max(lo_T, u_prev - step_max[0]), hi_T)
        first_hi = max(min(hi_T, u_prev + step_max[0]), lo_T)
        if first_hi - first_lo < 1e-9 * (hi_T - lo_T):  # the solver needs an interval, not a point
            first_lo, first_hi = first_lo - 1e-9 * (hi_T - lo_T), first_hi + 1e-9 * (hi_T - lo_T)
    # start: the given program made feasible (levels clipped, then the rate limit walked forward)
    start = np.clip(T_in if which == 0 else Q, lo_T, hi_T)
    start[0] = min(max(start[0], first_lo), first_hi)
    for k in range(1, n):
        start[k] = start[k - 1] + np.clip(start[k] - start[k - 1], -step_max[k - 1], step_max[k - 1])
    Gg0 = np.ascontiguousarray(Gg_kg_s, dtype=np.float64)
    extra_names: list[str] = []
    z0 = [start[0], *np.diff(start)]
    lb = [first_lo, *(-step_max)]
    ub = [first_hi, *step_max]
    if limits.gg_free:
        extra_names.append("Gg")
        g_start = float(np.clip(np.mean(Gg0), limits.Gg_min_kg_s, limits.Gg_max_kg_s))
        z0.append(g_start)
        lb.append(limits.Gg_min_kg_s)
        ub.append(limits.Gg_max_kg_s)
    if tm0_bounds is not None:
        extra_names.append("Tm0")
        z0.append(float(np.clip(x0[S_TM], *tm0_bounds)))
        lb.append(tm0_bounds[0])
        ub.append(tm0_bounds[1])
    lb, ub = np.array(lb), np.array(ub)
    # the start, projected into its bounds: the walked start's increments can exceed the rate
    # bound by a rounding error (1e-14), which the solver refuses
    z0 = np.clip(np.array(z0), lb, ub)
    counter = {"sims": 0}

    def unpack(z):
        u = np.cumsum(z[:n])
        tgi, q = (u, Q) if which == 0 else (T_in, u)
        if Tgi_bias_C:
            tgi = tgi + Tgi_bias_C
        gg = Gg0
        x = x0
        j = n
        if limits.gg_free:
            gg = np.full(n, z[j])
            j += 1
        if tm0_bounds is not None:
            x = x0.copy()
            x[S_TM] = z[j]
        if which == 1:
            x = x.copy()
            x[S_H] = u[0]  # the heater's lag starts settled at the first setting, as the simulator does
        return u, tgi, q, gg, x

    cache: dict = {}
    if ror_weight:  # the one RoR definition as a linear map of the knots' Ta (rows with a RoR)
        D, valid = ror_operator(t)
        ror_rows = D[valid].toarray()
        ror_target = ror_rows @ target
    lower = np.tril(np.ones((n, n)))  # d u_k / d z_j = 1 for j <= k

    def simulate(z):
        key = z.tobytes()
        if key not in cache:
            u, tgi, q, gg, x = unpack(z)
            cache.clear()
            cache[key] = (u, tgi, q, gg, x, _run(t, gg, tgi, q, F, x, p, zoh))
            counter["sims"] += 1
        return cache[key]

    def residuals(z):
        u, _, _, _, _, out = simulate(z)
        r_track = w * (out[:, S_TA] - target)
        over = np.maximum(u - hi_T, 0.0) - np.maximum(lo_T - u, 0.0)
        parts = [r_track, LEVEL_PENALTY * over, smoothness * z[1:n]]
        if ror_weight:
            parts.append(ror_weight * (ror_rows @ out[:, S_TA] - ror_target))
        r = np.concatenate(parts)
        return np.where(np.isfinite(r), r, 1e6)

    def jacobian(z):
        u, tgi, q, gg, x, out = simulate(z)
        m = z.shape[0]
        # d Ta_i / d u (the knots' levels, then the extras' columns), unweighted
        if sensitivities == "exact":  # forward sensitivities: one run gives every column
            _, du = program_sensitivity(t, gg, tgi, q, F, x, p, zoh, which, extra_names)
            counter["sims"] += 1
        else:  # the reference: forward differences on the compiled integrator
            du = np.empty((n, m))
            ta = np.ascontiguousarray(out[:, S_TA])
            states = np.ascontiguousarray(out[:, :6])
            delta = 1.0 if which == 0 else 1e-2 * (hi_T - lo_T)
            jt = np.empty((n, n))
            ta_input_jacobian(t, gg, tgi, q, F, which, states, ta, p, zoh, H_MAX_S, delta, jt)
            du[:, :n] = jt
            counter["sims"] += n // 2
            for j, name in enumerate(extra_names, start=n):
                h = 1e-3 * max(abs(z[j]), 1e-3) if name == "Gg" else 0.5
                zp = z.copy()
                zp[j] += h
                _, tp, qp, gp, xp = unpack(zp)
                outp = _run(t, gp, tp, qp, F, xp, p, zoh)
                counter["sims"] += 1
                du[:, j] = (outp[:, S_TA] - out[:, S_TA]) / h
        # d Ta_i / d z: u_k = sum_{j <= k} z_j, so column j sums the knot columns k >= j
        dta = du.copy()
        dta[:, :n] = np.cumsum(du[:, n - 1 :: -1], axis=1)[:, ::-1]
        J = np.zeros((3 * n - 1 + (ror_rows.shape[0] if ror_weight else 0), m))
        active = ((u > hi_T) | (u < lo_T)).astype(float)
        J[n : 2 * n, :n] = LEVEL_PENALTY * lower * active[:, None]
        J[2 * n : 3 * n - 1, 1:n] = smoothness * np.eye(n - 1)
        J[:n] = w[:, None] * dta
        if ror_weight:  # d(RoR)/dz: the RoR is a linear map of Ta, so its rows map d Ta / d z
            J[3 * n - 1 :] = ror_weight * (ror_rows @ dta)
        return np.where(np.isfinite(J), J, 0.0)

    with one_blas_thread():
        if solver == "gauss-newton":
            sol = _projected_gauss_newton(residuals, jacobian, z0, lb, ub, max_iterations)
        else:
            sol = least_squares(
                residuals,
                z0,
                jac=jacobian,
                bounds=(lb, ub),
                method="trf",
                x_scale="jac",
                max_nfev=max_iterations,
                xtol=1e-8,
                ftol=1e-8,
            )
    u, tgi, q, gg, x = unpack(sol.x)
    u = np.clip(u, lo_T, hi_T)  # keeps the rate limit (clipping is 1-Lipschitz)
    tgi, q = (u, q) if which == 0 else (T_in, u)
    out = _run(t, gg, tgi + Tgi_bias_C if Tgi_bias_C else tgi, q, F, x, p, zoh)
    counter["sims"] += 1
    if sol.success:
        notes = []
    elif getattr(sol, "status", None) == 0:  # SciPy's least_squares: max_nfev reached
        notes = [
            f"the optimiser used all {max_iterations} of its evaluations before it settled: the program is the best it found"
        ]
    else:
        notes = [f"optimiser stopped: {sol.message}"]
    return ProgramResult(
        time_s=t,
        Tgi_C=np.array(tgi),
        heater=np.array(q),
        fan=F,
        Gg_kg_s=np.array(gg, dtype=np.float64),
        Ta_pred_C=out[:, S_TA].copy(),
        states=out,
        params=p,
        solve_s=time.perf_counter() - t0_clock,
        iterations=int(sol.nfev),
        simulations=counter["sims"],
        notes=notes,
        zoh=zoh,
    )


def _projected_gauss_newton(fun, jac, z0, lb, ub, max_iterations: int, rtol: float = 1e-8):
    """Box-bounded damped Gauss-Newton (Levenberg-Marquardt with the bound-active variables held):
    the receding-horizon solver. Each iteration takes the Jacobian at the current point, holds
    the variables a bound stops (at it, with the gradient pushing out), solves the damped normal
    equations for the others, projects the step into the box and accepts it if the cost falls
    (else raises the damping). ``max_iterations`` counts residual evaluations, as SciPy's
    ``max_nfev`` does. Returns an object with ``x``, ``nfev``, ``success``, ``message``."""
    z = np.clip(np.asarray(z0, dtype=float), lb, ub)
    r = fun(z)
    cost, nfev, mu = float(r @ r), 1, 1e-4
    span = np.maximum(ub - lb, 1e-12)
    message = "iteration budget spent"
    while nfev < max_iterations:
        J = jac(z)
        g = J.T @ r
        held = ((z <= lb + 1e-10 * span) & (g > 0)) | ((z >= ub - 1e-10 * span) & (g < 0))
        free = ~held
        A = J[:, free]
        H = A.T @ A
        d = np.maximum(np.diag(H), 1e-12)
        accepted = False
        while nfev < max_iterations:
            step = np.zeros_like(z)
            step[free] = np.linalg.solve(H + mu * np.diag(d), -g[free])
            zn = np.clip(z + step, lb, ub)
            rn = fun(zn)
            nfev += 1
            cn = float(rn @ rn)
            if cn < cost:
                accepted = True
                done = cost - cn <= rtol * cost
                z, r, cost, mu = zn, rn, cn, max(mu / 3.0, 1e-8)
                break
            mu *= 4.0
        if not accepted or done:
            message = "converged" if accepted else message
            break
    return types.SimpleNamespace(x=z, nfev=nfev, success=True, message=message)


def runnable_program(
    program: ProgramResult, target_C, actuator: Actuator, hold_s: float = MIN_HOLD_S, passes: int = 2
) -> ProgramResult:
    """The continuous heater ``program`` made one a person (or Artisan) can run: the settings the
    machine has (``actuator``'s steps), changed at most every ``hold_s`` seconds.

    Each ``hold_s`` window takes the nearest setting to the continuous program's mean over it,
    so the heat it delivers matches; then, ``passes`` times over the windows, a window's setting
    moves one step up or down where that brings the predicted probe closer to ``target_C`` (sum
    of squares). The same compiled model, parameters and charge state as the continuous program.
    A continuous actuator (no step) returns ``program`` unchanged.
    """
    if not actuator.stepped:
        return program
    t0_clock = time.perf_counter()
    t = program.time_s
    u = program.heater
    window = np.floor((t - t[0]) / hold_s + 1e-9).astype(int)
    n_win = int(window[-1]) + 1
    levels = actuator.quantise([u[window == k].mean() for k in range(n_win)])
    x0 = program.states[0].copy()
    target = np.asarray(target_C, dtype=float)
    sims = 0

    def run(lv):
        nonlocal sims
        q = lv[window]
        x = x0.copy()
        x[5] = q[0]  # the heater's lag starts settled at the first setting, as the simulator does
        sims += 1
        return q, _run(t, program.Gg_kg_s, program.Tgi_C, q, program.fan, x, program.params, program.zoh)

    q, out = run(levels)
    best = float(np.sum((out[:, S_TA] - target) ** 2))
    for _ in range(passes):
        improved = False
        for k in range(n_win):
            for d in (actuator.step, -actuator.step):
                trial = levels.copy()
                trial[k] = actuator.quantise(trial[k] + d)
                if trial[k] == levels[k]:
                    continue
                qt, ot = run(trial)
                sse = float(np.sum((ot[:, S_TA] - target) ** 2))
                if sse < best - 1e-9:
                    levels, q, out, best, improved = trial, qt, ot, sse, True
                    break
        if not improved:
            break
    return ProgramResult(
        time_s=t,
        Tgi_C=program.Tgi_C,
        heater=q,
        fan=program.fan,
        Gg_kg_s=program.Gg_kg_s,
        Ta_pred_C=out[:, S_TA].copy(),
        states=out,
        params=program.params,
        solve_s=program.solve_s + time.perf_counter() - t0_clock,
        iterations=program.iterations,
        simulations=program.simulations + sims,
        notes=list(program.notes),
        zoh=program.zoh,
    )


def true_runs(mask) -> list[tuple[int, int]]:
    """(first, last) index of each run of True in a boolean sequence."""
    m = np.asarray(mask, dtype=bool)
    edges = np.flatnonzero(np.diff(np.concatenate([[False], m, [False]]).astype(np.int8)))
    return [(int(a), int(b) - 1) for a, b in zip(edges[0::2], edges[1::2])]


def level_labels(limits: ProgramLimits) -> tuple[str, str]:
    """The floor and the ceiling of ``limits`` as the roaster reads them: the machine's settings
    ("P0", "P9"; "100 %"; "3.2", a reading), else the level with its unit ("150 degC")."""
    if limits.actuator is not None:
        return limits.actuator.label(limits.low), limits.actuator.label(limits.high)
    return f"{limits.low:g} {limits.unit}", f"{limits.high:g} {limits.unit}"


def limit_spans(t, u, limits: ProgramLimits) -> list[dict]:
    """Time ranges where the program ``u`` sits on a limit:
    ``[{"limit", "from_s", "to_s", "holds_back"}, ...]`` (``holds_back`` "up": the limit keeps
    the program from heating more; "down": from heating less).

    Levels: within 0.01 % of the range of the floor or ceiling at a knot. Rate: an interval
    whose change is within 1 % of the largest the rate limit allows.
    """
    t = np.asarray(t, dtype=float)
    u = np.asarray(u, dtype=float)
    tol = 1e-4 * (limits.high - limits.low)
    name, unit = limits.decide, limits.unit
    low, high = level_labels(limits)
    rate = f"{limits.rate_per_min:g} {unit}/min"
    if unit == "tens":  # levels shown in tens (the actuator's unit): said as the machine's levels
        rate = f"{limits.rate_per_min / 10.0:g} levels/min"
    elif unit == "reading":  # no unit to name
        rate = f"{limits.rate_per_min:g}/min"
    flags = {
        f"{name} at its {high} ceiling": u >= limits.high - tol,
        f"{name} at its {low} floor": u <= limits.low + tol,
    }
    step = np.diff(u)
    cap = limits.rate_per_min / 60.0 * np.diff(t)
    up = np.concatenate([[False], step >= 0.99 * cap])
    down = np.concatenate([[False], step <= -0.99 * cap])
    flags[f"{name} rising at its {rate} rate limit"] = up
    flags[f"{name} falling at its {rate} rate limit"] = down
    spans = []
    for name, mask in flags.items():
        # the direction the limit holds the program back: a ceiling or a rising rate keeps it
        # from heating more ("up"), a floor or a falling rate from heating less ("down")
        side = "up" if ("ceiling" in name or "rising" in name) else "down"
        for k, j in true_runs(mask):
            start = t[k - 1] if "rate" in name and k > 0 else t[k]
            spans.append({"limit": name, "from_s": float(start), "to_s": float(t[j]), "holds_back": side})
    return sorted(spans, key=lambda s: s["from_s"])


def input_reach_C(program: ProgramResult, limits: ProgramLimits) -> np.ndarray:
    """How far the decided input can move the program's predicted probe at each knot [degC]: the
    probe with the input at its ceiling from CHARGE on, minus with it at its floor, everything else
    (the charge state, the other inputs, the plant) as the program has it.

    More heat into the drum or the gas at any time leaves the later probe higher (the heat paths run
    from hot to cold; the drying a hotter bean speeds is not proven never to outweigh it, so this is
    checked: on a 0.8 kg Bullet and a 0.25 kg Skywalker transfer of the shared logs, and in
    tests/test_transfer.py), so a program's probe lies between these two runs, and a miss larger than
    their difference at a knot is not the program's to close, whatever the limits: in the first
    seconds after CHARGE a heater's lag and the drum's heat capacity leave the probe's fall onto the
    beans to the charge state alone (0.8 kg in the Bullet, a model fitted on its 490-500 g logs: P0
    against P9 moves the probe by under 0.1 degC in the first 15 s and 2.5 degC by the first minute).
    Two runs of the compiled simulator.
    """
    out = []
    for level in (limits.low, limits.high):
        x0 = np.array(program.states[0, :N_STATES], dtype=np.float64)
        if limits.decide == "Tgi":
            tgi, q = np.full_like(program.Tgi_C, level), program.heater
        else:
            tgi, q = program.Tgi_C, np.full_like(program.heater, level)
            x0[S_H] = level  # the heater's lag settled at its setting, as the simulator starts it
        run = _run(program.time_s, program.Gg_kg_s, tgi, q, program.fan, x0, program.params, program.zoh)
        out.append(run[:, S_TA])
    return out[1] - out[0]
