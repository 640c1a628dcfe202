"""``roastlab whatif``: a logged roast replayed with changes."""

from __future__ import annotations

import argparse

from .common import (
    MODEL_HELP,
    add_band_option,
    add_initial_options,
    add_units_option,
    check_targets,
    float_arg,
    initial_changes,
    read_inputs,
    say,
    temperature_arg,
    warn_if_failed,
    write_artisan_files,
    write_json_and_plot,
)


def cmd_whatif(args) -> int:
    from ..io.files import Outputs
    from ..io.importers.mapping import load_map
    from ..workflows.model import load_model
    from ..workflows.whatif import drop_time_s, parse_set, parse_setting_change, whatif

    outputs = Outputs([args.log, args.model, args.map])
    check_targets(outputs, args.json, args.alog, args.alarms, plot=args.plot)
    model = load_model(args.model)
    warn_if_failed(model, args.model)
    cmap = load_map(args.map) if args.map else model.column_map
    units = cmap.setting_units() if cmap is not None else {}
    setting_changes = [
        parse_setting_change(name, getattr(args, name), units.get(name, ""))
        for name in ("heater", "fan")
        if getattr(args, name)
    ]
    setting_changes += [parse_set(text, units) for text in args.set or []]
    changes = initial_changes(args)
    if args.tgi is not None:
        from ..model.limits import check_value

        changes["Tgi_offset_C"] = check_value("Tgi_offset_C", args.tgi, "--tgi")
    if args.batch_kg is not None:
        from ..model.limits import check_value

        changes["batch_kg"] = check_value("batch_kg", args.batch_kg, "--batch-kg")
    batch = read_inputs(args.log, args.map, model)
    say(batch.notes)
    actuators = {k: cmap.actuator(k) for k in ("heater", "fan") if cmap is not None and getattr(cmap, k)}
    drop = {}
    if args.drop_at is not None:
        drop["drop_s"] = drop_time_s(args.drop_at, float(batch.time_s[-1]))
    if args.drop_bt is not None:
        drop["drop_bt_C"] = args.drop_bt
    result = whatif(model, batch, setting_changes, actuators=actuators, band_level=args.band, **drop, **changes)
    units = args.units or batch.temp_unit  # the log's own unit unless asked otherwise
    print(result.table(units=units))
    with outputs as out:
        write_json_and_plot(out, args, result.to_json_dict(), result, units=units)
        write_artisan_files(out, args, result)
    return 0


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    from ..metrics.profile import mmss
    from ..model.actuators import DROP_LATER_MAX_S

    p = sub.add_parser(
        "whatif",
        help="predict a logged roast as run and with changed settings, batch or charge state",
        description="Apply MODEL.json to LOG twice, as logged and with the changes, and print the roaster's "
        "milestones (turning point, DRY END, first crack, temperature at DROP, development time and ratio; for BT "
        "Artisan's AUC, the area above BT at TP from TP to DROP) as "
        "measured, as run by the model and with the changes, with the change and the model's own error on this "
        "log. Judged on the beans (the model's bean temperature; the log's second bean reading as 'measured' "
        "where it has one), the probe BT below: a batch-size change also changes how deep the probe sits in the "
        "bed. DRY END and first crack are when a curve reaches the temperature the log marks them at. A note "
        "says where a change is within the model's own error. Settings (heater, fan) exist when the model's map "
        "reads them, in the map's units (percent, level; W, rpm, Hz; a gas pressure such as kPa; a reading as logged); a model that does "
        "not respond to a changed setting says so; --tgi works on any model. --drop-at or --drop-bt end the changed "
        "roast elsewhere than the log, its milestones read at that DROP.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
        "  roastlab whatif roast.alog --model model.json --heater +5 --plot whatif.png\n"
        "  roastlab whatif roast.json --model bullet.json --heater +1@4:00    # one step more from 4:00 on\n"
        "  roastlab whatif roast.json --model bullet.json --set heater=6@2:00 --fan -2\n"
        "  roastlab whatif roast.json --model bullet.json --batch-kg 0.8 --tm0 260 --units F\n"
        "  roastlab whatif roast.json --model bullet.json --heater -1@5:00 --band    # with the 90 % band\n"
        "  roastlab whatif roast.alog --model model.json --drop-at +0:20     # development time, 20 s longer\n"
        "  roastlab whatif roast.alog --model model.json --heater -5@6:00 --drop-bt 205   # lower heat, same drop BT\n"
        "  roastlab whatif roast.json --model bullet.json --heater -1@5:00 --alog next.alog   # to roast against\n"
        "  roastlab whatif roast.alog --model model.json --heater -10@4:00 --alarms next.alrm  # for Artisan to run",
    )
    p.add_argument("log", metavar="LOG", help="the roast log (read with the model's map, or --map)")
    p.add_argument("--model", required=True, metavar="MODEL.json", help=MODEL_HELP)
    p.add_argument("--map", metavar="MAP.toml", help="column map for LOG (default: the model's own)")
    p.add_argument(
        "--heater",
        metavar="+D[@T]|xF[@T]",
        help="shift (+1, -2) or scale (x1.1) the logged heater setting, from CHARGE or from time T (m:ss or s), "
        "in the map's unit (percent, level, W or a gas pressure such as kPa)",
    )
    p.add_argument(
        "--fan", metavar="+D[@T]|xF[@T]", help="as --heater, for the fan setting (percent, level, rpm or Hz)"
    )
    p.add_argument(
        "--set",
        action="append",
        metavar="SETTING=V@T",
        help="set heater or fan to V from time T (m:ss or s) on, e.g. heater=6@2:00; with a sign it is relative: "
        "heater=+1@4:00 (repeatable)",
    )
    p.add_argument(
        "--tgi",
        type=temperature_arg("--tgi", delta=True),
        help="add this to the inlet gas temperature [degC; 36F for degF]",
    )
    p.add_argument("--batch-kg", type=float_arg("--batch-kg"), help="green batch mass [kg] (default: the log's)")
    drop = p.add_mutually_exclusive_group()
    drop.add_argument(
        "--drop-at",
        metavar="T|+D|-D",
        help="drop the changed roast at T after CHARGE (m:ss or s), or D later (+0:20) or earlier (-0:15) than the "
        "log: its development time, temperature at DROP and the rest read at that DROP; past the logged DROP "
        f"the settings are held at their last values (at most {mmss(DROP_LATER_MAX_S)} more)",
    )
    drop.add_argument(
        "--drop-bt",
        type=temperature_arg("--drop-bt"),
        metavar="TEMP",
        help="drop the changed roast when its BT reaches TEMP [degC; 400F for degF], as the log's probe would read "
        "it: the model's BT plus its own miss on the log then (past the logged DROP, its miss at DROP)",
    )
    add_initial_options(p)
    add_band_option(p, "the changed probe BT's prediction band", "its median width and BT at DROP in the table, "
                    "shaded in --plot, in --json")  # fmt: skip
    add_units_option(
        p,
        "temperatures in the table and the figure in C or F (default: the log's own, as Artisan recorded it; "
        "--tm0, --tb0 and --tgi are degC unless written with an F: 400F)",
    )
    p.add_argument("--json", metavar="WHATIF.json", help="write the table as JSON (temperatures in degC, times in s)")
    p.add_argument("--plot", metavar="FIG.png", help="overlay measured BT and both predictions (.png/.svg/.pdf)")
    p.add_argument(
        "--alog",
        metavar="BACKGROUND.alog",
        help="write the changed roast as an Artisan background to roast against: BT and ET predicted, DRY and first "
        "crack where the predicted BT reaches the log's marks, the changed heater and fan as events",
    )
    p.add_argument(
        "--alarms",
        metavar="SETTINGS.alrm",
        help="write the changed heater and fan settings as an Artisan alarm set that moves the Burner and Air "
        "sliders at each change after CHARGE (Config > Alarms > Load; a machine Artisan controls)",
    )
    p.set_defaults(func=cmd_whatif)
