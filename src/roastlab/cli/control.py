"""``roastlab control`` and ``roastlab control compare``: the closed-loop testbench."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import InputError
from .common import (
    MODEL_HELP,
    Parser,
    check_targets,
    float_arg,
    model_from_args,
    progress,
    read_inputs,
    say,
    write_json_and_plot,
)


def _control_inputs(args):
    """The model, reference and plant of a ``control`` run (the standard synthetic reference when
    no --reference is given)."""
    from ..control import standard_reference

    model = model_from_args(args, args.plant or "120kg")
    if args.reference:
        reference = read_inputs(args.reference, args.map, model)
        say(reference.notes)
    else:
        reference = standard_reference()
        say(["no --reference: following the SYNTHETIC standard reference (roastlab.control.standard_reference)"])
    return model, reference


def cmd_control(args) -> int:
    from ..control import load_scenario, make_controller, run_closed_loop
    from ..control.loop import find_scenario
    from ..io.files import Outputs

    if args.what == "compare":
        return cmd_control_compare(args)
    outputs = Outputs([args.reference, args.model, args.map, args.plant, args.scenario])
    check_targets(outputs, args.out, args.json, plot=args.plot)
    controller = make_controller(args.controller)
    if args.ror_weight:
        if args.controller != "mpc":
            raise InputError("--ror-weight is an MPC option", "command line")
        from ..control import MPC

        controller = MPC(ror_weight=args.ror_weight)
    scenario = load_scenario(find_scenario(args.scenario)) if args.scenario else None
    model, reference = _control_inputs(args)
    result = run_closed_loop(model, reference, controller, scenario, args.plant)
    m = result.metrics
    print(
        f"{m['controller']} on '{m['scenario']}': BT RMSE {m['rmse_C']:.2f} °C, max {m['max_abs_C']:.1f} °C, "
        f"RoR RMSE {m['ror_rmse_C_per_min']:.2f} °C/min, drop time "
        + ("not reached" if m["drop_time_error_s"] is None else f"{m['drop_time_error_s']:+.0f} s")
        + f", {m['constraint_violations']} requests clipped, step {m['step_ms_median']:.2f} ms median "
        f"({m['step_ms_p99']:.2f} ms p99)"
    )
    with outputs as out:
        if args.out:
            out.write_text(args.out, result.trace_csv_text())
        write_json_and_plot(out, args, m, result)
    return 0


def cmd_control_compare(args) -> int:
    from ..control import compare, make_controller, standard_scenarios
    from ..io.files import Outputs

    scenarios = standard_scenarios()
    if args.scenarios:
        folder = Path(args.scenarios)
        if not folder.is_dir():
            raise InputError("not a folder of scenario .toml files", folder)
        scenarios = sorted(folder.glob("*.toml"))
        if not scenarios:
            raise InputError("no .toml scenario files in this folder", folder)
    outputs = Outputs([args.reference, args.model, args.map, args.plant, *scenarios])
    check_targets(outputs, args.json, plot=args.plot)
    names = [c.strip() for c in args.controllers.split(",") if c.strip()]
    controllers = [make_controller(c) for c in names]
    if not controllers:
        raise InputError("no controllers given", "--controllers")
    model, reference = _control_inputs(args)
    result = compare(
        model, reference, scenarios, controllers, args.plant, oracle=args.oracle, progress=progress("control compare")
    )
    print(result.table())
    with outputs as out:
        write_json_and_plot(out, args, result.to_json_dict(), result)
    return 0


def _add_control_options(p, compare: bool) -> None:
    p.add_argument(
        "--model", "--theta", dest="model", metavar="MODEL.json", help=MODEL_HELP + " (default: the paper's theta*)"
    )
    p.add_argument("--hgm", type=float_arg("--hgm"), help="gas-metal coefficient [kW/(m2 K)]; overrides the model")
    p.add_argument("--hbm", type=float_arg("--hbm"), help="metal-bean coefficient [kW/(m2 K)]; overrides the model")
    p.add_argument("--pbm", type=float_arg("--pbm"), help="bean-metal contact fraction in (0, 1); overrides the model")
    p.add_argument("--plant", help="plant preset (120kg, 360kg) or PLANT.toml (default: the model's, else 120kg)")
    p.add_argument(
        "--reference",
        metavar="REF.csv",
        help="the roast to follow: a batch CSV with Ta_C (BT) and its inputs, or a log with --map "
        "(default: the SYNTHETIC standard reference, 17 min on the 120 kg plant)",
    )
    p.add_argument("--map", metavar="MAP.toml", help="REF is a raw log read with this column map")
    if compare:
        p.add_argument(
            "--scenarios", metavar="DIR", help="folder of scenario .toml files (default: the 9 shipped scenarios)"
        )
        p.add_argument(
            "--controllers",
            default="replay,pid,pid-bumpless,mpc",
            metavar="LIST",
            help="comma-separated controllers to run (default replay,pid,pid-bumpless,mpc)",
        )
        p.add_argument(
            "--oracle",
            action="store_true",
            help="also solve each scenario open loop with the roaster known (what is reachable; seconds each)",
        )
        p.add_argument("--json", metavar="TABLE.json", help="write every row and the summary as JSON")
        p.add_argument("--plot", metavar="FIG.png", help="RMSE per scenario and controller, and the BT errors")
    else:
        p.add_argument(
            "--controller",
            choices=("pid", "pid-bumpless", "mpc", "replay"),
            default="mpc",
            help="pid: Artisan's software PID (its defaults, integral from 0 at CHARGE); pid-bumpless: the same "
            "started at the actuator's position; mpc: model predictive control with a Kalman filter; "
            "replay: the reference's own inputs (default mpc)",
        )
        p.add_argument(
            "--scenario",
            metavar="S.toml",
            help="scenario file, or a shipped scenario by name (cold-drum, hot-drum, ...; default: nominal; "
            "see docs/control.md)",
        )
        p.add_argument(
            "--ror-weight",
            type=float_arg("--ror-weight"),
            default=0.0,
            help="mpc: also track the reference's rate of rise, this weight per degC/min against 1 per degC "
            "(default 0: the level only)",
        )
        p.add_argument("--json", metavar="METRICS.json", help="write the metrics as JSON")
        p.add_argument("--plot", metavar="FIG.png", help="BT, rate of rise, the input and the drum temperature")
        p.add_argument(
            "--out", metavar="TRACE.csv", help="write the trace: every sample's reference, BT, input, states"
        )


def add_parsers(sub) -> None:
    """Register ``roastlab control`` (and ``control compare``) on the subparsers ``sub``."""
    p = sub.add_parser(
        "control",
        help="closed-loop control on the model: PID, MPC or replay against a scenario",
        description="Run a controller against a simulated roaster that differs from the controller's model as a "
        "scenario says (batch mass, moisture, drum temperature, coefficients, gas supply, probe noise and delay), "
        "following a reference BT curve. 'control compare' runs every controller on every scenario. Scenario keys: "
        "docs/control.md; the shipped set: roastlab.control.standard_scenarios().",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
        "  roastlab control --controller mpc --scenario cold.toml --plot mpc.png --json m.json\n"
        "  roastlab control --model MODEL.json --plant 120kg --reference REF.csv --controller pid --out trace.csv\n"
        "  roastlab control compare --json table.json --plot compare.png\n"
        "metrics: rmse_C, max_abs_C (BT vs reference), ror_rmse_C_per_min, drop_time_error_s, actuator_travel, "
        "constraint_violations (requests the actuator clipped), step_ms_median/p99 (the controller's own time).",
    )
    _add_control_options(p, compare=False)
    csub = p.add_subparsers(dest="what", metavar="[compare]", parser_class=Parser)
    csub.required = False
    q = csub.add_parser(
        "compare",
        help="every controller on every scenario: one table and a figure",
        description="Run every controller on every scenario (default: the 9 shipped ones) against the same "
        "reference and print one table; --json and --plot write it.",
    )
    _add_control_options(q, compare=True)
    p.set_defaults(func=cmd_control, what=None)
