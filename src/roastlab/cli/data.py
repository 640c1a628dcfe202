"""``roastlab import``, ``roastlab datasets`` and ``roastlab reproduce``: logs in, synthetic data out, the paper end to end."""

from __future__ import annotations

import sys

from .common import (
    Parser,
    progress,
    seed_arg,
)


def cmd_import(args) -> int:
    from ..io.batch import write_batch_csv_text
    from ..io.files import Outputs
    from ..io.importers import import_log, load_map

    outputs = Outputs([args.log, args.map])
    outputs.check(args.out)
    cmap = load_map(args.map) if args.map else None
    batch = import_log(args.log, cmap, name=args.name)
    for note in batch.notes:
        print(f"warning: {args.log}: {note}", file=sys.stderr)
    with outputs as out:
        out.write_text(args.out, write_batch_csv_text(batch, comment=f"imported by roastlab from {args.log}"))
    mass = f", green batch {batch.Mb_kg * 1000:.0f} g" if batch.Mb_kg else ""
    print(
        f"imported {batch.n} samples ({batch.time_s[0]:.0f}..{batch.time_s[-1]:.0f} s){mass}: BT {batch.Ta_C[0]:.1f} -> {batch.Ta_C[-1]:.1f} degC -> {args.out}"
    )
    return 0


def cmd_reproduce(args) -> int:
    from ..workflows.reproduce import run, summary_table

    summary = run(args.out, args.data, seed=args.seed, progress=progress("identify"))
    print(summary_table(summary))
    return 0


def cmd_datasets(args) -> int:
    from ..workflows.datasets import make_paper

    written = make_paper(args.seed, args.out)
    print(f"wrote {len(written)} files of SYNTHETIC data under {args.out} (seed {args.seed})")
    return 0


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    from ..workflows.datasets import PAPER_SEED

    p = sub.add_parser(
        "reproduce",
        help="the paper end to end: identify on dataset-I, validate on dataset-V",
        description="Identify on the synthetic dataset-I (120 kg), validate on dataset-V (360 kg) and write "
        "the fitted MODEL.json (as model.json), metrics.json, report.md, fig2_profiles.png and fig3_errors.png (all or none).",
    )
    p.add_argument("--out", default="out/reproduce", metavar="DIR", help="output folder (default out/reproduce)")
    p.add_argument(
        "--data", metavar="DIR", help="folder holding dataset-I and dataset-V (default: the shipped synthetic data)"
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="seed of the identification (default %(default)s)")
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser(
        "import",
        help="convert a roast log (Artisan .alog/.csv, RoasTime .json, CSV, Parquet) into a batch CSV",
        description="Read a log with a column map and write the canonical batch CSV time_s,Gg_kg_s,Tgi_C,Ta_C "
        "(Artisan and RoasTime logs: time 0 at CHARGE, cut after DROP, °F converted, green weight kept as '# Mb_kg').",
        epilog="example: roastlab import roast.alog --map examples/skywalker/map.toml --out batch.csv\n"
        "then: roastlab simulate --model MODEL.json --inputs batch.csv --out pred.csv (a model fitted with a map also "
        "reads the raw log itself)",
    )
    p.add_argument("log", metavar="LOG", help="the roast log")
    p.add_argument(
        "--map",
        metavar="MAP.toml",
        help="column map (default: Artisan's BT and ET for an Artisan log, a Bullet's channels for a RoasTime "
        "log, the canonical column names for a CSV or Parquet table; `roastlab init` writes one from your logs)",
    )
    p.add_argument("--out", required=True, metavar="BATCH.csv", help="where to write the batch CSV")
    p.add_argument("--name", help="batch name (default: the log's file name)")
    p.set_defaults(func=cmd_import)

    p = sub.add_parser(
        "datasets",
        help="generate the synthetic stand-in datasets",
        description="Generate SYNTHETIC stand-in datasets to fit with 'roastlab identify ... --out MODEL.json'.",
    )
    dsub = p.add_subparsers(dest="what", metavar="WHAT", parser_class=Parser)
    dsub.required = True
    q = dsub.add_parser(
        "make-paper",
        help="write dataset-I and dataset-V (SYNTHETIC) from a seed",
        description="Generate the synthetic stand-ins of the paper's datasets, byte-identical for a given seed "
        "(fit them with 'roastlab identify ... --out MODEL.json').",
    )
    q.add_argument(
        "--seed", type=seed_arg, default=PAPER_SEED, help=f"random seed (default {PAPER_SEED}, the shipped data)"
    )
    q.add_argument("--out", default="paper-synthetic", metavar="DIR", help="output folder (default paper-synthetic)")
    q.set_defaults(func=cmd_datasets)
