"""``roastlab identify`` and ``roastlab validate``: fit a model file to logs, score it on others."""

from __future__ import annotations

from pathlib import Path

from ..errors import InputError
from .common import (
    add_band_option,
    add_batch_options,
    add_model_options,
    add_starts_option,
    add_units_option,
    check_targets,
    failed_fit_status,
    fit_inputs,
    float_arg,
    initial_changes,
    json_text,
    load_batches,
    model_from_args,
    parse_assignments,
    progress,
    say,
    seed_arg,
    weights_arg,
    write_json_and_plot,
)

FIT_HELP_COMPARE = "logs with their green weight (raw logs with --map, or batch CSVs)"


def cmd_identify(args) -> int:
    from ..io.files import Outputs

    outputs = Outputs(fit_inputs(args))
    outputs.check(args.out)
    batches, plant_spec = load_batches(args)
    if plant_spec is None:
        raise InputError("--plant is required unless a dataset folder names its plant", "command line")
    if args.baseline:
        from ..fit.baseline import describe, fit_first_order

        doc = {**fit_first_order(batches), "plant": str(plant_spec)}
        with outputs as out:
            out.write_text(args.out, json_text(doc))
        print(f"first-order baseline on {len(batches)} batch(es): {describe(doc)}, SSR {doc['SSR']:.1f} -> {args.out}")
        return 0
    fix = parse_assignments(args.fix, "--fix", ranged=False)
    bounds = parse_assignments(args.bounds, "--bounds", ranged=True)
    if args.per_batch:
        return _identify_per_batch(args, batches, plant_spec, fix, bounds, outputs)
    from ..io.importers import load_map
    from ..workflows.fitting import fit

    initial = initial_changes(args)
    result = fit(
        batches,
        plant_spec,
        args.spec,
        fix=fix,
        bounds=bounds,
        estimate_tm0=args.estimate_tm0,
        initial=initial,
        moisture=args.moisture or "schwartzberg",
        hold=args.hold or "linear",
        method=args.method,
        seed=args.seed,
        starts=args.starts,
        column_map=load_map(args.map) if args.map else None,
        progress=progress("identify"),
        weights=weights_arg(args.weight),
        bed=args.bed,
    )
    from ..io.modelfile import model_document_text

    with outputs as out:
        out.write_text(args.out, model_document_text(result.model.to_document()))
    print(result.report())
    print(f"-> {args.out}")
    return failed_fit_status(result.failed, args.out)


def _identify_per_batch(args, batches, plant_spec, fix, bounds, outputs) -> int:
    from ..workflows.fitting import fit_per_batch

    if args.estimate_tm0 or args.spec:
        raise InputError("--per-batch fits hgm, hbm, Pbm only (no --spec, no --estimate-tm0)", "command line")
    result = fit_per_batch(
        batches,
        plant_spec,
        fix=fix,
        bounds=bounds,
        initial=initial_changes(args),
        moisture=args.moisture or "schwartzberg",
        hold=args.hold or "linear",
        seed=args.seed,
        progress=progress("fit per batch"),
    )
    doc = {**result.to_json_dict(), "plant": str(plant_spec), "fixed": sorted(fix)}
    with outputs as out:
        out.write_text(args.out, json_text(doc))
    print(
        f"identified theta per batch for {len(result.names)} batch(es) on plant {plant_spec} in {result.wall_s:.2f} s ({result.simulations} simulations)"
    )
    print(f"{result.summary()} -> {args.out}")
    return 0


def cmd_validate(args) -> int:
    from ..evaluate.validate import metrics_by_size, panels_by_size
    from ..io.batch import logs_temp_unit
    from ..io.files import Outputs
    from ..metrics.profile import delta_text, display_temp_delta, temp_symbol
    from ..report.figures import plot_fit

    outputs = Outputs(fit_inputs(args))
    check_targets(outputs, args.json, plot=args.plot)
    if args.predictions:
        outputs.folder(args.predictions, create=False)
    if args.baseline:
        return _validate_baseline(args, outputs)
    model = model_from_args(args, args.plant)
    batches, plant_spec = load_batches(args, model)
    changes = initial_changes(args)
    if args.tgi_offset is not None:
        changes["Tgi_offset_C"] = args.tgi_offset
    if args.band is not None and (changes or plant_spec not in (None, model.plant)):
        # said before the validation runs, not after its table
        raise InputError(
            "--band scores the model as fitted: drop --plant/--tgi-offset/--tb0/--tm0/--x0", "command line"
        )
    result = model.validate(batches, plant=plant_spec, **changes)
    fitted = model.fitted_roasts(batches)
    say(result.notes + list(fitted.values()))
    th = model.theta
    units = args.units or logs_temp_unit(batches)  # the logs' own unit unless asked otherwise
    print(
        result.table(
            f"validation on plant {result.plant}, theta = hgm {th.hgm:.4f}, hbm {th.hbm:.4f}, Pbm {th.Pbm:.4f}",
            units,
        )
    )
    doc = result.to_json_dict()
    if fitted:
        from ..evaluate.metrics import average_metrics

        doc["not_held_out"] = fitted
        held = [row for name, row in zip(result.names, result.rows) if name not in fitted]
        if held:
            doc["average_held_out"] = avg = average_metrics(held)
            print(
                f"held out only ({len(held)} of {len(result.names)} logs; the others are named above): "
                f"FIT {avg['FIT']:.1f} %, MAE {delta_text(avg['MAE'], units, 2)}"
            )
    kg = {b.name: b.Mb_kg for b in batches}  # each scored log's green weight, by its name
    masses = [kg.get(name) for name in result.names]
    held_at = [k for k, name in enumerate(result.names) if name not in fitted]
    if by_size := metrics_by_size(result.rows, masses, held_at):
        doc["by_size"] = by_size  # degC, as the rest of the document
        print(f"\nby batch size ({'the held-out logs' if fitted else 'every log'}):")
        for g in by_size:
            label = _size_label(g)
            mae = display_temp_delta(g["MAE"], units)
            print(f"{label:<36} FIT {g['FIT']:>6.1f} %  MAE {mae:>6.2f} {temp_symbol(units)}")
    bands = None
    if args.band is not None:
        doc["band"], bands = _band_table(model, batches, args.band, units)
    with outputs as out:
        if args.json:
            out.write_text(args.json, json_text(doc))
        if args.plot:
            plot_fit(
                result,
                args.plot,
                title=f"measured vs predicted BT, plant {result.plant}",
                outputs=out,
                bands=bands,
                units=units,
                **(panels_by_size(result.names, masses, held_at) if by_size else {}),  # a panel of each size in turn
            )
        if args.predictions:
            written = set()
            for name, frame in result.frames().items():
                stem = _safe_stem(name, written)
                out.write_text(
                    Path(args.predictions) / f"{stem}.csv",
                    frame.to_csv(index=False, float_format="%.6f", lineterminator="\n"),
                )
    if args.predictions:
        print(f"wrote {len(result.names)} prediction CSV(s) to {args.predictions}")
    return 0


def cmd_compare_models(args) -> int:
    from ..io.files import Outputs
    from ..io.importers import load_map
    from ..workflows.compare import compare_models

    outputs = Outputs(fit_inputs(args))
    check_targets(outputs, args.json, plot=args.plot)
    batches, plant_spec = load_batches(args)
    check_targets(outputs, args.json, args.plot)  # again, now that the files a dataset folder names were read
    if plant_spec is None:
        raise InputError("--plant is required unless a dataset folder names its plant", "command line")
    result = compare_models(
        batches,
        plant_spec,
        args.spec,
        args.variant or None,
        column_map=load_map(args.map) if args.map else None,
        step_kg=args.group_step_kg,
        group_by=args.group_by,
        seed=args.seed,
        starts=args.starts,
        progress=progress("compare-models"),
    )
    print(result.summary())
    with outputs as out:
        write_json_and_plot(out, args, result.to_json_dict(), result)
    return 0


def _size_label(group: dict) -> str:
    """A batch-size group's row label in validate's tables: "size 0.2 kg (1 log)"."""
    return f"size {group['size']} ({group['logs']} log{'s' * (group['logs'] > 1)})"


def _band_table(model, batches, level, units: str = "C") -> tuple[dict, list]:
    """Print and return how often each batch's measured probe lies inside the model's band (its width in
    ``units``, "C" or "F"; the returned document's in degC), and the bands (drawn by --plot)."""
    from ..evaluate.bands import band_report, stored_spread
    from ..metrics.profile import display_temp_delta, temp_symbol

    if not stored_spread(model):
        print("note: the model file has no roast-to-roast spread (fitted on one log, or by an older roastlab): "
              "the band is the parameters' alone")  # fmt: skip
    report, bands = band_report(model, batches, level)
    print(f"\n{level:.0%} prediction band (parameters and roast-to-roast spread, roastlab.evaluate.bands):")
    print(f"{'batch':<36} {'kg':>6} {'inside':>7} {'median width':>13}")
    for r in report["batches"]:
        kg = "" if not r["Mb_kg"] else f"{r['Mb_kg']:.3g}"
        print(
            f"{r['name'][:36]:<36} {kg:>6} {r['inside']:>7.0%} {display_temp_delta(r['median_width_C'], units):>10.1f} {temp_symbol(units)}"
        )
    for g in report["by_size"]:
        print(f"{_size_label(g):<36} {'':>6} {g['inside']:>7.0%}")
    print(f"{'all samples':<36} {'':>6} {report['inside_all']:>7.0%}   (a calibrated band holds about {level:.0%})")
    if report["note"]:
        print(f"note: {report['note']}")
    doc = {"level": level, "inside_all": report["inside_all"], "batches": report["batches"]}
    doc.update({k: report[k] for k in ("by_size", "note") if report[k]})  # only when there are several sizes, a note
    return doc, bands


def _safe_stem(name: str, taken: set) -> str:
    """A file stem from a batch name: no path separators or control characters, unique."""
    stem = "".join(c if (c.isalnum() or c in "-_.") else "_" for c in name)[:80].strip(".") or "batch"
    base, k = stem, 2
    while stem in taken:
        stem, k = f"{base}-{k}", k + 1
    taken.add(stem)
    return stem


def _validate_baseline(args, outputs) -> int:
    from ..fit.baseline import baseline_document, describe, load_baseline, validation_of_first_order
    from ..io.batch import logs_temp_unit
    from ..report.figures import plot_fit

    if not args.model:
        raise InputError(
            "--baseline first-order needs --model BASELINE.json from 'identify --baseline first-order'", "command line"
        )
    params = load_baseline(args.model)
    batches, plant_spec = load_batches(args)
    result = validation_of_first_order(batches, params, str(plant_spec))
    units = args.units or logs_temp_unit(batches)
    print(result.table(f"first-order baseline ({describe(params, units)})", units))
    with outputs as out:
        if args.json:
            out.write_text(args.json, json_text(baseline_document(params, result)))
        if args.plot:
            plot_fit(result, args.plot, title="measured vs first-order baseline", outputs=out, units=units)
    return 0


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    p = sub.add_parser(
        "identify",
        help="fit a model on batches (eqs. 18-19) and write MODEL.json",
        description="Minimise the summed SSR of the probe temperature (and, with --weight Tb2=W or a spec's "
        "[weights], of the model's bean temperature against a second bean reading) over the given batches within bounds, "
        "by a seeded global search (scattered starts polished by bounded least squares) or differential evolution. "
        "Writes the fitted model file (roastlab-model/1): plant, theta and every other fitted or held value with "
        "standard errors and bounds, the initial states, the column map, fit-set metrics and provenance. "
        "Exit status 1 when the fit failed (states the machine cannot have, such as drum metal below the beans; "
        "the model file is written and marked failed), 2 on bad input.",
        epilog="example: roastlab identify --plant 120kg dataset-I/ --out model.json",
    )
    add_batch_options(
        p,
        "fit the first-order baseline dBT/dt = (Tgi + offset [+ k_h heater + k_f fan] - BT)/tau instead "
        "(Tgi = ET on an ET map; the settings when the map reads heater/fan)",
    )
    p.add_argument("--out", required=True, metavar="MODEL.json", help="where to write the model file")
    p.add_argument(
        "--method", choices=("global", "de"), default="global", help="global search (default) or differential evolution"
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="random seed of the search (default %(default)s)")
    add_starts_option(p)
    p.add_argument(
        "--fix", action="append", metavar="NAME=V", help="hold a parameter fixed, e.g. --fix hgm=0.01 (repeatable)"
    )
    p.add_argument(
        "--bounds", action="append", metavar="NAME=LO:HI", help="change bounds, e.g. --bounds hbm=0.01:0.5 (repeatable)"
    )
    p.add_argument(
        "--estimate-tm0",
        action="store_true",
        help="estimate each batch's initial metal temperature as a nuisance parameter",
    )
    p.add_argument(
        "--per-batch",
        action="store_true",
        help="fit a separate theta to every batch (fleet mode; writes a per-batch table, not a model file)",
    )
    p.add_argument(
        "--spec",
        metavar="FIT.toml",
        help="fit spec: free parameters (theta, process constants, initial states) with bounds, output weights",
    )
    p.add_argument(
        "--weight",
        action="append",
        metavar="OUTPUT=W",
        help="weight of a fitted output: Ta (the bean probe, default 1), Tb2 (a second bean reading read by the "
        "map's [Tb2], or its first_crack: the log's FCs mark as the beans' temperature; compared with the model's "
        "Tb; default 0) or ET (the logged ET, compared with the model's "
        "outlet gas; default 0), e.g. --weight Tb2=0.25; W = residual sets it from a first fit's residuals "
        "(--weight ET=residual), and a second fit searches again from the first's optimum "
        "(repeatable; overrides the spec's [weights])",
    )
    add_model_options(p, with_model=False)
    p.set_defaults(func=cmd_identify)

    from ..evaluate.bands import BAND_LEVEL
    from ..evaluate.metrics import GROUP_STEP_SHARE
    from ..model.bed import VARIANTS
    from ..workflows.compare import GROUPINGS
    from .common import variant_arg

    p = sub.add_parser(
        "compare-models",
        help="fit model variants (bed laws) on the same logs; AIC, BIC, leave-one-size-out (or -roaster-, -log-out) FIT "
        "and band calibration",
        description="Fit each model variant on all the logs (summed SSR, AIC, BIC, free parameters, parameters on "
        "a bound, fit-set FIT) and cross-validate it by batch size: the logs are grouped by green weight, and for "
        "each group the variant is fitted on the other groups and predicts that one with nothing refitted. The "
        "variant to prefer is the one with the highest leave-one-size-out FIT, not the best fit. With --group-by unit "
        "the groups are the roasters that recorded the logs instead (leave-one-roaster-out), with --group-by log "
        f"each log alone (leave-one-log-out). Each held-out group is also scored against the {100 * BAND_LEVEL:.0f} % prediction band of "
        "the model fitted without it: the share of its samples inside is the band's cross-validated calibration. "
        "Each fit is a "
        "full identification, so this takes (variants x (groups + 1)) fits: minutes on real logs. It writes no "
        "model file: fit the chosen variant with 'roastlab identify --bed LAWS ... --out MODEL.json'.",
        epilog="example: roastlab compare-models --plant examples/bullet/plant.toml --map examples/bullet/map.toml "
        "--spec examples/bullet/fit.toml logs/*.json --json compare.json --plot compare.png. With one --variant "
        "(e.g. probe=tumbling,probe_gas=mean) and --group-by log it gives each log's FIT and band share from fits "
        "on the others: the band's calibration on your own roasts.",
    )
    p.add_argument("batches", nargs="+", metavar="BATCH", help=FIT_HELP_COMPARE)
    p.add_argument("--plant", help="plant preset or PLANT.toml (default: the dataset's)")
    p.add_argument("--map", metavar="MAP.toml", help="the BATCH arguments are raw logs read with this column map")
    p.add_argument("--spec", metavar="FIT.toml", help="fit spec: free parameters, bounds, initial states, weights")
    p.add_argument(
        "--variant",
        action="append",
        type=variant_arg,
        metavar="VARIANT",
        help="a variant: bed laws and parameters held at a value or freed within the quantity table's bounds, "
        "e.g. 'paper', 'contact=wall,probe=tumbling' or 'probe=tumbling,h_probe_m=0.2' / 'h_probe_m=free' "
        "(repeatable; a profile of one parameter is several variants; default: " + "; ".join(VARIANTS) + ")",
    )
    p.add_argument(
        "--group-by",
        choices=GROUPINGS,
        default="size",
        help="cross-validate by batch size (default; leave-one-size-out), by the roaster that recorded each log "
        "(unit: RoasTime's serial number; leave-one-roaster-out, each drum predicted from the make's other drums) "
        "or by log (leave-one-log-out: each roast predicted from all the others, the test of a new roast's band)",
    )
    p.add_argument(
        "--group-step-kg",
        type=float_arg("--group-step-kg"),
        help=f"green weights are grouped by rounding to this step [kg] (default {GROUP_STEP_SHARE:g} x the median)",
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="random seed of every fit (default %(default)s)")
    add_starts_option(p, " per fit")
    p.add_argument("--json", metavar="COMPARE.json", help="write every variant's figures as JSON")
    p.add_argument(
        "--plot",
        metavar="FIG.png",
        help="bar charts of each held-out group's FIT per variant and of its share inside the band",
    )
    p.set_defaults(func=cmd_compare_models, baseline=None)

    p = sub.add_parser(
        "validate",
        help="apply a model file to batches and report the paper's metrics",
        description="Apply MODEL.json (all of it: theta, fitted flow and constants, initial states; default: the "
        "paper's theta*) to each batch and report n, SSR, ||e||, MAE, MPE, MAPE, FIT, rho per batch and on average. "
        "A batch the model was fitted on (by name, or a copy of one by its recording start) or one roast given "
        "twice is named, and the held-out batches' own average is printed beside the table's; logs of more than "
        "one batch size get their FIT and MAE by size (the held-out ones). Temperatures in the logs' unit.",
        epilog="example: roastlab validate --model model.json --plant 360kg dataset-V/ --predictions pred/",
    )
    add_batch_options(
        p, "validate the first-order baseline (--model BASELINE.json from 'identify --baseline first-order')"
    )
    p.add_argument("--json", metavar="METRICS.json", help="write the metrics as JSON")
    p.add_argument("--plot", metavar="FIG.png", help="plot measured vs predicted BT with residuals (.png/.svg/.pdf)")
    p.add_argument(
        "--predictions",
        metavar="DIR",
        help="write one CSV per batch: time_s, measured Ta_C, Ta_pred_C, predicted states, inputs as applied",
    )
    p.add_argument(
        "--tgi-offset", type=float_arg("--tgi-offset"), help="what-if: add this to the inlet gas / ET [degC]"
    )
    add_band_option(p, "score the model's prediction band", "the share of each batch's measured probe samples "
                    "inside it and its median width, then the share per batch size when the logs have several")  # fmt: skip
    add_units_option(
        p,
        "temperatures in the table, the band's widths and the figure in C or F (default: the logs' own, as "
        "Artisan recorded them; a set of both reads in C); MPE and MAPE stay percent of the reading in degC, as "
        "the paper's Table 2 defines them, and --json, --predictions and --tgi-offset stay in degC",
    )
    add_model_options(p)
    p.set_defaults(func=cmd_validate)
