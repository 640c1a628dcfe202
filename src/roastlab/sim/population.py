"""Many simulations in one compiled, parallel call: parameter sets x batches.

Batches of different lengths are packed into padded arrays (:class:`PackedBatches`); every
run pairs one batch with one parameter vector and one initial state. From
:data:`roastlab.sim.lanes.MIN_RUNS` runs sharing one set of laws up, the runs go through the
lanes integrator (:mod:`roastlab.sim.lanes`: several runs per core in vector instructions, the
same steps); fewer go one at a time through the kernel of :func:`roastlab.simulate`. Either way
a run's values agree with one-at-a-time :func:`roastlab.simulate` to rounding (1e-9 degC, tested).

Parameters that vary between runs are addressed by name (:func:`param_columns`): the three
theta coefficients, any process constant, the metal mass, and the initial states
``Tb0_C, Tm0_C, X0, He0_kJ_kg, Ta0_C`` (X0 also updates the dry mass Mbd = Mb/(1+X0)).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..model.layout import S_TA, S_TB, S_TM
from ..model.parameters import REGISTRY, STATE0
from ..model.rhs import P, drum_at_charge_C, dry_mass_kg, pack_params
from . import lanes
from .kernels import H_MAX_S, I_TGO, N_OUT, NS, simulate_population_kernel, ta_population_kernel
from .simulate import InitialState, check_hold

#: Registry names that set a parameter-vector entry, and its index. ``Gg_kg_s`` sets the
#: gas-flow factor: the batch's Gg column is then a 1 kg/s placeholder (a map with
#: ``[Gg] identify = true``), so the factor is the flow itself.
PARAM_SLOTS = {name: P[q.slot] for name, q in REGISTRY.items() if q.slot in P}


@dataclass
class PackedBatches:
    """Batches packed for the population kernels.

    T, GG, TGI : (nb, nmax) padded inputs [s], [kg/s], [degC]; QQ, FF : (nb, nmax) heater and
    fan settings (zeros without the actuator extension); N : (nb,) valid lengths;
    TA : (nb, nmax) measured Ta, NaN-padded (NaN everywhere if not measured);
    TB2 : (nb, nmax) a second bean reading compared with Tb, NaN where not measured;
    ET : (nb, nmax) the roaster's ET as logged, compared with the outlet gas Tgo when fitted;
    x0 : (nb, 6) initial state vectors (X0 is the moisture everywhere else); PB : (nb, n_params) parameter vectors at the start theta;
    Mb : (nb,) green batch mass of each batch's plant [kg] (for Mbd when X0 varies).
    """

    T: np.ndarray
    GG: np.ndarray
    TGI: np.ndarray
    N: np.ndarray
    TA: np.ndarray
    x0: np.ndarray
    PB: np.ndarray
    Mb: np.ndarray
    names: list[str]
    zoh: bool
    h_max_s: float = H_MAX_S
    QQ: np.ndarray | None = None
    FF: np.ndarray | None = None
    TB2: np.ndarray | None = None
    ET: np.ndarray | None = None

    def __post_init__(self) -> None:
        for name in ("QQ", "FF"):
            if getattr(self, name) is None:
                setattr(self, name, np.zeros_like(self.T))
        for name in ("TB2", "ET"):
            if getattr(self, name) is None:
                setattr(self, name, np.full_like(self.T, np.nan))

    @property
    def inputs(self) -> tuple:
        """The kernels' leading arguments: (T, GG, TGI, QQ, FF, N)."""
        return self.T, self.GG, self.TGI, self.QQ, self.FF, self.N

    @property
    def n_batches(self) -> int:
        return len(self.N)

    def mask(self) -> np.ndarray:
        """(nb, nmax) True where a sample is valid."""
        return np.arange(self.T.shape[1])[None, :] < self.N[:, None]


def pack_batches(
    batches, plants, theta, initial=None, moisture="schwartzberg", hold="linear", h_max_s=H_MAX_S, bed=None
) -> PackedBatches:
    """Pack :class:`roastlab.io.batch.Batch` objects with their plants (one per batch or one for all).

    ``initial`` is an :class:`InitialState` for all batches; each batch's ``initial`` dict
    (e.g. ``{"Tm0_C": 105}``) overrides it, and Ta(0) defaults to the batch's first measured Ta.
    ``bed``: the bed laws (:mod:`roastlab.model.bed`; None = the paper's).
    """
    from ..io.plants import load_plant

    nb = len(batches)
    if not isinstance(plants, (list, tuple)):
        plants = [plants] * nb
    loaded: dict = {}  # read each distinct plant file once, not once per batch
    for spec in plants:
        key = str(spec) if isinstance(spec, (str, Path)) else id(spec)
        if key not in loaded:
            loaded[key] = load_plant(spec)
    plants = [loaded[str(s) if isinstance(s, (str, Path)) else id(s)] for s in plants]
    base = initial or InitialState()
    nmax = max(b.n for b in batches)
    T = np.zeros((nb, nmax))
    GG = np.ones((nb, nmax))
    TGI = np.zeros((nb, nmax))
    TA = np.full((nb, nmax), np.nan)
    QQ = np.zeros((nb, nmax))
    FF = np.zeros((nb, nmax))
    TB2 = np.full((nb, nmax), np.nan)
    ET = np.full((nb, nmax), np.nan)
    X0 = np.zeros((nb, NS))
    N = np.zeros(nb, dtype=np.int64)
    PB = None
    Mb = np.zeros(nb)
    for i, (b, plant) in enumerate(zip(batches, plants)):
        n = b.n
        N[i] = n
        T[i, :n], GG[i, :n], TGI[i, :n] = b.time_s, b.Gg_kg_s, b.Tgi_C
        # padding repeats the last sample so the arrays stay physically sane
        T[i, n:] = b.time_s[-1] + np.arange(1, nmax - n + 1)
        GG[i, n:], TGI[i, n:] = b.Gg_kg_s[-1], b.Tgi_C[-1]
        if b.Ta_C is not None:
            TA[i, :n] = b.Ta_C
        for arr, series in ((QQ, b.heater), (FF, b.fan)):
            if series is not None:
                arr[i, :n], arr[i, n:] = series, series[-1]
        if b.Tb2_C is not None:
            TB2[i, :n] = b.Tb2_C
        if getattr(b, "ET_C", None) is not None:
            ET[i, :n] = b.ET_C
        fields = {**base.__dict__, **b.initial}
        state = InitialState(**fields)
        X0[i] = state.vector(None if b.Ta_C is None else float(b.Ta_C[0]), float(QQ[i, 0]))
        if getattr(b, "Mb_kg", None):  # the batch's own green weight (e.g. from an Artisan log)
            plant = dataclasses.replace(plant, Mb_kg=float(b.Mb_kg))
        p = pack_params(plant, theta, state.X0, moisture, bed)
        if PB is None:
            PB = np.zeros((nb, len(p)))
        PB[i] = p
        Mb[i] = plant.Mb_kg
    return PackedBatches(
        T, GG, TGI, N, TA, X0, PB, Mb, [b.name for b in batches], check_hold(hold), float(h_max_s), QQ, FF, TB2, ET
    )


def run_arrays(packed: PackedBatches, names: list[str], values: np.ndarray):
    """Build per-run (batch_of, X0, PP) for ``m`` value sets over all batches.

    ``values`` has shape (m, nb, len(names)): the value of each named parameter for each
    run. Returns arrays for m * nb runs ordered (set, batch). With ``Tm0_share`` among the names,
    the batch's drum-start value (its log's reading, or ``Tm0_C`` named here) is a reading and the
    run starts from the drum it implies (:func:`roastlab.model.rhs.drum_at_charge_C`).
    """
    m, nb = values.shape[0], packed.n_batches
    X0 = np.repeat(packed.x0[None, :, :], m, axis=0).copy()
    PP = np.repeat(packed.PB[None, :, :], m, axis=0).copy()
    for j, name in enumerate(names):
        v = values[:, :, j]
        if name in PARAM_SLOTS:
            PP[:, :, PARAM_SLOTS[name]] = v
        elif name in STATE0:
            X0[:, :, STATE0[name]] = v
            if name == "X0":
                PP[:, :, P["Mbd"]] = dry_mass_kg(packed.Mb[None, :], v)
        else:
            raise KeyError(name)
    if "Tm0_share" in names:  # the drum at CHARGE from its reading (1, the default, leaves it as read)
        X0[:, :, S_TM] = drum_at_charge_C(X0[:, :, S_TM], PP[:, :, P["Tm0_share"]], PP[:, :, P["T_room"]])
    batch_of = np.tile(np.arange(nb, dtype=np.int64), m)
    return batch_of, X0.reshape(m * nb, NS), PP.reshape(m * nb, -1)


def _lanes_key(PP: np.ndarray, use_lanes: bool | None) -> int | None:
    """The lanes' law key for runs ``PP``, or None for the scalar kernel. ``use_lanes`` None: the
    lanes from :data:`roastlab.sim.lanes.MIN_RUNS` runs up; True: whenever the runs share their laws;
    False: never. A caller that splits one workload into pieces (Dask tasks, fleet chunks) decides
    once for the whole, so every piece takes the same integrator and the results do not depend on
    the split (the two agree to rounding, not bit for bit)."""
    if use_lanes is None:
        return lanes.usable(PP)
    return lanes.law_key(PP) if use_lanes else None


def predict_ta(
    packed: PackedBatches, names: list[str], values: np.ndarray, use_lanes: bool | None = None
) -> np.ndarray:
    """Simulated probe reading for every (value set, batch): shape (m, nb, nmax), NaN-padded
    (``use_lanes``: :func:`predict_outputs`)."""
    return predict_outputs(packed, names, values, with_tb=False, use_lanes=use_lanes)[0]


def _only(batches, batch_of, *arrays):
    """The runs of ``batches`` (indices; None: every run): (which of the runs, and the arrays' rows of them)."""
    if batches is None:
        return None, (batch_of, *arrays)
    wanted = np.zeros(max(int(batch_of.max()), int(np.max(batches))) + 1, dtype=bool)
    wanted[batches] = True
    keep = np.flatnonzero(wanted[batch_of])
    return keep, (batch_of[keep], *(a[keep] for a in arrays))


def _scattered(keep, out: np.ndarray, runs: int) -> np.ndarray:
    """``out`` of the runs ``keep`` (None: all ``runs``) placed among ``runs`` rows, NaN elsewhere."""
    if keep is None:
        return out
    full = np.full((runs, *out.shape[1:]), np.nan)
    full[keep] = out
    return full


def predict_outputs(
    packed: PackedBatches,
    names: list[str],
    values: np.ndarray,
    with_tb: bool = True,
    with_tgo=False,
    tol_scale=1.0,
    use_lanes: bool | None = None,
    batches=None,
):
    """Simulated probe reading Ta, (``with_tb``) bean temperature Tb and (``with_tgo``) outlet gas
    Tgo for every (value set, batch): arrays of shape (m, nb, nmax), NaN-padded; Tb and Tgo are
    None when not asked for. Returns (ta, tb) or, with ``with_tgo``, (ta, tb, tgo). ``tol_scale``
    loosens the integrator's tolerances (:func:`roastlab.sim.kernels.integrate_into`; 1: full accuracy).
    ``use_lanes``: which integrator (:func:`_lanes_key`; None: by the number of runs). ``batches``:
    the indices of the batches to simulate (None: all); the others' rows are NaN."""
    m, nb = values.shape[0], packed.n_batches
    keep, (batch_of, X0, PP) = _only(batches, *run_arrays(packed, names, values))
    runs = batch_of.shape[0]
    key = _lanes_key(PP, use_lanes)
    if key is not None:  # many runs: several at once per core
        cols = np.array([S_TA, *((S_TB,) if with_tb else ()), *((I_TGO,) if with_tgo else ())], dtype=np.int64)
        out = np.full((runs, packed.T.shape[1], cols.size), np.nan)
        lanes.simulate_runs(*packed.inputs, batch_of, X0, PP, packed.zoh, packed.h_max_s, cols, out, tol_scale, key)
        out = _scattered(keep, out, m * nb)
        ta = out[:, :, 0]
        tb = out[:, :, 1] if with_tb else None
        tgo = out[:, :, -1] if with_tgo else None
    else:
        ta = np.full((runs, packed.T.shape[1]), np.nan)
        tb = np.full_like(ta, np.nan) if with_tb else np.empty((0, 0))
        tgo = np.full_like(ta, np.nan) if with_tgo else np.empty((0, 0))
        ta_population_kernel(
            *packed.inputs, batch_of, X0, PP, packed.zoh, packed.h_max_s, ta, tb, tgo, float(tol_scale)
        )
        ta = _scattered(keep, ta, m * nb)
        tb = _scattered(keep, tb, m * nb) if with_tb else tb
        tgo = _scattered(keep, tgo, m * nb) if with_tgo else tgo
    out = (ta.reshape(m, nb, -1), (tb.reshape(m, nb, -1) if with_tb else None))
    return (*out, tgo.reshape(m, nb, -1)) if with_tgo else out


def output_sensitivities(
    packed: PackedBatches, names: list[str], values: np.ndarray, directions, with_tgo=False, batches=None
):
    """The fitted outputs and their exact derivatives with respect to ``directions``, for one
    value set over every batch (forward sensitivities,
    :func:`roastlab.sim.sensitivity.population_sensitivities`).

    ``values`` (nb, len(names)): each named parameter's value per batch (as one set of
    :func:`predict_outputs`). ``directions``: one (j, b) per column, the derivative with respect to
    ``names[j]`` in batch ``b`` only, or in every batch when b < 0. Returns {"Ta": (value (nb,
    nmax), derivative (nb, nmax, m)), "Tb": ..., and with ``with_tgo`` "Tgo": ...}, NaN-padded.
    ``batches``: the indices of the batches to simulate (None: all); the others' rows are NaN.
    """
    from .sensitivity import outlet_sens_kernel, population_sensitivities

    nb, nmax, m = packed.n_batches, packed.T.shape[1], len(directions)
    batch_of, X0, PP = run_arrays(packed, names, values[None, :, :])
    S0 = np.zeros((nb, NS, m))
    # the drum at CHARGE, room + (reading - room) / share: d/d reading = 1/share, d/d share = -(drum - room)/share
    share = PP[:, P["Tm0_share"]] if "Tm0_share" in names else np.ones(nb)
    room = PP[:, P["T_room"]]
    triplets: list[list] = [[] for _ in range(nb)]
    for col, (j, b) in enumerate(directions):
        name = names[j]
        for bb in range(nb) if b < 0 else (b,):
            if name == "Tm0_share":
                S0[bb, S_TM, col] = -(X0[bb, S_TM] - room[bb]) / share[bb]
            elif name in PARAM_SLOTS:
                triplets[bb].append((PARAM_SLOTS[name], col, 1.0))
                if name == "T_room_C":  # the drum at CHARGE sits above the room
                    S0[bb, S_TM, col] = 1.0 - 1.0 / share[bb]
            elif name in STATE0:
                S0[bb, STATE0[name], col] = 1.0 / share[bb] if name == "Tm0_C" else 1.0
                if name == "X0":  # Mbd = dry_mass_kg(Mb, X0) = Mb / (1 + X0): d Mbd / d X0 = -Mbd / (1 + X0)
                    x0 = X0[bb, STATE0[name]]
                    triplets[bb].append((P["Mbd"], col, -dry_mass_kg(packed.Mb[bb], x0) / (1.0 + x0)))
            else:
                raise KeyError(name)
    width = max(1, max(len(t) for t in triplets))
    PQ = np.zeros((nb, width), dtype=np.int64)
    PC = np.zeros((nb, width), dtype=np.int64)
    PV = np.zeros((nb, width))  # padding: value 0, no effect
    for bb, items in enumerate(triplets):
        for e, (q, c, v) in enumerate(items):
            PQ[bb, e], PC[bb, e], PV[bb, e] = q, c, v
    # every state's sensitivity when Tgo is asked for (it depends on Tb, Tm, X and H)
    rows = np.arange(NS, dtype=np.int64) if with_tgo else np.array([S_TA, S_TB], dtype=np.int64)
    keep, (batch_of, X0, PP, S0, PQ, PC, PV) = _only(batches, batch_of, X0, PP, S0, PQ, PC, PV)
    runs = batch_of.shape[0]
    out_x = np.full((runs, nmax, NS), np.nan)
    out_s = np.full((runs, nmax, rows.size, m), np.nan)
    population_sensitivities(
        *packed.inputs, batch_of, X0, PP, packed.zoh, packed.h_max_s, S0, PQ, PC, PV, rows, out_x, out_s
    )
    res = {}
    if with_tgo:
        g = np.full((runs, nmax), np.nan)
        dg = np.full((runs, nmax, m), np.nan)
        outlet_sens_kernel(packed.GG, packed.TGI, packed.FF, packed.N, batch_of, out_x, out_s, PP, PQ, PC, PV,
                           packed.zoh, g, dg)  # fmt: skip
        res["Tgo"] = (_scattered(keep, g, nb), _scattered(keep, dg, nb))
    out_x, out_s = _scattered(keep, out_x, nb), _scattered(keep, out_s, nb)
    row = {int(r): k for k, r in enumerate(rows)}
    return {
        "Ta": (out_x[:, :, S_TA], out_s[:, :, row[S_TA], :]),
        "Tb": (out_x[:, :, S_TB], out_s[:, :, row[S_TB], :]),
        **res,
    }


def _population_task(packed, names, values, use_lanes):
    """One Dask task of :func:`simulate_population`: single-threaded (the cluster is the parallelism)."""
    import numba

    numba.set_num_threads(1)
    return simulate_population(packed, names, values, use_lanes=use_lanes)


def simulate_population(
    packed: PackedBatches,
    names: list[str] = (),
    values: np.ndarray | None = None,
    client=None,
    use_lanes: bool | None = None,
) -> np.ndarray:
    """All six states and Tgo for every (value set, batch): shape (m, nb, nmax, 7), NaN-padded.

    With no ``names``, simulates each batch once at its packed parameters. With a
    ``dask.distributed`` ``client`` (e.g. Monte Carlo over many uncertain value sets) the value
    sets are split into one piece per worker thread and simulated there; the result is the
    same array, value for value, as without (every piece takes the integrator the whole population
    would, ``use_lanes``: :func:`_lanes_key`).

    >>> import numpy as np
    >>> from roastlab.io.batch import Batch
    >>> t = np.arange(0, 901, 30.0)
    >>> b = Batch("check", t, np.full_like(t, 0.4), np.full_like(t, 450.0))
    >>> pk = pack_batches([b], "120kg", (0.01, 0.0254, 0.5793))
    >>> hbm = np.array([[[0.0254]], [[0.05]]])           # two parameter sets, one batch
    >>> out = simulate_population(pk, ["hbm"], hbm)
    >>> round(float(out[0, 0, -1, 0]), 2), bool(out[1, 0, -1, 0] != out[0, 0, -1, 0])
    (218.31, True)
    """
    names = list(names)
    if values is None:
        values = np.zeros((1, packed.n_batches, 0))
    m, nb = values.shape[0], packed.n_batches
    batch_of, X0, PP = run_arrays(packed, names, values)
    key = _lanes_key(PP, use_lanes)
    if client is not None and m > 1:
        slots = sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values())
        cuts = np.array_split(np.arange(m), max(1, min(slots, m)))
        packed_f = client.scatter(packed, broadcast=True)
        futures = [
            client.submit(_population_task, packed_f, names, values[c], key is not None, pure=False)
            for c in cuts
            if len(c)
        ]
        return np.concatenate(client.gather(futures), axis=0)
    out = np.full((m * nb, packed.T.shape[1], N_OUT), np.nan)
    if key is not None:  # many runs: several at once per core
        cols = np.arange(N_OUT, dtype=np.int64)
        lanes.simulate_runs(*packed.inputs, batch_of, X0, PP, packed.zoh, packed.h_max_s, cols, out, 1.0, key)
    else:
        simulate_population_kernel(*packed.inputs, batch_of, X0, PP, packed.zoh, packed.h_max_s, out)
    mask = packed.mask()
    out = out.reshape(m, nb, packed.T.shape[1], N_OUT)
    out[:, ~mask, :] = np.nan
    return out
