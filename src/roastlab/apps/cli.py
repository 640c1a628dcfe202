"""The ``roastlab`` command line: a thin layer that parses, calls the library, formats.

Every :class:`~roastlab.errors.RoastlabError` becomes one line on stderr and exit code 2.
Every command plans its outputs first (:class:`roastlab.io.files.Outputs`): an output that is
one of the run's inputs, a folder or a special file is refused before any work, and the
outputs are written together at the end or not at all.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from ..errors import InputError, ParameterError, RoastlabError
from .common import MODEL_HELP, Parser, count_arg, float_arg, json_text, progress, seed_arg, write_json_and_plot


def _say(notes) -> None:
    for note in notes:
        print(f"note: {note}", file=sys.stderr)


# ----------------------------------------------------------------------------- shared options
def _add_model_options(p: argparse.ArgumentParser, with_model: bool = True) -> None:
    if with_model:
        p.add_argument("--model", "--theta", dest="model", metavar="MODEL.json", help=MODEL_HELP)
        p.add_argument("--hgm", type=float_arg("--hgm"), help="gas-metal coefficient [kW/(m2 K)]; overrides the model")
        p.add_argument("--hbm", type=float_arg("--hbm"), help="metal-bean coefficient [kW/(m2 K)]; overrides the model")
        p.add_argument(
            "--pbm", type=float_arg("--pbm"), help="bean-metal contact fraction in (0, 1); overrides the model"
        )
    _add_initial_options(p)
    p.add_argument(
        "--moisture",
        choices=("schwartzberg", "printed"),
        help="moisture law, eq. 13 (default: the model's, else schwartzberg)",
    )
    p.add_argument(
        "--hold", choices=("linear", "zoh"), help="input hold between samples (default: the model's, else linear)"
    )


def _add_initial_options(p: argparse.ArgumentParser) -> None:
    """--tb0, --tm0, --x0: the charge state (read back by :func:`_initial_changes`)."""
    from ..model.quantities import default

    p.add_argument(
        "--tb0",
        type=float_arg("--tb0"),
        help=f"initial bean temperature [degC] (default: the model's, else {default('Tb0_C'):g})",
    )
    p.add_argument(
        "--tm0",
        type=float_arg("--tm0"),
        help=f"initial drum metal temperature, the preheat [degC] (default: the model's or the log's, else {default('Tm0_C'):g})",
    )
    p.add_argument(
        "--x0",
        type=float_arg("--x0"),
        help=f"initial moisture [kg/kg dry] (default: the model's, else {default('X0'):g})",
    )


def _initial_changes(args) -> dict:
    from ..model.limits import check_value

    changes = {}
    for opt, name in (("tb0", "Tb0_C"), ("tm0", "Tm0_C"), ("x0", "X0")):
        v = getattr(args, opt, None)
        if v is not None:
            changes[name] = check_value(name, v, f"--{opt}")
    return changes


def _model_from_args(args, plant_spec):
    """The model of a command: --model (or the paper's theta*), with --hgm/--hbm/--pbm and variants applied."""
    from ..workflows.model import FittedModel, load_model

    if getattr(args, "model", None):
        model = load_model(args.model)
    else:
        if plant_spec is None:
            raise InputError("--plant is required without --model", "command line")
        model = FittedModel.paper(plant_spec)
    overrides = {
        k: getattr(args, o)
        for k, o in (("hgm", "hgm"), ("hbm", "hbm"), ("Pbm", "pbm"))
        if getattr(args, o, None) is not None
    }
    if overrides:
        model = model.with_values(**overrides)
        try:
            model.theta  # noqa: B018 - validates the overridden theta
        except RoastlabError as exc:
            raise InputError(str(exc), "command line") from None
    for key in ("moisture", "hold"):
        if getattr(args, key, None):
            model.doc[key] = getattr(args, key)
            setattr(model, key, getattr(args, key))
    return model


def _read_inputs(path, map_path, model):
    """A batch CSV, or a raw log read with --map or with the map the model was fitted with."""
    from ..workflows.model import load_log

    if map_path:
        return load_log(path, map_path)
    cmap = None if model is None else model.column_map
    suffix = Path(path).suffix.lower()
    raw_csv = suffix == ".csv" and cmap is not None and cmap.format in ("artisan-csv", "csv")
    if raw_csv or suffix in (".alog", ".json", ".parquet", ".pq"):
        if cmap is None:
            raise InputError("a raw log needs a column map: the model has none, pass --map MAP.toml", path)
        return load_log(path, cmap)
    return load_log(path)


# ----------------------------------------------------------------------------- commands
def cmd_simulate(args) -> int:
    from ..io.files import Outputs
    from ..report.figures import check_figure_path, plot_simulation

    out_plan = Outputs([args.inputs, args.model, args.map, args.plant])
    out_plan.check(args.out)
    if args.plot:
        check_figure_path(out_plan.check(args.plot))
    model = _model_from_args(args, args.plant)
    batch = _read_inputs(args.inputs, args.map, model)
    changes = _initial_changes(args)
    if args.tgi_offset is not None:
        changes["Tgi_offset_C"] = args.tgi_offset
    result = model.predict(batch, plant=args.plant, **changes)
    _say(result.meta.get("notes", []))
    with out_plan as out:
        if Path(args.out).suffix.lower() == ".json":
            out.write_text(args.out, result.to_json_text(heat_flows=args.heat_flows))
        else:
            out.write_text(args.out, result.to_csv_text(heat_flows=args.heat_flows))
        if args.plot:
            plot_simulation(result, args.plot, f"{batch.name} on {result.meta['plant']} (simulated)", outputs=out)
    last = result.states[-1]
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


def _parse_assignments(items, option: str, ranged: bool):
    """Parse ``name=value`` (or ``name=lo:hi`` when ``ranged``) options."""
    out = {}
    for item in items or []:
        name, sep, text = item.partition("=")
        if not sep or not name:
            raise InputError(
                f"{option} expects NAME={'LO:HI' if ranged else 'VALUE'}, got {item[:60]!r}", "command line"
            )
        if ranged:
            out[name.strip()] = _range_arg(text, f"{option} {name[:30]}")
            continue
        try:
            value = float(text)
        except (ValueError, OverflowError):
            raise InputError(f"{option} {name[:30]}: cannot read {text[:40]!r} as a number", "command line") from None
        if not math.isfinite(value):
            raise InputError(f"{option} {name[:30]}: values must be finite", "command line")
        out[name.strip()] = value
    return out


def _range_arg(text: str, label: str) -> tuple[float, float]:
    """``LO:HI`` as two finite floats with LO < HI; ``label`` names the option in errors."""
    lo, sep, hi = text.partition(":")
    try:
        if not sep:
            raise ValueError
        value = (float(lo), float(hi))
    except (ValueError, OverflowError):
        raise InputError(f"{label}: cannot read {text[:40]!r} as LO:HI", "command line") from None
    if not all(math.isfinite(v) for v in value):
        raise InputError(f"{label}: values must be finite", "command line")
    if not value[0] < value[1]:
        raise InputError(f"{label}: inverted or empty bounds {value[0]:g}:{value[1]:g} (need LO < HI)", "command line")
    return value


def _load_batches(args, model=None):
    """The BATCH arguments as batches, and the plant spec to use (--plant, else the dataset's)."""
    from ..io.batch import expand_batch_args
    from ..workflows.model import load_log

    if getattr(args, "map", None) or (
        model is not None and model.column_map is not None and not any(Path(p).is_dir() for p in args.batches)
    ):
        cmap = args.map if args.map else model.column_map
        if all(Path(p).suffix.lower() == ".csv" for p in args.batches) and not args.map:
            batches, dataset_plant = expand_batch_args(args.batches, require_Ta=True)
        else:
            batches, dataset_plant = [load_log(p, cmap) for p in args.batches], None
        for b in batches:
            for note in b.notes:
                print(f"warning: {b.source}: {note}", file=sys.stderr)
    else:
        batches, dataset_plant = expand_batch_args(args.batches, require_Ta=True)
    return batches, args.plant or dataset_plant


def _fit_inputs(args) -> list:
    return [*args.batches, args.map, getattr(args, "spec", None), args.plant, getattr(args, "model", None)]


def cmd_identify(args) -> int:
    from ..io.files import Outputs

    outputs = Outputs(_fit_inputs(args))
    outputs.check(args.out)
    batches, plant_spec = _load_batches(args)
    if plant_spec is None:
        raise InputError("--plant is required unless a dataset folder names its plant", "command line")
    if args.baseline:
        from ..fit.baseline import describe, fit_first_order

        doc = {**fit_first_order(batches), "plant": str(plant_spec)}
        with outputs as out:
            out.write_text(args.out, json_text(doc))
        print(f"first-order baseline on {len(batches)} batch(es): {describe(doc)}, SSR {doc['SSR']:.1f} -> {args.out}")
        return 0
    fix = _parse_assignments(args.fix, "--fix", ranged=False)
    bounds = _parse_assignments(args.bounds, "--bounds", ranged=True)
    if args.per_batch:
        return _identify_per_batch(args, batches, plant_spec, fix, bounds, outputs)
    from ..io.importers import load_map
    from ..workflows.fitting import fit

    initial = _initial_changes(args)
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
        weights=_weights_arg(args.weight),
    )
    from ..io.modelfile import model_document_text

    with outputs as out:
        out.write_text(args.out, model_document_text(result.model.to_document()))
    print(result.report())
    print(f"-> {args.out}")
    return 0


def _weights_arg(items) -> dict[str, float]:
    """``--weight OUTPUT=W`` options as checked output weights (errors name the command line)."""
    from ..fit.identify import check_weights

    given = _parse_assignments(items, "--weight", ranged=False)
    try:
        check_weights(given)
    except ParameterError as exc:
        raise InputError(f"--weight: {exc.problem}", "command line") from None
    return given


def _identify_per_batch(args, batches, plant_spec, fix, bounds, outputs) -> int:
    from ..fit.batchfit import identify_each
    from ..model.parameters import THETA_NAMES, THETA_START
    from ..sim.population import pack_batches
    from ..sim.simulate import InitialState
    from ..workflows.model import PAPER_INITIAL

    unknown = sorted((set(fix) | set(bounds)) - set(THETA_NAMES))
    if unknown or args.estimate_tm0 or args.spec:
        raise InputError(
            "--per-batch fits hgm, hbm, Pbm only (no --spec, no --estimate-tm0, no other parameters)", "command line"
        )
    init = InitialState(**{**PAPER_INITIAL, **_initial_changes(args)})
    packed = pack_batches(
        batches, plant_spec, THETA_START, init, args.moisture or "schwartzberg", args.hold or "linear"
    )
    result = identify_each(packed, bounds=bounds, fix=fix, seed=args.seed, progress=progress("fit per batch"))
    doc = {**result.to_json_dict(), "plant": str(plant_spec), "fixed": sorted(fix)}
    with outputs as out:
        out.write_text(args.out, json_text(doc))
    print(
        f"identified theta per batch for {packed.n_batches} batch(es) on plant {plant_spec} in {result.wall_s:.2f} s ({result.simulations} simulations)"
    )
    if packed.n_batches <= 20:
        print(f"{'batch':<20}{'hgm':>9}{'hbm':>9}{'Pbm':>9}{'SSR':>12}{'FIT %':>9}")
        for name, th, ssr, fit in zip(result.names, result.theta, result.SSR, result.FIT):
            print(f"{name[:20]:<20}{th[0]:>9.4f}{th[1]:>9.4f}{th[2]:>9.4f}{ssr:>12.3f}{fit:>9.2f}")
    summ = result.summary()
    for name in THETA_NAMES:
        v = summ[name]
        print(f"{name}: mean {v['mean']:.4f}, std {v['std']:.4f}, range [{v['min']:.4f}, {v['max']:.4f}]")
    print(f"FIT: mean {summ['FIT']['mean']:.2f} %, worst {summ['FIT']['min']:.2f} % -> {args.out}")
    return 0


def cmd_validate(args) -> int:
    from ..io.files import Outputs
    from ..report.figures import check_figure_path, plot_fit

    outputs = Outputs(_fit_inputs(args))
    for target in (args.json, args.plot):
        if target:
            outputs.check(target)
    if args.plot:
        check_figure_path(args.plot)
    if args.predictions:
        outputs.folder(args.predictions, create=False)
    if args.baseline:
        return _validate_baseline(args, outputs)
    model = _model_from_args(args, args.plant)
    batches, plant_spec = _load_batches(args, model)
    changes = _initial_changes(args)
    if args.tgi_offset is not None:
        changes["Tgi_offset_C"] = args.tgi_offset
    result = model.validate(batches, plant=plant_spec, **changes)
    _say(result.notes)
    th = model.theta
    print(
        result.table(
            f"validation on plant {result.plant}, theta = hgm {th.hgm:.4f}, hbm {th.hbm:.4f}, Pbm {th.Pbm:.4f}"
        )
    )
    with outputs as out:
        if args.json:
            out.write_text(args.json, json_text(result.to_json_dict()))
        if args.plot:
            plot_fit(result, args.plot, title=f"measured vs predicted BT, plant {result.plant}", outputs=out)
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


def _safe_stem(name: str, taken: set) -> str:
    """A file stem from a batch name: no path separators or control characters, unique."""
    stem = "".join(c if (c.isalnum() or c in "-_.") else "_" for c in name)[:80].strip(".") or "batch"
    base, k = stem, 2
    while stem in taken:
        stem, k = f"{base}-{k}", k + 1
    taken.add(stem)
    return stem


def _validate_baseline(args, outputs) -> int:
    from ..evaluate.metrics import average_metrics
    from ..evaluate.validate import ValidationResult
    from ..fit.baseline import SETTING_GAINS, describe, validate_first_order
    from ..report.figures import plot_fit

    if not args.model:
        raise InputError(
            "--baseline first-order needs --model BASELINE.json from 'identify --baseline first-order'", "command line"
        )
    params = _read_baseline_json(args.model)
    batches, plant_spec = _load_batches(args)
    preds, rows = validate_first_order(batches, params)
    result = ValidationResult(
        [b.name for b in batches],
        [b.time_s for b in batches],
        [b.Ta_C for b in batches],
        preds,
        [],
        rows,
        str(plant_spec),
    )
    print(result.table(f"first-order baseline ({describe(params)})"))
    with outputs as out:
        if args.json:
            doc = {
                "baseline": "first-order",
                "tau_s": params["tau_s"],
                "offset_C": params["offset_C"],
                **{k: params[k] for k in SETTING_GAINS.values() if k in params},
                "batches": [{"name": n, **r} for n, r in zip(result.names, rows)],
                "average": average_metrics(rows),
            }
            out.write_text(args.json, json_text(doc))
        if args.plot:
            plot_fit(result, args.plot, title="measured vs first-order baseline", outputs=out)
    return 0


def _read_baseline_json(path) -> dict:
    from ..io.files import read_input_text
    from ..io.modelfile import parse_json_document

    data = parse_json_document(read_input_text(path, "JSON"), path)
    if not isinstance(data, dict):
        raise InputError("expected a JSON object", path)
    if data.get("baseline") != "first-order":
        raise InputError("not a first-order baseline file (from 'identify --baseline first-order')", path)
    from ..fit.baseline import SETTING_GAINS

    optional = [k for k in SETTING_GAINS.values() if k in data]
    for key in ("tau_s", "offset_C", *optional):
        v = data.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise InputError("missing or not a finite number", path, f"key {key}")
    if not data["tau_s"] > 0:
        raise InputError("tau_s must be > 0", path, "key tau_s")
    return data


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
    changes = _initial_changes(args)
    if args.tgi is not None:
        changes["Tgi_offset_C"] = args.tgi
    if args.batch_kg is not None:
        from ..model.limits import check_value

        changes["batch_kg"] = check_value("batch_kg", args.batch_kg, "--batch-kg")
    model = load_model(args.model)
    batch = _read_inputs(args.log, args.map, model)
    _say(batch.notes)
    result = whatif(model, batch, setting_changes, **changes)
    print(result.table())
    with outputs as out:
        write_json_and_plot(out, args, result.to_json_dict(), result)
    return 0


def cmd_transfer(args) -> int:
    from ..fit.program import ProgramLimits
    from ..io.files import Outputs
    from ..model.limits import check_value
    from ..report.figures import check_figure_path
    from ..workflows.model import load_model
    from ..workflows.transfer import transfer

    outputs = Outputs([args.reference, args.model, args.map, args.plant_from, args.plant_to])
    for target in (args.out, args.json, args.plot, args.alog):
        if target:
            outputs.check(target)
    if args.plot:
        check_figure_path(args.plot)
    if args.gg is not None and (args.gg_min is not None or args.gg_max is not None):
        raise InputError(
            "--gg fixes the flow; --gg-min/--gg-max let the optimiser choose it: give one or the other", "command line"
        )
    model = load_model(args.model)
    reference = _read_inputs(args.reference, args.map, model)
    _say(reference.notes)
    initial = {}
    for opt, name in (("tb0", "Tb0_C"), ("x0", "X0")):
        if getattr(args, opt) is not None:
            initial[name] = check_value(name, getattr(args, opt), f"--{opt}")
    tm0_free = None
    if args.tm0 is not None:
        if args.tm0.strip().lower() == "free":
            tm0_free = _range_arg(args.tm0_range, "--tm0-range")
        else:
            try:
                initial["Tm0_C"] = check_value("Tm0_C", float(args.tm0), "--tm0")
            except ValueError:
                raise InputError(f"expected a temperature [degC] or 'free', got {args.tm0!r}", "--tm0") from None
    if args.decide == "heater":
        if reference.heater is None:
            raise InputError(
                "--decide heater needs a reference with a heater setting (a map with [heater])", args.reference
            )
        top = float(max(reference.heater))
        low = 0.0 if args.heater_min is None else args.heater_min
        high = (top if top > 0 else 1.0) if args.heater_max is None else args.heater_max
        limits = ProgramLimits(low, high, args.heater_rate, args.gg_min, args.gg_max, decide="heater")
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
    )
    _say(result.metrics["notes"])
    print(result.summary())
    with outputs as out:
        out.write_text(args.out, result.program_csv_text())
        write_json_and_plot(out, args, result.to_json_dict(), result)
        if args.alog:
            out.write_text(args.alog, result.alog_text())
    return 0


def _control_inputs(args):
    """The model, reference and plant of a ``control`` run (the standard synthetic reference when
    no --reference is given)."""
    from ..control import standard_reference

    model = _model_from_args(args, args.plant or "120kg")
    if args.reference:
        reference = _read_inputs(args.reference, args.map, model)
        _say(reference.notes)
    else:
        reference = standard_reference()
        _say(["no --reference: following the SYNTHETIC standard reference (roastlab.control.standard_reference)"])
    return model, reference


def cmd_control(args) -> int:
    from ..control import load_scenario, make_controller, run_closed_loop
    from ..io.files import Outputs
    from ..report.figures import check_figure_path

    if args.what == "compare":
        return cmd_control_compare(args)
    outputs = Outputs([args.reference, args.model, args.map, args.plant, args.scenario])
    for target in (args.out, args.json, args.plot):
        if target:
            outputs.check(target)
    if args.plot:
        check_figure_path(args.plot)
    controller = make_controller(args.controller)
    if args.ror_weight:
        if args.controller != "mpc":
            raise InputError("--ror-weight is an MPC option", "command line")
        from ..control import MPC

        controller = MPC(ror_weight=args.ror_weight)
    scenario = load_scenario(args.scenario) if args.scenario else None
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
    from ..report.figures import check_figure_path

    scenarios = standard_scenarios()
    if args.scenarios:
        folder = Path(args.scenarios)
        if not folder.is_dir():
            raise InputError("not a folder of scenario .toml files", folder)
        scenarios = sorted(folder.glob("*.toml"))
        if not scenarios:
            raise InputError("no .toml scenario files in this folder", folder)
    outputs = Outputs([args.reference, args.model, args.map, args.plant, *scenarios])
    for target in (args.json, args.plot):
        if target:
            outputs.check(target)
    if args.plot:
        check_figure_path(args.plot)
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
        p.add_argument("--scenario", metavar="S.toml", help="scenario file (default: nominal; see docs/control.md)")
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


def _add_control_command(sub) -> None:
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


def cmd_bench(args) -> int:
    from ..apps.bench import run, table
    from ..io.files import Outputs

    outputs = Outputs()
    if args.save:
        outputs.check(args.save)
    res = run(quiet=args.json, only=args.only)
    if args.json:
        print(json.dumps(res, indent=1))
    else:
        print(table(res))
    if args.save:
        with outputs as out:
            out.write_text(args.save, json.dumps(res, indent=1) + "\n")
    return 0


FIT_HELP = "batch CSVs (time_s,Gg_kg_s,Tgi_C,Ta_C) and/or dataset folders with a dataset.toml; raw logs with --map"


def _add_batch_options(p, baseline_help: str) -> None:
    """Options shared by identify and validate: the batches, their plant, a map, the baseline."""
    p.add_argument("batches", nargs="+", metavar="BATCH", help=FIT_HELP)
    p.add_argument("--plant", help="plant preset or PLANT.toml (default: the model's plant, else the dataset's)")
    p.add_argument(
        "--map",
        metavar="MAP.toml",
        help="the BATCH arguments are raw logs (Artisan .alog/.csv, CSV, Parquet) read with this column map",
    )
    p.add_argument("--baseline", choices=("first-order",), help=baseline_help)


def _add_fit_commands(sub) -> None:
    from ..workflows.datasets import PAPER_SEED

    p = sub.add_parser(
        "identify",
        help="fit a model on batches (eqs. 18-19) and write MODEL.json",
        description="Minimise the summed SSR of the probe temperature (and, with --weight Tb2=W or a spec's "
        "[weights], of the model's bean temperature against a second bean reading) over the given batches within bounds, "
        "by a seeded global search (scattered starts polished by bounded least squares) or differential evolution. "
        "Writes the fitted model file (roastlab-model/1): plant, theta and every other fitted or held value with "
        "standard errors and bounds, the initial states, the column map, fit-set metrics and provenance.",
        epilog="example: roastlab identify --plant 120kg dataset-I/ --out model.json",
    )
    _add_batch_options(
        p,
        "fit the first-order baseline dBT/dt = (Tgi + offset [+ k_h heater + k_f fan] - BT)/tau instead "
        "(Tgi = ET on an ET map; the settings when the map reads heater/fan)",
    )
    p.add_argument("--out", required=True, metavar="MODEL.json", help="where to write the model file")
    p.add_argument(
        "--method", choices=("global", "de"), default="global", help="global search (default) or differential evolution"
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="random seed of the search (default 0)")
    p.add_argument("--starts", type=count_arg("--starts", 1, 100), default=6, help="local polishes (default 6)")
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
        help="weight of a fitted output: Ta (the bean probe, default 1) or Tb2 (a second bean reading read by the "
        "map's [Tb2], compared with the model's Tb; default 0), e.g. --weight Tb2=0.25 (repeatable; overrides "
        "the spec's [weights])",
    )
    _add_model_options(p, with_model=False)
    p.set_defaults(func=cmd_identify)

    p = sub.add_parser(
        "validate",
        help="apply a model file to batches and report the paper's metrics",
        description="Apply MODEL.json (all of it: theta, fitted flow and constants, initial states; default: the "
        "paper's theta*) to each batch and report n, SSR, ||e||, MAE, MPE, MAPE, FIT, rho per batch and on average.",
        epilog="example: roastlab validate --model model.json --plant 360kg dataset-V/ --predictions pred/",
    )
    _add_batch_options(
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
    _add_model_options(p)
    p.set_defaults(func=cmd_validate)

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
    p.add_argument("--seed", type=seed_arg, default=0, help="seed of the identification (default 0)")
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser(
        "bench",
        help="measure speed against a solve_ivp baseline in one run",
        description="Measure single-batch and population simulation speed-ups over solve_ivp(LSODA), "
        "identification time on dataset-I, fleet identification scaling (10/100/1,000 batches), the cold CLI "
        "and profile transfer (accuracy on synthetic references, against its baselines and a generic SciPy "
        "solver). Takes a few minutes on 2 cores. Needs no MODEL.json: it times the paper's model.",
    )
    p.add_argument(
        "--only",
        choices=("transfer", "control", "fleet"),
        help="run one section only (fleet: 100,000 synthetic batches end to end, ~15 min; not in the default run)",
    )
    p.add_argument("--json", action="store_true", help="print the figures as JSON (progress goes quiet)")
    p.add_argument("--save", metavar="FILE.json", help="also save the JSON to a file")
    p.set_defaults(func=cmd_bench)

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
    _add_initial_options(p)
    p.add_argument("--json", metavar="WHATIF.json", help="write the table as JSON")
    p.add_argument("--plot", metavar="FIG.png", help="overlay measured BT and both predictions (.png/.svg/.pdf)")
    p.set_defaults(func=cmd_whatif)

    p = sub.add_parser(
        "transfer",
        help="compute the input program that reproduces a roast on another plant or batch size",
        description="Find the inlet-gas program (or, with --decide heater, the heater program) that makes the "
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
        "  BACKGROUND.alog  an Artisan profile to load as background (BT predicted, program as Burner/Air events)\n\n"
        "examples:\n"
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
    p.add_argument("--out", required=True, metavar="PROGRAM.csv", help="where to write the program")
    p.add_argument(
        "--batch-kg",
        type=float_arg("--batch-kg"),
        help="green batch on B [kg] (default: B's nominal batch; the reference's when B = A)",
    )
    p.add_argument(
        "--tb0", type=float_arg("--tb0"), help="bean temperature at CHARGE on B [degC] (default: the model's, else 30)"
    )
    p.add_argument(
        "--tm0",
        metavar="C|free",
        help="drum temperature at CHARGE on B [degC], or 'free' to let the optimiser choose it (the preheat)",
    )
    p.add_argument(
        "--tm0-range", default="60:300", metavar="LO:HI", help="range for --tm0 free [degC] (default 60:300)"
    )
    p.add_argument(
        "--x0", type=float_arg("--x0"), help="green moisture on B [kg/kg dry] (default: the model's, else 0.1)"
    )
    p.add_argument(
        "--decide",
        choices=("Tgi", "heater"),
        default="Tgi",
        help="the input the program sets (default Tgi; heater needs a model and reference with the actuator extension)",
    )
    p.add_argument(
        "--tgi-min", type=float_arg("--tgi-min"), default=150.0, help="lowest inlet temperature [degC] (default 150)"
    )
    p.add_argument(
        "--tgi-max", type=float_arg("--tgi-max"), default=550.0, help="highest inlet temperature [degC] (default 550)"
    )
    p.add_argument(
        "--tgi-rate",
        type=float_arg("--tgi-rate"),
        default=120.0,
        help="fastest change of the inlet temperature [degC/min] (default 120)",
    )
    p.add_argument("--heater-min", type=float_arg("--heater-min"), help="lowest heater setting (default 0)")
    p.add_argument(
        "--heater-max",
        type=float_arg("--heater-max"),
        help="highest heater setting (default: the reference's largest)",
    )
    p.add_argument(
        "--heater-rate",
        type=float_arg("--heater-rate"),
        default=60.0,
        help="fastest heater change [setting/min] (default 60)",
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
        help="spacing of the program's knots [s] (default 5)",
    )
    p.add_argument(
        "--tolerance",
        type=float_arg("--tolerance"),
        default=2.0,
        help="feasible when max |predicted - target| <= this [degC] (default 2)",
    )
    p.add_argument("--json", metavar="METRICS.json", help="write the metrics, baselines and limits as JSON")
    p.add_argument(
        "--plot", metavar="FIG.png", help="target vs predicted BT, the program with its limits, the baselines"
    )
    p.add_argument(
        "--alog", metavar="BACKGROUND.alog", help="write an Artisan background profile of the prediction and program"
    )
    p.set_defaults(func=cmd_transfer)

    p = sub.add_parser(
        "import",
        help="convert a roast log (Artisan .alog/.csv, CSV, Parquet) into a batch CSV",
        description="Read a log with a column map and write the canonical batch CSV time_s,Gg_kg_s,Tgi_C,Ta_C "
        "(Artisan logs: time 0 at CHARGE, cut after DROP, °F converted, green weight kept as '# Mb_kg').",
        epilog="example: roastlab import roast.alog --map examples/skywalker/map.toml --out batch.csv\n"
        "then: roastlab simulate --model MODEL.json --inputs batch.csv --out pred.csv (a model fitted with a map also "
        "reads the raw log itself)",
    )
    p.add_argument("log", metavar="LOG", help="the roast log")
    p.add_argument("--map", metavar="MAP.toml", help="column map (default: canonical column names)")
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


def build_parser() -> argparse.ArgumentParser:
    from .. import __version__

    parser = Parser(
        prog="roastlab",
        description="Simulate, identify and validate the scalable coffee-roasting-chamber model "
        "(Procedia Computer Science 2021) on plants of any size. A fit is one model file (MODEL.json, "
        "from 'identify'); simulate and validate take it with --model and apply all of it the same way.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
        "  roastlab reproduce                       the paper end to end on the shipped SYNTHETIC data\n"
        "  roastlab simulate --plant 120kg --inputs in.csv --out out.csv --plot out.png\n"
        "  roastlab identify --plant 120kg dataset-I/ --out model.json\n"
        "  roastlab validate --model model.json --plant 360kg dataset-V/\n"
        "  roastlab simulate --model model.json --inputs batch.csv --out pred.csv --tgi-offset 20\n"
        "  roastlab import roast.alog --map map.toml --out batch.csv\n"
        "  roastlab bench                           speed against solve_ivp (about a minute)\n\n"
        "Every command: bad input gives one line naming the file and the problem, exit code 2.",
    )
    parser.add_argument("--version", action="version", version=f"roastlab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True

    p = sub.add_parser(
        "simulate",
        help="simulate one batch with a model file (default: the paper's theta*)",
        description="Simulate one batch with MODEL.json (all of it, as validate applies it). INPUTS is a batch CSV "
        "(time_s,Gg_kg_s,Tgi_C[,Ta_C]) or a raw log read with --map or with the model's own map. OUT.csv gets "
        "time_s,Tb_C,Tm_C,X_kg_kg,He_kJ_kg,Ta_C,Tgo_C (OUT.json: the same as JSON).",
        epilog="example: roastlab simulate --model model.json --inputs batch.csv --out pred.csv --tgi-offset 20",
    )
    _add_model_options(p)
    p.add_argument("--plant", help="plant preset (120kg, 360kg) or PLANT.toml (default: the model's plant)")
    p.add_argument(
        "--inputs", required=True, metavar="INPUTS.csv", help="input samples (time_s,Gg_kg_s,Tgi_C[,Ta_C]) or a log"
    )
    p.add_argument("--map", metavar="MAP.toml", help="INPUTS is a raw log read with this column map")
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
    p.add_argument("--x0", type=float_arg("--x0"), default=0.1, help="moisture used for Mbd and F (default 0.1)")
    p.set_defaults(func=cmd_plant)

    _add_fit_commands(sub)
    _add_control_command(sub)
    from .fleet_cli import add_fleet_command

    add_fleet_command(sub, Parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    from ..io.files import begin_run

    parser = build_parser()
    args = parser.parse_args(argv)
    begin_run()
    try:
        return int(args.func(args) or 0)
    except RoastlabError as exc:
        print(f"roastlab {args.command}: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("roastlab: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0


def _one_line(text: str, limit: int = 300) -> str:
    """An error message as one printable line of at most ``limit`` characters."""
    flat = "".join(c if c.isprintable() else "?" for c in text.replace("\n", " "))
    return flat if len(flat) <= limit else flat[: limit - 1] + "…"


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
