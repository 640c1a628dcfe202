"""``roastlab fleet``: ingest logs into a DuckDB store, fit every batch, report drift (thin layer)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import InputError
from .common import Parser, count_arg, json_text, progress


def _db_output(db, inputs) -> Path:
    """The store path: a DuckDB file or nothing yet; never one of the command's inputs, never
    another kind of file (a log or CSV given as --db by mistake is refused, not overwritten)."""
    from ..io.files import Outputs

    path = Outputs([p for p in inputs if p]).check(db)
    if path.exists() and path.stat().st_size > 0:
        with open(path, "rb") as fh:
            head = fh.read(12)
        if head[8:12] != b"DUCK":
            raise InputError("exists and is not a DuckDB file; refusing to write a fleet store into it", path)
    return path


def cmd_fleet_ingest(args) -> int:
    from ..fleet import ingest

    _db_output(args.db, [args.manifest])
    report = ingest(args.db, args.manifest, progress=progress("ingest"), wait_s=args.wait)
    for line in report.rejected:
        print(f"roastlab fleet ingest: rejected: {line}", file=sys.stderr)
    print(report.summary())
    return 2 if report.rejected else 0


def _per_machine(values: list[str] | None, what: str) -> tuple[str | None, dict[str, str]]:
    """``[MACHINE=]FILE`` options: (one file for every machine or None, {machine: file})."""
    single, named = None, {}
    for v in values or []:
        name, sep, path = v.partition("=")
        if sep and not Path(v).exists():
            named[name] = path
        elif single is None:
            single = v
        else:
            raise InputError(f"give one {what} for every machine, or MACHINE={what} per machine", "command line")
    if single is not None and named:
        raise InputError(f"give one {what} for every machine, or MACHINE={what} per machine", "command line")
    return single, named


def _specs(values: list[str] | None, models: list[str] | None = None):
    """The fleet specs of ``--spec`` (and the machine models of ``--model``): one for every machine
    or ``{machine: FleetSpec}``; None for the default."""
    from ..fleet import fleet_spec

    spec, specs = _per_machine(values, "--spec FIT.toml")
    model, models_of = _per_machine(models, "--model MODEL.json")
    if (model is not None and spec is None) or (models_of and spec is not None):
        raise InputError("give --model and --spec alike: both for every machine, or both per machine", "command line")
    lost = sorted(set(models_of) - set(specs))
    if lost:
        raise InputError(
            f"--model {', '.join(lost)}=...: give the machine's --spec too (what each batch frees)", "command line"
        )
    if spec is not None:
        return fleet_spec(spec, model)
    return {name: fleet_spec(path, models_of.get(name)) for name, path in specs.items()} or None


def cmd_fleet_fit(args) -> int:
    from ..fleet import fit_fleet

    if args.workers is not None and args.scheduler:
        raise InputError("give --workers N or --scheduler ADDRESS, not both", "command line")
    given = [*(args.spec or []), *(args.model or [])]
    _db_output(args.db, [v.partition("=")[2] if "=" in v and not Path(v).exists() else v for v in given])
    spec = _specs(args.spec, args.model)
    report = fit_fleet(
        args.db,
        spec,
        workers=args.workers,
        scheduler=args.scheduler,
        chunk=args.chunk,
        progress=progress("fit"),
        wait_s=args.wait,
    )
    print(report.summary())
    return 0


def cmd_fleet_report(args) -> int:
    from ..fleet import fleet_report
    from ..io.files import Outputs

    outputs = Outputs([args.db])
    if args.json:
        outputs.check(args.json)
    if args.plot and Path(args.plot).exists():
        outputs.folder(args.plot, create=False)  # an existing non-folder is refused before any work
    report = fleet_report(args.db)  # a missing or foreign store fails here, before any folder is made
    print(report.table())
    with outputs as out:
        if args.json:
            out.write_text(args.json, json_text(report.to_dict()))
        if args.plot:
            report.plot_machines(args.plot, outputs=out)
    return 0


def cmd_fleet_synthetic(args) -> int:
    from ..fleet.synthetic import make_fleet

    truth = make_fleet(args.out, args.batches, seed=args.seed, progress=progress("write"))
    changes = sum(len(m["changes"]) for m in truth["machines"])
    print(
        f"SYNTHETIC fleet: {args.batches} batches over {len(truth['machines'])} machines ({changes} injected "
        f"change(s)) in {args.out}; ingest it with: roastlab fleet ingest --db FLEET.duckdb --manifest "
        f"{Path(args.out) / 'manifest.csv'}"
    )
    return 0


def _add_wait(q) -> None:
    """The ``--wait`` option of the commands that write the store."""
    q.add_argument(
        "--wait",
        type=count_arg("--wait", 0, 86_400),
        default=0,
        metavar="SECONDS",
        help="if another process has the store open, wait up to this long for it (default 0: refuse at once)",
    )


def add_parsers(sub) -> None:
    """Register ``roastlab fleet`` and its subcommands on the subparsers ``sub``."""
    from ..fleet.drift import CUSUM_H, CUSUM_K

    parser_class = Parser

    p = sub.add_parser(
        "fleet",
        help="many roasters and years of batches: a DuckDB store, a fit per batch, drift alarms",
        description="Keep every batch of every machine in one DuckDB file (FLEET.duckdb, no server), fit each "
        "batch's heat-transfer coefficients, and watch each machine's coefficients for drift (a fouling drum, a "
        "failing burner or fan, a drifting probe). Each machine's batches are fitted under its machine model "
        "(--model MODEL.json, from 'roastlab identify'), with the coefficients to watch freed per batch by its "
        "fit spec (--spec). Schema, detector and thresholds: docs/fleet.md.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
        "  roastlab fleet synthetic --out fleet-data --batches 1000          # a SYNTHETIC fleet to try it on\n"
        "  roastlab fleet ingest --db fleet.duckdb --manifest fleet-data/manifest.csv\n"
        "  roastlab fleet fit    --db fleet.duckdb --workers 2\n"
        "  roastlab fleet report --db fleet.duckdb --json report.json --plot figures/\n"
        "manifest.csv columns: path,machine,plant,started_at[,map] (paths relative to the manifest; started_at "
        "ISO 8601, UTC unless it names a zone).",
    )
    fsub = p.add_subparsers(dest="what", metavar="WHAT", parser_class=parser_class)
    fsub.required = True

    q = fsub.add_parser(
        "ingest",
        help="read the logs a manifest lists into the store",
        description="Read every log a manifest lists into the store, committed 2,000 batches at a time (an "
        "interrupted ingest keeps what it committed; running it again adds the rest). A row that cannot be "
        "ingested (missing file, unknown plant, bad date, unreadable log) is reported on one line with its line "
        "number and the others still ingest (exit code 2 if any row was rejected). A file already in the store "
        "(same SHA-256) is skipped, so ingesting again is a no-op.",
    )
    q.add_argument("--db", required=True, metavar="FLEET.duckdb", help="the store (created if missing)")
    q.add_argument("--manifest", required=True, metavar="MANIFEST.csv", help="CSV: path,machine,plant,started_at[,map]")
    _add_wait(q)
    q.set_defaults(func=cmd_fleet_ingest)

    q = fsub.add_parser(
        "fit",
        help="fit every batch not yet fitted (resumable)",
        description="Fit each batch's coefficients separately (the compiled per-batch fitter) for every batch "
        "that has no fit with its machine's spec yet. Results are committed chunk by chunk: an interrupted run "
        "loses at most the chunks in flight and the next run fits only what is missing. Without --workers or "
        "--scheduler it runs in this process on all cores; the results are identical whichever path runs.",
    )
    q.add_argument("--db", required=True, metavar="FLEET.duckdb", help="the store")
    q.add_argument(
        "--spec",
        action="append",
        metavar="[MACHINE=]FIT.toml",
        help="what each batch's fit frees and holds (every free parameter is fitted per batch); MACHINE=FIT.toml "
        "for one machine (repeatable). Default: hgm and hbm free, Pbm held at theta*",
    )
    q.add_argument(
        "--model",
        action="append",
        metavar="[MACHINE=]MODEL.json",
        help="the machine model (from 'roastlab identify' or 'fit-roaster') each batch is fitted under: all its "
        "values, bed laws, initial state and moisture law, as 'validate' applies it; the machine's --spec then "
        "frees per batch only ([free]). MACHINE=MODEL.json for one machine (repeatable)",
    )
    q.add_argument("--workers", type=count_arg("--workers", 1, 1024), help="start a local Dask cluster of N processes")
    q.add_argument("--scheduler", metavar="ADDRESS", help="use an existing Dask cluster (e.g. tcp://host:8786)")
    q.add_argument(
        "--chunk",
        type=count_arg("--chunk", 1, 1_000_000),
        default=500,
        help="batches per task and commit (default %(default)s)",
    )
    _add_wait(q)
    q.set_defaults(func=cmd_fleet_fit)

    q = fsub.add_parser(
        "report",
        help="each machine's coefficient history, drift alarms and outlier batches",
        description="Print each machine's coefficients (median and batch-to-batch spread), its drift alarms "
        f"(self-starting CUSUM, k = {CUSUM_K:g}, h = {CUSUM_H:g}) and outlier batches. --json writes the report (per machine: "
        "alarms [{parameter, batch_index, started_at, direction, ...}], outliers, periods); --plot writes one "
        "figure per machine.",
    )
    q.add_argument("--db", required=True, metavar="FLEET.duckdb", help="the store (read only)")
    q.add_argument("--json", metavar="REPORT.json", help="write the report as JSON")
    q.add_argument("--plot", metavar="DIR", help="write <machine>.png coefficient histories into this folder")
    q.set_defaults(func=cmd_fleet_report)

    q = fsub.add_parser(
        "synthetic",
        help="write a SYNTHETIC fleet (seeded; machines with injected drift) to try the commands on",
        description="Write a synthetic fleet: batch CSVs under OUT/<machine>/, OUT/manifest.csv, OUT/truth.json "
        "(the injected changes) and a README. Every file says it is synthetic.",
    )
    q.add_argument("--out", required=True, metavar="DIR", help="folder to write into")
    q.add_argument(
        "--batches",
        type=count_arg("--batches", 1, 10_000_000),
        default=1000,
        help="batches in all (default %(default)s)",
    )
    q.add_argument("--seed", type=int, default=14, help="random seed (default %(default)s)")
    q.set_defaults(func=cmd_fleet_synthetic)
