"""``roastlab transfer``: the program that gives a reference curve on another plant or batch size."""

from __future__ import annotations

import argparse

from ..errors import InputError
from .common import (
    MODEL_HELP,
    add_band_option,
    add_units_option,
    check_targets,
    float_arg,
    range_arg,
    read_inputs,
    say,
    temperature_arg,
    warn_if_failed,
    write_artisan_files,
    write_json_and_plot,
)


def cmd_transfer(args) -> int:
    from ..fit.program import ProgramLimits
    from ..io.files import Outputs
    from ..model.limits import check_value
    from ..workflows.model import load_model
    from ..workflows.transfer import default_limits, transfer

    outputs = Outputs([args.reference, args.target, args.model, args.map, args.plant_from, args.plant_to])
    check_targets(outputs, args.out, args.json, args.alog, args.alarms, plot=args.plot)
    if args.gg is not None and (args.gg_min is not None or args.gg_max is not None):
        raise InputError(
            "--gg fixes the flow; --gg-min/--gg-max let the optimiser choose it: give one or the other", "command line"
        )
    model = load_model(args.model)
    warn_if_failed(model, args.model)
    reference = read_inputs(args.reference, args.map, model)
    say(reference.notes)
    if args.target:
        from ..io.importers import import_log
        from ..workflows.transfer import aim_at

        # any log's BT, read with its format's own channels (another machine's map is not this model's)
        reference = aim_at(reference, import_log(args.target, None))
        say(reference.notes)
    initial = {}
    for opt, name in (("tb0", "Tb0_C"), ("x0", "X0")):
        if getattr(args, opt) is not None:
            initial[name] = check_value(name, getattr(args, opt), f"--{opt}")
    tm0_free = None
    if args.tm0 is not None:
        if args.tm0.strip().lower() == "free":
            tm0_free = range_arg(args.tm0_range, "--tm0-range")
        else:
            try:
                initial["Tm0_C"] = check_value("Tm0_C", temperature_arg("--tm0")(args.tm0), "--tm0")
            except argparse.ArgumentTypeError:
                raise InputError(
                    f"expected a temperature [degC; 400F for degF] or 'free', got {args.tm0!r}", "--tm0"
                ) from None
    decide = args.decide or default_limits(model, args.plant_from, args.plant_to).decide
    if decide == "heater":
        if reference.heater is None:
            raise InputError(
                "--decide heater needs a reference with a heater setting (a map with [heater])", args.reference
            )
        cmap = model.column_map
        actuator = cmap.actuator("heater") if cmap is not None and cmap.heater else None
        if actuator is None:
            raise InputError("--decide heater needs a model whose map declares the heater ([heater])", args.model)
        limits = ProgramLimits.for_actuator(
            actuator, args.heater_min, args.heater_max, args.heater_rate, args.gg_min, args.gg_max
        )
    else:
        limits = ProgramLimits(args.tgi_min, args.tgi_max, args.tgi_rate, args.gg_min, args.gg_max)
    result = transfer(
        model,
        reference,
        args.plant_from,
        args.plant_to,
        limits=limits,
        batch_kg=args.batch_kg,
        gg_kg_s=args.gg,
        interval_s=args.interval_s,
        tm0_free=tm0_free,
        tolerance_C=args.tolerance,
        initial=initial,
        band_level=args.band,
        units=args.units,
    )
    say(result.metrics["notes"])
    print(result.summary())
    with outputs as out:
        out.write_text(args.out, result.program_csv_text())
        write_json_and_plot(out, args, result.to_json_dict(), result)
        write_artisan_files(out, args, result)
    return 0


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    # the model's tables only: the transfer itself (its exact sensitivities) is imported when it runs
    from ..model.actuators import MIN_HOLD_S, TGI_LIMITS, TM0_FREE_RANGE_C
    from ..model.quantities import default

    p = sub.add_parser(
        "transfer",
        help="compute the input program that reproduces a roast on another plant or batch size",
        description="Find the heater program (where the model's map reads a heater and the inlet is room air), "
        "else the inlet-gas program (--decide chooses), that makes the "
        "model's bean probe on plant B (--to) follow the reference roast's BT from CHARGE to DROP on plant A "
        "(--from), within level and rate limits. The model's carried-over values (theta, process constants) are "
        "applied on B. Prints the fit of the program against two baselines computed in the same run: B with A's "
        "inputs unchanged, and A's inputs retimed by the phase times that run gives (what a person does with "
        "Artisan's Transposer). An unreachable target is not an error: the best program is written, 'feasible' "
        "is false and the output says where and which limit holds it back. A batch-size change on one machine "
        "is --to = --from with --batch-kg.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="outputs:\n"
        "  PROGRAM.csv   time_s,Gg_kg_s,Tgi_C[,heater,fan],Ta_pred_C with the charge state as '# key = value'\n"
        "                lines: 'roastlab simulate --model M --plant B --inputs PROGRAM.csv' reproduces Ta_pred_C\n"
        "  METRICS.json  rmse_C, max_abs_C, feasible, solve_s, the baselines, the limits the program sits on\n"
        "  BACKGROUND.alog  an Artisan profile to load as background: BT predicted, ET the model's, the\n"
        "                reference's CHARGE/DRY/FCs/DROP marks, the program as Burner/Air events\n"
        "  PROGRAM.alrm  Artisan alarms that run the program: at each change, the Burner (Air) slider moved to\n"
        "                it (a level in tens, as Artisan's Aillio setups: P6 = 60), the setting at CHARGE at 0:01\n\n"
        "A heater program is rounded to the machine's settings (the map's [heater] min, max, step) and held\n"
        f"at least {MIN_HOLD_S:g} s between changes: the runnable program; the continuous one's error is printed "
        "beside it.\n\n"
        "examples:\n"
        "  roastlab transfer --model myroaster/model.json --reference roast.alog --batch-kg 0.25 --out program.csv \\\n"
        "      --plot transfer.png --alog next.alog --alarms next.alrm   # your roaster's log at another batch size\n"
        "  roastlab transfer --model myroaster/model.json --reference roast.alog --target bullet.json --out program.csv\n"
        "                                          # another machine's roast on yours\n"
        "  roastlab transfer --model model.json --from 120kg --to 360kg --reference batch1.csv --out program.csv\n"
        "  roastlab transfer --model model.json --from 120kg --to 120kg --batch-kg 84 --reference batch1.csv \\\n"
        "      --out program.csv --tm0 free --plot transfer.png --alog background.alog",
    )
    p.add_argument("--model", required=True, metavar="MODEL.json", help=MODEL_HELP)
    p.add_argument(
        "--from", dest="plant_from", metavar="PLANT_A", help="plant the reference was roasted on (default: the model's)"
    )
    p.add_argument(
        "--to", dest="plant_to", metavar="PLANT_B", help="plant to compute the program for (default: PLANT_A)"
    )
    p.add_argument(
        "--reference", required=True, metavar="REF", help="batch CSV (time_s,Gg_kg_s,Tgi_C,Ta_C) or a log (with --map)"
    )
    p.add_argument("--map", metavar="MAP.toml", help="column map for a raw-log reference (default: the model's own)")
    p.add_argument(
        "--target",
        metavar="TARGET",
        help="follow this log's BT instead of the reference's: another machine's roast, a profile drawn in Artisan's "
        "Designer (any .alog, RoasTime .json or batch CSV, read with its format's own channels); the reference, a "
        "log of the model's machine, then gives the program's start, the batch and the charge state",
    )
    p.add_argument("--out", required=True, metavar="PROGRAM.csv", help="where to write the program")
    p.add_argument(
        "--batch-kg",
        type=float_arg("--batch-kg"),
        help="green batch on B [kg] (default: B's nominal batch; the reference's when B = A)",
    )
    p.add_argument(
        "--tb0",
        type=temperature_arg("--tb0"),
        help=f"bean temperature at CHARGE on B [degC; 72F for degF] (default: the model's, else {default('Tb0_C'):g})",
    )
    p.add_argument(
        "--tm0",
        metavar="C|free",
        help="drum temperature at CHARGE on B [degC; 400F for degF], or 'free' to let the optimiser choose it (the "
        "preheat)",
    )
    p.add_argument(
        "--tm0-range",
        default="{:g}:{:g}".format(*TM0_FREE_RANGE_C),
        metavar="LO:HI",
        help="range for --tm0 free [degC] (default {:g}:{:g})".format(*TM0_FREE_RANGE_C),
    )
    p.add_argument(
        "--x0",
        type=float_arg("--x0"),
        help=f"green moisture on B [kg/kg dry] (default: the model's, else {default('X0'):g})",
    )
    p.add_argument(
        "--decide",
        choices=("Tgi", "heater"),
        help="the input the program sets (default: the heater, on the machine's steps, where the model's map "
        "reads a heater and the inlet is room air; else Tgi)",
    )
    p.add_argument(
        "--tgi-min",
        type=float_arg("--tgi-min"),
        default=TGI_LIMITS[0],
        help=f"lowest inlet temperature [degC] (default {TGI_LIMITS[0]:g})",
    )
    p.add_argument(
        "--tgi-max",
        type=float_arg("--tgi-max"),
        default=TGI_LIMITS[1],
        help=f"highest inlet temperature [degC] (default {TGI_LIMITS[1]:g})",
    )
    p.add_argument(
        "--tgi-rate",
        type=float_arg("--tgi-rate"),
        default=TGI_LIMITS[2],
        help=f"fastest change of the inlet temperature [degC/min] (default {TGI_LIMITS[2]:g})",
    )
    p.add_argument(
        "--heater-min", type=float_arg("--heater-min"), help="lowest heater setting (default: the map's [heater] min)"
    )
    p.add_argument(
        "--heater-max", type=float_arg("--heater-max"), help="highest heater setting (default: the map's [heater] max)"
    )
    p.add_argument(
        "--heater-rate",
        type=float_arg("--heater-rate"),
        help="fastest heater change [setting/min] (default: the map's [heater] rate_per_min)",
    )
    p.add_argument(
        "--gg",
        type=float_arg("--gg"),
        help="fixed gas flow on B [kg/s] (default: A's flow times the batch-mass ratio)",
    )
    p.add_argument(
        "--gg-min",
        type=float_arg("--gg-min"),
        help="with --gg-max: the optimiser chooses a constant gas flow in this range [kg/s]",
    )
    p.add_argument("--gg-max", type=float_arg("--gg-max"), help="see --gg-min")
    p.add_argument(
        "--interval-s",
        type=float_arg("--interval-s"),
        default=5.0,
        help="spacing of the program's knots [s] (default %(default)g)",
    )
    p.add_argument(
        "--tolerance",
        type=float_arg("--tolerance"),
        default=2.0,
        help="feasible when max |predicted - target| <= this [degC] (default %(default)g)",
    )
    add_band_option(p, "the predicted BT's prediction band", "its median width and BT at DROP in the output, "
                    "shaded in --plot, in --json: where a roast run with the program is expected")  # fmt: skip
    add_units_option(
        p,
        "temperatures in the summary and the figure in C or F (default: the reference log's own, as Artisan "
        "recorded it, which --alog is written in; the limits, --tolerance, OUT and --json stay in degC)",
    )
    p.add_argument("--json", metavar="METRICS.json", help="write the metrics, baselines and limits as JSON")
    p.add_argument(
        "--plot", metavar="FIG.png", help="target vs predicted BT, the program with its limits, the baselines"
    )
    p.add_argument(
        "--alog", metavar="BACKGROUND.alog", help="write an Artisan background profile of the prediction and program"
    )
    p.add_argument(
        "--alarms",
        metavar="PROGRAM.alrm",
        help="write the heater program (and the logged fan) as an Artisan alarm set that moves the Burner and Air "
        "sliders at its changes after CHARGE (Config > Alarms > Load; a machine Artisan controls)",
    )
    p.set_defaults(func=cmd_transfer)
