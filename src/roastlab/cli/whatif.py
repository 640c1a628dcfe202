"""``roastlab whatif``: a logged roast replayed with changes."""

from __future__ import annotations

import argparse

from .common import (
    MODEL_HELP,
    add_initial_options,
    float_arg,
    initial_changes,
    read_inputs,
    say,
    write_json_and_plot,
)


def cmd_whatif(args) -> int:
    from ..io.files import Outputs
    from ..report.figures import check_figure_path
    from ..workflows.model import load_model
    from ..workflows.whatif import parse_set, parse_setting_change, whatif

    outputs = Outputs([args.log, args.model, args.map])
    for target in (args.json, args.plot):
        if target:
            outputs.check(target)
    if args.plot:
        check_figure_path(args.plot)
    setting_changes = [
        parse_setting_change(name, getattr(args, name)) for name in ("heater", "fan") if getattr(args, name)
    ]
    setting_changes += [parse_set(text) for text in args.set or []]
    changes = initial_changes(args)
    if args.tgi is not None:
        changes["Tgi_offset_C"] = args.tgi
    if args.batch_kg is not None:
        from ..model.limits import check_value

        changes["batch_kg"] = check_value("batch_kg", args.batch_kg, "--batch-kg")
    model = load_model(args.model)
    batch = read_inputs(args.log, args.map, model)
    say(batch.notes)
    result = whatif(model, batch, setting_changes, **changes)
    print(result.table())
    with outputs as out:
        write_json_and_plot(out, args, result.to_json_dict(), result)
    return 0


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    p = sub.add_parser(
        "whatif",
        help="predict a logged roast as run and with changed settings, batch or charge state",
        description="Apply MODEL.json to LOG twice, as logged and with the changes, and print the predicted BT at "
        "the logged DROP time and the times to reach 150 degC, 170 degC and the logged first-crack temperature, "
        "with the change in each. Settings (heater, fan) exist when the model's map reads them (the actuator "
        "extension); --tgi works on any model.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
        "  roastlab whatif roast.alog --model model.json --heater +1 --plot whatif.png\n"
        "  roastlab whatif roast.json --model bullet.json --set heater=6@120 --fan -2\n"
        "  roastlab whatif roast.json --model bullet.json --batch-kg 0.8 --tm0 260",
    )
    p.add_argument("log", metavar="LOG", help="the roast log (read with the model's map, or --map)")
    p.add_argument("--model", required=True, metavar="MODEL.json", help=MODEL_HELP)
    p.add_argument("--map", metavar="MAP.toml", help="column map for LOG (default: the model's own)")
    p.add_argument("--heater", metavar="+D|xF", help="shift (+1, -2) or scale (x1.1) the logged heater setting")
    p.add_argument("--fan", metavar="+D|xF", help="shift (+1, -2) or scale (x1.1) the logged fan setting")
    p.add_argument(
        "--set",
        action="append",
        metavar="SETTING=V@S",
        help="set heater or fan to V from S seconds after CHARGE on, e.g. heater=6@120 (repeatable)",
    )
    p.add_argument("--tgi", type=float_arg("--tgi"), help="add this to the inlet gas temperature [degC]")
    p.add_argument("--batch-kg", type=float_arg("--batch-kg"), help="green batch mass [kg] (default: the log's)")
    add_initial_options(p)
    p.add_argument("--json", metavar="WHATIF.json", help="write the table as JSON")
    p.add_argument("--plot", metavar="FIG.png", help="overlay measured BT and both predictions (.png/.svg/.pdf)")
    p.set_defaults(func=cmd_whatif)
