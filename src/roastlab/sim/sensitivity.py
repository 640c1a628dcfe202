"""Sensitivities of the simulated states to parameters, initial states and input programs.

Exact (forward) sensitivities, :func:`integrate_sens_into`: the derivative S = dx/dz of the
states with respect to m directions z (free parameters, initial states, the knots of an input
program) is carried through the same Dormand-Prince 5(4) steps as the states
(:func:`roastlab.sim.kernels.integrate_into`): each stage's sensitivity is

    K_i = J_x(y_i) (S + h sum_j a_ij K_j) + J_u(y_i) du/dz(t_i) + J_p(y_i) dp/dz,

the derivative of the integrator's own step map (internal differentiation, with the step sizes
the state's error control chose), where J_x, J_u and J_p are the exact Jacobians of the one
right-hand side, generated from it symbolically (:mod:`roastlab.sim.jacobian`). One run gives
every column at once for about three right-hand-side evaluations per stage, instead of two
simulations per column for central differences, and no difference step to choose.
Tested against central differences and against CasADi's Jacobian (tests/test_sensitivity.py).

Finite differences, kept as the reference, :func:`ta_input_jacobian`: the sensitivity of the
probe reading to an input program by re-running the compiled integrator.

The program is the inlet gas temperature Tgi (or the heater setting) at every sample of a time grid (held linearly or
zero-order between samples, as in :func:`roastlab.sim.kernels.integrate_into`). Changing Tgi at
sample k cannot change anything before sample k - 1 (linear hold) or k (zero-order hold), so
each column of the Jacobian restarts the integration from the stored state there and runs to
the end: about n/2 full simulations for n samples instead of n, in parallel over the columns.
The restart takes fresh adaptive steps, so a column carries the integrator's local error
(~1e-4 degC) divided by the perturbation; with a 1 degC perturbation that is negligible.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import prange
from numba.core import types
from numba.extending import overload, register_jitable

from ..model.layout import N_INPUTS, N_PARAMS, S_H, S_TA, S_TM, S_X, U_GG, U_HEATER, U_TGI
from . import kernels as _k
from .cache import compiled, literal_entry
from .jacobian import OUTLET_FUNCTION_NAME, code_key
from .jacobian import load as _load_jacobian
from .kernels import (
    H0_S,
    H_MAX_S,
    MAX_STEPS,
    N_OUT,
    NS,
    STIFF_MARK,
    error_share,
    integrate_into,
    interval_inputs,
    next_step,
    rms_error,
)

_outlet_jacobian = register_jitable(_load_jacobian(OUTLET_FUNCTION_NAME))


@functools.cache
def _rhs_jacobian_for(key: int):
    """The generated Jacobian of the right-hand side with the model codes of combination ``key``
    compiled in (:func:`roastlab.sim.jacobian.load`; -1: read from ``p`` at run time)."""
    return register_jitable(_load_jacobian(key=key))


def _rhs_jacobian(key, x0, x1, x2, x3, x4, x5, u0, u1, u2, u3, p, want, f, Jx, Ju, Jp):
    """The generated Jacobian (:mod:`roastlab.sim.jacobian`) for compiled code: ``key`` a
    compile-time constant gives the function with that combination's codes written in, any other
    whole number the one that reads them from ``p``."""
    raise NotImplementedError("compiled code only")


@overload(_rhs_jacobian, prefer_literal=True)
def _rhs_jacobian_overload(key, x0, x1, x2, x3, x4, x5, u0, u1, u2, u3, p, want, f, Jx, Ju, Jp):
    function = _rhs_jacobian_for(key.literal_value if isinstance(key, types.IntegerLiteral) else -1)

    def impl(key, x0, x1, x2, x3, x4, x5, u0, u1, u2, u3, p, want, f, Jx, Ju, Jp):
        function(x0, x1, x2, x3, x4, x5, u0, u1, u2, u3, p, want, f, Jx, Ju, Jp)

    return impl


@compiled
def _column(k, t, Gg, Tgi, Q, F, which, states, ta_base, p, zoh, h_max, delta, jac):
    n = t.shape[0]
    start = k
    if not zoh and k > 0:
        start = k - 1  # a linear hold reaches back one interval
    m = n - start
    tgi = Tgi[start:].copy()
    q = Q[start:].copy()
    if which == 0:
        tgi[k - start] += delta
    else:
        q[k - start] += delta
    out = np.empty((m, N_OUT))
    x0 = np.empty(NS)
    for i in range(NS):
        x0[i] = states[start, i]
    integrate_into(t[start:], Gg[start:], tgi, q, F[start:], m, x0, p, zoh, h_max, out, H0_S, False)
    for i in range(start):
        jac[i, k] = 0.0
    for i in range(m):
        jac[start + i, k] = (out[i, S_TA] - ta_base[start + i]) / delta


@compiled(parallel=True)
def ta_input_jacobian(t, Gg, Tgi, Q, F, which, states, ta_base, p, zoh, h_max, delta, jac):
    """jac[i, k] = d Ta(t_i) / d u_k for the run whose states are ``states`` (n x NS).

    ``u`` is the inlet temperature Tgi [degC] (``which`` = 0) or the heater setting Q
    (``which`` = 1); ``ta_base`` is the run's probe reading, ``delta`` the forward-difference
    step in u's units. Rows before the first sample a change at k can reach are zero.
    """
    for k in prange(t.shape[0]):
        _column(np.int64(k), t, Gg, Tgi, Q, F, which, states, ta_base, p, zoh, h_max, delta, jac)


@compiled
def _stage(y, g, T, q, f, p, w, k, zoh, du_ptr, du_j, du_c, du_v, Y, pq, pc, pv, want, nc, fx, Jx, Ju, Jp, K, key):
    """One stage at state ``y`` and inputs (g, T, q, f): fx = f(y, u) and, over the first ``nc``
    columns, K = J_x Y + J_u du/dz + J_p dp/dz. du/dz is sample k's sparse rows (held, or
    blended with sample k + 1's by ``w`` under a linear hold); dp/dz the triplets (pq, pc, pv),
    whose parameters ``want`` flags (only their columns of J_p are computed); ``key`` the model
    codes' combination (:func:`_rhs_jacobian`).
    Loops run over the contiguous column index, so the compiler can vectorise them."""
    _rhs_jacobian(key, y[0], y[1], y[2], y[3], y[4], y[5], g, T, q, f, p, want, fx, Jx, Ju, Jp)
    for i in range(NS):
        for c in range(nc):
            K[i, c] = 0.0
        for j in range(NS):
            a = Jx[i, j]
            if a != 0.0:
                for c in range(nc):
                    K[i, c] += a * Y[j, c]
    for e in range(pq.shape[0]):
        c = pc[e]
        if c < nc:
            for i in range(NS):
                K[i, c] += Jp[i, pq[e]] * pv[e]
    if du_ptr.shape[0] > 0:
        for kk in range(k, k + (1 if zoh else 2)):
            share = 1.0 if zoh else (1.0 - w if kk == k else w)
            if share == 0.0:
                continue
            for e in range(du_ptr[kk], du_ptr[kk + 1]):
                c = du_c[e]
                if c < nc:
                    v = share * du_v[e]
                    for i in range(NS):
                        K[i, c] += Ju[i, du_j[e]] * v


#: Dormand-Prince 5(4) as a table (rows: stages 2-7, the 7th is the 5th-order solution),
#: nodes and error weights: the same numbers as :mod:`roastlab.sim.kernels` spells out.
_DP_A = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [_k._A21, 0.0, 0.0, 0.0, 0.0, 0.0],
        [_k._A31, _k._A32, 0.0, 0.0, 0.0, 0.0],
        [_k._A41, _k._A42, _k._A43, 0.0, 0.0, 0.0],
        [_k._A51, _k._A52, _k._A53, _k._A54, 0.0, 0.0],
        [_k._A61, _k._A62, _k._A63, _k._A64, _k._A65, 0.0],
        [_k._B1, 0.0, _k._B3, _k._B4, _k._B5, _k._B6],
    ]
)
_DP_C = np.array([0.0, _k._C2, _k._C3, _k._C4, _k._C5, 1.0, 1.0])
_DP_E = np.array([_k._E1, 0.0, _k._E3, _k._E4, _k._E5, _k._E6, _k._E7])


@compiled
def integrate_sens_into(
    t,
    Gg,
    Tgi,
    Q,
    F,
    n,
    x0,
    p,
    zoh,
    h_max,
    S0,
    ncol,
    du_ptr,
    du_j,
    du_c,
    du_v,
    pq,
    pc,
    pv,
    rows,
    out,
    outS,
    h0=H0_S,
    key=-1,
):
    """:func:`roastlab.sim.kernels.integrate_into` (same steps, same states) with the forward
    sensitivity S = dx/dz of m directions z.

    ``S0`` (NS, m): dx(0)/dz. ``ncol`` (n,): during interval k only the first ncol[k] columns of
    S can be non-zero (a program's knots in time order), or empty for all m. Inputs' derivatives,
    sparse by sample: d u_{du_j[e]}(t_k) / d z_{du_c[e]} = du_v[e] for e in du_ptr[k]:du_ptr[k+1]
    (u = [Gg, Tgi, heater, fan]; held between samples like the inputs), or an empty ``du_ptr``
    when no input depends on z. dp/dz as triplets: d p[pq[e]] / d z[pc[e]] = pv[e].
    Writes the states to ``out[:n, :NS]`` and S[rows[r], :] to ``outS[:n, r, :]``; returns the
    next step size. The states' error control alone chooses the steps. ``key``: the model codes'
    combination ``p`` holds, as a compile-time constant (:func:`roastlab.sim.jacobian.code_key`), or
    -1 (the codes read from ``p``).
    """
    m = S0.shape[1]
    A, C, E = _DP_A, _DP_C, _DP_E
    x = np.empty(NS)
    S = np.zeros((NS, m))
    for i in range(NS):
        x[i] = x0[i]
        out[0, i] = x0[i]
        for c in range(m):
            S[i, c] = S0[i, c]
    for r in range(rows.shape[0]):
        for c in range(m):
            outS[0, r, c] = S[rows[r], c]
    kx = np.empty((7, NS))
    KS = np.zeros((7, NS, m))
    y = np.empty(NS)
    Y = np.zeros((NS, m))
    Jx = np.zeros((NS, NS))
    Ju = np.zeros((NS, N_INPUTS))
    Jp = np.zeros((NS, N_PARAMS))
    want = np.zeros(N_PARAMS, dtype=np.bool_)  # the parameters z moves: J_p's columns to compute
    for e in range(pq.shape[0]):
        want[pq[e]] = True
    fx = np.empty(NS)
    h = min(h_max, h0)
    steps = 0
    nc = m
    for k in range(n - 1):
        dt, g0, T0, q0, f0, dg, dT, dq, df = interval_inputs(t, Gg, Tgi, Q, F, k, zoh)
        if ncol.shape[0] > 0:
            nc = min(ncol[k], m)
        s = 0.0
        # as in integrate_into: a zero-order hold jumps at the sample, so the first stage is new; a
        # linear hold reuses the last stage (a column that becomes active here starts at zero:
        # its state sensitivity is zero and so is its input's derivative at this sample)
        if zoh or k == 0:
            _stage(
                x, g0, T0, q0, f0, p, 0.0, k, zoh, du_ptr, du_j, du_c, du_v, S, pq, pc, pv, want, nc, fx, Jx, Ju, Jp,
                KS[0], key,
            )  # fmt: skip
            for i in range(NS):
                kx[0, i] = fx[i]
        while s < dt:
            steps += 1
            if steps > MAX_STEPS or h < 1e-9 * dt:
                _fill(out, outS, k + 1, n, STIFF_MARK)
                return h
            last = False
            h_try = h
            if s + h >= dt * (1.0 - 1e-12):
                h = dt - s
                last = True
            for st in range(1, 7):
                a = s + C[st] * h
                for i in range(NS):
                    acc = 0.0
                    for j in range(st):
                        acc += A[st, j] * kx[j, i]
                    y[i] = x[i] + h * acc
                    for c in range(nc):
                        Y[i, c] = S[i, c]
                for j in range(st):
                    coef = h * A[st, j]
                    if coef != 0.0:
                        for i in range(NS):
                            for c in range(nc):
                                Y[i, c] += coef * KS[j, i, c]
                _stage(
                    y, g0 + dg * a, T0 + dT * a, q0 + dq * a, f0 + df * a, p, a / dt, k, zoh,
                    du_ptr, du_j, du_c, du_v, Y, pq, pc, pv, want, nc, fx, Jx, Ju, Jp, KS[st], key,
                )  # fmt: skip
                for i in range(NS):
                    kx[st, i] = fx[i]
            # the last stage was evaluated at the 5th-order solution: y and Y hold it
            err = 0.0
            for i in range(NS):
                e = 0.0
                for j in range(7):
                    e += E[j] * kx[j, i]
                err += error_share(h * e, x[i], y[i], i)
            err = rms_error(err)
            if not (err == err):  # as integrate_into: NaN below a microsecond step, else a smaller step
                if h < 1e-6:
                    _fill(out, outS, k + 1, n, np.nan)
                    return h
                h = h * 0.2
                continue
            if err <= 1.0:
                s = dt if last else s + h
                for i in range(NS):
                    x[i] = y[i]
                    kx[0, i] = kx[6, i]
                    for c in range(nc):
                        S[i, c] = Y[i, c]
                        KS[0, i, c] = KS[6, i, c]
                if x[S_X] < 0.0:
                    x[S_X] = 0.0
                    for c in range(nc):
                        S[S_X, c] = 0.0
            h = next_step(err, h, h_try, last, h_max)
        for i in range(NS):
            out[k + 1, i] = x[i]
        for r in range(rows.shape[0]):
            for c in range(m):
                outS[k + 1, r, c] = S[rows[r], c]
    return h


@compiled
def _fill(out, outS, start, n, value):
    for j in range(start, n):
        for i in range(NS):
            out[j, i] = value
        for r in range(outS.shape[1]):
            for c in range(outS.shape[2]):
                outS[j, r, c] = value


@compiled(parallel=True)
def sens_population_kernel(
    T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, S0, PQ, PC, PV, rows, out_x, out_s, key
):
    """Forward sensitivities of ``len(batch_of)`` runs in parallel (as
    :func:`roastlab.sim.kernels.ta_population_kernel`): run i starts from X0[i] with S0[i]
    (NS, m), parameters PP[i] and dp/dz triplets PQ[i], PC[i], PV[i] (pad with PV = 0); no input
    depends on z. Writes the states to out_x[i] and S[rows] to out_s[i]. ``key``: the model
    codes' combination every PP[i] holds (:func:`population_sensitivities` passes it as a constant)."""
    no_int = np.zeros(0, dtype=np.int64)
    no_float = np.zeros(0)
    for i in prange(batch_of.shape[0]):
        b = batch_of[i]
        integrate_sens_into(
            T[b], GG[b], TGI[b], QQ[b], FF[b], N[b], X0[i], PP[i], zoh, h_max, S0[i], no_int,
            no_int, no_int, no_int, no_float, PQ[i], PC[i], PV[i], rows, out_x[i], out_s[i], H0_S, key,
        )  # fmt: skip


def population_sensitivities(T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, S0, PQ, PC, PV, rows, out_x, out_s):
    """:func:`sens_population_kernel` compiled for the model codes the runs share
    (:func:`roastlab.sim.jacobian.code_key`, a compile-time constant: the Jacobian's tests of them
    are decided once, not at every stage: a sensitivity run of dataset-I takes a fifth less,
    docs/performance.md), or reading them from ``PP`` where the runs differ."""
    key = code_key(PP)
    args = (T, GG, TGI, QQ, FF, N, batch_of, X0, PP, bool(zoh), float(h_max), S0, PQ, PC, PV, rows, out_x, out_s, key)
    if key < 0:
        sens_population_kernel(*args)
        return
    _rhs_jacobian_for(key)  # its module, whose name a kernel loaded from the disk cache refers to
    literal_entry(sens_population_kernel, args, len(args) - 1)(*args)


@compiled(parallel=True)
def outlet_sens_kernel(GG, TGI, FF, N, batch_of, X, S, PP, PQ, PC, PV, zoh, out_g, out_dg):
    """The outlet gas temperature Tgo (eq. 15e) and its exact derivative dTgo/dz at every sample
    of each run, from the run's states X[i] (nmax, NS) and state sensitivities S[i] (nmax, NS, m)
    (:func:`sens_population_kernel` with every state's row) and the dp/dz triplets; no input
    depends on z. Sample k >= 1 uses the inputs :func:`roastlab.sim.kernels.integrate_into`
    gives Tgo there (sample k - 1's under a zero-order hold, k's under a linear one)."""
    m = S.shape[3]
    for i in prange(batch_of.shape[0]):
        b = batch_of[i]
        g = np.zeros(1)
        Gx = np.zeros((1, NS))
        Gu = np.zeros((1, N_INPUTS))
        Gp = np.zeros((1, N_PARAMS))
        for k in range(N[b]):
            j = k - 1 if (zoh and k > 0) else k
            _outlet_jacobian(X[i, k, 0], X[i, k, 1], X[i, k, 2], X[i, k, 3], X[i, k, 4], X[i, k, 5],
                             GG[b, j], TGI[b, j], 0.0, FF[b, j], PP[i], g, Gx, Gu, Gp)  # fmt: skip
            out_g[i, k] = g[0]
            for c in range(m):
                v = 0.0
                for st in range(NS):
                    v += Gx[0, st] * S[i, k, st, c]
                out_dg[i, k, c] = v
            for e in range(PQ.shape[1]):
                out_dg[i, k, PC[i, e]] += Gp[0, PQ[i, e]] * PV[i, e]


@functools.lru_cache(maxsize=64)
def _program_directions(n: int, which: int, extras: tuple, zoh: bool):
    """The fixed arrays of :func:`program_sensitivity` for a program's shape (cached: a receding
    horizon asks for the same shape at every step)."""
    e = len(extras)
    m = n + e
    S0 = np.zeros((NS, m))
    # columns: the extras first (active from the start), then the knots in time order, so the
    # columns live during interval k are a prefix (ncol)
    per_sample = [[(U_TGI if which == 0 else U_HEATER, e + k, 1.0)] for k in range(n)]
    for j, name in enumerate(extras):
        if name == "Gg":
            for k in range(n):
                per_sample[k].append((U_GG, j, 1.0))
        elif name == "Tm0":
            S0[S_TM, j] = 1.0
        else:
            raise ValueError(f"unknown program direction {name!r}")
    if which == 1:
        S0[S_H, e] = 1.0
    du_ptr = np.zeros(n + 1, dtype=np.int64)
    du_ptr[1:] = np.cumsum([len(r) for r in per_sample])
    flat = [item for r in per_sample for item in r]
    du_j = np.array([a for a, _, _ in flat], dtype=np.int64)
    du_c = np.array([b for _, b, _ in flat], dtype=np.int64)
    du_v = np.array([v for _, _, v in flat], dtype=np.float64)
    ncol = e + np.minimum(np.arange(n, dtype=np.int64) + (1 if zoh else 2), n)
    for a in (S0, du_ptr, du_j, du_c, du_v, ncol):
        a.setflags(write=False)
    return S0, ncol, du_ptr, du_j, du_c, du_v


_NO_INT = np.zeros(0, dtype=np.int64)
_NO_FLOAT = np.zeros(0)
_ROW_TA = np.array([S_TA], dtype=np.int64)


def program_sensitivity(t, Gg, Tgi, Q, F, x0, p, zoh, which, extras=(), h_max=H_MAX_S):
    """States and the exact d Ta / d z of a run whose decided input is a program on the samples.

    ``which`` 0: z's first n entries are the inlet temperature Tgi at each sample [degC]; 1: the
    heater setting (whose lag state starts at the first setting, x0[H] = u_0, as the simulator
    does). ``extras`` name further directions after the knots: ``"Gg"`` (a constant gas flow
    [kg/s] on every sample) and ``"Tm0"`` (the drum's start temperature [degC]).
    Returns (states (n, NS), dTa (n, n + len(extras))).
    """
    t = np.ascontiguousarray(t, dtype=np.float64)
    n = t.shape[0]
    e = len(extras)
    S0, ncol, du_ptr, du_j, du_c, du_v = _program_directions(n, int(which), tuple(extras), bool(zoh))
    out = np.empty((n, NS))
    outS = np.empty((n, 1, n + e))
    integrate_sens_into(
        t, np.ascontiguousarray(Gg, dtype=np.float64), np.ascontiguousarray(Tgi, dtype=np.float64),
        np.ascontiguousarray(Q, dtype=np.float64), np.ascontiguousarray(F, dtype=np.float64), n,
        np.ascontiguousarray(x0, dtype=np.float64), p, zoh, h_max, S0, ncol, du_ptr, du_j, du_c, du_v,
        _NO_INT, _NO_INT, _NO_FLOAT, _ROW_TA, out, outS,
    )  # fmt: skip
    if e == 0:
        return out, outS[:, 0, :]
    return out, np.concatenate([outS[:, 0, e:], outS[:, 0, :e]], axis=1)
