"""The compiled integrator: adaptive Dormand-Prince 5(4) over the model's one right-hand side.

The integrator goes from input sample to input sample, so every input breakpoint (a kink of a
linearly held input, a jump of a zero-order-held one) is a step boundary and the right-hand
side is smooth inside each step. Inside a sample interval it takes adaptive Dormand-Prince
5(4) steps (at most ``h_max_s``) that keep the local error below ``ATOL + RTOL |x|`` per state.
Adaptivity matters: over plausible roasts the dynamics are slow (time constants of 5-500 s),
but if beans are driven far past roasting temperatures Schwartzberg's moisture law becomes
stiff (rate ~6 1/s at 400 degC) and a fixed step would silently lose accuracy.

Against a 1e-10-tolerance SciPy reference the error stays below 1e-3 degC over randomised
inputs and parameters (tests/test_reference.py). The kernels call
:func:`roastlab.model.rhs.derivatives` (compiled inline), are cached on disk (:func:`roastlab.sim.cache.compiled`, keyed on the source hash) so a
second process does not recompile, and the population kernel runs in parallel over cores.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange
from numba.extending import overload
from numba.np.unsafe.ndarray import to_fixed_tuple

from ..model.rhs import N_PARAMS, N_STATES, derivatives, outlet_gas_C
from .cache import compiled

#: Largest integration step [s].
H_MAX_S = 30.0
#: First trial step of a run [s]: the step control shrinks it at once if the error asks for it,
#: and a stepped run carries the adapted step from call to call so it equals a batch run.
H0_S = 5.0
#: Local error tolerances per state [Tb degC, Tm degC, X kg/kg, He kJ/kg, Ta degC, H setting]
#: and relative. The temperatures bind: the worst global error against the reference is
#: ~6e-4 degC, 17x inside the 0.01 degC contract; 10x tighter costs ~25 % more evaluations.
ATOL = np.array([1e-4, 1e-4, 1e-7, 1e-3, 1e-4, 1e-4])
RTOL = 1e-6
NS = N_STATES
#: Most Dormand-Prince steps (accepted or rejected) one run may take: about half a second of
#: compiled work, ~1000x what a plausible roast needs. Values that make the model this stiff (a
#: tiny drum mass with large coefficients, a huge Arrhenius factor) would otherwise run for up
#: to an hour; the run stops instead and its remaining samples are marked :data:`STIFF_MARK`.
MAX_STEPS = 1_000_000
#: The step budget of a run integrated at a looser tolerance (``tol_scale`` > 1: the trial points
#: of :func:`roastlab.fit.identify.identify`, simulated only to be ranked), per sample interval and
#: at least. A plausible roast takes 1-3 steps an interval there, and the stiffest runs that still
#: finish in the tests' plausible box (drum coefficients a hundred times the paper's) about 350:
#: they run as before. A trial point that makes the model far stiffer (the largest heater gain with
#: no air, the largest Arrhenius factor) would spend :data:`MAX_STEPS` on each of its runs, seconds
#: that hold up its lane group (:mod:`roastlab.sim.lanes`) and the whole screening, to rank last all
#: the same: it is marked as stiff sooner instead (the Bullet example's screening 1.4 s against 4.8 s).
SCREENING_STEPS_PER_INTERVAL = 1000
SCREENING_MIN_STEPS = 10_000
#: What the states of a run hold from where the explicit integrator gave up on stiffness (the
#: step budget spent, or the step collapsed below 1e-9 of the sample interval); a trial that
#: stays non-finite down to a microsecond step writes NaN instead, so callers can say which.
STIFF_MARK = np.inf
#: Output columns: the six states, then the outlet gas temperature Tgo.
N_OUT = NS + 1
I_TGO = NS


# Dormand-Prince 5(4) tableau (Hairer, Norsett & Wanner, Solving ODEs I, table 5.2).
_C2, _C3, _C4, _C5 = 1 / 5, 3 / 10, 4 / 5, 8 / 9
_A21 = 1 / 5
_A31, _A32 = 3 / 40, 9 / 40
_A41, _A42, _A43 = 44 / 45, -56 / 15, 32 / 9
_A51, _A52, _A53, _A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
_A61, _A62, _A63, _A64, _A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
_B1, _B3, _B4, _B5, _B6 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
_E1, _E3, _E4, _E5, _E6, _E7 = 71 / 57600, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40


def parameter_tuple(p):
    """The parameter vector ``p`` as a tuple of its values (plain Python: ``tuple(p)``).

    Compiled, a tuple is a set of values, not memory: the compiler knows no store of the
    integrator can change it, so what the right-hand side computes from the parameters alone
    (the bed laws' branches and areas, 1/(Mm cm), k1/Db^2, the probe's coverage) is computed once
    per run instead of once per evaluation. Same arithmetic, same values as with the array.
    """
    return tuple(p)


@overload(parameter_tuple)
def _parameter_tuple_compiled(p):
    def impl(p):
        return to_fixed_tuple(p, N_PARAMS)

    return impl


@compiled(inline="always")
def _f(x, g, T, q, f, p, out):
    d = derivatives(x[0], x[1], x[2], x[3], x[4], x[5], g, T, q, f, p)
    out[0] = d[0]
    out[1] = d[1]
    out[2] = d[2]
    out[3] = d[3]
    out[4] = d[4]
    out[5] = d[5]


@compiled(inline="always")
def interval_inputs(t, Gg, Tgi, Q, F, k, zoh):
    """Sample interval k: its length dt [s], the inputs at its start (Gg, Tgi, heater, fan) and
    their slopes per second inside it (zero under a zero-order hold, else linear to sample k+1)."""
    t0 = t[k]
    dt = t[k + 1] - t0
    g0 = Gg[k]
    T0 = Tgi[k]
    q0 = Q[k]
    f0 = F[k]
    if zoh:
        return dt, g0, T0, q0, f0, 0.0, 0.0, 0.0, 0.0
    return dt, g0, T0, q0, f0, (Gg[k + 1] - g0) / dt, (Tgi[k + 1] - T0) / dt, (Q[k + 1] - q0) / dt, (F[k + 1] - f0) / dt


@compiled(inline="always")
def error_share(e, x_old, x_new, i):
    """State i's share of a trial step's squared error: (e / (ATOL[i] + RTOL max(|x_old|, |x_new|)))^2
    for its local error estimate ``e``; :func:`rms_error` turns the sum over the states into the norm."""
    r = e / (ATOL[i] + RTOL * max(abs(x_old), abs(x_new)))
    return r * r


@compiled(inline="always")
def rms_error(sum_of_shares):
    """The step's error norm from the summed :func:`error_share`: RMS over the paper's five states (H
    adds its error only when a heater moves it), so runs without the actuator extension take
    exactly the steps they always took."""
    return math.sqrt(sum_of_shares / 5.0)


@compiled(inline="always")
def next_step(err, h, h_try, last, h_max):
    """The step size after a trial of size ``h`` with a finite RMS error ``err``: grown after an
    accepted step (by at most 5; back to the trial size ``h_try`` after a step cut short at a
    sample), shrunk (by at most 5) after a rejected one."""
    return next_step_given(err, err**-0.2, h, h_try, last, h_max)


@compiled(inline="always")
def next_step_given(err, err_pow, h, h_try, last, h_max):
    """:func:`next_step` with ``err_pow`` = err^-0.2 computed by the caller (the lanes integrator
    computes it for all its runs at once, :mod:`roastlab.sim.lanes`)."""
    if err <= 1.0:
        fac = 5.0 if err < 1e-10 else min(5.0, 0.9 * err_pow)
        return h_try if last else min(h_max, h * fac)
    return h * max(0.2, 0.9 * err_pow)


@compiled(inline="always")
def step_budget(n, tol_scale):
    """Most steps a run of ``n`` samples may take: :data:`MAX_STEPS` at the full accuracy
    (``tol_scale`` 1), :data:`SCREENING_STEPS_PER_INTERVAL` an interval (at least
    :data:`SCREENING_MIN_STEPS`, at most :data:`MAX_STEPS`) at a looser one.

    >>> step_budget(150, 1.0), step_budget(150, 100.0), step_budget(5, 100.0), step_budget(3601, 100.0)
    (1000000, 149000, 10000, 1000000)
    """
    if tol_scale <= 1.0:
        return MAX_STEPS
    return min(MAX_STEPS, max(SCREENING_MIN_STEPS, SCREENING_STEPS_PER_INTERVAL * (n - 1)))


@compiled
def integrate_into(t, Gg, Tgi, Q, F, n, x0, p, zoh, h_max, out, h0=H0_S, with_tgo=True, tol_scale=1.0, evals=None):
    """Integrate one batch over samples t[0..n-1]; write states and Tgo to out[:n, :N_OUT].

    Inputs per sample: gas flow ``Gg`` [kg/s], inlet temperature ``Tgi`` [degC], heater
    setting ``Q`` and fan setting ``F`` (zeros when the actuator extension is off).
    Adaptive Dormand-Prince 5(4) inside each sample interval (input kinks are always step
    boundaries). Local error per step is kept below ATOL + RTOL |x| per state. ``h0`` is the
    first trial step; the step size the next call should start from is returned. Fitting
    needs only Ta, so ``with_tgo=False`` skips the outlet-gas output (column I_TGO left as is).
    ``tol_scale`` multiplies ATOL and RTOL (1: the contract's accuracy; a screening of many
    trial points that only ranks them may pass more, :data:`roastlab.fit.identify.SCREENING_TOL_SCALE`).
    ``evals`` (an int64 array of one, or None): adds the number of right-hand-side evaluations
    the run made (:func:`count_evaluations`; with None the count is compiled out).
    """
    x = np.empty(NS)
    for i in range(NS):
        x[i] = x0[i]
        out[0, i] = x0[i]
    if with_tgo:
        out[0, I_TGO] = outlet_gas_C(x, Gg[0], Tgi[0], F[0], p)
    pt = parameter_tuple(p)  # the right-hand side's parameter-only terms once per run
    k1 = np.empty(NS)
    k2 = np.empty(NS)
    k3 = np.empty(NS)
    k4 = np.empty(NS)
    k5 = np.empty(NS)
    k6 = np.empty(NS)
    k7 = np.empty(NS)
    y = np.empty(NS)
    xn = np.empty(NS)
    h = min(h_max, h0)
    steps = 0
    budget = step_budget(n, tol_scale)
    for k in range(n - 1):
        dt, g0, T0, q0, f0, dg, dT, dq, df = interval_inputs(t, Gg, Tgi, Q, F, k, zoh)
        s = 0.0
        if zoh or k == 0:
            # a zero-order hold jumps at the sample, so the derivative there is new; a linear
            # hold is continuous, so the last stage of the previous interval is still valid
            _f(x, g0, T0, q0, f0, pt, k1)
            if evals is not None:
                evals[0] += 1
        while s < dt:
            steps += 1
            if steps > budget or h < 1e-9 * dt:
                # the step budget spent or the step collapsed: too stiff for an explicit method
                for j in range(k + 1, n):
                    for i in range(N_OUT):
                        out[j, i] = STIFF_MARK
                return h
            last = False
            h_try = h
            if s + h >= dt * (1.0 - 1e-12):
                h = dt - s  # land exactly on the next sample
                last = True
            a = s + _C2 * h
            for i in range(NS):
                y[i] = x[i] + h * _A21 * k1[i]
            _f(y, g0 + dg * a, T0 + dT * a, q0 + dq * a, f0 + df * a, pt, k2)
            a = s + _C3 * h
            for i in range(NS):
                y[i] = x[i] + h * (_A31 * k1[i] + _A32 * k2[i])
            _f(y, g0 + dg * a, T0 + dT * a, q0 + dq * a, f0 + df * a, pt, k3)
            a = s + _C4 * h
            for i in range(NS):
                y[i] = x[i] + h * (_A41 * k1[i] + _A42 * k2[i] + _A43 * k3[i])
            _f(y, g0 + dg * a, T0 + dT * a, q0 + dq * a, f0 + df * a, pt, k4)
            a = s + _C5 * h
            for i in range(NS):
                y[i] = x[i] + h * (_A51 * k1[i] + _A52 * k2[i] + _A53 * k3[i] + _A54 * k4[i])
            _f(y, g0 + dg * a, T0 + dT * a, q0 + dq * a, f0 + df * a, pt, k5)
            a = s + h
            for i in range(NS):
                y[i] = x[i] + h * (_A61 * k1[i] + _A62 * k2[i] + _A63 * k3[i] + _A64 * k4[i] + _A65 * k5[i])
            _f(y, g0 + dg * a, T0 + dT * a, q0 + dq * a, f0 + df * a, pt, k6)
            for i in range(NS):
                xn[i] = x[i] + h * (_B1 * k1[i] + _B3 * k3[i] + _B4 * k4[i] + _B5 * k5[i] + _B6 * k6[i])
            _f(xn, g0 + dg * a, T0 + dT * a, q0 + dq * a, f0 + df * a, pt, k7)
            if evals is not None:
                evals[0] += 6  # stages 2-7 (stage 1 is the last step's 7th: first same as last)
            err = 0.0
            for i in range(NS):
                e = h * (_E1 * k1[i] + _E3 * k3[i] + _E4 * k4[i] + _E5 * k5[i] + _E6 * k6[i] + _E7 * k7[i])
                err += error_share(e, x[i], xn[i], i)
            err = rms_error(err) / tol_scale
            if not (err == err):
                if h < 1e-6:
                    # a trial that stays non-finite down to a microsecond step: report NaN rather
                    # than loop or lie
                    for j in range(k + 1, n):
                        for i in range(N_OUT):
                            out[j, i] = np.nan
                    return h
                # a non-finite trial (a stiff start overshooting into exp overflow): a smaller
                # step, as for a large error, instead of giving up
                h = h * 0.2
                continue
            if err <= 1.0:
                s = dt if last else s + h
                for i in range(NS):
                    x[i] = xn[i]
                    k1[i] = k7[i]  # first same as last
                if x[2] < 0.0:
                    x[2] = 0.0
            h = next_step(err, h, h_try, last, h_max)
        for i in range(NS):
            out[k + 1, i] = x[i]
        if with_tgo:
            j = k if zoh else k + 1
            out[k + 1, I_TGO] = outlet_gas_C(x, Gg[j], Tgi[j], F[j], p)
    return h


def failure(states: np.ndarray, t: np.ndarray) -> str | None:
    """Why a run's states (rows at times ``t``) stopped being finite, in words; None if they did not."""
    bad = ~np.isfinite(states)
    if not bad.any():
        return None
    i = int(np.argwhere(bad)[0][0])
    after = f"t = {t[max(i - 1, 0)]:g} s"
    if np.all(states[i] == STIFF_MARK):
        return (
            f"the model is too stiff to integrate after {after} (over {MAX_STEPS:,} steps, or a step below a "
            "billionth of the sample interval): these values give it a time constant far below a second"
        )
    return f"the simulation went non-finite after {after}"


@compiled
def count_evaluations(t, Gg, Tgi, Q, F, x0, p, zoh, h_max):
    """How many right-hand-side evaluations :func:`integrate_into` makes for one run (accepted and
    rejected trials alike): the integrator's cost in units of the model, for the benchmark."""
    n = t.shape[0]
    out = np.empty((n, N_OUT))
    evals = np.zeros(1, dtype=np.int64)
    integrate_into(t, Gg, Tgi, Q, F, n, x0, p, zoh, h_max, out, H0_S, False, 1.0, evals)
    return evals[0]


@compiled
def simulate_one(t, Gg, Tgi, Q, F, x0, p, zoh, h_max):
    n = t.shape[0]
    out = np.empty((n, N_OUT))
    integrate_into(t, Gg, Tgi, Q, F, n, x0, p, zoh, h_max, out)
    return out


@compiled(parallel=True)
def simulate_population_kernel(T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, out):
    """Simulate ``len(batch_of)`` runs in parallel.

    Run i uses the inputs of batch ``batch_of[i]`` (rows of the padded arrays T, GG, TGI, QQ
    (heater), FF (fan) with valid length N[b]), initial state X0[i] and parameter vector
    PP[i]; writes out[i, :N[b]].
    """
    for i in prange(batch_of.shape[0]):
        b = batch_of[i]
        integrate_into(T[b], GG[b], TGI[b], QQ[b], FF[b], N[b], X0[i], PP[i], zoh, h_max, out[i])


@compiled(parallel=True)
def ta_population_kernel(T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, out_ta, out_tb, out_tgo, tol_scale):
    """Like :func:`simulate_population_kernel` but keeps only the fitted outputs: the probe
    reading Ta, the bean temperature Tb when ``out_tb`` has rows (a second bean reading is
    fitted) and the outlet gas Tgo when ``out_tgo`` has rows (ET is fitted); pass empty (0, 0)
    arrays to keep Ta only. ``tol_scale``: :func:`integrate_into`'s (1 for the full accuracy)."""
    nmax = T.shape[1]
    with_tb = out_tb.shape[0] > 0
    with_tgo = out_tgo.shape[0] > 0
    for i in prange(batch_of.shape[0]):
        b = batch_of[i]
        scratch = np.empty((nmax, N_OUT))
        n = N[b]
        integrate_into(
            T[b], GG[b], TGI[b], QQ[b], FF[b], n, X0[i], PP[i], zoh, h_max, scratch, H0_S, with_tgo, tol_scale
        )
        for j in range(n):
            out_ta[i, j] = scratch[j, 4]
        if with_tb:
            for j in range(n):
                out_tb[i, j] = scratch[j, 0]
        if with_tgo:
            for j in range(n):
                out_tgo[i, j] = scratch[j, I_TGO]


@compiled
def step_kernel(x, u0, u1, dt, p, zoh, h_max, h0):
    """One step of ``dt`` seconds from state ``x`` (length NS) with inputs ``u0`` at the start
    and ``u1`` at the end (each [Gg, Tgi, heater, fan]); returns (state, Tgo, next step)."""
    t = np.array([0.0, dt])
    g = np.array([u0[0], u1[0]])
    T = np.array([u0[1], u1[1]])
    q = np.array([u0[2], u1[2]])
    f = np.array([u0[3], u1[3]])
    out = np.empty((2, N_OUT))
    h = integrate_into(t, g, T, q, f, 2, x, p, zoh, h_max, out, h0)
    return out[1, :NS].copy(), out[1, I_TGO], h


@compiled(parallel=True)
def step_population_kernel(X, U, PP, zoh, h_max, H, T2, UU, scratch):
    """Advance many roasts by one interval of ``T2[1]`` seconds in one parallel call.

    Roast i starts from state X[i] (length NS, overwritten with the state at the end) with the
    inputs U[i] = [Gg, Tgi, heater, fan] held over the interval (``zoh``; a linear hold ramps
    from the previous call's inputs, kept in UU[i, :, 1], to U[i]), parameter vector PP[i] and first trial step H[i] (overwritten
    with the next). T2 (2,) = [0, interval]; UU (n, 4, 2) and scratch (n, 2, N_OUT) are caller-owned
    work arrays, so a step allocates nothing per roast beyond the integrator's own.
    """
    for i in prange(X.shape[0]):
        for j in range(4):
            UU[i, j, 0] = U[i, j] if zoh else UU[i, j, 1]  # a linear hold ramps from the last inputs
            UU[i, j, 1] = U[i, j]
        H[i] = integrate_into(
            T2, UU[i, 0], UU[i, 1], UU[i, 2], UU[i, 3], 2, X[i], PP[i], zoh, h_max, scratch[i], H[i], False
        )
        for k in range(NS):
            X[i, k] = scratch[i, 1, k]
