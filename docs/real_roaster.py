"""Regenerate the measured figures of docs/real-roaster.md (`make real-roaster`).

Fits both real machines with their example files, split alternately by sorted name (first of
each pair fits, second is held out), fits the first-order baseline on the same logs and the
same inputs, and tests batch-size scaling on the Bullet (fit on 490-500 g only, every other
batch mass predicted with nothing refitted). Writes docs/real-roaster-results.md and
docs/real-roaster-scaling.png. Needs ../shared/data/real beside the repository.
"""

from __future__ import annotations

import dataclasses
import functools
import sys
import time
from pathlib import Path

import numpy as np

import roastlab
from roastlab.evaluate.metrics import average_metrics, fit_percent, mean_gap
from roastlab.fit import uncertainty
from roastlab.fit.baseline import describe, fit_first_order, validate_first_order
from roastlab.io.fitspec import load_fit_spec
from roastlab.io.importers.mapping import load_map
from roastlab.model.bed import PAPER_BED
from roastlab.model.parameters import REGISTRY
from roastlab.workflows.compare import Variant

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "real"
DOCS = ROOT / "docs"


@functools.cache
def grams(path: Path) -> int | None:
    """A Bullet log's green batch [g] as ``roastlab init`` reads it: the weight the log records, else
    the grams in its file name (roastlab.workflows.survey.inspect_log); None if neither."""
    from roastlab.workflows.survey import inspect_log

    kg = inspect_log(path).batch_kg
    return None if kg is None else round(kg * 1000)


#: The Bullet's fit batch sizes [g]: the roaster's nominal 0.5 kg as its owner weighed it.
NOMINAL_G = (490, 500)
#: The same, as the tables and figures name it.
NOMINAL = f"{NOMINAL_G[0]}-{NOMINAL_G[1]} g"


def nominal_size(path: Path) -> bool:
    """A Bullet log of the fit's batch size (:data:`NOMINAL_G`)."""
    g = grams(path)
    return g is not None and NOMINAL_G[0] <= g <= NOMINAL_G[1]


def roasts(paths, example: str) -> list[Path]:
    """The logs that are roasts the example's files can drive, as ``roastlab fit-roaster`` takes a folder:
    a recording that cannot be read as one, or a copy of another (roastlab.workflows.survey.readable_logs),
    or one that records no setting the example's map drives the model with (a log whose heater never
    moved, logs_without_controls) or that the example's map refuses for another reason is left out and said on
    stderr. ``example``: its folder under examples/."""
    from roastlab.errors import InputError
    from roastlab.io.importers.mapping import load_map
    from roastlab.workflows.survey import logs_without_controls, readable_logs

    infos, left_out = readable_logs(paths)
    cmap = load_map(ROOT / "examples" / example / "map.toml")
    controls = {k: (getattr(cmap, k) or {}).get("column") for k in ("heater", "fan")}
    left_out |= logs_without_controls(infos, controls)
    for info in infos:  # anything else the example's map refuses in a log (the import's one line)
        if info.path.name not in left_out:
            try:
                roastlab.load_log(info.path, cmap)
            except InputError as exc:
                left_out[info.path.name] = str(exc)
    for why in left_out.values():
        print(f"left out: {why}", file=sys.stderr)
    return [i.path for i in infos if i.path.name not in left_out]


def bullet_logs() -> list[Path]:
    """The Bullet logs that are roasts (:func:`roasts`) and record their green weight (:func:`grams`), by name."""
    return list(_logs("bullet", "*.json"))


def skywalker_logs() -> list[Path]:
    """The Skywalker's Artisan logs that are roasts (:func:`roasts`), by name."""
    return list(_logs("skywalker", "*.alog"))


@functools.cache
def _logs(example: str, pattern: str) -> tuple[Path, ...]:
    """One example's logs as :func:`roasts` takes them, read once (what is left out is said once)."""
    return tuple(p for p in roasts(sorted((DATA / example).glob(pattern)), example) if grams(p) is not None)


def nominal_logs() -> list[Path]:
    """The Bullet logs of the fit's batch size (:data:`NOMINAL_G`), sorted by name."""
    return [p for p in bullet_logs() if nominal_size(p)]


def unit(path: Path) -> str:
    """The roaster unit that recorded a RoasTime log (its serial number; roastime.read_roastime)."""
    from roastlab.io.importers.roastime import read_roastime

    return read_roastime(path).unit


def load(paths, column_map):
    return [roastlab.load_log(p, column_map) for p in paths]


def mean(rows, key):
    """The batches' mean of one metric (evaluate.metrics.average_metrics, the paper's Average row)."""
    return average_metrics(rows)[key]


def output_table(v_fit, v_val, lines):
    """Markdown rows of each output's mean FIT and MAE (Ta vs the probe, then each further output:
    Tb vs the second bean reading, Tgo vs the logged ET; roastlab.model.parameters.MODEL_OF_OUTPUT)."""
    from roastlab.model.parameters import MODEL_OF_OUTPUT

    names = [o for o in v_fit.outputs if o in v_val.outputs]
    head = ["set", "Ta FIT %", "Ta MAE °C"]
    for o in names:
        head += [f"{MODEL_OF_OUTPUT[o]} vs {o} FIT %", f"{MODEL_OF_OUTPUT[o]} vs {o} MAE °C"]
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for name, v in (("fit", v_fit), ("held out", v_val)):
        cells = [name, f"{v.average['FIT']:.1f}", f"{v.average['MAE']:.2f}"]
        for o in names:
            a = v.output_average(o)
            cells += [f"{a['FIT']:.1f}", f"{a['MAE']:.2f}"]
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")


def paper_probe_variant(example, fit_b, val_b, column_map, lines):
    """The same fit with the paper's probe (eq. 17, no immersion term) on Ta alone: the comparison row."""
    spec = load_fit_spec(example / "fit.toml")
    # h_probe 0 is eq. 17 bit for bit (roastlab.model.rhs.probe_coverage); on Ta alone
    spec = dataclasses.replace(Variant(PAPER_BED, (("h_probe_m", 0.0),)).spec(spec), weights={}, bed=PAPER_BED)
    model = roastlab.fit(fit_b, example / "plant.toml", spec, column_map=column_map).model
    v_fit, v_val = model.validate(fit_b), model.validate(val_b)
    lines += [
        "The same fit with the paper's probe (eq. 17, no immersion term) and on Ta alone, for comparison:",
        "",
    ]
    output_table(v_fit, v_val, lines)
    return model


def split(paths) -> tuple[list[Path], list[Path]]:
    """The logs sorted by name, split alternately: (1st, 3rd, ... fit; 2nd, 4th, ... held out)."""
    return paths[0::2], paths[1::2]


def machine(title, example, paths, lines):
    """Fit, hold out and compare with the baseline; append markdown to ``lines``; return the model."""
    column_map = load_map(example / "map.toml")
    fit_paths, val_paths = split(paths)
    fit_b, val_b = load(fit_paths, column_map), load(val_paths, column_map)
    t0 = time.perf_counter()
    result = roastlab.fit(fit_b, example / "plant.toml", example / "fit.toml", column_map=column_map)
    fit_s = time.perf_counter() - t0
    model = result.model
    v_fit, v_val = model.validate(fit_b), model.validate(val_b)
    base = fit_first_order(fit_b)
    _, b_fit = validate_first_order(fit_b, base)
    _, b_val = validate_first_order(val_b, base)
    lines += [
        f"### {title}",
        "",
        f"Fit on {len(fit_b)} logs in {fit_s:.1f} s; held out {len(val_b)} logs.",
        "",
        "| set | logs | model FIT % | model MAE °C | baseline FIT % | baseline MAE °C |",
        "|---|---|---|---|---|---|",
        f"| fit | {len(fit_b)} | {v_fit.average['FIT']:.1f} | {v_fit.average['MAE']:.2f} "
        f"| {mean(b_fit, 'FIT'):.1f} | {mean(b_fit, 'MAE'):.2f} |",
        f"| held out | {len(val_b)} | {v_val.average['FIT']:.1f} | {v_val.average['MAE']:.2f} "
        f"| {mean(b_val, 'FIT'):.1f} | {mean(b_val, 'MAE'):.2f} |",
        "",
    ]
    if v_fit.outputs:
        weights = result.identification.outputs
        lines += [
            "Per output (the model's Ta against the bean probe, its Tb against the second bean reading, its "
            "outlet gas Tgo against the logged ET; "
            + ", ".join(f"weight {k} {o['weight']:g}" for k, o in weights.items())
            + "):",
            "",
        ]
        output_table(v_fit, v_val, lines)
    if "Tb2" in v_fit.outputs:
        paper_probe_variant(example, fit_b, val_b, column_map, lines)
    lines += [
        f"First-order baseline on the same inputs: {describe(base)}.",
        "",
        "| parameter | value | std. error | bounds | unit |",
        "|---|---|---|---|---|",
    ]
    bounds = {f.name: (f.lower, f.upper) for f in load_fit_spec(example / "fit.toml").free}
    for name, entry in model.parameters.items():
        se = entry.get("stderr")
        lo, hi = bounds.get(name, (None, None))
        on = lo is not None and any(a.item() for a in uncertainty.at_bounds(entry["value"], lo, hi))
        se_text = "on bound" if on else ("-" if se is None else f"{se:.3g}")
        b_text = "" if lo is None else f"[{lo:g}, {hi:g}]"
        lines.append(f"| {name} | {entry['value']:.4g} | {se_text} | {b_text} | {REGISTRY[name].unit} |")
    lines.append("")
    print(
        f"{title}: fit FIT {v_fit.average['FIT']:.1f} %, held-out FIT {v_val.average['FIT']:.1f} % "
        f"MAE {v_val.average['MAE']:.2f} °C; baseline held-out {mean(b_val, 'FIT'):.1f} %",
        file=sys.stderr,
    )
    return model, column_map, (v_val.average["FIT"], v_val.average["MAE"], v_val.rows)


def gap_text(gap: dict) -> str:
    """A :func:`roastlab.evaluate.metrics.mean_gap` as "-8.2 (90 % interval -17.0 to +0.5)"."""
    if np.isnan(gap["low"]):
        return f"{gap['gap']:+.1f}"
    return f"{gap['gap']:+.1f} ({100 * gap['level']:.0f} % interval {gap['low']:+.1f} to {gap['high']:+.1f})"


def scaling(model, column_map, paths, nominal_val, lines):
    """The Bullet's batch-size test: FIT per batch mass with the 490-500 g model; a figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    others = [p for p in paths if not nominal_size(p)]
    batches = load(others, column_map)
    v = model.validate(batches)
    by_mass: dict[int, list] = {}
    for p, row in zip(others, v.rows):
        by_mass.setdefault(grams(p), []).append(row)
    fit_units = sorted({unit(p) for p in paths if nominal_size(p)})
    units = [unit(p) for p in others]
    lines += [
        "### Batch-size scaling on the Bullet",
        "",
        f"Model fitted on the {NOMINAL} logs only (above); each other log predicted with its own green "
        f"weight and nothing refitted. The unit is the roaster's serial number in the log: the {NOMINAL} "
        f"logs all come from unit {', '.join(fit_units)}; the other units' logs test the batch size and "
        "another drum of the same make at once.",
        "",
        "| batch g | unit | Ta FIT % | Ta MAE °C | Ta MPE % | Tb vs IR FIT % | Tb vs IR MPE % |",
        "|---|---|---|---|---|---|---|",
    ]
    second = dict(zip(v.outputs["Tb2"]["names"], v.outputs["Tb2"]["rows"]))
    order = sorted(range(len(others)), key=lambda i: (grams(others[i]), others[i].name))
    for i in order:
        row, row2 = v.rows[i], second[v.names[i]]
        lines.append(
            f"| {grams(others[i])} | {units[i]} | {row['FIT']:.1f} | {row['MAE']:.2f} | {row['MPE']:+.2f} "
            f"| {row2['FIT']:.1f} | {row2['MPE']:+.2f} |"
        )
    same = [r for r, u in zip(v.rows, units) if u in fit_units]

    def span(masses):  # "200-470 g" over the batch masses of a group
        return f"{min(masses)} g" if min(masses) == max(masses) else f"{min(masses)}-{max(masses)} g"

    # lighter and heavier than the fit's logs, from whatever weights the folder holds
    lighter = sorted(g for g in by_mass if g < NOMINAL_G[0])
    heavier = sorted(g for g in by_mass if g > NOMINAL_G[1])
    groups = {
        **({f"lighter, {span(lighter)}": [r for g in lighter for r in by_mass[g]]} if lighter else {}),
        **({f"heavier, {span(heavier)}": [r for g in heavier for r in by_mass[g]]} if heavier else {}),
        "every other size": list(v.rows),
        f"the same unit as the fit ({', '.join(fit_units)})": same,
        "other units": [r for r, u in zip(v.rows, units) if u not in fit_units],
    }
    lines += [
        "",
        f"Each group against the held-out {NOMINAL} logs, the gap of the means with its 90 % interval "
        "(Welch's t over the logs, `roastlab.evaluate.metrics.mean_gap`); MPE is signed, positive where "
        "the model reads low:",
        "",
    ]
    nominal_rows = nominal_val[2]
    for name, rows in groups.items():
        if rows:
            fit_gap = mean_gap([r["FIT"] for r in rows], [r["FIT"] for r in nominal_rows])
            bias_gap = mean_gap([r["MPE"] for r in rows], [r["MPE"] for r in nominal_rows])
            lines.append(
                f"- {name}: mean FIT {mean(rows, 'FIT'):.1f} % ({len(rows)} log{'s' * (len(rows) > 1)}), "
                f"{gap_text(fit_gap)} points against the {fit_gap['n_reference']} held-out {NOMINAL} logs; "
                f"mean MPE {mean(rows, 'MPE'):+.1f} %, {gap_text(bias_gap)} points against theirs."
            )
    ir = [second[n]["FIT"] for n in v.names]
    lines.append(
        f"- the model's Tb against the IR reading on these {len(ir)} logs: mean FIT {np.mean(ir):.1f} % "
        "(no probe model involved)."
    )
    lines.append("")

    fig, (ax, ax3, ax2) = plt.subplots(1, 3, figsize=(16, 4.4), gridspec_kw={"width_ratios": [1, 1, 1.3]})
    ms = np.array([grams(p) for p in others], dtype=float)
    fits = np.array([r["FIT"] for r in v.rows])
    own = np.array([u in fit_units for u in units])
    ax.scatter(ms[own], fits[own], color="C3", label="bean probe Ta, the fit's unit")
    ax.scatter(ms[~own], fits[~own], facecolors="none", edgecolors="C3", label="bean probe Ta, other units")
    ax.scatter(ms, [second[n]["FIT"] for n in v.names], color="C1", marker="x", label="IR reading vs model Tb")
    ax.axhline(nominal_val[0], color="C0", ls="--", label=f"held-out {NOMINAL} ({nominal_val[0]:.1f} %)")
    floor = max(78.0, nominal_val[0] - 6.0)  # issue 25: >= 78 % and within 6 points of the nominal logs
    ax.axhspan(floor, max(floor, nominal_val[0]), color="C0", alpha=0.1, label="target: >= 78 % and within 6 points")
    ax.set_xlabel("green batch mass [g]")
    ax.set_ylabel("FIT [%]")
    ax.set_title(f"Aillio Bullet: model fitted on {NOMINAL}")
    ax.set_ylim(min(0.0, float(np.min(fits)) - 5.0), 100)  # a log predicted worse than its mean stays in view
    ax.legend(fontsize=8, loc="lower center")
    ax.grid(alpha=0.3)
    # the evidence for probe immersion: probe minus IR reading late in the roast, by batch mass
    every = load(paths, column_map)
    gaps = []
    for b, r in zip(every, model.predict_many(every)):
        late = slice(int(0.5 * b.n), int(0.95 * b.n))
        gaps.append((b.Mb_kg * 1000, np.nanmean(b.Ta_C[late] - b.Tb2_C[late]), np.mean(r.Ta_C[late] - r.Tb_C[late])))
    g = np.array(gaps)
    ax3.scatter(g[:, 0], g[:, 1], color="k", label="measured: probe - IR reading")
    ax3.scatter(g[:, 0], g[:, 2], color="C3", marker="^", label="model: Ta - Tb")
    ax3.set_xlabel("green batch mass [g]")
    ax3.set_ylabel("mean over the 2nd half of the roast [°C]")
    ax3.set_title("the probe reads further below the beans in small batches")
    ax3.legend(fontsize=8)
    ax3.grid(alpha=0.3)
    pick = [int(np.argmin(ms)), int(np.argmax(ms))]
    for i, color in zip(pick, ("C2", "C4")):
        b, pred = batches[i], v.predicted[i]
        ax2.plot(b.time_s / 60, b.Ta_C, color=color, lw=1.5, label=f"{int(ms[i])} g measured")
        ax2.plot(v.time_s[i] / 60, pred, color=color, lw=1.2, ls="--", label=f"{int(ms[i])} g predicted")
    ax2.set_xlabel("time since CHARGE [min]")
    ax2.set_ylabel("bean probe [°C]")
    ax2.set_title("smallest and largest batch")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(DOCS / "real-roaster-scaling.png", dpi=110)
    plt.close(fig)


def best_drum_start(model, batch, keep, around_C: float, span_C: float = 100.0) -> float:
    """The drum start Tm0 [degC] whose prediction fits ``batch``'s probe samples ``keep`` best (least
    squares; the model's own prediction, ``FittedModel.predict`` with the change ``Tm0_C``): a 5 degC
    grid over ``around_C`` +- ``span_C`` (the SSR need not have one minimum), then Brent's method
    within a step of the grid's best."""
    from scipy.optimize import minimize_scalar

    def ssr(tm0):
        return float(np.sum((model.predict(batch, Tm0_C=tm0).Ta_C[keep] - batch.Ta_C[keep]) ** 2))

    grid = around_C + np.arange(-span_C, span_C + 1e-9, 5.0)
    g = float(grid[int(np.argmin([ssr(x) for x in grid]))])
    return float(minimize_scalar(ssr, bounds=(g - 5.0, g + 5.0), method="bounded", options={"xatol": 0.1}).x)


def drum_start(model, column_map, paths, lines, early_s: float = 180.0):
    """How much of each log's error the drum's unlogged heat at CHARGE can explain.

    Per held-out log (the other sizes and the held-out nominal logs): the drum start Tm0 that best
    fits the whole log, and the one that best fits the probe up to ``early_s`` with the rest of the roast then
    scored (what a roaster watching the first minutes could know). Every prediction is the model's
    own (:func:`best_drum_start`); nothing else is refitted."""
    from roastlab.metrics.profile import crossing_time_s, first_crack_s

    nominal_held = set(split(nominal_logs())[1])
    held = [p for p in paths if not nominal_size(p) or p in nominal_held]

    def probe(b, tm0):
        return model.predict(b, Tm0_C=tm0).Ta_C

    rows = []
    for p, b in zip(held, load(held, column_map)):
        logged = float(b.initial["Tm0_C"])
        whole = best_drum_start(model, b, np.ones(b.n, bool), logged)
        late = b.time_s > early_s
        early = best_drum_start(model, b, ~late, logged)
        fc_s = first_crack_s(b.time_s, b.events)
        level = None if fc_s is None else float(np.interp(fc_s, b.time_s, b.Ta_C))
        marked = level is not None and fc_s > early_s
        rec = {"path": p, "logged": logged, "whole": whole, "early": early, "marked": marked}
        for key, tm0 in (("at_logged", logged), ("at_whole", whole), ("at_early", early)):
            ta = probe(b, tm0)
            rec[key] = fit_percent(b.Ta_C, ta)
            rec[key + "_late"] = fit_percent(b.Ta_C[late], ta[late])
            hit = crossing_time_s(b.time_s, ta, level) if marked else None
            rec[key + "_fc"] = None if hit is None else hit - fc_s
        rows.append(rec)
    lines += [
        "### The drum's heat at CHARGE",
        "",
        f"Each held-out log with the drum start that best fits its whole probe curve, and with the one "
        f"that best fits its first {early_s / 60:g} minutes, the rest of the roast then scored (FIT after "
        f"{early_s / 60:g} min; first crack: the model's probe reaching the log's reading at its FCs mark, "
        "error in s, positive late; blank where the log marks no first crack or the model's probe never "
        "gets there):",
        "",
        "| log | unit | preheat °C | best start °C | FIT % at preheat | at best | start from first minutes °C "
        "| FIT after, at preheat | after, from first minutes | FCs error at preheat s | from first minutes s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]

    def s(v):
        return "" if v is None else f"{v:+.0f}"

    for r in rows:
        lines.append(
            f"| {r['path'].stem} | {unit(r['path'])} | {r['logged']:.0f} | {r['whole']:.0f} | {r['at_logged']:.1f} "
            f"| {r['at_whole']:.1f} | {r['early']:.0f} | {r['at_logged_late']:.1f} | {r['at_early_late']:.1f} "
            f"| {s(r['at_logged_fc'])} | {s(r['at_early_fc'])} |"
        )

    def summary(name, group):
        if not group:
            return
        marked = sum(r["marked"] for r in group)
        fc0 = [abs(r["at_logged_fc"]) for r in group if r["at_logged_fc"] is not None]
        fc1 = [abs(r["at_early_fc"]) for r in group if r["at_early_fc"] is not None]
        lines.append(
            f"- {name} ({len(group)} logs): FIT {np.mean([r['at_logged'] for r in group]):.1f} % at the preheat, "
            f"{np.mean([r['at_whole'] for r in group]):.1f} % at each log's best start (best minus preheat "
            f"{min(r['whole'] - r['logged'] for r in group):+.0f} to {max(r['whole'] - r['logged'] for r in group):+.0f} °C); "
            f"after {early_s / 60:g} min {np.mean([r['at_logged_late'] for r in group]):.1f} % at the preheat, "
            f"{np.mean([r['at_early_late'] for r in group]):.1f} % from the first minutes; first crack median "
            f"|error| {np.median(fc0) if fc0 else float('nan'):.0f} s at the preheat (the model reaches it on "
            f"{len(fc0)} of the {marked} logs that mark it), {np.median(fc1) if fc1 else float('nan'):.0f} s from "
            f"the first minutes ({len(fc1)} of {marked})"
        )

    lines += [""]
    summary(f"held-out {NOMINAL}", [r for r in rows if nominal_size(r["path"])])
    summary("every other size", [r for r in rows if not nominal_size(r["path"])])
    lines.append("")


def variants_and_bands(column_map, paths, lines):
    """Each bed-law variant (roastlab.model.bed, the probe's depth scale fitted) and the example's
    own spec (its laws, the depth scale held) fitted on the same 490-500 g logs: held-out nominal
    FIT, every other size predicted, and the 90 % band's coverage (roastlab.evaluate.bands)."""
    from roastlab.evaluate.bands import band_coverage, share_inside
    from roastlab.io.fitspec import load_fit_spec
    from roastlab.model.bed import SURFACE_HEAT, VARIANTS
    from roastlab.workflows.compare import FREE

    example = ROOT / "examples" / "bullet"
    nominal = [p for p in paths if nominal_size(p)]
    others = [p for p in paths if not nominal_size(p)]
    fit_p, val_p = split(nominal)
    fit_b, val_b, oth_b = load(fit_p, column_map), load(val_p, column_map), load(others, column_map)
    lines += [
        f"### Bed-law variants (fitted on the same {NOMINAL} logs: `fit.toml` with each variant's laws and "
        "h_probe_m free, then the example's `fit.toml` as it is)",
        "",
        f"| variant | held-out {NOMINAL} Ta FIT % / MAE °C | other sizes Ta FIT % | other sizes Tb vs IR FIT % "
        "| 90 % band: inside, held out | inside, other sizes | of them, the fit's unit | median width °C |",
        "|---|---|---|---|---|---|---|---|",
    ]
    fit_units = {unit(p) for p in nominal}
    own = [unit(p) in fit_units for p in others]
    spec = load_fit_spec(example / "fit.toml")
    variants = {f"{name}, h_probe_m {FREE}": Variant(laws, (("h_probe_m", FREE),)) for name, laws in VARIANTS.items()}
    variants[f"example: {spec.bed.name}, h_probe_m {spec.fixed['h_probe_m']:g} m"] = Variant(spec.bed)
    # the two heat paths that grow with the bed's surface, off in the example (roastlab.model.bed.SURFACE_HEAT)
    for extra in SURFACE_HEAT:
        variants[f"example + {extra}"] = Variant.parse(f"{spec.bed.name},{extra}")
    for name, variant in variants.items():
        model = roastlab.fit(
            fit_b, example / "plant.toml", variant.spec(spec), column_map=column_map, bed=variant.laws
        ).model
        v_val, v_oth = model.validate(val_b), model.validate(oth_b)
        cov_val, cov_oth = band_coverage(model, val_b), band_coverage(model, oth_b)

        width = float(np.median([r["median_width_C"] for r in cov_val + cov_oth]))
        lines.append(
            f"| {name} | {v_val.average['FIT']:.1f} / {v_val.average['MAE']:.2f} | {v_oth.average['FIT']:.1f} "
            f"| {v_oth.output_average('Tb2')['FIT']:.1f} | {share_inside(cov_val):.0%} | {share_inside(cov_oth):.0%} "
            f"| {share_inside([c for c, o in zip(cov_oth, own) if o]):.0%} | {width:.1f} |"
        )
        print(
            f"variant {name}: held-out {v_val.average['FIT']:.1f} %, others {v_oth.average['FIT']:.1f} %",
            file=sys.stderr,
        )
    lines.append("")


def spread_against_refits(column_map, paths, lines):
    """The bands' roast-to-roast spread takes each fitted log's error as predicted without it, by the
    fit's own rule (roastlab.fit.uncertainty.held_out_residuals: the fit redone from its optimum
    without the log); here against the example fitted anew (global search) without each 490-500 g
    fit log in turn."""
    from roastlab.evaluate.bands import roast_spread

    example = ROOT / "examples" / "bullet"
    fit_b = load(split([p for p in paths if nominal_size(p)])[0], column_map)
    full = roastlab.fit(fit_b, example / "plant.toml", example / "fit.toml", column_map=column_map)
    held = full.identification.held_out_Ta
    own_v = full.model.validate(fit_b)
    lines += [
        f"### The bands' roast-to-roast spread: the fit's leave-one-log-out against new fits (Bullet, {NOMINAL} fit logs)",
        "",
        "| log | RMS error in the fit °C | left out, the fit's rule °C | fitted anew without it °C |",
        "|---|---|---|---|",
    ]
    times, refit_errors = [], []
    for i, b in enumerate(fit_b):
        model = roastlab.fit(
            fit_b[:i] + fit_b[i + 1 :], example / "plant.toml", example / "fit.toml", column_map=column_map
        ).model
        v = model.validate([b])
        e = np.asarray(v.predicted[0]) - np.asarray(v.measured[0])
        own = np.asarray(own_v.predicted[i]) - np.asarray(own_v.measured[i])
        times.append(np.asarray(v.time_s[0]))
        refit_errors.append(e)
        rms = [float(np.sqrt(np.nanmean(x**2))) for x in (own, held[i, : e.size], e)]
        lines.append(f"| {b.name} | {rms[0]:.2f} | {rms[1]:.2f} | {rms[2]:.2f} |")
    linear = full.model.doc["fit"]["spread"]["rms_C"]
    refit = roast_spread(times, refit_errors)["rms_C"]
    lines += [
        "",
        f"Median spread over the roast: {np.median(linear):.2f} °C by the fit's rule, {np.median(refit):.2f} °C from the new fits.",
        "",
    ]
    print(f"spread: fit's rule {np.median(linear):.2f} °C, new fits {np.median(refit):.2f} °C", file=sys.stderr)


def skywalker_et(paths, lines):
    """ET minus BT on each Skywalker log (median from 1 min after CHARGE to DROP, and at 4:00):
    whether ET can be fitted as one model quantity on every log."""
    from roastlab.io.importers.artisan import read_alog

    lines += [
        "### Skywalker: what ET measures, log by log",
        "",
        "| log | ET - BT, median 1:00-DROP [°C] | at 4:00 [°C] |",
        "|---|---|---|",
    ]
    from roastlab.metrics.profile import et_minus_bt_C

    medians = []
    for path in paths:
        log = read_alog(path)
        t, et, bt = log.time_s, log.channels["ET"], log.channels["BT"]
        med = et_minus_bt_C(t, et, bt, log.events.get("DROP"))
        i = int(np.searchsorted(t, 240.0))
        medians.append(med)
        lines.append(f"| {path.stem} | {med:+.1f} | {et[i] - bt[i]:+.1f} |")
    below = sum(m < 0 for m in medians)
    lines += [
        "",
        f"ET reads below BT through the roast on {below} of {len(medians)} logs and above it on the others: "
        "the channel does not measure the same thing on every log. The example's map (`[ET] above_BT = true`) "
        "drops ET on the logs where it reads below BT.",
        "",
    ]
    drum_at_charge(paths, lines)


STEADY_C = 2.5  # a reading that moves less than this over the minute before CHARGE is steady [degC]
PROBE_FAULT_C = 300.0  # no empty preheated drum reads this; a probe fault does (R55's BT before CHARGE) [degC]


def drum_at_charge(paths, lines, before_s: float = 60.0):
    """How far BT and ET move over the last ``before_s`` before CHARGE on each Skywalker log (the
    preheated empty drum): which reading at CHARGE can stand for the drum's temperature then
    (roastlab.io.importers.artisan.DRUM_AT_CHARGE)."""
    from roastlab.io.importers.artisan import DRUM_AT_CHARGE, read_alog

    lines += [
        f"### Skywalker: the drum at CHARGE (the map reads {DRUM_AT_CHARGE[0]} then)",
        "",
        f"| log | BT at CHARGE [°C] | its range over the {before_s:g} s before [°C] | ET at CHARGE [°C] "
        f"| its range over the {before_s:g} s before [°C] |",
        "|---|---|---|---|---|",
    ]
    spans = {"BT": [], "ET": []}
    for path in paths:
        log = read_alog(path, align_charge=False)
        t, c = log.time_s, log.charge_index
        before = (t >= t[c] - before_s) & (t <= t[c])
        row = [path.stem]
        for name in ("BT", "ET"):
            v = log.channels[name][before]
            v = v[np.isfinite(v) & (v < PROBE_FAULT_C)]
            spans[name].append(float(np.ptp(v)) if len(v) else np.nan)
            row += [f"{log.channels[name][c]:.1f}", f"{spans[name][-1]:.1f}"]
        lines.append("| " + " | ".join(row) + " |")
    bt, et = np.array(spans["BT"]), np.array(spans["ET"])
    lines += [
        "",
        f"Over the {before_s:g} s before CHARGE, BT moves by a median {np.nanmedian(bt):.1f} °C (more than "
        f"{STEADY_C:g} °C on {int(np.sum(bt > STEADY_C))} of {len(bt)} logs) and ET by a median "
        f"{np.nanmedian(et):.1f} °C, up to {np.nanmax(et):.1f} °C: BT, the probe soaked in the empty preheated "
        "drum, is steady when the beans go in, while ET's reading at CHARGE depends on the second the button "
        "was pressed.",
        "",
    ]


def main() -> int:
    if not DATA.is_dir():
        print(f"{DATA}: real logs not found (../shared/data/real beside the repository)", file=sys.stderr)
        return 2
    lines = ["<!-- generated by docs/real_roaster.py (make real-roaster); do not edit by hand -->", ""]
    sky = skywalker_logs()
    machine("Skywalker (heater and fan settings, shell loss)", ROOT / "examples" / "skywalker", sky, lines)
    skywalker_et(sky, lines)
    bullet, nominal = bullet_logs(), nominal_logs()
    model, column_map, val = machine(
        f"Aillio Bullet R1, {NOMINAL} batches", ROOT / "examples" / "bullet", nominal, lines
    )
    scaling(model, column_map, bullet, val, lines)
    drum_start(model, column_map, bullet, lines)
    variants_and_bands(column_map, bullet, lines)
    spread_against_refits(column_map, bullet, lines)
    (DOCS / "real-roaster-results.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("wrote docs/real-roaster-results.md, docs/real-roaster-scaling.png", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
