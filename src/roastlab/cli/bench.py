"""``roastlab bench``: the benchmark of ``benchmarks/bench.py`` (a checkout only; it is not installed)."""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import InputError


def find_benchmark() -> Path:
    """``benchmarks/bench.py`` of the checkout this roastlab runs from (or of the current folder)."""
    here = Path(__file__).resolve().parents[3] / "benchmarks" / "bench.py"  # src/roastlab/cli -> the checkout
    for candidate in (here, Path.cwd() / "benchmarks" / "bench.py"):
        if candidate.is_file():
            return candidate
    raise InputError(
        "the benchmark runs from a roastlab checkout (benchmarks/bench.py is not installed): run 'make bench' there",
        "roastlab bench",
    )


def load_benchmark():
    """The benchmark module, loaded from :func:`find_benchmark` (the project's own file)."""
    import importlib.util

    path = find_benchmark()
    spec = importlib.util.spec_from_file_location("roastlab_benchmarks_bench", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def cmd_bench(args) -> int:
    from ..io.files import Outputs

    bench = load_benchmark()
    run, table = bench.run, bench.table

    outputs = Outputs()
    if args.save:
        outputs.check(args.save)
    res = run(quiet=args.json, only=args.only)
    if args.json:
        print(json.dumps(res, indent=1))
    else:
        print(table(res))
    if args.save:
        with outputs as out:
            out.write_text(args.save, json.dumps(res, indent=1) + "\n")
    return 0


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    p = sub.add_parser(
        "bench",
        help="measure speed against a solve_ivp baseline in one run (from a checkout: benchmarks/bench.py)",
        description="Measure single-batch and population simulation speed-ups over solve_ivp(LSODA), "
        "identification time on dataset-I, fleet identification scaling (10/100/1,000 batches), the cold CLI "
        "and profile transfer (accuracy on synthetic references, against its baselines and a generic SciPy "
        "solver), exact sensitivities against finite differences, and the MPC against CasADi + IPOPT. Whatever "
        "can use several cores is timed on one thread (the figures targets are checked on) and on all cores, "
        "and the identification also with one core kept busy by another process (all cores at most 1.5x one "
        "thread); timings are medians of repetitions. Takes about a minute on 2 cores once the kernels are "
        "compiled. Needs no MODEL.json: it times the paper's model.",
    )
    p.add_argument(
        "--only",
        choices=("transfer", "sensitivity", "control", "fleet"),
        help="run one section only (fleet: 100,000 synthetic batches end to end and 10,000 in-process and on 2 "
        "Dask workers, ~10 min; not in the default run)",
    )
    p.add_argument("--json", action="store_true", help="print the figures as JSON (progress goes quiet)")
    p.add_argument("--save", metavar="FILE.json", help="also save the JSON to a file")
    p.set_defaults(func=cmd_bench)
