"""``roastlab fit-roaster``: fit a roaster that ``roastlab init`` set up
(:mod:`roastlab.workflows.survey`), validate the fit on held-out logs, compare it with the
first-order baseline and write the model and a report (:func:`fit_roaster`); optionally each log
held out once, the other batch sizes predicted from one, or one roaster unit's logs alone.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from pathlib import Path

from ..errors import InputError
from ..io.batch import logs_temp_unit
from ..metrics.profile import delta_text, display_temp_delta, display_units, temp_symbol
from .survey import (
    INLET_NAMES,
    UNNAMED_UNIT,
    find_name,
    log_paths,
    logs_without_controls,
    logs_without_weight,
    readable_logs,
    spans_batch_sizes,
    unit_counts,
)

#: A number in a note, or a clock time (m:ss, h:mm:ss: one value, its seconds ordering it).
_NUMBER = re.compile(r"-?\d+(?::\d\d)+|-?\d+(?:\.\d+)?")


def _value(token: str) -> float:
    """A :data:`_NUMBER` token's value, a clock time in seconds."""
    sign = -1.0 if token.startswith("-") else 1.0
    total = 0.0
    for part in token.lstrip("-").split(":"):
        total = 60.0 * total + float(part)
    return sign * total


#: A note said alike on this many logs or fewer names them; on more, it counts them.
NAMED_UP_TO = 4


def grouped_notes(notes: dict[str, list[str]], at_least: int = 3) -> list[str]:
    """The import's notes of each log (``{log name: [note, ...]}``) as lines to read: ``"name: note"``,
    except that a note said alike on ``at_least`` logs or more (the same words, other numbers) is one
    line, ``"16 logs: dropped 1-6 incomplete sample(s) (missing values)"``, each number the range over
    those logs (their names too, up to :data:`NAMED_UP_TO` of them)."""
    groups: dict[tuple, list[tuple[str, str, list[str]]]] = {}
    for name, said in notes.items():
        for note in said:
            groups.setdefault(tuple(_NUMBER.split(note)), []).append((name, note, _NUMBER.findall(note)))
    lines = []
    for words, rows in groups.items():
        if len(rows) < at_least:
            lines += [f"{name}: {note}" for name, note, _ in rows]
            continue
        spans = []
        for k in range(len(words) - 1):
            by_value = sorted((_value(r[2][k]), r[2][k]) for r in rows)
            lo, hi = by_value[0][1], by_value[-1][1]
            spans.append(
                lo if by_value[0][0] == by_value[-1][0] else f"{lo} to {hi}" if lo.startswith("-") else f"{lo}-{hi}"
            )
        text = "".join(w + (spans[k] if k < len(spans) else "") for k, w in enumerate(words))
        names = f" ({', '.join(r[0] for r in rows)})" if len(rows) <= NAMED_UP_TO else ""
        lines.append(f"{len(rows)} logs{names}: {text}")
    return lines


#: The figures fit-roaster writes beside report.md, by file name (the report links them by it).
HELD_OUT_FIGURE, SIZES_FIGURE = "heldout.png", "sizes.png"


def logs_of_unit(infos, unit: str) -> tuple[list, dict[str, str]]:
    """The logs recorded by the roaster unit ``unit`` (its serial number, :attr:`LogInfo.unit`), and
    one line of why the others are left out (``{"--unit": why}``, empty when there are none).

    Units of one make differ by more than a batch size does (docs/real-roaster.md, "Batch-size
    scaling on the Bullet"), so a drum's model is fitted on that drum's logs. ``InputError`` when no
    log names the unit (with the units the logs do name) or only one does.
    """
    mine = [i for i in infos if i.unit == unit]
    if not mine:
        named = [i for i in infos if i.unit]
        raise InputError(
            f"no log was recorded by unit {unit}: "
            + (
                f"the logs name units {unit_counts(named)} (serial number: logs)"
                if named
                else "the logs name no unit (RoasTime logs carry the roaster's serial number; Artisan's do not)"
            ),
            "--unit",
        )
    if len(mine) < 2:
        raise InputError(
            f"unit {unit} recorded only {mine[0].path.name}: fit-roaster needs two of its logs (one to fit, one to "
            "hold out)",
            "--unit",
        )
    others = [i for i in infos if i.unit != unit]
    why = f"{len(others)} log(s) of other units ({unit_counts(others)}), by --unit {unit}"
    return mine, ({"--unit": why} if others else {})


def held_out_by_unit(batches, rows, band_rows=None) -> list[dict]:
    """The held-out logs' figures by the roaster unit each records (``Batch.unit``, RoasTime's serial
    number), most logs first: ``[{"unit", "logs", "FIT", "MAE" (the paper's Average over the unit's
    logs, :func:`roastlab.evaluate.metrics.average_metrics`), "inside" (the share of its samples
    inside the band, :func:`roastlab.evaluate.bands.share_inside`; None without a band)}]``. Empty
    unless the logs name more than one unit: where they do, one fit treats the drums as one, and
    this says which drum it serves."""
    from ..evaluate.bands import share_inside
    from ..evaluate.metrics import average_metrics

    units = [b.unit or UNNAMED_UNIT for b in batches]
    if len({b.unit for b in batches if b.unit}) < 2:
        return []
    out = []
    for unit, k in Counter(units).most_common():
        mine = [i for i, u in enumerate(units) if u == unit]
        mean = average_metrics([rows[i] for i in mine])
        inside = None if band_rows is None else share_inside([band_rows[i] for i in mine])
        out.append({"unit": unit, "logs": k, "FIT": mean["FIT"], "MAE": mean["MAE"], "inside": inside})
    return out


def below_baseline(model_fit_pct: float, baseline_fit_pct: float, column_map) -> str | None:
    """The verdict when the model predicts the held-out logs worse than the first-order lag fed the
    same inputs (its FIT on them below the baseline's), with what the logs may lack; None otherwise."""
    if not model_fit_pct < baseline_fit_pct:
        return None
    text = (
        f"the model predicts the held-out logs worse than a first-order lag fed the same inputs "
        f"(FIT {model_fit_pct:.1f} % against {baseline_fit_pct:.1f} %): do not plan roasts with it"
    )
    inlet = column_map.Tgi.get("column")
    if column_map.heater is None and inlet and not find_name([inlet], INLET_NAMES):  # a logged inlet is the inlet
        text += (
            f"; no heater setting is logged, so the logged {inlet} drives the model as the "
            "air entering the drum, which it is only where that probe sits in the inlet air: log the "
            "burner or heater setting (an Artisan event or extra device) or the inlet air's temperature "
            "(an extra device named Inlet) and run init again"
        )
    return text


def band_sentence(band: dict, units: str = "C") -> str:
    """:func:`roastlab.evaluate.bands.held_out_band` in words: the share inside against the level and the width (its note
    apart), the width in ``units`` ("C" or "F")."""
    level = f"{100 * band['level']:.0f} %"
    return (
        f"{100 * band['inside_all']:.0f} % of the held-out logs' probe samples lie inside the {level} prediction "
        f"band ({'parameters and spread between roasts' if band.get('spread', True) else 'parameters only'}; "
        f"a calibrated band holds about {level}), median width "
        f"{delta_text(band['median_width_C'], units)}"
    )


def fit_roaster(
    config_dir,
    paths,
    *,
    progress=None,
    seed: int = 0,
    every_log: bool = False,
    by_size: bool = False,
    fit_size_kg: float | None = None,
    unit: str | None = None,
    units: str | None = None,
) -> dict:
    """Fit, validate and report a roaster set up by :func:`init_roaster`.

    The logs, sorted by when they were roasted (Artisan ``roastepoch``, RoasTime ``dateTime``;
    by name when a log has no date), are split alternately: the 1st, 3rd, ... fit, the 2nd,
    4th, ... are held out. Writes
    ``config_dir``/model.json, report.md, the same report as report.html (one file a browser opens,
    its figures inside it) and heldout.png (measured vs predicted BT of the held-out logs); returns
    the figures of the report.

    Logs that do not record a setting the map drives the model with, or their green weight, are
    left out (:func:`logs_without_controls`, :func:`logs_without_weight`). A fit that fails on its states with both of the heater's paths
    free is refitted with the drum's path alone (:func:`drum_path_alone`), said in ``refit``; an output
    fit.toml weighs that none of the fit's logs records (an ET the map leaves out) is left out of that fit
    (:func:`outputs_the_logs_lack`), said in ``unweighed``; a model
    that predicts the held-out logs worse than the first-order baseline is called so
    (:func:`below_baseline`).

    ``every_log``: also hold every log out once, predicted by a fit on all the others
    (leave-one-log-out, :func:`roastlab.workflows.compare.compare_models` with the fit spec's own
    bed laws), and report each log's FIT and its share inside the 90 % band: one split of a few
    roasts moves the held-out figure by points, this uses every roast (one fit per log, plus one).

    ``by_size`` (or ``fit_size_kg``, the fit size named): also fit on the logs of one batch size
    alone and predict every other size with nothing refitted, the paper's scaling claim on this
    roaster (:mod:`roastlab.workflows.sizes`; one more fit), written to the report and
    ``config_dir``/sizes.png.

    ``unit``: fit only the logs of that roaster unit (its serial number; :func:`logs_of_unit`), the
    others left out and said in one line.

    ``units``: "C" or "F", the report's temperatures and figures (default: the unit the logs were
    recorded in, :func:`roastlab.io.batch.logs_temp_unit`); the model file, the fit's own sentences
    and the returned figures (``*_C``, MAE) stay in degC.
    """
    from ..evaluate.bands import held_out_band
    from ..evaluate.metrics import average_metrics
    from ..fit.baseline import describe, fit_first_order, validate_first_order
    from ..io.files import Outputs
    from ..io.fitspec import load_fit_spec
    from ..io.importers.mapping import load_map
    from ..io.modelfile import model_document_text
    from .model import load_log
    from .sizes import across_sizes, across_sizes_figure, across_sizes_lines, size_split

    d = Path(config_dir)
    if d.is_file():  # the folder forgotten, a log in its place
        raise InputError(
            "a file, not a folder: the first argument is the folder 'roastlab init LOG... --out DIR' wrote, then the logs",
            d,
        )
    for name in ("map.toml", "plant.toml", "fit.toml"):
        if not (d / name).is_file():
            raise InputError(f"no {name} here: run 'roastlab init LOG... --out {d}' first", d)
    passed_over: dict[str, str] = {}
    paths = log_paths(paths, passed_over)
    if len(paths) < 2:
        raise InputError(
            "give at least two logs: one to fit, one to hold out; one log alone is fitted, unchecked, by "
            f"roastlab identify --plant D/plant.toml --map D/map.toml --spec D/fit.toml --out D/model.json LOG (D = {d})",
            "fit-roaster",
        )
    cmap = load_map(d / "map.toml")
    infos, unreadable = readable_logs(paths, cmap.batch_kg)
    infos, other_units = logs_of_unit(infos, unit) if unit is not None else (infos, {})
    paths = [i.path for i in infos]
    unusable = {
        **logs_without_weight(infos),
        **logs_without_controls(infos, {k: (getattr(cmap, k) or {}).get("column") for k in ("heater", "fan")}),
    }
    left_out = {**passed_over, **unreadable, **other_units, **unusable}
    if left_out:
        keep = [k for k, i in enumerate(infos) if i.path.name not in unusable]
        paths, infos = [paths[k] for k in keep], [infos[k] for k in keep]
        if len(paths) < 2:
            raise InputError(
                f"fewer than two logs can be read and record their green weight and the settings the map drives "
                f"the model with ({'; '.join(left_out.values())})",
                "fit-roaster",
            )
    if all(i.started_epoch_s for i in infos):  # by when they were roasted, else by name
        order, by = sorted(range(len(paths)), key=lambda k: infos[k].started_epoch_s), "date"
    else:
        order, by = sorted(range(len(paths)), key=lambda k: paths[k].name), "name"
    paths = [paths[k] for k in order]
    batches, unloadable = [], {}
    for p in paths:  # a log the map cannot drive the model with (its ET elsewhere and ET the inlet): left out
        try:
            batches.append(load_log(p, cmap))
        except InputError as exc:
            unloadable[p.name] = f"{p.name} cannot be fitted with the map ({exc.problem})"
    if unloadable:
        left_out.update(unloadable)
        paths = [p for p in paths if p.name not in unloadable]
        if len(paths) < 2:
            raise InputError(
                f"fewer than two logs can be fitted with the map ({'; '.join(unloadable.values())})", "fit-roaster"
            )
    recorded = logs_temp_unit(batches)
    units = display_units(units or recorded)
    u = temp_symbol(units)

    def dT(v: float) -> float:  # an error or a width in the report's unit
        return display_temp_delta(v, units)

    sizes = size_split(batches, fit_size_kg) if (by_size or fit_size_kg is not None) else None
    fit_b, val_b = batches[0::2], batches[1::2]
    spec, depth_held = depth_held_on_one_size(load_fit_spec(d / "fit.toml"), fit_b)
    spec, unweighed = outputs_the_logs_lack(spec, fit_b)
    stage = progress or (lambda done, total, text="": None)  # a stage of unknown length: total 0
    from ..sim.cache import cold

    first = "; first run: compiling, 2-3 min once" if cold() else ""  # the kernels, then cached
    stage(0, 0, f"fitting {len(fit_b)} logs{first}")
    result, spec, refit = fit_checked(fit_b, d, spec, cmap, seed, progress, units)
    model = result.model
    stage(0, 0, "validating, the baseline and the band")
    v_fit, v_val = model.validate(fit_b), model.validate(val_b)
    base = fit_first_order(fit_b)
    _, b_fit = validate_first_order(fit_b, base)
    _, b_val = validate_first_order(val_b, base)
    bf, bv = average_metrics(b_fit), average_metrics(b_val)
    verdict = below_baseline(v_val.average["FIT"], bv["FIT"], cmap)
    weighed = [f"{line[0].upper()}{line[1:]}." for line in model.residual_weight_lines(units)]
    roaster_name = model.plant.name if model.plant else "roaster"
    lines = [
        f"# {roaster_name}: fitted by roastlab fit-roaster",
        "",
        *([f"**The fit failed**: {result.failed_in(units)}.", ""] if result.failed else []),
        *([f"**Not usable**: {verdict}.", ""] if verdict else []),
        f"{len(batches)} logs sorted by {by}, split alternately: {len(fit_b)} fit, {len(val_b)} held out "
        f"(the fit never saw them). Fit in {result.identification.wall_s:.1f} s.",
        "",
        *(
            [
                f"Temperatures in °F, {'the unit the logs were recorded in' if recorded == 'F' else 'as asked'}; the "
                "model file and the parameters' table in °C.",
                "",
            ]
            if units == "F"
            else []
        ),  # fmt: skip
        *(line for why in left_out.values() for line in (f"Left out: {why}.", "")),
        *([f"Refitted: {refit}.", ""] if refit else []),
        *([f"The fit {depth_held}.", ""] if depth_held else []),
        *([f"The fit {unweighed}.", ""] if unweighed else []),
        *(
            [
                "Read from the logs:",
                "",
                *(f"- {line}" for line in grouped_notes({p.name: b.notes for p, b in zip(paths, batches)})),
                "",
            ]
            if any(b.notes for b in batches)
            else []
        ),  # fmt: skip
        f"| set | logs | model FIT % | model MAE {u} | baseline FIT % | baseline MAE {u} |",
        "|---|---|---|---|---|---|",
        f"| fit | {len(fit_b)} | {v_fit.average['FIT']:.1f} | {dT(v_fit.average['MAE']):.2f} | {bf['FIT']:.1f} | {dT(bf['MAE']):.2f} |",
        f"| held out | {len(val_b)} | {v_val.average['FIT']:.1f} | {dT(v_val.average['MAE']):.2f} | {bv['FIT']:.1f} | {dT(bv['MAE']):.2f} |",
        "",
        f"Baseline: the first-order lag fed the same inputs ({describe(base, units)}).",
        "",
        *weighed,
        *([""] if weighed else []),
        "| parameter | value | std. error | unit |",
        "|---|---|---|---|",
    ]
    for name, value, se, unit, how in model.table():
        lines.append(f"| {name} | {value or how} | {se or ('on a bound' if how == 'fitted' else '-')} | {unit} |")
    lines += ["", "What the fit says in plain words:", ""]
    lines += [f"- {w}" for w in result.warnings_in(units)] or ["- no warnings"]
    band, bands = held_out_band(model, val_b)
    shaded = f", the {100 * band['level']:.0f} % prediction band shaded" if band else ""
    lines += [
        "",
        f"Held-out logs, measured and predicted BT{shaded}, and their rate of rise (right axis):",
        "",
        f"![held out]({HELD_OUT_FIGURE})",
        "",
    ]
    if band is None:
        lines += [f"| held-out log | FIT % | MAE {u} |", "|---|---|---|"]
        lines += [f"| {n} | {r['FIT']:.1f} | {dT(r['MAE']):.2f} |" for n, r in zip(v_val.names, v_val.rows)]
    else:
        level = f"{100 * band['level']:.0f} %"
        lines += [
            f"| held-out log | FIT % | MAE {u} | inside the {level} band | its median width {u} |",
            "|---|---|---|---|---|",
        ]
        lines += [
            f"| {n} | {r['FIT']:.1f} | {dT(r['MAE']):.2f} | {100 * b['inside']:.0f} % | {dT(b['median_width_C']):.1f} |"
            for n, r, b in zip(v_val.names, v_val.rows, band["batches"])
        ]
        lines += ["", f"{band_sentence(band, units)}." + (f" Note: {band['note']}." if band["note"] else "")]
        if band["by_size"]:
            lines += ["", "| batch size | held-out logs | inside the band |", "|---|---|---|"]
            lines += [f"| {g['size']} | {g['logs']} | {100 * g['inside']:.0f} % |" for g in band["by_size"]]
    by_unit = held_out_by_unit(val_b, v_val.rows, band["batches"] if band else None)
    if by_unit:
        lines += [
            "",
            "Held out by roaster unit (the serial number the logs record; one fit treats the units as one drum):",
            "",
            f"| unit | held-out logs | FIT % | MAE {u} | inside the band |",
            "|---|---|---|---|---|",
        ]
        lines += [
            f"| {g['unit']} | {g['logs']} | {g['FIT']:.1f} | {dT(g['MAE']):.2f} | "
            + ("-" if g["inside"] is None else f"{100 * g['inside']:.0f} %")
            + " |"
            for g in by_unit
        ]
    if every_log:
        stage(0, 0, f"each log held out once: {len(batches)} fits")
    every = held_out_one_by_one(batches, d, cmap, seed, progress, spec) if every_log else None
    if every is not None:
        lines += every_log_lines(every, len(batches), units)
    across = None
    if sizes is not None:
        size_b = [batches[k] for k in sizes.fit]
        size_spec, size_depth = depth_held_on_one_size(spec, size_b)
        size_spec, size_unweighed = outputs_the_logs_lack(size_spec, size_b)
        stage(0, 0, f"fitting {sizes.fit_size} alone ({len(size_b)} logs) for the other sizes")
        size_fit, _, size_refit = fit_checked(size_b, d, size_spec, cmap, seed, progress, units)
        across = across_sizes(size_fit.model, batches, sizes)
        across["failed"], across["refit"] = size_fit.failed_in(units), size_refit
        lines += across_sizes_lines(across, SIZES_FIGURE, units)
        if size_depth:
            lines += ["", f"The fit on {sizes.fit_size} alone {size_depth}."]
        if size_unweighed:
            lines += ["", f"The fit on {sizes.fit_size} alone {size_unweighed}."]
        if size_refit:
            lines += ["", f"Refitted (the fit on {sizes.fit_size} alone): {size_refit}."]
        if size_fit.failed:
            lines += ["", f"**The fit on {sizes.fit_size} alone failed**: {size_fit.failed_in(units)}."]
    from ..evaluate.validate import panels_by_size
    from ..report.figures import figure_bytes, plot_fit
    from ..report.markdown import html_document

    stage(0, 0, "writing the report and its figures")
    # held-out logs of several sizes (an alternate split of every size): a panel of each size in turn
    held_kg = [b.Mb_kg for b in val_b]
    held_title = f"{roaster_name}: held-out logs, measured and predicted BT"
    figures = {
        d / HELD_OUT_FIGURE: plot_fit(
            v_val, title=held_title, bands=bands, units=units, **panels_by_size(v_val.names, held_kg)
        )
    }
    if across is not None:
        figures[d / SIZES_FIGURE] = across_sizes_figure(across)
    pngs = {path: figure_bytes(fig, path) for path, fig in figures.items()}
    report = "\n".join(lines) + "\n"
    title = f"{roaster_name}: fit report"
    with Outputs(paths) as out:
        out.write_text(d / "model.json", model_document_text(model.to_document()))
        out.write_text(d / "report.md", report)
        # the same report as one page that opens in any browser, its figures inside it
        out.write_text(d / "report.html", html_document(title, report, {p.name: b for p, b in pngs.items()}))
        for path, png in pngs.items():
            out.write_bytes(path, png)
    stage(1, 1, "done")  # closes the open stage
    return {
        "fit": {"FIT": v_fit.average["FIT"], "MAE": v_fit.average["MAE"]},
        "held_out": {"FIT": v_val.average["FIT"], "MAE": v_val.average["MAE"]},
        "baseline_held_out": {"FIT": bv["FIT"], "MAE": bv["MAE"]},
        "below_baseline": verdict,
        "left_out": left_out,
        "refit": refit,
        "unweighed": unweighed,
        "notes": {p.name: list(b.notes) for p, b in zip(paths, batches) if b.notes},
        "band": band,
        "units": units,
        "held_out_by_unit": by_unit,
        "every_log": every
        and {
            "FIT": every.cv_FIT,
            "band_inside": every.cv_band_inside,
            "band_median_width_C": every.cv_band_width_C,
            "by_log": every.cv_by_group,
        },
        "across_sizes": across,
        "warnings": result.warnings_in(units),
        "failed": result.failed_in(units),
        "model": d / "model.json",
        "report": d / "report.md",
        "report_html": d / "report.html",
        "figures": list(figures),
    }


def depth_held_on_one_size(spec, batches):
    """``spec`` with the probe's depth scale held at its start where it frees it and ``batches`` are all
    of one batch size (one of ``compare-models``' size groups): only a change of batch size determines it
    (:func:`fit_spec_text` frees it where the logs span sizes; a fit on one of them, as ``--by-size``'s,
    cannot). Returns ``(spec, sentence or None)``."""
    import dataclasses

    depth = next((f for f in spec.free if f.name == "h_probe_m"), None)
    if depth is None or spans_batch_sizes([b.Mb_kg for b in batches]):
        return spec, None
    held = dataclasses.replace(
        spec, free=[f for f in spec.free if f is not depth], fixed={**spec.fixed, "h_probe_m": depth.start}
    )
    return held, f"holds the probe's depth scale at {depth.start:g} m: logs of one batch size cannot determine it"


def outputs_the_logs_lack(spec, batches):
    """``spec`` with the weight of each second output it fits (ET, the second bean reading Tb2) set to 0
    where none of ``batches`` records it. ``init`` weighs what the logs it read record; the logs one fit
    is given (the fit half, one batch size) can all lack it: the Skywalker's first four logs' ET reads
    below BT, and the map leaves it out (:func:`roastlab.workflows.fitting.et_dropped`), where
    ``identify`` would refuse the spec. Returns ``(spec, sentence or None)``."""
    import dataclasses

    from .fitting import SECOND_OUTPUTS, et_dropped, records, weighs

    lacking = [name for name in SECOND_OUTPUTS if weighs(spec.weights, name) and not records(batches, name)]
    if not lacking:
        return spec, None
    held = dataclasses.replace(spec, weights={**spec.weights, **dict.fromkeys(lacking, 0.0)})
    why = (
        " (the map leaves out an ET that reads below BT through the roast)"
        if "ET" in lacking and et_dropped(batches)
        else ""
    )
    return held, (
        f"leaves out {' and '.join(lacking)}, which fit.toml weighs: none of the {len(batches)} logs it fits "
        f"records {'them' if len(lacking) > 1 else 'it'}{why}"
    )


def fit_checked(batches, config_dir: Path, spec, column_map, seed: int, progress=None, units: str = "C"):
    """Fit ``batches`` with ``spec`` (:func:`roastlab.workflows.fitting.fit`); a fit that fails on
    its states with both of the heater's paths free is refitted with the drum's path alone
    (:func:`drum_path_alone`). Returns ``(result, spec as used, refit sentence or None)``, the sentence's
    temperatures in ``units`` ("C" or "F")."""
    from .fitting import fit

    plant = Path(config_dir) / "plant.toml"
    result = fit(batches, plant, spec, column_map=column_map, progress=progress, seed=seed)
    drum_only = drum_path_alone(spec) if result.failed else None
    if drum_only is not None:  # both heater paths free and the drum below the beans: the drum's path alone
        again = fit(batches, plant, drum_only, column_map=column_map, progress=progress, seed=seed)
        if not again.failed:
            refit = (
                f"with the heater free to heat the air and the drum, the fit failed on {result.failed_in(units)}; "
                "refitted with the heater heating the drum alone (Tgi_gain_C held at 0), the path of a drum "
                "roaster; to keep this, remove Tgi_gain_C from [free] in fit.toml"
            )
            return again, drum_only, refit
    return result, spec, None


def drum_path_alone(spec):
    """``spec`` with the heater's path into the air held shut (Tgi_gain_C fixed at 0), where it frees
    both of the heater's paths; None otherwise. BT alone cannot tell the two paths apart, and a fit
    that sends the heat through the air with the drum below the beans has failed
    (:attr:`roastlab.workflows.model.FittedModel.failed`); the drum is a drum roaster's path."""
    import dataclasses

    names = {p.name for p in spec.free}
    if not {"Qe_gain_kW", "Tgi_gain_C"} <= names:
        return None
    return dataclasses.replace(
        spec, free=[p for p in spec.free if p.name != "Tgi_gain_C"], fixed={**spec.fixed, "Tgi_gain_C": 0.0}
    )


def held_out_one_by_one(batches, config_dir: Path, column_map, seed: int, progress=None, spec=None):
    """Each log predicted by a fit on all the others, with the fit spec as it is (its own bed laws;
    ``spec``, default ``config_dir``/fit.toml): the :class:`~roastlab.workflows.compare.VariantScore`
    of leave-one-log-out."""
    from ..io.fitspec import load_fit_spec
    from .compare import Variant, compare_models

    spec = spec or load_fit_spec(config_dir / "fit.toml")
    return compare_models(
        batches,
        config_dir / "plant.toml",
        spec,
        [Variant(spec.bed)],
        column_map=column_map,
        group_by="log",
        seed=seed,
        progress=progress,
    ).scores[0]


def every_log_lines(score, n_logs: int, units: str = "C") -> list[str]:
    """The report's section on every log held out once (:func:`held_out_one_by_one`), its band's width
    in ``units``."""
    from ..evaluate.bands import BAND_LEVEL

    level = f"{100 * BAND_LEVEL:.0f} %"
    has_band = math.isfinite(score.cv_band_inside)
    lines = [
        "",
        "## Every log held out once",
        "",
        f"Each of the {n_logs} logs predicted by a fit on the other {n_logs - 1} (leave-one-log-out): one split "
        "of a few roasts moves the held-out figure by points; this uses every roast.",
        "",
        f"| log | FIT % |{f' inside the {level} band |' if has_band else ''}",
        f"|---|---|{'---|' if has_band else ''}",
    ]
    for name, fit_pct in score.cv_by_group.items():
        inside = score.cv_band_by_group.get(name, math.nan)
        band = f" {100 * inside:.0f} % |" if has_band and math.isfinite(inside) else (" - |" if has_band else "")
        lines.append(f"| {name} | {fit_pct:.1f} |{band}")
    lines += [
        "",
        f"Every log held out once: {every_log_sentence(score.cv_FIT, score.cv_band_inside, score.cv_band_width_C, units)}"
        + (f"; an honest band holds about {level}." if has_band else "."),
    ]
    return lines


def every_log_sentence(fit_pct: float, band_inside: float, band_width_C: float, units: str = "C") -> str:
    """Every log held out once, in one clause: the report's and the terminal's (:func:`held_out_one_by_one`), the
    band's width in ``units``."""
    text = f"FIT {fit_pct:.1f} % on average"
    if math.isfinite(band_inside):
        text += (
            f", {100 * band_inside:.0f} % of the samples inside the band of the fit without their log "
            f"(median width {delta_text(band_width_C, units)})"
        )
    return text
