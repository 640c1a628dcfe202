"""Many runs on one core at once: the Dormand-Prince integrator over SIMD lanes.

:func:`roastlab.sim.kernels.integrate_into` takes one run through its steps; one evaluation of the
right-hand side is ~35 ns of scalar work, a third of it four calls of the C library's ``exp``.
Here :data:`LANES` runs share the same instructions: every stage evaluates the one right-hand
side (:func:`roastlab.model.rhs.derivatives`, rebuilt by :func:`roastlab.model.rhs.rebind` with
``exp``, ``power`` and ``cube_root`` of :mod:`roastlab.sim.vecmath`, plain arithmetic the compiler turns into
vector instructions) for every lane in one loop, so a vector register carries several runs.

Each lane keeps its own step size, sample interval and error control, exactly the rules of
:func:`~roastlab.sim.kernels.integrate_into` (:func:`~roastlab.sim.kernels.next_step`,
:func:`~roastlab.sim.kernels.error_share`, :func:`~roastlab.sim.kernels.interval_inputs`), so
a lane takes the steps the scalar integrator takes and the states agree to rounding (the
vectorised ``exp`` is within one unit in the last place of the C library's; tested). A lane
whose run has ended takes the next run of its share, so lanes stay busy while runs of different
lengths and stiffness finish at different times.
"""

from __future__ import annotations

import warnings

import numpy as np
from numba import literally, prange
from numba.core import cgutils, types
from numba.core.errors import NumbaIRAssumptionWarning
from numba.extending import intrinsic, register_jitable

from ..model.layout import (
    I_CONTACT,
    I_EPSRAD,
    I_FEXP,
    I_HEXP,
    I_HLEXP,
    I_HPROBE,
    I_KFLIGHT,
    I_PROBEGAS,
    I_PROBELAW,
    I_SWELL,
    I_XEXP,
    N_PARAMS,
)
from ..model.rhs import outlet_gas_C, rebind
from . import vecmath
from .cache import compiled, literal_entry
from .kernels import (
    _A21,
    _A31,
    _A32,
    _A41,
    _A42,
    _A43,
    _A51,
    _A52,
    _A53,
    _A54,
    _A61,
    _A62,
    _A63,
    _A64,
    _A65,
    _B1,
    _B3,
    _B4,
    _B5,
    _B6,
    _C2,
    _C3,
    _C4,
    _C5,
    _E1,
    _E3,
    _E4,
    _E5,
    _E6,
    _E7,
    H0_S,
    I_TGO,
    NS,
    STIFF_MARK,
    error_share,
    interval_inputs,
    next_step_given,
    rms_error,
    step_budget,
)

#: Runs one core integrates together. The compiler takes 4 lanes per vector instruction (256-bit
#: registers, also on AVX-512 processors, for which LLVM's tuning prefers them: docs/performance.md,
#: "What a vector instruction holds"); 32 give each loop eight independent iterations to overlap. On the
#: project's 2-core VM, one thread, the benchmark's population: 8 lanes 16.2, 16 lanes 14.8, 32 lanes
#: 13.7 us per run (scalar integrator 29.7); 32 lanes' work array (~29 kB) still fits the L1 cache.
LANES = 32
#: Groups of lanes per thread: the unit of parallel work is a group, which works through its share of
#: the runs (a lane whose run ends takes the next). One: numba's default scheduling gives each thread
#: one equal share of a parallel loop, so more groups per thread even nothing out, and each group ends
#: in a tail where its last runs go on with its other lanes idle, every step a whole 32-lane
#: evaluation. A stiff run in a fit's screening makes that tail long: the Bullet example's fit took
#: 5.8-6.4 s with one group per thread against 7.2-7.6 s with four (one thread), the same model file
#: (docs/performance.md, "One group per thread").
GROUPS_PER_THREAD = 1

# the one right-hand side over vectorisable elementary operations, compiled inline into the lanes
_vector_model = rebind(exp=vecmath.exp, power=vecmath.power, cube_root=vecmath.cube_root)
for _name, _function in vars(_vector_model).items():
    # derivatives inline in numba's IR, as in the scalar integrator (the compiler would not inline a
    # function that large, and a call stops the loop's vectorisation); the compiler inlines the small
    # ones itself (inlining them all in numba's IR too took 23 s of compiling instead of 6, for nothing)
    register_jitable(inline="always" if _name == "derivatives" else "never")(_function)
_derivatives = _vector_model.derivatives

# A lane group keeps everything its lanes compute in one flat array Z, row after row of LANES
# values: with the row offsets compile-time constants the compiler proves that a stage's loads
# and stores do not overlap and vectorises the loop over lanes without run-time checks.
_X = 0  # the states (NS rows)
_Y = _X + NS  # a stage's argument
_XN = _Y + NS  # the trial step's end
_KO = _XN + NS  # the right-hand side of the last evaluation
_K1 = _KO + NS  # the seven stages, NS rows each
_U = _K1 + 7 * NS  # per lane: s, the trial step, a stage's time [s], the error and err^-0.2, the inputs, slopes
_S, _HS, _A, _ERR, _POW, _G0, _DG, _T0, _DT, _Q0, _DQ, _F0, _DF = range(_U, _U + 13)
_PT = _U + 13  # the parameter vector (N_PARAMS rows)
_ROWS = _PT + N_PARAMS


@register_jitable
def _at(row, lane):
    """Z's index of ``row`` for lane ``lane`` (unsigned: no negative-index wraparound for the compiler
    to reason about). A small function the compiler inlines itself: inlined in numba's IR as well, at
    each of the thousands of places the lanes code indexes Z, it took half of a set of laws' compile
    (83 s against 43 s on 2026-11-28, 2 cores) and ran no faster (lanes over scalar 0.75 either way)."""
    return np.uint64(row * LANES + lane)


@register_jitable
def _k(stage, i):
    """Z's row of state i's derivative at Dormand-Prince stage ``stage`` (1-7)."""
    return _K1 + (stage - 1) * NS + i


#: The parameter slots that choose a law (bed laws, the moisture exponent, the heater's and the fan's
#: drive exponents, the heater's lag exponent, the beans' swelling): one value for every run of a lanes
#: call, compiled in as constants (see :func:`law_key`). An exponent that is not a whole number, a gas
#: burner's or a draft's square root, a radiant heater's 3/4, runs the scalar integrator, as its power in
#: every lane would cost more than the lanes gain; so does a swelling that is not a whole number, as the
#: key holds whole numbers only (its cube root is cheap, :func:`roastlab.sim.vecmath.cube_root`, but as
#: a per-lane value the paper's beans would pay for it too: a vector instruction computes both sides of
#: ``swell_factor``'s branch).
LAW_SLOTS = (I_CONTACT, I_PROBELAW, I_PROBEGAS, I_XEXP, I_HEXP, I_FEXP, I_HLEXP, I_SWELL)
_LAW_BASE = 4  # each law slot's value is a whole number below this
#: The parameter slots of terms that a 0 turns off (the right-hand side tests ``p[slot] == 0.0``): the
#: probe's depth scale (0, the paper's probe, always immersed), the wall's radiation and the gas meeting
#: the bed's surface. Where every run of a call holds 0 in one, the key says so (:func:`law_key`) and the
#: lanes compile the 0 in, so the term's test is decided when compiling instead of both of its sides
#: computed in every lane; any other value is read per lane, as every parameter is. The same values
#: either way, to the bit; the paper's runs are about a tenth faster (docs/performance.md, "Terms that
#: are off"). The shell loss, the heater's gains and the fan's flow are not among them: a fitted value
#: often ends on its bound 0, and a model fitted with it free would then run on a second kernel.
OFF_SLOTS = (I_HPROBE, I_EPSRAD, I_KFLIGHT)
_OFF_BASE = _LAW_BASE ** len(LAW_SLOTS)  # a key's off bits (law_key) start here


def law_key(PP: np.ndarray) -> int | None:
    """The laws the runs of parameter vectors ``PP`` (runs x N_PARAMS) share, as one whole number
    (slot j's value times 4^j), or None when they differ between runs or are not whole numbers
    below 4 (the caller then uses the scalar integrator).

    The lanes integrator is compiled once per key with these values as constants, so the laws'
    branches are decided when compiling instead of evaluated, both sides, in every lane
    (a vector instruction computes both sides of a branch). Paper's laws: contact, probe and probe
    gas 0, moisture exponent 2, heater and fan exponents 1: 128 + 256 + 1024 = 1408. Above the laws,
    bit j (times 4^8) says that :data:`OFF_SLOTS`' j-th term is off in every run: with the paper's
    probe and neither extension, 1408 + 7 4^8 = 460160.
    """
    if PP.shape[0] == 0:
        return None
    first = PP[0, list(LAW_SLOTS)]
    if not np.all(PP[:, list(LAW_SLOTS)] == first[None, :]):
        return None
    if not compiles_in(first):
        return None
    off = sum(2**j for j, slot in enumerate(OFF_SLOTS) if np.all(PP[:, slot] == 0.0))
    return int(sum(int(v) * _LAW_BASE**j for j, v in enumerate(first))) + off * _OFF_BASE


def compiles_in(values) -> bool:
    """Whether law-slot ``values`` can be compiled in as constants (:func:`law_key`): whole numbers
    from 0 to 3. Others (a gas burner's square root, a swelling of 0.5) run the scalar integrator."""
    v = np.asarray(values, dtype=float)
    return bool(np.all((v == np.round(v)) & (v >= 0) & (v < _LAW_BASE)))


@intrinsic
def _lane_parameters(typingctx, Z, lane, key):
    """Lane ``lane``'s parameter vector (Z's rows from _PT) as a tuple of values, the law slots and the
    slots of the terms off in every run the constants of ``key`` (:func:`law_key`, a compile-time
    constant). Loads only, no array view, whose reference counting would put a call into the lane loop
    and stop its vectorisation."""
    if not isinstance(key, types.IntegerLiteral):
        return None
    laws = {slot: float((key.literal_value // _LAW_BASE**j) % _LAW_BASE) for j, slot in enumerate(LAW_SLOTS)}
    laws.update({slot: 0.0 for j, slot in enumerate(OFF_SLOTS) if (key.literal_value // _OFF_BASE) >> j & 1})
    tup = types.UniTuple(types.float64, N_PARAMS)

    def codegen(context, builder, signature, args):
        aryty = signature.args[0]
        ary = context.make_array(aryty)(context, builder, args[0])
        values = []
        for q in range(N_PARAMS):
            if q in laws:
                values.append(context.get_constant(types.float64, laws[q]))
                continue
            index = builder.add(context.get_constant(types.intp, (_PT + q) * LANES), args[1])
            values.append(builder.load(cgutils.get_item_pointer(context, builder, aryty, ary, [index])))
        return context.make_tuple(builder, tup, values)

    return tup(Z, lane, key), codegen


@compiled(error_model="numpy")
def _evaluate(Z, key):
    """The right-hand side at rows _Y.. of every lane, at its input time (row _A), into rows _KO..:
    one Dormand-Prince stage of all lanes in one vectorised loop; the laws of ``key`` (:func:`law_key`)."""
    literally(key)  # compiled once per key: the laws are constants
    for lane in range(LANES):
        a = Z[_at(_A, lane)]
        d = _derivatives(
            Z[_at(_Y, lane)],
            Z[_at(_Y + 1, lane)],
            Z[_at(_Y + 2, lane)],
            Z[_at(_Y + 3, lane)],
            Z[_at(_Y + 4, lane)],
            Z[_at(_Y + 5, lane)],
            Z[_at(_G0, lane)] + Z[_at(_DG, lane)] * a,
            Z[_at(_T0, lane)] + Z[_at(_DT, lane)] * a,
            Z[_at(_Q0, lane)] + Z[_at(_DQ, lane)] * a,
            Z[_at(_F0, lane)] + Z[_at(_DF, lane)] * a,
            _lane_parameters(Z, lane, key),
        )
        for i in range(NS):
            Z[_at(_KO + i, lane)] = d[i]


@register_jitable(inline="always")
def _stage(Z, stage, a1, a2, a3, a4, a5, a6, c, key):
    """Dormand-Prince stage ``stage`` (2-7) of every lane: its argument x + h sum_j a_j k_j at time
    s + c h, and the right-hand side there into k_stage (for stage 7 the argument, the step's end,
    also into _XN). Inlined where ``stage`` and the coefficients are constants, so every row below is
    one and a zero coefficient's term is left out, as the scalar integrator writes the sums (not
    multiplied by 0: a stage left over from a rejected non-finite trial would make it NaN)."""
    for lane in range(LANES):
        Z[_at(_A, lane)] = Z[_at(_S, lane)] + c * Z[_at(_HS, lane)]
    for i in range(NS):
        for lane in range(LANES):
            acc = a1 * Z[_at(_k(1, i), lane)]
            if a2 != 0.0:
                acc += a2 * Z[_at(_k(2, i), lane)]
            if a3 != 0.0:
                acc += a3 * Z[_at(_k(3, i), lane)]
            if a4 != 0.0:
                acc += a4 * Z[_at(_k(4, i), lane)]
            if a5 != 0.0:
                acc += a5 * Z[_at(_k(5, i), lane)]
            if a6 != 0.0:
                acc += a6 * Z[_at(_k(6, i), lane)]
            Z[_at(_Y + i, lane)] = Z[_at(_X + i, lane)] + Z[_at(_HS, lane)] * acc
    _evaluate(Z, key)
    for i in range(NS):
        for lane in range(LANES):
            Z[_at(_k(stage, i), lane)] = Z[_at(_KO + i, lane)]
    if stage == 7:
        for i in range(NS):
            for lane in range(LANES):
                Z[_at(_XN + i, lane)] = Z[_at(_Y + i, lane)]


@compiled(parallel=True, error_model="numpy")
def lanes_population_kernel(T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, cols, out, tol_scale, key, threads):
    """Simulate ``len(batch_of)`` runs, :data:`LANES` at a time per core.

    Arguments as :func:`roastlab.sim.kernels.simulate_population_kernel`; ``cols`` (int64) names
    the output columns kept (states 0-5, :data:`~roastlab.sim.kernels.I_TGO` for the outlet gas),
    written to out[i, :N[b], j] for ``cols[j]``; ``tol_scale`` as in
    :func:`~roastlab.sim.kernels.integrate_into`.
    """
    runs = batch_of.shape[0]
    groups = max(1, min(runs // (2 * LANES), GROUPS_PER_THREAD * threads))
    for g in prange(groups):
        _lane_group(T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, cols, out, tol_scale, g * runs // groups,
                    (g + 1) * runs // groups, key)  # fmt: skip


@compiled
def _write_row(out, r, j, cols, Z, lane, tgo):
    for c in range(cols.shape[0]):
        col = cols[c]
        out[r, j, c] = tgo if col == I_TGO else Z[_at(_X + col, lane)]


@compiled(error_model="numpy")
def _lane_group(T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, cols, out, tol_scale, lo, hi, key):
    """Runs lo..hi-1 through :data:`LANES` lanes; a lane that finishes takes the next run."""
    W = LANES
    Z = np.zeros(_ROWS * W)
    for lane in range(W):  # idle lanes compute on a valid parameter set and state
        for q in range(N_PARAMS):
            Z[_at(_PT + q, lane)] = PP[lo, q]
        for i in range(NS):
            Z[_at(_X + i, lane)] = X0[lo, i]
    H = np.full(W, H0_S)  # the step size each lane tries next
    DTI = np.ones(W)  # each lane's sample interval [s]
    LAST = np.zeros(W, dtype=np.bool_)
    run = np.full(W, -1, dtype=np.int64)
    K = np.zeros(W, dtype=np.int64)
    STEPS = np.zeros(W, dtype=np.int64)
    FRESH = np.zeros(W, dtype=np.bool_)  # lanes whose first stage must be evaluated anew
    xl = np.empty(NS)
    with_tgo = _wants_tgo(cols)
    nxt = lo
    active = 0
    for lane in range(W):
        while nxt < hi and run[lane] < 0:
            active += _start(lane, nxt, T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, cols, out, with_tgo, Z,
                             H, DTI, run, K, STEPS, FRESH)  # fmt: skip
            nxt += 1
    while active > 0:
        _first_stages(Z, FRESH, key)
        for lane in range(W):
            s = Z[_at(_S, lane)]
            last = s + H[lane] >= DTI[lane] * (1.0 - 1e-12)
            LAST[lane] = last
            Z[_at(_HS, lane)] = DTI[lane] - s if last else H[lane]  # land exactly on the next sample
        _stage(Z, 2, _A21, 0.0, 0.0, 0.0, 0.0, 0.0, _C2, key)
        _stage(Z, 3, _A31, _A32, 0.0, 0.0, 0.0, 0.0, _C3, key)
        _stage(Z, 4, _A41, _A42, _A43, 0.0, 0.0, 0.0, _C4, key)
        _stage(Z, 5, _A51, _A52, _A53, _A54, 0.0, 0.0, _C5, key)
        _stage(Z, 6, _A61, _A62, _A63, _A64, _A65, 0.0, 1.0, key)
        _stage(Z, 7, _B1, 0.0, _B3, _B4, _B5, _B6, 1.0, key)
        for lane in range(W):  # every lane's error norm at once (integrate_into's rule)
            h = Z[_at(_HS, lane)]
            e2 = 0.0
            for i in range(NS):
                e = h * (
                    _E1 * Z[_at(_k(1, i), lane)] + _E3 * Z[_at(_k(3, i), lane)] + _E4 * Z[_at(_k(4, i), lane)]
                    + _E5 * Z[_at(_k(5, i), lane)] + _E6 * Z[_at(_k(6, i), lane)] + _E7 * Z[_at(_k(7, i), lane)]
                )  # fmt: skip
                e2 += error_share(e, Z[_at(_X + i, lane)], Z[_at(_XN + i, lane)], i)
            err = rms_error(e2) / tol_scale
            Z[_at(_ERR, lane)] = err
            Z[_at(_POW, lane)] = vecmath.power(err, -0.2)
        # each lane's bookkeeping after its trial, integrate_into's rules
        for lane in range(W):
            r = run[lane]
            if r < 0:
                continue
            STEPS[lane] += 1
            b = batch_of[r]
            k = K[lane]
            n = N[b]
            h = Z[_at(_HS, lane)]
            err = Z[_at(_ERR, lane)]
            done = False
            if STEPS[lane] > step_budget(n, tol_scale) or H[lane] < 1e-9 * DTI[lane]:
                # the step budget spent or the step collapsed: too stiff for an explicit method
                _mark(out, r, k + 1, n, cols, STIFF_MARK)
                done = True
            elif not (err == err):
                if h < 1e-6:  # non-finite down to a microsecond step: NaN rather than loop or lie
                    _mark(out, r, k + 1, n, cols, np.nan)
                    done = True
                else:
                    H[lane] = h * 0.2
            else:
                last = LAST[lane]
                if err <= 1.0:
                    Z[_at(_S, lane)] = DTI[lane] if last else Z[_at(_S, lane)] + h
                    for i in range(NS):
                        Z[_at(_X + i, lane)] = Z[_at(_XN + i, lane)]
                        Z[_at(_k(1, i), lane)] = Z[_at(_k(7, i), lane)]  # first same as last
                    if Z[_at(_X + 2, lane)] < 0.0:
                        Z[_at(_X + 2, lane)] = 0.0
                H[lane] = next_step_given(err, Z[_at(_POW, lane)], h, H[lane], last, h_max)
                if err <= 1.0 and last:  # the sample interval is done
                    k += 1
                    K[lane] = k
                    tgo = 0.0
                    if with_tgo:
                        j = k - 1 if zoh else k
                        for i in range(NS):
                            xl[i] = Z[_at(_X + i, lane)]
                        tgo = outlet_gas_C(xl, GG[b, j], TGI[b, j], FF[b, j], PP[r])
                    _write_row(out, r, k, cols, Z, lane, tgo)
                    if k == n - 1:
                        done = True
                    else:
                        _interval(lane, k, b, T, GG, TGI, QQ, FF, zoh, Z, DTI, False, FRESH)
            if done:
                run[lane] = -1
                active -= 1
                while nxt < hi and run[lane] < 0:
                    active += _start(lane, nxt, T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, cols, out,
                                     with_tgo, Z, H, DTI, run, K, STEPS, FRESH)  # fmt: skip
                    nxt += 1


@compiled
def _wants_tgo(cols):
    for c in range(cols.shape[0]):
        if cols[c] == I_TGO:
            return True
    return False


@compiled
def _mark(out, r, j0, n, cols, value):
    """Rows j0..n-1 of run r hold ``value`` (where integrate_into gave up)."""
    for j in range(j0, n):
        for c in range(cols.shape[0]):
            out[r, j, c] = value


@compiled(error_model="numpy")
def _interval(lane, k, b, T, GG, TGI, QQ, FF, zoh, Z, DTI, first, FRESH):
    """Lane ``lane`` enters sample interval k of batch b: its inputs and slopes, s = 0, and marked
    FRESH where integrate_into evaluates the first stage anew (a zero-order hold's jump, or the first
    interval; :func:`_first_stages` does it for every marked lane at once before the next trial)."""
    dt, g0, t0, q0, f0, dg, dT, dq, df = interval_inputs(T[b], GG[b], TGI[b], QQ[b], FF[b], k, zoh)
    DTI[lane] = dt
    Z[_at(_S, lane)] = 0.0
    Z[_at(_G0, lane)] = g0
    Z[_at(_T0, lane)] = t0
    Z[_at(_Q0, lane)] = q0
    Z[_at(_F0, lane)] = f0
    Z[_at(_DG, lane)] = dg
    Z[_at(_DT, lane)] = dT
    Z[_at(_DQ, lane)] = dq
    Z[_at(_DF, lane)] = df
    FRESH[lane] = zoh or first


@compiled(error_model="numpy")
def _first_stages(Z, FRESH, key):
    """The first stage anew for the lanes marked FRESH (a run's start; every interval under a
    zero-order hold), all of them in one vectorised evaluation at their states and interval starts;
    the other lanes' results are discarded (their first stage is the last step's seventh). With no
    lane marked, nothing: under a linear hold most trials, whose first stages are all the last step's."""
    fresh = False
    for lane in range(LANES):
        fresh |= FRESH[lane]
    if not fresh:
        return
    for lane in range(LANES):
        for i in range(NS):
            Z[_at(_Y + i, lane)] = Z[_at(_X + i, lane)]
        Z[_at(_A, lane)] = 0.0
    _evaluate(Z, key)
    for lane in range(LANES):
        if FRESH[lane]:
            for i in range(NS):
                Z[_at(_k(1, i), lane)] = Z[_at(_KO + i, lane)]
            FRESH[lane] = False


@compiled(error_model="numpy")
def _start(lane, r, T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, cols, out, with_tgo, Z, H, DTI, run, K,
           STEPS, FRESH):  # fmt: skip
    """Put run r on lane ``lane``: its parameters, initial state and first output row. Returns 1, or 0
    for a run of one sample (nothing to integrate: the row is written and the lane stays free)."""
    b = batch_of[r]
    for i in range(NS):
        Z[_at(_X + i, lane)] = X0[r, i]
    for q in range(N_PARAMS):
        Z[_at(_PT + q, lane)] = PP[r, q]
    tgo = outlet_gas_C(X0[r], GG[b, 0], TGI[b, 0], FF[b, 0], PP[r]) if with_tgo else 0.0
    _write_row(out, r, 0, cols, Z, lane, tgo)
    if N[b] < 2:
        return 0
    run[lane] = r
    K[lane] = 0
    STEPS[lane] = 0
    H[lane] = min(h_max, H0_S)
    _interval(lane, 0, b, T, GG, TGI, QQ, FF, zoh, Z, DTI, True, FRESH)
    return 1


#: Fewest runs for which the population uses the lanes: with fewer, most of a group's lanes would idle.
MIN_RUNS = LANES


def usable(PP: np.ndarray) -> int | None:
    """The :func:`law_key` of the runs ``PP`` when the lanes integrator should take them (enough
    runs, one set of laws), else None."""
    return law_key(PP) if PP.shape[0] >= MIN_RUNS else None


def simulate_runs(T, GG, TGI, QQ, FF, N, batch_of, X0, PP, zoh, h_max, cols, out, tol_scale, key) -> None:
    """Run :func:`lanes_population_kernel` for the laws ``key`` (:func:`usable`) on numba's threads.

    The key is a compile-time constant of the kernel (:func:`roastlab.sim.cache.literal_entry`).
    """
    import numba

    args = (T, GG, TGI, QQ, FF, N, batch_of, X0, PP, bool(zoh), float(h_max), cols, out, float(tol_scale), int(key),
            numba.get_num_threads())  # fmt: skip
    with warnings.catch_warnings():
        # numba's own pedantic check of its SSA pass flags the phis of vecmath's inlined
        # conditional expressions ("not in scope"); the compiled code is correct (tested)
        warnings.simplefilter("ignore", NumbaIRAssumptionWarning)
        entry = literal_entry(lanes_population_kernel, args, 14)
    entry(*args)
