"""Compile the kernels ahead, on every core: ``roastlab compile``.

The compiled kernels (:mod:`roastlab.sim`) are built on their first call and kept in the disk cache
(:func:`roastlab.sim.cache.cache_dir`); a first fit takes minutes of that. Each kernel compiles on one
core, and processes started together each compile what they need, the same kernel in each: under
``pytest -n 2`` both workers compiled the lanes, the sensitivities, the probe's population kernel and
the per-batch fitter at the same time, 128 s of the 445 s of compiling a clean clone's suite did
(measured 2026-11-29 with numba's compile events). Here each kernel is compiled once, in one of a pool
of processes, by a small run through the same public call as a fit makes (so the signatures are the
ones a fit asks for), each family of jobs in processes of its own (:func:`chains`); later processes
load them from the cache.

A *job* is one group of kernels that share compiled callees (compiled in one process, so a callee is
not compiled twice): the lanes integrator once per set of laws (:func:`roastlab.sim.lanes.law_key`),
the scalar population kernels with the per-batch fitter, the exact sensitivities once per bed and
moisture law (:func:`roastlab.sim.jacobian.code_key`; the program's with the paper's), and the
single-run stepper. With a warm cache every job only loads, in about a second.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from ..model.bed import BedLaws


@dataclass(frozen=True)
class LawSet:
    """The laws a set of runs shares, which the lanes integrator compiles in (one kernel per set):
    the bed laws, the moisture law, ``held``, the held values of the other parameters the lanes
    compile in as constants (:data:`roastlab.sim.lanes.LAW_SLOTS`: the drive exponents, the beans'
    swelling) where they differ from the quantity table's defaults, as sorted (name, value) pairs, and
    ``on``, the terms a 0 turns off that are on (:data:`roastlab.sim.lanes.OFF_SLOTS`: held at
    another value, or free), as sorted names."""

    bed: BedLaws = BedLaws()
    moisture: str = "schwartzberg"
    held: tuple[tuple[str, float], ...] = ()
    on: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        held = "".join(f", {k} {v:g}" for k, v in self.held)
        on = "".join(f", {k} on" for k in self.on)
        return f"{self.bed.name}, {self.moisture} moisture{held}{on}"


def held_law_values(values: dict[str, float]) -> tuple[tuple[str, float], ...]:
    """The entries of ``values`` (registry names) that the lanes compile in as constants and that differ
    from the quantity table's defaults, sorted by name: :attr:`LawSet.held`. The bed laws' and the
    moisture law's slots are set by those laws, not here."""
    from ..model.parameters import REGISTRY
    from ..sim.lanes import LAW_SLOTS
    from ..sim.population import PARAM_SLOTS

    return tuple(
        sorted(
            (name, float(v))
            for name, v in values.items()
            if PARAM_SLOTS.get(name) in LAW_SLOTS and float(v) != REGISTRY[name].default
        )
    )


def terms_on(values: dict[str, float], free=()) -> tuple[str, ...]:
    """The names among ``values`` (registry names; a value other than 0) and ``free`` (names a fit
    frees) of the terms that a 0 turns off (:data:`roastlab.sim.lanes.OFF_SLOTS`), sorted: :attr:`LawSet.on`."""
    from ..sim.lanes import OFF_SLOTS
    from ..sim.population import PARAM_SLOTS

    named = {name for name, v in values.items() if float(v) != 0.0} | set(free)
    return tuple(sorted(name for name in named if PARAM_SLOTS.get(name) in OFF_SLOTS))


def law_set_of(path) -> LawSet:
    """The laws of a fit spec (``.toml``: its ``[bed]``, the default moisture law, its ``[fixed]``
    values the lanes compile in, the terms it holds on or frees) or a model file (``.json``: its bed
    and moisture law, its values the lanes compile in, the terms its values turn on)."""
    from pathlib import Path

    path = Path(path)
    if path.suffix.lower() == ".json":
        from .model import load_model

        model = load_model(path)
        return LawSet(model.bed or BedLaws(), model.moisture, held_law_values(model.values), terms_on(model.values))
    from ..io.fitspec import load_fit_spec

    spec = load_fit_spec(path)
    return LawSet(spec.bed, held=held_law_values(spec.fixed), on=terms_on(spec.fixed, (f.name for f in spec.free)))


def _batch():
    """One short SYNTHETIC batch on the 120 kg plant: inputs only, to call the kernels with."""
    from ..io.batch import Batch

    t = np.arange(0.0, 121.0, 30.0)
    b = Batch("compile", t, np.full_like(t, 0.4), np.full_like(t, 450.0), Ta_C=np.full_like(t, 25.0))
    b.heater = np.full_like(t, 50.0)
    b.fan = np.full_like(t, 50.0)
    return b


def _packed(laws: LawSet = LawSet(), n: int = 1):
    from ..model.parameters import THETA_PAPER
    from ..sim.population import pack_batches

    return pack_batches([_batch()] * n, "120kg", THETA_PAPER, moisture=laws.moisture, bed=laws.bed)


def job_lanes(bed: str, moisture: str, held: tuple[tuple[str, float], ...] = (), on: tuple[str, ...] = ()) -> str:
    """The lanes integrator for one set of laws (:func:`roastlab.sim.population.predict_outputs`); the
    terms ``on`` at the middle of their fit bounds (the kernel is the same for any value but 0)."""
    from ..model.parameters import REGISTRY
    from ..sim import lanes
    from ..sim.population import predict_outputs

    laws = LawSet(BedLaws.parse(bed), moisture, tuple(held), tuple(on))
    packed = _packed(laws)
    names = ["hbm", *(k for k, _ in laws.held), *laws.on]
    values = np.empty((lanes.MIN_RUNS, 1, len(names)))
    values[:] = [0.0254, *(v for _, v in laws.held), *(sum(REGISTRY[k].bounds) / 2 for k in laws.on)]
    predict_outputs(packed, names, values, with_tgo=True, use_lanes=True)
    return f"lanes ({laws.name})"


def job_population() -> str:
    """The scalar population kernels (probe and all states) and the per-batch fitter, which share the
    integrator (:func:`roastlab.sim.kernels.integrate_into`)."""
    from ..fit.batchfit import identify_each
    from ..sim.population import predict_outputs, simulate_population

    packed = _packed()
    predict_outputs(packed, ["hbm"], np.full((1, 1, 1), 0.0254), with_tgo=True, use_lanes=False)
    simulate_population(packed, use_lanes=False)
    identify_each(packed, n_trial=2, max_iter=1)
    return "population kernels and the per-batch fitter"


def job_sensitivities(bed: str = BedLaws().name, moisture: str = "schwartzberg", program: bool = True) -> str:
    """The exact sensitivities of a fit (every output, the outlet gas's too) for one bed and moisture
    law (compiled per combination of the model's codes, :func:`roastlab.sim.jacobian.code_key`) and,
    with ``program``, those of a program."""
    from ..sim.population import output_sensitivities
    from ..sim.sensitivity import program_sensitivity

    laws = LawSet(BedLaws.parse(bed), moisture)
    packed = _packed(laws)
    output_sensitivities(packed, ["hbm"], np.full((1, 1), 0.0254), [(0, -1)], with_tgo=True)
    if program:
        b = _batch()
        n = b.n
        x0 = packed.x0[0].copy()
        p = packed.PB[0].copy()
        program_sensitivity(b.time_s, b.Gg_kg_s, b.Tgi_C, np.zeros(n), np.zeros(n), x0, p, False, 0)
    return f"sensitivities ({laws.bed.name}, {laws.moisture} moisture{', a program' if program else ''})"


def job_stepper() -> str:
    """The one stepper (:func:`roastlab.sim.simulate.advance`) and the single-run simulator."""
    from ..sim.simulate import advance, simulate

    packed = _packed()
    u = np.array([0.4, 450.0, 0.0, 0.0])
    advance(packed.x0[0].copy(), u, u, 1.0, packed.PB[0].copy())
    b = _batch()
    simulate("120kg", b.time_s, b.Gg_kg_s, b.Tgi_C)
    return "stepper and single run"


def jobs(law_sets=(LawSet(),)) -> list[tuple]:
    """The jobs for ``law_sets`` (the paper's laws by default), the lanes first: (function, args). A set
    whose held values the lanes cannot compile in (a gas burner's square root, a swelling of 0.5) has
    no lanes job: its runs take the scalar integrator (:func:`roastlab.sim.lanes.compiles_in`)."""
    from ..sim.lanes import compiles_in

    seen: list[LawSet] = []
    for laws in law_sets:
        if laws not in seen and compiles_in([v for _, v in laws.held]):
            seen.append(laws)
    codes: list[tuple[str, str]] = []  # the sensitivities' kernel is one per bed and moisture law
    for laws in (LawSet(), *law_sets):
        if (laws.bed.name, laws.moisture) not in codes:
            codes.append((laws.bed.name, laws.moisture))
    return [
        *((job_lanes, (laws.bed.name, laws.moisture, laws.held, laws.on)) for laws in seen),
        (job_population, ()),
        *((job_sensitivities, (bed, moisture, k == 0)) for k, (bed, moisture) in enumerate(codes)),
        (job_stepper, ()),
    ]


#: Seconds each job took from an empty cache, one process on 2 cores (2026-11-29): the first set of laws'
#: lanes, each further set's (the lanes' shared callees then compiled), and the other jobs together.
#: Only the split of the processes between the two families uses them (:func:`chains`).
LANES_FIRST_S, LANES_MORE_S, SCALAR_S = 49.0, 28.0, 77.0


def chains(todo: list[tuple], processes: int) -> list[list[tuple]]:
    """``todo`` split into at most ``processes`` lists, each run in order by one process.

    Jobs of one family share compiled callees (the lanes of every set of laws their vector arithmetic,
    the scalar kernels the integrator), which a process compiles once for all its jobs; two processes
    running jobs of one family each compile those callees. So each family gets its own processes, in
    proportion to its measured cost (:data:`LANES_FIRST_S`), and its jobs are dealt out among them.
    From an empty cache on 2 cores the lanes of two sets of laws and the rest took 118 s as five jobs
    dealt to two processes and 155 s in one process (2026-11-29).
    """
    lanes_jobs = [j for j in todo if j[0] is job_lanes]
    others = [j for j in todo if j[0] is not job_lanes]
    if processes <= 1 or not lanes_jobs or not others:
        n = max(1, min(processes, len(todo)))
        return [todo[i::n] for i in range(n)]
    cost = LANES_FIRST_S + LANES_MORE_S * (len(lanes_jobs) - 1)
    n_lanes = min(len(lanes_jobs), processes - 1, max(1, round(processes * cost / (cost + SCALAR_S))))
    n_other = min(len(others), processes - n_lanes)
    return [lanes_jobs[i::n_lanes] for i in range(n_lanes)] + [others[i::n_other] for i in range(n_other)]


_PROGRESS = None  # a worker process's queue back to the parent (set by _init_worker)


def _init_worker(queue) -> None:
    global _PROGRESS
    _PROGRESS = queue


def _run(job, args):
    import numba

    numba.set_num_threads(1)  # compiling is one core's work; the runs are tiny
    t0 = time.perf_counter()
    text = job(*args)
    return text, time.perf_counter() - t0


def _run_chain(chain) -> list[tuple[str, float]]:
    done = []
    for job, args in chain:
        done.append(_run(job, args))
        if _PROGRESS is not None:
            _PROGRESS.put(done[-1])
    return done


def process_count(n_jobs: int, processes: int | None = None) -> int:
    """The processes :func:`compile_kernels` uses for ``n_jobs``: ``processes``, or one per core, never
    more than the jobs."""
    return max(1, min(processes or os.cpu_count() or 1, n_jobs))


def compile_kernels(law_sets=(LawSet(),), processes: int | None = None, progress=None) -> list[tuple[str, float]]:
    """Compile (or load from the cache) every kernel a fit, a prediction and the page use, for the
    lanes' ``law_sets``, in ``processes`` processes (:func:`process_count`; the jobs split by
    :func:`chains`).

    ``progress(done, total, text)`` is called as each job finishes, ``text`` naming it and its seconds.
    Returns (job, seconds) in the order they finished.
    """
    import queue as queues

    todo = jobs(law_sets)
    groups = chains(todo, process_count(len(todo), processes))
    done: list[tuple[str, float]] = []

    def finished(item):
        done.append(item)
        if progress:
            progress(len(done), len(todo), f"{item[0]}: {item[1]:.1f} s")

    if len(groups) == 1:
        for job, args in todo:
            finished(_run(job, args))
        return done
    # spawn: a fresh interpreter per process (numba's threads and a forked parent do not mix)
    context = multiprocessing.get_context("spawn")
    with context.Manager() as manager:
        back = manager.Queue()
        with ProcessPoolExecutor(len(groups), mp_context=context, initializer=_init_worker, initargs=(back,)) as pool:
            futures = [pool.submit(_run_chain, chain) for chain in groups]
            # meanwhile the exact Jacobian's source, generated by SymPy once per source version (16 s on
            # 2 cores), is written here, where it holds up no compile: the sensitivities, the only job
            # that needs it, come after the population kernels in their process and then load it
            from ..sim import jacobian

            jacobian.load()
            while len(done) < len(todo):
                try:
                    finished(back.get(timeout=0.5))
                except queues.Empty:
                    failed = [f for f in futures if f.done() and f.exception() is not None]
                    if failed:
                        raise failed[0].exception() from None
    return done


__all__ = ["LawSet", "law_set_of", "held_law_values", "terms_on", "compile_kernels", "chains", "jobs", "process_count"]
