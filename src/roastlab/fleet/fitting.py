"""Fit every batch of a fleet store, in-process or on Dask, resumably.

The batches not yet fitted with a spec are read from the store in chunks (``CHUNK`` batches
of one machine) and each chunk goes to :func:`fit_chunk`, which packs it and runs the
compiled per-batch fitter :func:`roastlab.fit.batchfit.identify_each`. A chunk's results are
committed as soon as it returns, so an interrupted run loses at most the chunks in flight,
and the next run fits only what is missing: nothing is fitted twice.

Where the chunks run:

* in-process (default): the compiled fitter spreads each chunk over the cores (numba);
* ``workers=N``: a local ``dask.distributed`` cluster of N single-threaded processes;
* ``scheduler="tcp://host:8786"``: an existing Dask cluster.

On Dask each task runs the fitter single-threaded (the cluster provides the parallelism).
A batch's fit does not depend on the chunk it is in, the thread count or the order, so the
stored results are identical whichever path ran (tests/test_fleet.py checks it).
"""

from __future__ import annotations

import dataclasses
import datetime
import hashlib
import json
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..io.batch import Batch
from ..io.fitspec import FitSpec, load_fit_spec
from ..model.bed import PAPER_BED, BedLaws
from ..model.parameters import DEFAULT_WEIGHTS, REGISTRY, THETA_NAMES, THETA_PAPER, THETA_START, FreeParameter
from .store import SERIES_COLUMNS, filled, open_store, plant_of, store_errors

#: Batches per task: large enough that shipping and committing are noise against the fitting
#: (~1-5 ms a batch), small enough that an interruption loses little.
CHUNK = 500
#: The per-batch fit when no spec is given: hgm and hbm within Table 1's bounds, Pbm held at
#: theta* (one batch rarely pins the bean-metal contact fraction: on the synthetic fleet it
#: ends on a bound in 9 fits out of 10 when free).
DEFAULT_FREE = ("hgm", "hbm")


@dataclass(frozen=True)
class FleetSpec:
    """What a per-batch fleet fit moves and holds; ``spec_id`` names it in the store."""

    names: tuple[str, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    start: tuple[float, ...]
    fixed: tuple[tuple[str, float], ...]
    initial: tuple[tuple[str, float], ...]
    moisture: str = "schwartzberg"
    hold: str = "linear"
    seed: int = 0
    n_trial: int = 32
    max_iter: int = 100
    source: str = ""
    #: the spec's [bed] laws that are not the paper's (without a machine model)
    bed: tuple[tuple[str, str], ...] = ()
    #: the machine model (a :class:`roastlab.workflows.model.FittedModel`) whose every value, bed law,
    #: initial state, moisture law and hold the batches are fitted under, or None
    model: object = field(default=None, compare=False, repr=False)

    def document(self) -> dict:
        doc = {
            "free": {n: [lo, hi, st] for n, lo, hi, st in zip(self.names, self.lower, self.upper, self.start)},
            "fixed": dict(self.fixed),
            "initial": dict(self.initial),
            "moisture": self.moisture,
            "hold": self.hold,
            "seed": self.seed,
            "n_trial": self.n_trial,
            "max_iter": self.max_iter,
        }
        if self.bed:
            doc["bed"] = dict(self.bed)
        if self.model is not None:
            doc["model"] = model_summary(self.model)
        return doc

    @property
    def spec_id(self) -> str:
        """SHA-256 (first 16 hex digits) of the spec's canonical JSON (not of its file's bytes)."""
        text = json.dumps(self.document(), sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def model_summary(model) -> dict:
    """What of a machine model a per-batch fit applies, as JSON (part of the spec's identity: a
    refitted model is a new spec, its batches fitted anew): every value, the initial state, the bed
    laws, the moisture law, the hold and the plant's name."""
    return {
        "parameters": {k: float(e["value"]) for k, e in sorted(model.parameters.items())},
        "initial": {k: model.initial[k] for k in sorted(model.initial)},
        "bed": model.bed.as_dict(),
        "moisture": model.moisture,
        "hold": model.hold,
        "plant": None if model.plant is None else model.plant.name,
    }


def fleet_spec(spec: str | FitSpec | None = None, model=None, **options) -> FleetSpec:
    """A :class:`FleetSpec` from a FIT.toml (every free parameter is per batch) or the default.

    ``model`` (a MODEL.json path or a :class:`~roastlab.workflows.model.FittedModel`) is the
    machine model: each batch is then fitted under all of it (its values, bed laws, initial state,
    moisture law and hold, as ``validate`` applies it), with the spec's free parameters moved per
    batch. The spec then holds nothing itself: its [fixed], [initial] and [bed] would be a second
    copy of the model's, and are refused.
    """
    if model is not None:
        return _model_spec(spec, model, **options)
    if spec is None:
        free = [FreeParameter(n, *REGISTRY[n].bounds, THETA_START.as_dict()[n]) for n in DEFAULT_FREE]
        fixed = {k: v for k, v in THETA_PAPER.as_dict().items() if k not in DEFAULT_FREE}
        initial, source = {}, ""
    else:
        spec = spec if isinstance(spec, FitSpec) else load_fit_spec(spec)
        free, fixed, initial, source = spec.free, spec.fixed, spec.initial, spec.source
        if any(w != DEFAULT_WEIGHTS.get(k) for k, w in spec.weights.items()):
            raise InputError(
                "fleet fits score the bean probe (Ta) alone: drop the [weights] table, which weights other outputs",
                source,
            )
    from ..fit.batchfit import free_slots

    try:
        free_slots([f.name for f in free])
    except InputError as exc:
        raise InputError(exc.problem, source or None) from None
    bed = () if spec is None else tuple(spec.bed.changed().items())
    return FleetSpec(
        tuple(f.name for f in free),
        tuple(float(f.lower) for f in free),
        tuple(float(f.upper) for f in free),
        tuple(float(f.start) for f in free),
        tuple(sorted((k, float(v)) for k, v in fixed.items())),
        tuple(sorted((k, float(v)) for k, v in initial.items())),
        source=str(source),
        bed=bed,
        **options,
    )


def _model_spec(spec, model, **options) -> FleetSpec:
    """:func:`fleet_spec` under a machine model: the spec frees, the model holds the rest."""
    from ..workflows.model import FittedModel, load_model

    if spec is None:
        raise InputError("a machine model needs a fit spec saying what each batch frees ([free])")
    where = model if not isinstance(model, FittedModel) else (model.source or "the machine model")
    model = model if isinstance(model, FittedModel) else load_model(model)
    if model.failed:
        raise InputError(f"the model's fit failed ({model.failed}): it is no machine model to fit batches under", where)
    spec = spec if isinstance(spec, FitSpec) else load_fit_spec(spec)
    # a spec's theta components not free read as held at theta* (load_fit_spec): not a table of its own
    written = {k: v for k, v in spec.fixed.items() if not (k in THETA_NAMES and v == THETA_PAPER.as_dict()[k])}
    held = [t for t, v in (("[fixed]", written), ("[initial]", spec.initial)) if v]
    held += ["[bed]"] if spec.bed != PAPER_BED else []
    if held:
        raise InputError(
            f"{' and '.join(held)}: the machine model holds every value, initial state and bed law; a fleet spec "
            "used with it frees per batch only ([free]): drop the table(s)",
            spec.source,
        )
    base = fleet_spec(spec, **{k: v for k, v in options.items() if k not in ("moisture", "hold")})
    return dataclasses.replace(base, fixed=(), moisture=model.moisture, hold=model.hold, model=model)


def held_model(spec: FleetSpec, plant):
    """The machine model a spec without a model file holds, as a model file would: theta* but for
    its [fixed], its [initial] and [bed] laws, its moisture law and hold. Both kinds of spec then
    reach the batches through :meth:`~roastlab.workflows.model.FittedModel.apply`."""
    from ..workflows.model import FittedModel

    fixed = dict(spec.fixed)
    model = FittedModel.paper(plant, [fixed.pop(k, THETA_PAPER.as_dict()[k]) for k in THETA_NAMES])
    model = model.with_values(**fixed, **dict(spec.initial))
    model.bed = BedLaws(**dict(spec.bed))
    model.moisture, model.hold = spec.moisture, spec.hold
    return model


def fit_chunk(batch_ids, batches: list[Batch], plant, spec: FleetSpec, threads: int | None = None) -> dict:
    """Fit each batch of one machine separately; runs in-process or as a Dask task.

    Returns arrays keyed ``batch_id, value, stderr, SSR, FIT, MAE, n, sims`` (one row per batch).
    """
    from ..fit.batchfit import identify_each
    from ..sim.population import run_arrays

    if threads is not None:
        import numba

        numba.set_num_threads(threads)
    # the machine model as validate applies it (values, bed laws, initial state), then the free ones per batch
    applied = (spec.model if spec.model is not None else held_model(spec, plant)).apply(batches, plant)
    packed = applied.packed
    if applied.names:
        _, packed.x0, packed.PB = run_arrays(packed, applied.names, applied.values)
    bounds = {n: (lo, hi) for n, lo, hi in zip(spec.names, spec.lower, spec.upper)}
    r = identify_each(
        packed,
        bounds=bounds,
        names=spec.names,
        start=dict(zip(spec.names, spec.start)),
        seed=spec.seed,
        n_trial=spec.n_trial,
        max_iter=spec.max_iter,
    )
    return {
        "batch_id": np.asarray(batch_ids, dtype=np.int64),
        "value": r.theta,
        "stderr": r.stderr,
        "SSR": r.SSR,
        "FIT": r.FIT,
        "MAE": r.MAE,
        "n": r.n_samples,
        "sims": r.sims,
    }


@dataclass
class FleetFitReport:
    """What a fleet fit did: batches fitted now, already fitted before, where it ran."""

    fitted: int = 0
    already: int = 0
    chunks: int = 0
    where: str = "in-process"
    wall_s: float = 0.0
    specs: dict = field(default_factory=dict)

    def summary(self) -> str:
        return (
            f"{self.fitted} batch(es) fitted ({self.already} already fitted) in {self.chunks} chunk(s), "
            f"{self.where}, {self.wall_s:.1f} s"
        )


def _load_chunk(con, ids: list[int]) -> list[Batch]:
    """The canonical batches of ``ids`` (ascending) from the store."""
    meta = con.execute(
        "SELECT batch_id, name, source, green_kg, initial_json, n_samples FROM batches "
        "WHERE batch_id IN (SELECT unnest(?::BIGINT[])) ORDER BY batch_id",
        [ids],
    ).fetchall()
    cols = ", ".join(SERIES_COLUMNS)
    arr = con.execute(
        f"SELECT batch_id, {cols} FROM series WHERE batch_id BETWEEN ? AND ? "
        "AND batch_id IN (SELECT unnest(?::BIGINT[])) ORDER BY batch_id, i",
        [ids[0], ids[-1], ids],
    ).fetchnumpy()
    data = {c: np.asarray(filled(arr[c]), dtype=float) for c in SERIES_COLUMNS}
    out = []
    a = 0
    for bid, name, source, green_kg, initial_json, n in meta:
        sl = slice(a, a + n)
        a += n

        def col(c, sl=sl):
            v = data[c][sl]
            return None if np.all(np.isnan(v)) else v

        tb2 = col("Tb2_C")
        out.append(
            Batch(
                name or str(bid),
                data["time_s"][sl],
                data["Gg_kg_s"][sl],
                data["Tgi_C"][sl],
                col("Ta_C"),
                source=source,
                initial=json.loads(initial_json or "{}"),
                Mb_kg=green_kg,
                heater=col("heater"),
                fan=col("fan"),
                Tb2_C=tb2,
            )
        )
    return out


def _write(con, spec: FleetSpec, res: dict, version: str) -> None:
    """Commit one chunk's fits (one transaction)."""
    import pandas as pd

    now = datetime.datetime.now(datetime.UTC)
    sid = spec.spec_id
    nb = len(res["batch_id"])
    fits = pd.DataFrame(
        {
            "batch_id": res["batch_id"],
            "spec_id": sid,
            "SSR": res["SSR"],
            "FIT": res["FIT"],
            "MAE": res["MAE"],
            "n_samples": res["n"].astype(np.int32),
            "simulations": res["sims"].astype(np.int64),
            "roastlab_version": version,
            "fitted_at": now,
        }
    )
    k = len(spec.names)
    vals = pd.DataFrame(
        {
            "batch_id": np.repeat(res["batch_id"], k),
            "spec_id": sid,
            "parameter": np.tile(np.array(spec.names, dtype=object), nb),
            "value": res["value"].reshape(-1),
            "stderr": res["stderr"].reshape(-1),
        }
    )
    con.execute("BEGIN TRANSACTION")
    try:
        con.register("_fits", fits)
        con.register("_vals", vals)
        con.execute(
            "INSERT INTO fits SELECT batch_id, spec_id, CASE WHEN isfinite(SSR) THEN SSR END, "
            "CASE WHEN isfinite(FIT) THEN FIT END, CASE WHEN isfinite(MAE) THEN MAE END, n_samples, simulations, "
            "roastlab_version, fitted_at FROM _fits"
        )
        con.execute(
            "INSERT INTO fit_values SELECT batch_id, spec_id, parameter, CASE WHEN isfinite(value) THEN value END, "
            "CASE WHEN isfinite(stderr) THEN stderr END FROM _vals"
        )
        con.unregister("_fits")
        con.unregister("_vals")
        con.execute("COMMIT")
    except BaseException:
        con.execute("ROLLBACK")
        raise


def _version() -> str:
    from .. import __version__

    return __version__


def _client(workers: int | None, scheduler: str | None):
    """(client, cluster or None) for a Dask path; InputError if Dask is not installed or unreachable."""
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise InputError("--workers/--scheduler need Dask: pip install 'roastlab[fleet]'") from None
    if scheduler:
        import re

        if not re.fullmatch(r"(tcp|tls)://[A-Za-z0-9_.\-\[\]:]+:\d{1,5}", str(scheduler)):
            raise InputError("expected a Dask scheduler address with its port, e.g. tcp://host:8786", scheduler)
        try:
            return Client(scheduler, timeout="10s"), None
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"cannot reach the Dask scheduler ({exc})", scheduler) from None
    import logging

    cluster = LocalCluster(
        n_workers=int(workers),
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,
    )
    return Client(cluster), cluster


def fit_fleet(
    db,
    spec: FleetSpec | dict | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    client=None,
    chunk: int = CHUNK,
    progress=None,
    on_commit=None,
    wait_s: float = 0.0,
) -> FleetFitReport:
    """Fit every batch of the store at ``db`` that has no fit with its machine's spec yet.

    ``spec`` is one :class:`FleetSpec` for every machine, ``{machine name: FleetSpec}`` (machines
    not named get the default) or None (the default, :data:`DEFAULT_FREE`). ``workers``,
    ``scheduler`` or an existing Dask ``client`` choose where the chunks run (module docstring).
    ``progress(done, total, text)`` follows the batches; ``on_commit(n)`` is called after each
    committed chunk (the tests interrupt there). A store locked by another process is waited for
    up to ``wait_s`` seconds.
    """
    from .drift import refresh_models

    t0 = time.perf_counter()
    con = open_store(db, wait_s=wait_s)
    report = FleetFitReport()
    default = fleet_spec()
    version = _version()
    owned = None
    with store_errors(db):
        try:
            machines = con.execute(
                "SELECT machine_id, name, plant, plant_toml FROM machines ORDER BY machine_id"
            ).fetchall()
            specs = {}
            for mid, name, _plant, _toml in machines:
                s = spec.get(name, default) if isinstance(spec, dict) else (spec or default)
                specs[mid] = s
                report.specs[name] = s.spec_id
            if isinstance(spec, dict):
                unknown = sorted(set(spec) - {m[1] for m in machines})
                if unknown:
                    raise InputError(
                        f"no machine {', '.join(unknown)} in the store (has: {', '.join(m[1] for m in machines)})"
                    )
            plants = {mid: plant_of(name, plant, toml) for mid, name, plant, toml in machines}
            for mid, name, _plant, _toml in machines:
                m = specs[mid].model
                if m is not None and m.plant is not None and m.plant != plants[mid]:
                    raise InputError(
                        f"machine {name} is plant {plants[mid].name}, its machine model was fitted on plant "
                        f"{m.plant.name}: fit its batches under a model of its own plant",
                        m.source,
                    )
            for s in {s.spec_id: s for s in specs.values()}.values():
                con.execute(
                    "INSERT OR IGNORE INTO fit_specs VALUES (?, ?, ?)",
                    [s.spec_id, json.dumps(s.document(), sort_keys=True), datetime.datetime.now(datetime.UTC)],
                )
            work = []  # (machine id, ids of one chunk)
            total = 0
            for mid, _name, _plant, _toml in machines:
                sid = specs[mid].spec_id
                ids = [
                    r[0]
                    for r in con.execute(
                        "SELECT batch_id FROM batches b WHERE machine_id = ? AND NOT EXISTS "
                        "(SELECT 1 FROM fits f WHERE f.batch_id = b.batch_id AND f.spec_id = ?) ORDER BY batch_id",
                        [mid, sid],
                    ).fetchall()
                ]
                report.already += con.execute(
                    "SELECT count(*) FROM fits f JOIN batches b USING (batch_id) WHERE b.machine_id = ? AND f.spec_id = ?",
                    [mid, sid],
                ).fetchall()[0][0]
                total += len(ids)
                work += [(mid, ids[a : a + chunk]) for a in range(0, len(ids), chunk)]
            if client is None and (workers or scheduler):
                client, owned = _client(workers, scheduler)
            report.where = (
                "in-process" if client is None else f"dask ({len(client.scheduler_info()['workers'])} workers)"
            )

            def done(mid, res):
                _write(con, specs[mid], res, version)
                report.fitted += len(res["batch_id"])
                report.chunks += 1
                if on_commit is not None:
                    on_commit(report.fitted)
                if progress is not None:
                    progress(report.fitted, total, "batches fitted")

            if client is None:
                for mid, ids in work:
                    done(mid, fit_chunk(ids, _load_chunk(con, ids), plants[mid], specs[mid]))
            else:
                _run_on_dask(client, con, work, plants, specs, done)
            refresh_models(con, {mid: s.spec_id for mid, s in specs.items()})
        finally:
            con.close()
            if owned is not None:
                client.close()
                owned.close()
    report.wall_s = time.perf_counter() - t0
    return report


def _run_on_dask(client, con, work, plants, specs, done) -> None:
    """Keep about two chunks per worker in flight; commit each as it returns."""
    from distributed import as_completed

    n_workers = max(1, sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values()))
    plant_futures = {mid: client.scatter(p, broadcast=True) for mid, p in plants.items()}
    queue = list(work)
    machine_of = {}  # future key -> machine id
    ac = as_completed()

    def submit():
        mid, ids = queue.pop(0)
        fut = client.submit(
            fit_chunk, ids, _load_chunk(con, ids), plant_futures[mid], specs[mid], threads=1, pure=False
        )
        machine_of[fut.key] = mid
        ac.add(fut)

    for _ in range(min(len(queue), 2 * n_workers)):
        submit()
    for fut in ac:
        res = fut.result()
        if queue:
            submit()
        done(machine_of.pop(fut.key), res)
        fut.release()
