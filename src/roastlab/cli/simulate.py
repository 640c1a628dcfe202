"""``roastlab simulate`` and ``roastlab plant``: one batch through a model file, a plant's geometry."""

from __future__ import annotations

from pathlib import Path

from .common import (
    add_band_option,
    add_model_options,
    float_arg,
    initial_changes,
    model_from_args,
    read_inputs,
    say,
)


def cmd_simulate(args) -> int:
    from ..io.files import Outputs
    from ..report.figures import check_figure_path, plot_simulation

    out_plan = Outputs([args.inputs, args.model, args.map, args.plant])
    out_plan.check(args.out)
    if args.plot:
        check_figure_path(out_plan.check(args.plot))
    model = model_from_args(args, args.plant)
    batch = read_inputs(args.inputs, args.map, model)
    changes = initial_changes(args)
    if args.tgi_offset is not None:
        changes["Tgi_offset_C"] = args.tgi_offset
    result = model.predict(batch, plant=args.plant, **changes)
    if args.band is not None:
        from ..errors import ParameterError
        from ..evaluate.bands import prediction_bands, require_band

        if args.model is None:
            raise ParameterError("the paper's theta* carries no band: give a fitted --model", "--band")
        require_band(model, args.model)
        result.band = prediction_bands(model, [batch], args.band, plant=args.plant, **changes)[0]
    say(result.meta.get("notes", []))
    with out_plan as out:
        if Path(args.out).suffix.lower() == ".json":
            out.write_text(args.out, result.to_json_text(heat_flows=args.heat_flows))
        else:
            out.write_text(args.out, result.to_csv_text(heat_flows=args.heat_flows))
        if args.plot:
            plot_simulation(result, args.plot, f"{batch.name} on {result.meta['plant']} (simulated)", outputs=out)
    last = result.states[-1]
    if result.band is not None:
        b = result.band
        print(
            f"{b.level * 100:g} % prediction band of BT (parameter covariance and roast-to-roast spread): median "
            f"width {b.median_width_C:.1f} degC; at the end {b.lower_C[-1]:.1f} to {b.upper_C[-1]:.1f} degC"
        )
    print(
        f"simulated {batch.name}: {len(result.time_s)} samples, {result.time_s[-1] - result.time_s[0]:.0f} s on plant {result.meta['plant']}; "
        f"final BT {last[4]:.2f} degC (bean core Tb {last[0]:.2f}), X {last[2]:.4f}, Tgo {result.Tgo_C[-1]:.1f} degC -> {args.out}"
    )
    return 0


def cmd_plant(args) -> int:
    from ..io.plants import load_plant
    from ..model.parameters import THETA_PAPER

    plant = load_plant(args.plant)
    th = THETA_PAPER
    print(f"plant {plant.name}")
    print(f"{'symbol':<8}{'value':>12}  {'unit':<6} meaning")
    for symbol, value, unit, meaning in plant.describe(th.hgm, th.hbm, th.Pbm, args.x0):
        print(f"{symbol:<8}{value:>12.4g}  {unit:<6} {meaning}")
    pc = plant.process.as_dict()
    print("process constants: " + ", ".join(f"{k}={v:g}" for k, v in pc.items()))
    return 0


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    from ..model.quantities import default

    p = sub.add_parser(
        "simulate",
        help="simulate one batch with a model file (default: the paper's theta*)",
        description="Simulate one batch with MODEL.json (all of it, as validate applies it). INPUTS is a batch CSV "
        "(time_s,Gg_kg_s,Tgi_C[,Ta_C]) or a raw log read with --map or with the model's own map. OUT.csv gets "
        "time_s,Tb_C,Tm_C,X_kg_kg,He_kJ_kg,Ta_C,Tgo_C (OUT.json: the same as JSON).",
        epilog="example: roastlab simulate --model model.json --inputs batch.csv --out pred.csv --tgi-offset 20",
    )
    add_model_options(p)
    p.add_argument("--plant", help="plant preset (120kg, 360kg) or PLANT.toml (default: the model's plant)")
    p.add_argument(
        "--inputs", required=True, metavar="INPUTS.csv", help="input samples (time_s,Gg_kg_s,Tgi_C[,Ta_C]) or a log"
    )
    p.add_argument("--map", metavar="MAP.toml", help="INPUTS is a raw log read with this column map")
    add_band_option(p, "the probe prediction's band", "Ta_lower_C, Ta_upper_C in OUT, shaded in --plot")
    p.add_argument(
        "--out", required=True, metavar="OUT.csv", help="where to write the simulated states (.csv or .json)"
    )
    p.add_argument(
        "--tgi-offset", type=float_arg("--tgi-offset"), help="what-if: add this to the inlet gas / ET [degC]"
    )
    p.add_argument("--heat-flows", action="store_true", help="also write Qgb, Qgm, Qbm, Qr [kW]")
    p.add_argument("--plot", metavar="FIG.png", help="also save a figure of the simulation (.png/.svg/.pdf)")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser(
        "plant",
        help="print a plant's geometry and derived quantities",
        description="Print geometry (Table 5) and derived quantities (eq. 6-7) of a plant (the plant a MODEL.json "
        "stores in full, or a preset or PLANT.toml).",
    )
    p.add_argument("plant", help="plant preset (120kg, 360kg) or PLANT.toml path")
    x0 = default("X0")
    p.add_argument("--x0", type=float_arg("--x0"), default=x0, help=f"moisture used for Mbd and F (default {x0:g})")
    p.set_defaults(func=cmd_plant)
