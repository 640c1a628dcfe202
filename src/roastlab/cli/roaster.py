"""``roastlab init`` and ``roastlab fit-roaster``: your own roaster from its logs, no hand-written files."""

from __future__ import annotations

import argparse
import sys

from .common import add_units_option, failed_fit_status, float_arg, progress


def cmd_init(args) -> int:
    from ..workflows.survey import init_roaster

    r = init_roaster(
        args.logs,
        args.out,
        batch_kg=args.batch_kg,
        capacity_kg=args.batch_capacity_kg,
        diameter_m=args.drum_diameter_m,
        length_m=args.drum_length_m,
        units={"heater": args.heater_unit, "fan": args.fan_unit},
        name=args.name,
    )
    s = r["survey"]
    aside = f" (and {len(s.unweighed)} without a green weight, below)" if s.unweighed else ""
    print(f"{len(s.logs)} log(s){aside}, format {s.format}, roaster {s.machine or '(not named)'}")
    print(
        f"  bean probe BT; heater: {'/'.join(s.renamed.get('heater', [s.heater or 'none']))} ({s.heater_unit or '-'}); "
        f"fan: {'/'.join(s.renamed.get('fan', [s.fan or 'none']))} ({s.fan_unit or '-'})"
    )
    et = (
        "yes"
        if s.has_et
        else "a bean reading, not the drum's air"
        if s.et_is_bean
        else "below BT on every log, not used (below)"
        if s.et_below_bt
        else "no"
    )
    role = "offered in the map" if s.heater else "the model's input"
    inlet = f"; inlet air: {s.inlet} ({role})" if s.inlet else ""
    from ..io.importers.roastime import IR_SERIES

    ir = f" (the IR; {IR_SERIES} in RoastWorld's export)" if s.format == "roastime" and s.second_bean else ""
    print(f"  second bean reading: {s.second_bean or 'none'}{ir}; ET: {et}{inlet}")
    masses = sorted({round(i.batch_kg * 1000) for i in s.logs})  # to the gram; a big drum's in kg
    print(f"  green batches: {', '.join(f'{g} g' if g < 1000 else f'{g / 1000:g} kg' for g in masses)}")
    for note in s.notes:
        print(f"  logs: {note}")
    for note in r["notes"]:
        print(f"  plant: {note}")
    print(f"wrote {args.out}/map.toml, plant.toml, fit.toml, fleet.toml; next: roastlab fit-roaster {args.out} LOG...")
    return 0


def cmd_fit_roaster(args) -> int:
    from ..metrics.profile import display_temp_delta, temp_symbol
    from ..workflows.roaster import band_sentence, every_log_sentence, fit_roaster, grouped_notes
    from ..workflows.sizes import across_sizes_sentence

    r = fit_roaster(
        args.dir,
        args.logs,
        progress=progress("fit-roaster"),
        seed=args.seed,
        every_log=args.every_log,
        by_size=args.by_size,
        fit_size_kg=args.fit_size_kg,
        unit=args.unit,
        units=args.units,
    )
    f, h, b, units = r["fit"], r["held_out"], r["baseline_held_out"], r["units"]
    u = temp_symbol(units)

    def dT(v: float) -> float:  # an error or a width in the report's unit
        return display_temp_delta(v, units)

    for line in grouped_notes(r["notes"]):
        print(f"note: {line}", file=sys.stderr)
    for why in r["left_out"].values():
        print(f"left out: {why}")
    if r["refit"]:
        print(f"refitted: {r['refit']}")
    if r["unweighed"]:
        print(f"note: the fit {r['unweighed']}")
    print(f"fit set:  FIT {f['FIT']:.1f} %, MAE {dT(f['MAE']):.2f} {u}")
    print(
        f"held out: FIT {h['FIT']:.1f} %, MAE {dT(h['MAE']):.2f} {u} (first-order baseline: {b['FIT']:.1f} %, {dT(b['MAE']):.2f} {u})"
    )
    if r["below_baseline"]:
        print(f"verdict:  {r['below_baseline']}")
    if r["band"] is not None:
        print(f"band:     {band_sentence(r['band'], units)}")
        if r["band"]["note"]:
            print(f"note: {r['band']['note']}")
    if r["held_out_by_unit"]:
        print(
            "held out by unit: "
            + ", ".join(
                f"{g['unit']} {g['FIT']:.1f} % ({g['logs']} log{'s' if g['logs'] > 1 else ''})"
                for g in r["held_out_by_unit"]
            )
        )
    e = r["every_log"]
    if e:
        print(
            f"each log held out once: {every_log_sentence(e['FIT'], e['band_inside'], e['band_median_width_C'], units)}"
        )
    a = r["across_sizes"]
    if a:
        print(f"across sizes: {across_sizes_sentence(a)}")
        if a["failed"]:
            print(f"warning: the fit on {a['fit_size']} alone failed: {a['failed']}", file=sys.stderr)
    for w in r["warnings"]:
        print(f"warning: {w}", file=sys.stderr)
    print(f"wrote {', '.join(str(f) for f in [r['model'], r['report'], r['report_html'], *r['figures']])}")
    return failed_fit_status(r["failed"], r["model"])


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    p = sub.add_parser(
        "init",
        help="read a roaster's logs and write its column map, plant, fit spec and fleet spec",
        description="Inspect LOG... (Artisan .alog/.csv, RoasTime .json (RoasTime's own or RoastWorld's export), or "
        "plain CSV with a header naming time, BT and ET, its first row the charge, of one roaster) and write DIR/map.toml "
        "(which channel is BT, the heater (a gas burner's pressure in the unit its name says, 'Gas kPa'), the fan, a second "
        "bean reading, ET, the inlet air), DIR/plant.toml (the drum, from its "
        "dimensions, a catalogue entry or the batch capacity, each estimate stated), DIR/fit.toml (what these "
        "logs can determine) and DIR/fleet.toml (what a fleet fit frees per batch under the fitted model), each "
        "commented with what was detected and what was guessed. A LOG that is a folder "
        "stands for its logs of one format (.alog where it has any, else .json, RoasTime's files without a suffix, .csv); the logs of another format in it are counted in a note, not read. "
        "A log that cannot be "
        "read as a roast (an empty or aborted recording), is a copy of another (the same recording start), records no "
        "green weight (nor one in its file name) or no setting the others record is named, and fit-roaster leaves it out. Logs are never modified. "
        "Then 'roastlab fit-roaster DIR LOG...' fits the model (its MODEL.json, DIR/model.json) and writes a report; 'roastlab fleet "
        "fit --spec R=DIR/fleet.toml --model R=DIR/model.json' fits each batch of a fleet store under it.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n  roastlab init roasts/*.alog --out myroaster\n  roastlab fit-roaster myroaster roasts/*.alog\n"
        "  roastlab init roasts --out myroaster        the logs in the folder roasts\n"
        "  roastlab init roasts --out mygas --heater-unit kPa   a burner logged as 'Gas' in kPa",
    )
    p.add_argument("logs", nargs="+", metavar="LOG", help="roast logs of one roaster, or a folder of them")
    p.add_argument("--out", required=True, metavar="DIR", help="folder for map.toml, plant.toml, fit.toml, fleet.toml")
    p.add_argument(
        "--name",
        help="the roaster's name in its plant, model and report (default: the make its logs record, else DIR's name)",
    )
    p.add_argument(
        "--batch-kg",
        type=float_arg("--batch-kg"),
        help="green batch [kg] of a log that records none (a log's own weight, else the grams in its file name, "
        "come first)",
    )
    p.add_argument("--batch-capacity-kg", type=float_arg("--batch-capacity-kg"), help="the roaster's rated batch [kg]")
    p.add_argument("--drum-diameter-m", type=float_arg("--drum-diameter-m"), help="inner drum diameter [m]")
    p.add_argument("--drum-length-m", type=float_arg("--drum-length-m"), help="inner drum length [m]")
    from ..model.actuators import CONTROL_UNITS

    for what, example in (
        ("heater", "a 'Gas' readout in kPa gets the burner's square-root law"),
        ("fan", "a draft in Pa gets the square-root law of the flow it drives"),
    ):
        p.add_argument(
            f"--{what}-unit",
            choices=CONTROL_UNITS[what],
            metavar="UNIT",
            help=f"the unit the {what} is logged in, where its name does not say it (default: by its name, else its "
            f"values); one of {', '.join(CONTROL_UNITS[what])}" + (f" ({example})" if example else ""),
        )
    p.set_defaults(func=cmd_init)

    p = sub.add_parser(
        "fit-roaster",
        help="fit, hold out, compare with a baseline and report, from 'roastlab init's files",
        description="With DIR from 'roastlab init': sort LOG... by when they were roasted (by name when a log has no date) and split them alternately (1st, 3rd, ... fit; "
        "2nd, 4th, ... held out), identify the model, validate it on the held-out logs, fit the first-order "
        "baseline on the same inputs, and write DIR/model.json (MODEL.json for every other command), "
        "DIR/report.md (the same as DIR/report.html, one page any browser opens, its figures inside) and "
        "DIR/heldout.png. A log that cannot be read as a roast, is a copy of another, records no green weight or "
        "no setting the map drives the model with is left out; a fit whose drum runs below the beans with the heater free to heat the air is refitted with the "
        "heater heating the drum alone; an output fit.toml weighs (ET, a second bean reading) that none of the fit's logs "
        "records is left out of that fit; a model worse than the baseline on the held-out logs is called not "
        "usable; each is said. Exit status 1 when the fit failed (states the machine cannot have, "
        "such as drum metal below the beans; the files are written and say so), 2 on bad input.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n  roastlab fit-roaster myroaster roasts/*.alog\n"
        "  roastlab fit-roaster myroaster roasts/*.alog --every-log   each log also held out once (minutes)\n"
        "  roastlab fit-roaster myroaster roasts/*.alog --by-size     fitted at one batch size, the others predicted\n"
        "  roastlab fit-roaster mybullet roasts/ --unit 2779           the logs of one unit of the make alone",
    )
    p.add_argument("dir", metavar="DIR", help="the folder 'roastlab init' wrote")
    p.add_argument("logs", nargs="+", metavar="LOG", help="the roaster's logs, or a folder of them")
    p.add_argument("--seed", type=int, default=0, help="seed of the global search (default %(default)s)")
    p.add_argument(
        "--every-log",
        action="store_true",
        help="also hold every log out once, predicted by a fit on all the others (leave-one-log-out: one fit "
        "per log, plus one), and report each log's FIT and its share inside the 90 %% band: the figure to judge "
        "the model by when one split of a few roasts is too few",
    )
    p.add_argument(
        "--by-size",
        action="store_true",
        help="also fit on the logs of one batch size alone (the size with the most logs, split alternately) and "
        "predict every other size with nothing refitted: the paper's claim that the machine's parameters carry "
        "over to another batch; the report gains a table per size (FIT, signed error, share inside the band, "
        "the gap to the held-out logs of the fit size with its 90 %% interval) and DIR/sizes.png (one more fit)",
    )
    p.add_argument(
        "--fit-size-kg",
        type=float_arg("--fit-size-kg"),
        metavar="KG",
        help="with --by-size (implied): the batch size to fit on [kg], e.g. 0.5 (default: the size with the most logs)",
    )
    p.add_argument(
        "--unit",
        metavar="SERIAL",
        help="fit only the logs recorded by this roaster unit (its serial number, as 'init' lists them; RoasTime "
        "logs carry it): one drum's model, the other units' logs left out and said. Units of one make differ by more "
        "than a batch size does; without --unit, held-out logs of several units are also reported by unit",
    )
    add_units_option(
        p,
        "the report's and the figures' temperatures in C or F (default: the unit the logs were recorded in; "
        "a folder of both reads in C); model.json stays in degC",
    )
    p.set_defaults(func=cmd_fit_roaster)
