"""The ``roastlab`` command line: a thin layer that parses, calls the library, formats.

Every :class:`~roastlab.errors.RoastlabError` becomes one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import sys

from .errors import InputError, RoastlabError


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit 2) instead of a usage block."""

    def error(self, message: str):  # noqa: D102
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def _float_arg(name: str):
    def parse(text: str) -> float:
        try:
            v = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number, got {text!r}") from None
        if v != v or v in (float("inf"), float("-inf")):
            raise argparse.ArgumentTypeError(f"{name} must be finite, got {text!r}")
        return v

    return parse


def _add_model_options(p: argparse.ArgumentParser, with_theta: bool = True) -> None:
    p.add_argument("--plant", required=True, help="plant preset (120kg, 360kg) or PLANT.toml path")
    if with_theta:
        p.add_argument("--theta", metavar="THETA.json", help="identified coefficients (default: the paper's theta*)")
        p.add_argument("--hgm", type=_float_arg("--hgm"), help="gas-metal coefficient [kW/(m2 K)]; overrides --theta")
        p.add_argument("--hbm", type=_float_arg("--hbm"), help="metal-bean coefficient [kW/(m2 K)]; overrides --theta")
        p.add_argument(
            "--pbm", type=_float_arg("--pbm"), help="bean-metal contact fraction in (0, 1); overrides --theta"
        )
    p.add_argument("--tb0", type=_float_arg("--tb0"), default=30.0, help="initial bean temperature [degC] (default 30)")
    p.add_argument(
        "--tm0", type=_float_arg("--tm0"), default=121.0, help="initial metal temperature [degC] (default 121)"
    )
    p.add_argument("--x0", type=_float_arg("--x0"), default=0.1, help="initial moisture [kg/kg dry] (default 0.1)")
    p.add_argument(
        "--moisture",
        choices=("schwartzberg", "printed"),
        default="schwartzberg",
        help="moisture law, eq. 13 (default schwartzberg)",
    )
    p.add_argument(
        "--hold", choices=("linear", "zoh"), default="linear", help="input hold between samples (default linear)"
    )


def _theta_from_args(args):
    from .theta import THETA_PAPER, Theta, load_theta_json

    theta, extra = THETA_PAPER, {}
    if getattr(args, "theta", None):
        theta, extra = load_theta_json(args.theta)
    values = theta.as_dict()
    for key, opt in (("hgm", "hgm"), ("hbm", "hbm"), ("Pbm", "pbm")):
        v = getattr(args, opt, None)
        if v is not None:
            values[key] = v
    try:
        return Theta(**values), extra
    except RoastlabError as exc:
        raise InputError(str(exc), "command line") from None


def _initial_from_args(args):
    from .simulate import InitialState

    if not 0.0 <= args.x0 < 1.0:
        raise InputError(f"--x0 must be in [0, 1) kg/kg, got {args.x0}", "command line")
    return InitialState(Tb0_C=args.tb0, Tm0_C=args.tm0, X0=args.x0)


# ----------------------------------------------------------------------------- commands
def cmd_simulate(args) -> int:
    from .data import read_batch_csv
    from .io import check_output_path
    from .plant import load_plant
    from .simulate import simulate

    plant = load_plant(args.plant)
    theta, _ = _theta_from_args(args)
    batch = read_batch_csv(args.inputs)
    out = check_output_path(args.out, [args.inputs] + ([args.theta] if args.theta else []))
    result = simulate(
        plant,
        batch.time_s,
        batch.Gg_kg_s,
        batch.Tgi_C,
        theta=theta,
        initial=_initial_from_args(args),
        Ta_measured_C=batch.Ta_C,
        moisture=args.moisture,
        hold=args.hold,
        name=batch.name,
    )
    if out.suffix.lower() == ".json":
        result.to_json(out, heat_flows=args.heat_flows)
    else:
        result.to_csv(out, heat_flows=args.heat_flows)
    if args.plot:
        check_output_path(args.plot, [args.inputs])
        result.plot(args.plot, title=f"{batch.name} on {plant.name} (simulated)")
    last = result.states[-1]
    print(
        f"simulated {batch.name}: {len(result.time_s)} samples, {result.time_s[-1] - result.time_s[0]:.0f} s on plant {plant.name}; "
        f"final Tb {last[0]:.2f} degC, Ta {last[4]:.2f} degC, X {last[2]:.4f}, Tgo {result.Tgo_C[-1]:.1f} degC -> {out}"
    )
    return 0


def cmd_plant(args) -> int:
    from .plant import load_plant
    from .theta import THETA_PAPER

    plant = load_plant(args.plant)
    th = THETA_PAPER
    print(f"plant {plant.name}")
    print(f"{'symbol':<8}{'value':>12}  {'unit':<6} meaning")
    for symbol, value, unit, meaning in plant.describe(th.hgm, th.hbm, th.Pbm, args.x0):
        print(f"{symbol:<8}{value:>12.4g}  {unit:<6} {meaning}")
    pc = plant.process.as_dict()
    print("process constants: " + ", ".join(f"{k}={v:g}" for k, v in pc.items()))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="roastlab",
        description="Simulate, identify and validate the scalable coffee-roasting-chamber model "
        "(Procedia Computer Science 2021) on plants of any size.",
    )
    parser.add_argument("--version", action="version", version="roastlab 0.1.0")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    p = sub.add_parser(
        "simulate",
        help="simulate one batch from an inputs CSV",
        description="Simulate one batch. INPUTS.csv has columns time_s,Gg_kg_s,Tgi_C[,Ta_C]; "
        "OUT.csv gets time_s,Tb_C,Tm_C,X_kg_kg,He_kJ_kg,Ta_C,Tgo_C (OUT.json: the same as JSON).",
    )
    _add_model_options(p)
    p.add_argument("--inputs", required=True, metavar="INPUTS.csv", help="input samples (time_s,Gg_kg_s,Tgi_C[,Ta_C])")
    p.add_argument(
        "--out", required=True, metavar="OUT.csv", help="where to write the simulated states (.csv or .json)"
    )
    p.add_argument("--heat-flows", action="store_true", help="also write Qgb, Qgm, Qbm, Qr [kW]")
    p.add_argument("--plot", metavar="FIG.png", help="also save a figure of the simulation")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser(
        "plant",
        help="print a plant's geometry and derived quantities",
        description="Print geometry (Table 5) and derived quantities (eq. 6-7) of a plant.",
    )
    p.add_argument("plant", help="plant preset (120kg, 360kg) or PLANT.toml path")
    p.add_argument("--x0", type=_float_arg("--x0"), default=0.1, help="moisture used for Mbd and F (default 0.1)")
    p.set_defaults(func=cmd_plant)

    for register in _EXTRA_COMMANDS:
        register(sub)
    return parser


#: Later modules append functions ``register(subparsers)`` here.
_EXTRA_COMMANDS: list = []


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except RoastlabError as exc:
        print(f"roastlab {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("roastlab: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
