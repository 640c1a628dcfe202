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


def _add_model_options(p: argparse.ArgumentParser, with_theta: bool = True, plant: bool = True) -> None:
    if plant:
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
    if batch.Mb_kg:  # the batch's own green weight (e.g. imported from an Artisan log)
        import dataclasses

        plant = dataclasses.replace(plant, Mb_kg=batch.Mb_kg)
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


def _parse_assignments(items, option: str, ranged: bool):
    """Parse ``name=value`` (or ``name=lo:hi`` when ``ranged``) options."""
    out = {}
    for item in items or []:
        name, sep, text = item.partition("=")
        if not sep or not name:
            raise InputError(f"{option} expects NAME={'LO:HI' if ranged else 'VALUE'}, got {item!r}", "command line")
        try:
            if ranged:
                lo, sep2, hi = text.partition(":")
                if not sep2:
                    raise ValueError
                value = (float(lo), float(hi))
            else:
                value = float(text)
        except ValueError:
            raise InputError(
                f"{option} {name}: cannot read {text!r} as {'LO:HI' if ranged else 'a number'}", "command line"
            ) from None
        if ranged and not value[0] < value[1]:
            raise InputError(
                f"{option} {name}: inverted or empty bounds {value[0]:g}:{value[1]:g} (need LO < HI)", "command line"
            )
        out[name.strip()] = value
    return out


def _load_batches(args, require_Ta=True):
    from .data import expand_batch_args
    from .plant import load_plant

    if getattr(args, "map", None):
        from .importers import import_log, load_map

        cmap = load_map(args.map)
        batches = [import_log(p, cmap) for p in args.batches]
        for b in batches:
            for note in b.notes:
                print(f"warning: {b.source}: {note}", file=sys.stderr)
        if not args.plant:
            raise InputError("--plant is required with --map", "command line")
        return batches, load_plant(args.plant)
    batches, dataset_plant = expand_batch_args(args.batches, require_Ta=require_Ta)
    plant_spec = args.plant or dataset_plant
    if plant_spec is None:
        raise InputError("--plant is required unless a dataset folder names its plant", "command line")
    return batches, load_plant(plant_spec)


def _print_warnings(warnings) -> None:
    for w in warnings:
        print(f"warning: {w}", file=sys.stderr)


def cmd_identify(args) -> int:
    import json

    from .identify import build_free_parameters, identify
    from .io import atomic_write_text, check_output_path
    from .population import pack_batches
    from .simulate import InitialState
    from .theta import THETA_START

    batches, plant = _load_batches(args)
    out = check_output_path(args.out, [b.source for b in batches if b.source] + [x for x in (args.map, args.spec) if x])
    if args.baseline:
        from .baseline import fit_first_order

        doc = {**fit_first_order(batches), "plant": plant.name}
        atomic_write_text(out, json.dumps(doc, indent=1) + "\n")
        print(
            f"first-order baseline on {len(batches)} batch(es): tau {doc['tau_s']:.1f} s, offset {doc['offset_C']:+.2f} degC, SSR {doc['SSR']:.1f} -> {out}"
        )
        return 0
    if args.spec:
        return _identify_with_spec(args, batches, plant, out)
    fix = _parse_assignments(args.fix, "--fix", ranged=False)
    bounds = _parse_assignments(args.bounds, "--bounds", ranged=True)
    free, fixed = build_free_parameters(fix, bounds, estimate_tm0=args.estimate_tm0)
    initial = InitialState(Tb0_C=args.tb0, Tm0_C=args.tm0, X0=args.x0)
    packed = pack_batches(batches, plant, THETA_START, initial=initial, moisture=args.moisture, hold=args.hold)
    if args.per_batch:
        return _identify_per_batch(args, packed, plant, fix, bounds, out)
    result = identify(packed, free, fixed, method=args.method, seed=args.seed, n_starts=args.starts)
    doc = {**result.to_json_dict(), "plant": plant.name}
    atomic_write_text(out, json.dumps(doc, indent=1) + "\n")
    _print_fit(result, len(batches), plant.name, out)
    return 0


def _identify_with_spec(args, batches, plant, out) -> int:
    import json

    from .fitspec import load_fit_spec
    from .identify import identify
    from .io import atomic_write_text
    from .population import pack_batches
    from .simulate import InitialState
    from .theta import THETA_START

    spec = load_fit_spec(args.spec)
    if args.fix or args.bounds or args.estimate_tm0 or args.per_batch:
        raise InputError(
            "--spec sets free and fixed parameters itself; drop --fix/--bounds/--estimate-tm0/--per-batch",
            "command line",
        )
    init_values = {"Tb0_C": args.tb0, "Tm0_C": args.tm0, "X0": args.x0, **spec.initial}
    initial = InitialState(**init_values)
    packed = pack_batches(batches, plant, THETA_START, initial=initial, moisture=args.moisture, hold=args.hold)
    result = identify(packed, spec.free, spec.fixed, method=args.method, seed=args.seed, n_starts=args.starts)
    doc = {
        **result.to_json_dict(),
        "plant": plant.name,
        "initial": init_values,
        "spec": str(args.spec),
        "map": str(args.map) if args.map else None,
        "moisture": args.moisture,
        "hold": args.hold,
    }
    atomic_write_text(out, json.dumps(doc, indent=1) + "\n")
    _print_fit(result, len(batches), plant.name, out)
    return 0


def _print_fit(result, n_batches, plant_name, out) -> None:
    print(
        f"identified on {n_batches} batch(es), {result.n_residuals} samples, plant {plant_name} [{result.method}, seed {result.seed}]"
    )
    print(f"{'parameter':<26}{'value':>12}{'std. error':>12}  bounds")
    for name, value in {**result.fixed, **result.values}.items():
        if isinstance(value, list):
            for bname, v in zip(result.batches, value):
                lab = f"{name}[{bname}]"
                lo, hi = result.bounds[lab]
                print(f"{lab[:26]:<26}{v:>12.5g}{_se(result.stderr[lab]):>12}  [{lo:g}, {hi:g}]")
        elif name in result.fixed:
            print(f"{name:<26}{value:>12.5g}{'fixed':>12}")
        else:
            lo, hi = result.bounds[name]
            print(f"{name:<26}{value:>12.5g}{_se(result.stderr[name]):>12}  [{lo:g}, {hi:g}]")
    print(f"summed SSR {result.SSR:.4f} °C², {result.nfev} simulations, {result.wall_s:.2f} s -> {out}")
    _print_warnings(result.warnings)


def _se(value) -> str:
    """A standard error for the table; None means the parameter is held by a bound."""
    return "on bound" if value is None else f"{value:.2g}"


def _identify_per_batch(args, packed, plant, fix, bounds, out) -> int:
    import json

    from .fleet import identify_each
    from .io import atomic_write_text
    from .theta import THETA_NAMES

    unknown = sorted(set(fix) | set(bounds) - set(THETA_NAMES))
    if unknown or args.estimate_tm0:
        raise InputError("--per-batch fits hgm, hbm, Pbm only (no --estimate-tm0, no other parameters)", "command line")
    result = identify_each(packed, bounds=bounds, fix=fix, seed=args.seed)
    doc = {**result.to_json_dict(), "plant": plant.name, "fixed": sorted(fix)}
    atomic_write_text(out, json.dumps(doc, indent=1) + "\n")
    print(
        f"identified theta per batch for {packed.n_batches} batch(es) on plant {plant.name} in {result.wall_s:.2f} s ({result.simulations} simulations)"
    )
    if packed.n_batches <= 20:
        print(f"{'batch':<20}{'hgm':>9}{'hbm':>9}{'Pbm':>9}{'SSR':>12}{'FIT %':>9}")
        for name, th, ssr, fit in zip(result.names, result.theta, result.SSR, result.FIT):
            print(f"{name[:20]:<20}{th[0]:>9.4f}{th[1]:>9.4f}{th[2]:>9.4f}{ssr:>12.3f}{fit:>9.2f}")
    summ = result.summary()
    for name in THETA_NAMES:
        v = summ[name]
        print(f"{name}: mean {v['mean']:.4f}, std {v['std']:.4f}, range [{v['min']:.4f}, {v['max']:.4f}]")
    print(f"FIT: mean {summ['FIT']['mean']:.2f} %, worst {summ['FIT']['min']:.2f} % -> {out}")
    return 0


def cmd_validate(args) -> int:
    import json

    from .io import atomic_write_text, check_output_path
    from .report import plot_fit
    from .simulate import InitialState
    from .validate import applicable_values, validate

    batches, plant = _load_batches(args)
    inputs = [b.source for b in batches if b.source] + ([args.theta] if args.theta else [])
    for target in (args.json, args.plot):
        if target:
            check_output_path(target, inputs)
    if args.baseline:
        return _validate_baseline(args, batches, plant)
    theta, extra = _theta_from_args(args)
    init_values = {"Tb0_C": args.tb0, "Tm0_C": args.tm0, "X0": args.x0}
    saved_initial = extra.get("initial")
    if isinstance(saved_initial, dict):  # the initial state the fit used
        init_values.update(
            {k: float(v) for k, v in saved_initial.items() if k in ("Tb0_C", "Tm0_C", "X0", "He0_kJ_kg", "Ta0_C")}
        )
    _apply_per_batch_initial(extra, batches)
    initial = InitialState(**init_values)
    result = validate(
        batches,
        plant,
        theta,
        initial=initial,
        moisture=args.moisture,
        hold=args.hold,
        extra_values=applicable_values(extra),
    )
    print(
        result.table(
            f"validation on plant {plant.name}, theta = hgm {theta.hgm:.4f}, hbm {theta.hbm:.4f}, Pbm {theta.Pbm:.4f}"
        )
    )
    if args.json:
        atomic_write_text(args.json, json.dumps(result.to_json_dict(), indent=1) + "\n")
    if args.plot:
        plot_fit(result, args.plot, title=f"measured vs simulated Ta, plant {plant.name}")
    return 0


def _apply_per_batch_initial(theta_json: dict, batches) -> None:
    """Per-batch identified initial states (e.g. Tm0_C per batch) apply to batches of the same name."""
    from .population import STATE0

    names = theta_json.get("batches")
    if not isinstance(names, list):
        return
    by_name = {b.name: b for b in batches}
    for key, values in theta_json.items():
        if key in STATE0 and isinstance(values, list) and len(values) == len(names):
            for bname, v in zip(names, values):
                if bname in by_name and isinstance(v, (int, float)) and not isinstance(v, bool):
                    by_name[bname].initial[key] = float(v)


def _validate_baseline(args, batches, plant) -> int:
    import json

    from .baseline import validate_first_order
    from .io import atomic_write_text
    from .metrics import average_metrics
    from .validate import ValidationResult

    if not args.theta:
        raise InputError(
            "--baseline first-order needs --theta BASELINE.json from 'identify --baseline first-order'", "command line"
        )
    params = _read_baseline_json(args.theta)
    preds, rows = validate_first_order(batches, params)
    result = ValidationResult(
        [b.name for b in batches], [b.time_s for b in batches], [b.Ta_C for b in batches], preds, [], rows, plant.name
    )
    print(
        result.table(
            f"first-order baseline (tau {params['tau_s']:.1f} s, offset {params['offset_C']:+.2f} degC) on plant {plant.name}"
        )
    )
    if args.json:
        doc = {
            "baseline": "first-order",
            "tau_s": params["tau_s"],
            "offset_C": params["offset_C"],
            "batches": [{"name": n, **r} for n, r in zip(result.names, rows)],
            "average": average_metrics(rows),
        }
        atomic_write_text(args.json, json.dumps(doc, indent=1) + "\n")
    if args.plot:
        from .report import plot_fit

        plot_fit(result, args.plot, title="measured vs first-order baseline")
    return 0


def _read_baseline_json(path) -> dict:
    import json

    from .io import read_input_text

    try:
        data = json.loads(read_input_text(path))
    except json.JSONDecodeError as exc:
        raise InputError(f"not valid JSON ({exc.msg} at line {exc.lineno})", path) from None
    if not isinstance(data, dict):
        raise InputError("expected a JSON object", path)
    for key in ("tau_s", "offset_C"):
        v = data.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InputError("missing or not a number", path, f"key {key}")
    if not data["tau_s"] > 0:
        raise InputError("tau_s must be > 0", path, "key tau_s")
    return data


def cmd_import(args) -> int:
    from .data import write_batch_csv
    from .importers import import_log, load_map
    from .io import check_output_path

    cmap = load_map(args.map) if args.map else None
    out = check_output_path(args.out, [args.log] + ([args.map] if args.map else []))
    batch = import_log(args.log, cmap, name=args.name)
    for note in batch.notes:
        print(f"warning: {args.log}: {note}", file=sys.stderr)
    write_batch_csv(out, batch, comment=f"imported by roastlab from {args.log}", decimals=4)
    mass = f", green batch {batch.Mb_kg * 1000:.0f} g" if batch.Mb_kg else ""
    print(
        f"imported {batch.n} samples ({batch.time_s[0]:.0f}..{batch.time_s[-1]:.0f} s){mass}: Ta {batch.Ta_C[0]:.1f} -> {batch.Ta_C[-1]:.1f} degC -> {out}"
    )
    return 0


def cmd_reproduce(args) -> int:
    from .reproduce import run, summary_table

    summary = run(args.out, args.data, seed=args.seed)
    print(summary_table(summary))
    return 0


def cmd_datasets(args) -> int:
    from .datasets import make_paper

    written = make_paper(args.seed, args.out)
    print(f"wrote {len(written)} files of SYNTHETIC data under {args.out} (seed {args.seed})")
    return 0


def cmd_bench(args) -> int:
    import json

    from .bench import run, table
    from .io import atomic_write_text

    res = run(quiet=args.json)
    if args.json:
        print(json.dumps(res, indent=1))
    else:
        print(table(res))
    if args.save:
        atomic_write_text(args.save, json.dumps(res, indent=1) + "\n")
    return 0


FIT_HELP = "batch CSVs (time_s,Gg_kg_s,Tgi_C,Ta_C) and/or dataset folders with a dataset.toml; raw logs with --map"


def _add_batch_options(p, baseline_help: str) -> None:
    """Options shared by identify and validate: the batches, their plant, a map, the baseline."""
    p.add_argument("batches", nargs="+", metavar="BATCH", help=FIT_HELP)
    p.add_argument("--plant", help="plant preset or PLANT.toml (default: the dataset's plant)")
    p.add_argument(
        "--map",
        metavar="MAP.toml",
        help="the BATCH arguments are raw logs (Artisan .alog/.csv, CSV, Parquet) read with this column map",
    )
    p.add_argument("--baseline", choices=("first-order",), help=baseline_help)


def _add_fit_commands(sub) -> None:
    from .datasets import PAPER_SEED

    p = sub.add_parser(
        "identify",
        help="identify theta = (hgm, hbm, Pbm) on batches (eqs. 18-19)",
        description="Minimise the summed SSR of the probe temperature over the given batches within bounds, "
        "by a seeded global search (scattered starts polished by bounded least squares) or differential evolution. "
        "Writes THETA.json with the optimum, standard errors, correlations and warnings.",
    )
    _add_batch_options(p, "fit the first-order baseline dBT/dt = (ET + offset - BT)/tau instead")
    p.add_argument("--out", required=True, metavar="THETA.json", help="where to write the result")
    p.add_argument(
        "--method", choices=("global", "de"), default="global", help="global search (default) or differential evolution"
    )
    p.add_argument("--seed", type=int, default=0, help="random seed of the search (default 0)")
    p.add_argument("--starts", type=int, default=6, help="local polishes in the global search (default 6)")
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
        help="fit a separate theta to every batch (fleet mode: compiled, parallel, linear in the number of batches)",
    )
    p.add_argument(
        "--spec",
        metavar="FIT.toml",
        help="fit spec: free parameters (theta, process constants, initial states) with bounds",
    )
    _add_model_options(p, with_theta=False, plant=False)
    p.set_defaults(func=cmd_identify)

    p = sub.add_parser(
        "validate",
        help="simulate batches with theta and report the paper's metrics",
        description="Simulate each batch with THETA.json (default: the paper's theta*) and report n, SSR, ||e||, MAE, MPE, MAPE, FIT, rho per batch and on average.",
    )
    _add_batch_options(p, "validate the first-order baseline (--theta from 'identify --baseline first-order')")
    p.add_argument("--json", metavar="METRICS.json", help="write the metrics as JSON")
    p.add_argument("--plot", metavar="FIG.png", help="plot measured vs simulated Ta per batch")
    _add_model_options(p, with_theta=True, plant=False)
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser(
        "reproduce",
        help="the paper end to end: identify on dataset-I, validate on dataset-V",
        description="Identify on the synthetic dataset-I (120 kg), validate on dataset-V (360 kg) and write "
        "theta.json, metrics.json, report.md, fig2_profiles.png and fig3_errors.png.",
    )
    p.add_argument("--out", default="out/reproduce", metavar="DIR", help="output folder (default out/reproduce)")
    p.add_argument(
        "--data", metavar="DIR", help="folder holding dataset-I and dataset-V (default: the shipped synthetic data)"
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the identification (default 0)")
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser(
        "bench",
        help="measure speed against a solve_ivp baseline in one run",
        description="Measure single-batch and population simulation speed-ups over solve_ivp(LSODA), "
        "identification time on dataset-I, fleet identification scaling (10/100/1,000 batches) and the cold CLI. "
        "Takes a few minutes on 2 cores.",
    )
    p.add_argument("--json", action="store_true", help="print the figures as JSON (progress goes quiet)")
    p.add_argument("--save", metavar="FILE.json", help="also save the JSON to a file")
    p.set_defaults(func=cmd_bench)

    p = sub.add_parser(
        "import",
        help="convert a roast log (Artisan .alog/.csv, CSV, Parquet) into a batch CSV",
        description="Read a log with a column map and write the canonical batch CSV time_s,Gg_kg_s,Tgi_C,Ta_C "
        "(Artisan logs: time 0 at CHARGE, cut after DROP, °F converted, green weight kept as '# Mb_kg').",
    )
    p.add_argument("log", metavar="LOG", help="the roast log")
    p.add_argument("--map", metavar="MAP.toml", help="column map (default: canonical column names)")
    p.add_argument("--out", required=True, metavar="BATCH.csv", help="where to write the batch CSV")
    p.add_argument("--name", help="batch name (default: the log's file name)")
    p.set_defaults(func=cmd_import)

    p = sub.add_parser("datasets", help="generate the synthetic stand-in datasets")
    dsub = p.add_subparsers(dest="what", metavar="WHAT", parser_class=_Parser)
    dsub.required = True
    q = dsub.add_parser(
        "make-paper",
        help="write dataset-I and dataset-V (SYNTHETIC) from a seed",
        description="Generate the synthetic stand-ins of the paper's datasets, byte-identical for a given seed.",
    )
    q.add_argument("--seed", type=int, default=PAPER_SEED, help=f"random seed (default {PAPER_SEED}, the shipped data)")
    q.add_argument(
        "--out",
        default="datasets/paper-synthetic",
        metavar="DIR",
        help="output folder (default datasets/paper-synthetic)",
    )
    q.set_defaults(func=cmd_datasets)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="roastlab",
        description="Simulate, identify and validate the scalable coffee-roasting-chamber model "
        "(Procedia Computer Science 2021) on plants of any size.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
        "  roastlab reproduce                       the paper end to end on the shipped SYNTHETIC data\n"
        "  roastlab simulate --plant 120kg --inputs in.csv --out out.csv --plot out.png\n"
        "  roastlab identify datasets/paper-synthetic/dataset-I --out theta.json\n"
        "  roastlab validate --plant 360kg --theta theta.json datasets/paper-synthetic/dataset-V\n"
        "  roastlab import roast.alog --map map.toml --out batch.csv\n"
        "  roastlab bench                           speed against solve_ivp (about a minute)\n\n"
        "Every command: bad input gives one line naming the file and the problem, exit code 2.",
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

    _add_fit_commands(sub)
    return parser


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
