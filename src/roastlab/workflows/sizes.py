"""The paper's scaling claim on a roaster's own logs: fitted at one batch size, every other size
predicted with nothing refitted (``roastlab fit-roaster --by-size``).

The paper (section 3.1, eqs. 7-11) derives the batch's areas and masses from its green weight and
keeps the machine's parameters, so a model identified at one batch size should predict another as
well as it predicts held-out roasts of its own size. The test, as issue 25 sets it for the Aillio
Bullet (docs/real-roaster.md, "Batch-size scaling on the Bullet"):

* the logs are grouped by green weight (:func:`roastlab.workflows.compare.size_groups`, the
  grouping leave-one-size-out uses);
* the fit size is the group with the most logs (the roaster's usual batch; a tie goes to the
  heavier group) or the one a user names; its logs, in the order given (fit-roaster's: by when they
  were roasted), are split alternately: the 1st, 3rd, ... fit, the 2nd, 4th, ... are the reference,
  held out;
* the model fitted on that half predicts the reference and every log of another size; each other
  size's mean FIT is set against the reference's, the gap with its 90 % interval over the logs
  (:func:`roastlab.evaluate.metrics.mean_gap`), and each log's share inside the 90 % prediction
  band (:func:`roastlab.evaluate.bands.band_report`).

A gap inside the reference's own spread is the claim holding on this machine; a gap beyond it says
by how much the batch size carries over worse than a new roast of the fit's size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class SizeSplit:
    """Which logs (indices into the batches) fit, are the reference, and are of other sizes."""

    labels: list[str]  # each batch's size group, "0.49-0.5 kg"
    fit_size: str  # the fit size's label
    fit: list[int]
    reference: list[int]
    others: list[int]
    named: bool = False  # the fit size was named (``fit_size_kg``), not the one with the most logs


def size_split(batches, fit_size_kg: float | None = None) -> SizeSplit:
    """Choose the fit size and split the logs (module docstring). :class:`~roastlab.errors.InputError`
    (one line) when the logs are all one size, none is of ``fit_size_kg``, or the fit size has fewer
    than two logs (one to fit, one to hold out)."""
    from ..evaluate.metrics import size_key
    from .compare import size_groups

    labels, step = size_groups(batches)
    sizes = sorted(set(labels), key=lambda lab: min(b.Mb_kg for b, x in zip(batches, labels) if x == lab))
    if len(sizes) < 2:
        raise InputError(
            f"the logs are all one batch size ({sizes[0]}): nothing to predict across sizes; give logs of "
            "other green weights",
            "--by-size",
        )
    if fit_size_kg is None:  # the most logs; a tie to the heavier size (the roaster's nominal batch, more often)
        fit_size = max(sizes, key=lambda lab: (labels.count(lab), sizes.index(lab)))
    else:
        key = size_key(fit_size_kg, step)
        chosen = [lab for b, lab in zip(batches, labels) if size_key(b.Mb_kg, step) == key]
        if not chosen:
            raise InputError(
                f"no log of {fit_size_kg:g} kg (the logs' batch sizes: {', '.join(sizes)})", "--fit-size-kg"
            )
        fit_size = chosen[0]
    members = [k for k, lab in enumerate(labels) if lab == fit_size]
    if len(members) < 2:
        raise InputError(
            f"only one log of {fit_size}: the fit size needs two, one to fit and one to hold out "
            f"(the logs' batch sizes: {', '.join(f'{s} ({labels.count(s)})' for s in sizes)})",
            "--fit-size-kg" if fit_size_kg is not None else "--by-size",
        )
    others = [k for k, lab in enumerate(labels) if lab != fit_size]
    return SizeSplit(labels, fit_size, members[0::2], members[1::2], others, fit_size_kg is not None)


def across_sizes(model, batches, split: SizeSplit) -> dict:
    """How ``model`` (fitted on ``split.fit``) predicts the reference and every other size:
    ``{"fit_size", "fit_size_named", "fit_logs", "reference": {"logs", "FIT", "MAE", "MPE", "inside"},
    "sizes": [{"size", "logs", "FIT", "MAE", "MPE", "inside", "FIT_beans", "gap"}, ...] (lightest first),
    "others": {... the same over every other log, "gap"}, "by_roaster": {"fit_roasters", "own": {...
    the fit's roaster's other sizes}, "other_roasters": {...}} or None (only where the logs name
    roasters and the other sizes come from both), "rows": [per log: "name", "size", "unit",
    "Mb_kg", "FIT", "MAE", "MPE", "inside", "reference", "FIT_beans"], "band_level"}``. ``inside`` is
    the share of the probe's samples inside the 90 % band (NaN when the model file carries no band);
    ``FIT_beans`` the model's bean temperature against a second bean reading (an infrared sensor; NaN
    where the log has none), which judges the beans without the probe's model; a
    ``gap`` is :func:`roastlab.evaluate.metrics.mean_gap` of the logs' FIT against the reference's."""
    from ..evaluate.bands import BAND_LEVEL, held_out_band, share_inside
    from ..evaluate.metrics import mean_gap

    order = split.reference + split.others
    chosen = [batches[k] for k in order]
    validation = model.validate(chosen)
    band, _ = held_out_band(model, chosen)
    band_rows = band["batches"] if band else None
    second = validation.outputs.get("Tb2", {})  # the model's beans against a second bean reading (an IR)
    beans = dict(zip(second.get("names", []), second.get("rows", [])))
    rows = []
    for j, k in enumerate(order):
        r = validation.rows[j]
        rows.append(
            {
                "name": validation.names[j],
                "size": split.labels[k],
                "unit": str(getattr(batches[k], "unit", "") or ""),
                "Mb_kg": float(batches[k].Mb_kg),
                "FIT": float(r["FIT"]),
                "MAE": float(r["MAE"]),
                "MPE": float(r["MPE"]),
                "n": int(band_rows[j]["n"]) if band_rows else 0,
                "inside": float(band_rows[j]["inside"]) if band_rows else math.nan,
                "reference": j < len(split.reference),
                "FIT_beans": float(beans[validation.names[j]]["FIT"]) if validation.names[j] in beans else math.nan,
            }
        )

    def summary(members: list[dict]) -> dict:
        out = {"logs": len(members)}
        for key in ("FIT", "MAE", "MPE"):
            out[key] = float(np.mean([m[key] for m in members]))
        out["inside"] = share_inside(members) if band_rows else math.nan
        read = [m["FIT_beans"] for m in members if math.isfinite(m["FIT_beans"])]
        out["FIT_beans"] = float(np.mean(read)) if read else math.nan
        return out

    reference = [r for r in rows if r["reference"]]
    other_rows = [r for r in rows if not r["reference"]]
    ref_fit = [r["FIT"] for r in reference]

    def group(members: list[dict]) -> dict:  # a group of other logs, with its gap to the reference
        return {**summary(members), "gap": mean_gap([m["FIT"] for m in members], ref_fit)}

    labels = dict.fromkeys(split.labels[k] for k in sorted(split.others, key=lambda k: batches[k].Mb_kg))
    sizes = [{"size": label, **group([r for r in other_rows if r["size"] == label])} for label in labels]
    # where the logs name their roasters and some other-size logs come from another one: the fit's own
    # roaster's other sizes apart from the other roasters' (a log of another drum tests two things at once)
    fit_units = sorted({str(getattr(batches[k], "unit", "") or "") for k in split.fit} - {""})
    own = [r for r in other_rows if r["unit"] in fit_units]
    foreign = [r for r in other_rows if r["unit"] not in fit_units]
    by_roaster = None
    if fit_units and own and foreign:
        by_roaster = {"fit_roasters": fit_units, "own": group(own), "other_roasters": group(foreign)}
    return {
        "fit_size": split.fit_size,
        "fit_size_named": split.named,
        "fit_logs": [batches[k].name for k in split.fit],
        "reference": summary(reference),
        "sizes": sizes,
        "others": group(other_rows),
        "by_roaster": by_roaster,
        "rows": rows,
        "band_level": BAND_LEVEL,
    }


def _logs(n: int) -> str:
    """``"1 log"``, ``"3 logs"``."""
    return f"{n} log" if n == 1 else f"{n} logs"


def gap_words(gap: dict) -> str:
    """A gap of :func:`roastlab.evaluate.metrics.mean_gap` in points, with its interval where known."""
    text = f"{gap['gap']:+.1f}"
    if math.isfinite(gap["low"]):
        text += f" ({100 * gap['level']:.0f} % interval {gap['low']:+.1f} to {gap['high']:+.1f})"
    return text


def across_sizes_sentence(res: dict) -> str:
    """The result in one line (the terminal's)."""
    o, ref, r = res["others"], res["reference"], res["by_roaster"]
    text = (
        f"fitted on {res['fit_size']} ({_logs(len(res['fit_logs']))}), every other size (FIT {o['FIT']:.1f} % over "
        f"{_logs(o['logs'])}) against the fit size's held-out logs ({ref['FIT']:.1f} % over {ref['logs']}): "
        f"{gap_words(o['gap'])} points"
    )
    if r:
        text += (
            f"; the fit's own roaster's other sizes {r['own']['FIT']:.1f} % (gap {r['own']['gap']['gap']:+.1f}), "
            f"other roasters' {r['other_roasters']['FIT']:.1f} % (gap {r['other_roasters']['gap']['gap']:+.1f})"
        )
    return text


def across_sizes_lines(res: dict, figure_name: str, units: str = "C") -> list[str]:
    """The report's section (Markdown lines), its MAE in ``units`` ("C" or "F")."""
    from ..metrics.profile import display_temp_delta, temp_symbol

    level = f"{100 * res['band_level']:.0f} %"
    has_band = math.isfinite(res["reference"]["inside"])
    has_beans = any(math.isfinite(r["FIT_beans"]) for r in res["rows"])
    units = sorted({r["unit"] for r in res["rows"]} - {""})

    def beans(x: float) -> str:
        return (f" {x:.1f} |" if math.isfinite(x) else " - |") if has_beans else ""

    def cells(s: dict) -> str:
        band = f" {100 * s['inside']:.0f} % |" if has_band else ""
        mae = display_temp_delta(s["MAE"], units)
        return f" {s['logs']} | {s['FIT']:.1f} | {mae:.2f} | {s['MPE']:+.2f} |{band}{beans(s['FIT_beans'])}"

    ref = res["reference"]
    lines = [
        "",
        "## Across batch sizes",
        "",
        f"The model fitted on {_logs(len(res['fit_logs']))} of {res['fit_size']} alone "
        f"({'the size named' if res['fit_size_named'] else 'the size with the most logs'}, split alternately: the "
        f"1st, 3rd, ... fit) predicts the other {_logs(ref['logs'])} of that size and "
        "every log of another size with nothing refitted: each batch's areas and masses scale with its green "
        "weight (the paper's section 3.1), the machine's parameters are the fit's. A size predicted about as "
        "well as the held-out logs of the fit's size is the paper's claim holding on this roaster. Signed "
        "error (MPE) positive where the model reads low."
        + (
            " Where the logs have a second bean reading (an infrared sensor), the model's beans against it "
            "judge the beans without the probe's model."
            if has_beans
            else ""
        ),
        "",
        f"| batch size | logs | FIT % | MAE {temp_symbol(units)} | signed error % |{f' inside the {level} band |' if has_band else ''}"
        f"{' beans vs the second reading, FIT % |' if has_beans else ''} gap to the held-out fit size, FIT points |",
        f"|---|---|---|---|---|{'---|' if has_band else ''}{'---|' if has_beans else ''}---|",
        f"| {res['fit_size']}, held out |{cells(ref)} |",
    ]
    lines += [f"| {s['size']} |{cells(s)} {gap_words(s['gap'])} |" for s in res["sizes"]]
    lines.append(f"| **every other size** |{cells(res['others'])} **{gap_words(res['others']['gap'])}** |")
    r = res["by_roaster"]
    if r:
        own = f"roaster {r['fit_roasters'][0]}" if len(r["fit_roasters"]) == 1 else "roasters"
        lines += [
            f"| other sizes, the fit's own {own} |{cells(r['own'])} {gap_words(r['own']['gap'])} |",
            f"| other sizes, other roasters |{cells(r['other_roasters'])} {gap_words(r['other_roasters']['gap'])} |",
        ]
    lines += [
        "",
        "A gap's interval is Welch's t over the logs' FIT (`roastlab.evaluate.metrics.mean_gap`): a size of one "
        "or two roasts cannot pin it.",
        "",
        f"| log | batch | {'roaster | ' if len(units) > 1 else ''}FIT % | signed error % |"
        f"{' inside the band |' if has_band else ''}{' beans vs the second reading, FIT % |' if has_beans else ''}",
        f"|---|---|{'---|' if len(units) > 1 else ''}---|---|{'---|' if has_band else ''}{'---|' if has_beans else ''}",
    ]
    for r in sorted(res["rows"], key=lambda r: (r["Mb_kg"], r["name"])):
        who = f" {r['unit'] or '-'} |" if len(units) > 1 else ""
        band = f" {100 * r['inside']:.0f} % |" if has_band else ""
        mark = " (held out, fit size)" if r["reference"] else ""
        lines.append(
            f"| {r['name']}{mark} | {1000 * r['Mb_kg']:.0f} g |{who} {r['FIT']:.1f} | {r['MPE']:+.2f} |{band}"
            f"{beans(r['FIT_beans'])}"
        )
    if len(units) > 1:
        lines += [
            "",
            f"The logs come from {len(units)} roasters ({', '.join(units)}): a log of another roaster tests the "
            "batch size and another drum at once.",
        ]
    lines += ["", f"![FIT by batch size]({figure_name})"]
    return lines


def across_sizes_figure(res: dict, title: str | None = None):
    """Each log's FIT against its green weight: the fit size's held-out logs, the other sizes (one
    marker per roaster when the logs name several), the held-out logs' mean as a line."""
    from ..report.figures import new_figure

    fig = new_figure(figsize=(9.0, 4.2))
    ax = fig.add_subplot()
    rows = res["rows"]
    units = sorted({r["unit"] for r in rows} - {""})
    markers = "osD^v<>ph*"
    ref = [r for r in rows if r["reference"]]
    ax.scatter([1000 * r["Mb_kg"] for r in ref], [r["FIT"] for r in ref], color="C0", marker="o",
               label=f"{res['fit_size']}, held out")  # fmt: skip
    others = [r for r in rows if not r["reference"]]
    groups = [(u, [r for r in others if r["unit"] == u]) for u in units] if len(units) > 1 else [("", others)]
    for j, (u, members) in enumerate(groups):
        if members:
            ax.scatter([1000 * r["Mb_kg"] for r in members], [r["FIT"] for r in members], color="C1",
                       marker=markers[j % len(markers)], label=f"other sizes{f', roaster {u}' if u else ''}")  # fmt: skip
    mean = res["reference"]["FIT"]
    ax.axhline(mean, color="C0", ls="--", lw=1, label=f"held-out mean {mean:.1f} %")
    ax.axhline(res["others"]["FIT"], color="C1", ls=":", lw=1, label=f"other sizes' mean {res['others']['FIT']:.1f} %")
    low = min(r["FIT"] for r in rows)
    ax.set_ylim(min(low - 5, 50), 100)
    ax.set_xlabel("green batch [g]")
    ax.set_ylabel("probe FIT [%] (model fitted on the fit size)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax.set_title(title or f"Fitted on {res['fit_size']}: every other batch size predicted")
    fig.tight_layout()
    return fig
