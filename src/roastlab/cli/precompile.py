"""``roastlab compile``: the model's kernels compiled ahead, on every core (:mod:`roastlab.workflows.precompile`)."""

from __future__ import annotations

import sys
import time

from .common import FIRST_COMPILE, bed_arg, count_arg


def cmd_compile(args) -> int:
    t0 = time.perf_counter()  # a new version of the sources also generates its Jacobian here (SymPy, once)
    from ..sim.cache import cache_dir
    from ..workflows.precompile import LawSet, compile_kernels, jobs, law_set_of, process_count

    law_sets = [LawSet(), *(law_set_of(path) for path in args.laws), *(LawSet(bed) for bed in args.bed)]
    total = len(jobs(law_sets))
    n = process_count(total, args.processes)
    print(
        f"roastlab compile: {total} jobs in {n} process{'es' if n > 1 else ''} (from an empty cache a few "
        "minutes, from a warm one seconds)",
        file=sys.stderr,
        flush=True,
    )
    compile_kernels(
        law_sets, n, progress=lambda done, n_jobs, text: print(f"[{done}/{n_jobs}] {text}", file=sys.stderr, flush=True)
    )
    print(f"kernels ready in {time.perf_counter() - t0:.1f} s; cache: {cache_dir()}")
    return 0


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    p = sub.add_parser(
        "compile",
        help="compile the model's kernels ahead, on every core (a first fit then starts at once)",
        description="Compile every kernel a fit, a prediction, a what-if and the page call (or load them from "
        "the cache), each once, in a pool of processes, the lanes and the other kernels each in processes of their own. "
        "A first run of any command otherwise "
        f"compiles what it needs on one core ({FIRST_COMPILE}). The lanes integrator, which "
        "simulates many runs at once, is compiled once per set of laws (the bed and moisture laws, and the held "
        "values it compiles in: the drive exponents, the beans' swelling), and a fit's exact sensitivities once per "
        "bed and moisture law: the paper's always, and those of each fit spec or model file given. With a warm cache "
        "it takes seconds.",
    )
    p.add_argument(
        "laws",
        nargs="*",
        metavar="SPEC_OR_MODEL",
        help="fit specs (fit.toml) or model files (MODEL.json) whose laws (bed, moisture, held exponents and "
        "swelling) to compile the lanes and the sensitivities for, besides the paper's",
    )
    p.add_argument(
        "--bed",
        type=bed_arg,
        action="append",
        default=[],
        metavar="LAWS",
        help="bed laws to compile the lanes and the sensitivities for as well, with the paper's moisture law "
        "(e.g. 'contact=wall'; the form of fit --bed); may be repeated",
    )
    p.add_argument(
        "--processes",
        type=count_arg("--processes", 1, 256),
        default=None,
        help="processes to compile in (default: one per core, at most one per job)",
    )
    p.set_defaults(func=cmd_compile)
