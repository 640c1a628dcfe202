"""Figures in a roaster's words: BT/ET curves (model names beside), rate of rise, residuals.

Figures are plain :class:`matplotlib.figure.Figure` objects, never registered with pyplot,
so a notebook shows each once. Saving goes through the output guard (:mod:`roastlab.io.files`).
"""

from __future__ import annotations

import io
import types
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io.files import Outputs
from ..metrics.profile import ROR_SPAN_S, implausible_states, mmss, rate_of_rise_C_per_min, turning_point
from ..model.constants import FIRST_CRACK_BEAN_C
from ..model.layout import S_TB, S_TM
from ..model.parameters import REGISTRY

#: Image formats a figure may be saved as (by the file suffix).
FIGURE_FORMATS = ("png", "svg", "pdf")


def check_figure_path(path) -> Path:
    """Refuse a figure path whose suffix is not an image format we write (before any output)."""
    path = Path(path)
    fmt = path.suffix.lstrip(".").lower()
    if fmt not in FIGURE_FORMATS:
        raise InputError(f"unknown figure format {path.suffix or '(none)'!r} (use .png, .svg or .pdf)", path)
    return path


def new_figure(**kwargs):
    """A Figure not registered with pyplot (no double display in Jupyter)."""
    from matplotlib.figure import Figure

    return Figure(**kwargs)


def figure_bytes(fig, path) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format=check_figure_path(path).suffix.lstrip(".").lower(), dpi=120, bbox_inches="tight")
    return buf.getvalue()


def save_figure(fig, path, outputs: Outputs | None = None) -> None:
    """Save a figure by suffix (PNG/SVG/PDF), into ``outputs`` if given, else atomically now."""
    data = figure_bytes(fig, path)
    if outputs is not None:
        outputs.write_bytes(path, data)
    else:
        with Outputs() as out:
            out.write_bytes(path, data)


def room_for_legend(*axes, share: float = 0.45) -> None:
    """Raise each of ``axes``' top by ``share`` of its height, so that a legend in the upper corner sits
    above the curves, not over them (settings panels whose steps run the panel's whole width)."""
    for ax in {id(a): a for a in axes}.values():
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo, hi + share * (hi - lo))


def finish_figure(fig, path, title, outputs=None):
    if title:
        fig.suptitle(title)
    if path is not None:
        save_figure(fig, path, outputs)
    return fig


def _events(ax, events: dict | None, color="0.55") -> None:
    """Event marks (CHARGE, DRY, FCs, DROP ...) as labelled vertical lines, Artisan-style; labels
    of marks closer than ~a fifth of a minute-axis tick alternate in height so they never overlap."""
    marks = sorted((t, name) for name, t in (events or {}).items() if t is not None and np.isfinite(t))
    lo, hi = ax.get_xlim() if ax.has_data() else (0.0, 1.0)
    span = max(hi - lo, 1e-9)
    last_x, level = -np.inf, 0
    for t, name in marks:
        x = t / 60.0
        if ax.has_data() and not lo - 0.02 * span <= x <= hi + 0.02 * span:
            continue  # well past the curves (COOL after DROP): a label there would sit outside the axes
        level = (level + 1) % 3 if x - last_x < 0.06 * span else 0
        ax.axvline(x, color=color, lw=0.8, ls=":")
        right = x > lo + 0.88 * span  # a mark near the right edge is labelled on its left
        ax.annotate(
            f"{name} {mmss(t)}",
            (x, 1.0 - 0.09 * level),
            xycoords=("data", "axes fraction"),
            fontsize=7,
            va="top",
            ha="right" if right else "left",
            xytext=(-2 if right else 2, -2),
            textcoords="offset points",
            color="0.3",
        )
        last_x = x


def time_axis(ax, label: str = "time after CHARGE [m:ss]") -> None:
    """The roaster's time axis: data in minutes, ticks written m:ss."""
    from matplotlib.ticker import FuncFormatter, MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(nbins=8, steps=[1, 2, 5, 10], integer=True))  # whole minutes
    ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: mmss(60.0 * x)))
    ax.set_xlabel(label)


def ror_limits(ax, time_s, *curves) -> None:
    """Clip a rate-of-rise axis [degC/min] to the roast's range after the turning point, so the
    charge drop (-100 degC/min and below) does not flatten the curves that matter. A curve on times of
    its own (a what-if dropped elsewhere) is given as ``(times, curve)``."""
    vals = []
    for bt in curves:
        t = np.asarray(time_s, dtype=float)
        if isinstance(bt, tuple):
            t, bt = np.asarray(bt[0], dtype=float), bt[1]
        if bt is None:
            continue
        tp_s, _ = turning_point(t, bt)
        ror = rate_of_rise_C_per_min(t, bt)
        after = (t >= (tp_s or 0.0) + ROR_SPAN_S) & np.isfinite(ror)
        vals.append(ror[after])
    v = np.concatenate(vals) if vals else np.array([])
    if v.size:
        top = float(np.percentile(v, 99))
        bottom = float(np.percentile(v, 1))
        ax.set_ylim(min(0.0, bottom) - 2.0, max(top, 5.0) * 1.15 + 1.0)


def temperature_axis(ax, label: str, units: str = "C", delta: bool = False, side: str = "left"):
    """Label ``ax``, whose curves are in degC, as ``label`` with ``{u}`` its unit; in "F" a Fahrenheit
    scale of its own (round degF ticks, :func:`~roastlab.metrics.profile.display_temp`) takes the
    place of the Celsius one, so every curve stays drawn from the same degC numbers. ``delta``: the
    axis holds differences or rates (degC/min), which convert without the 32 degF offset. ``side``:
    where the scale stands ("right" for a twin axis's, as a rate of rise's). Returns the axis that
    carries the scale (``ax`` itself in degC), for its ticks' style."""
    from ..metrics.profile import celsius_delta_of, celsius_of, display_temp, display_temp_delta, temp_symbol

    if units != "F":
        ax.set_ylabel(label.format(u=temp_symbol(units)))
        return ax

    there, back = (display_temp_delta, celsius_delta_of) if delta else (display_temp, celsius_of)
    scale = ax.secondary_yaxis(side, functions=(lambda v: there(v, "F"), lambda v: back(v, "F")))
    ax.tick_params(axis="y", **{side: False, f"label{side}": False})
    scale.set_ylabel(label.format(u=temp_symbol(units)))
    return scale


def _shade_band(ax, band, color: str, what: str) -> None:
    """A :class:`~roastlab.evaluate.bands.Band` shaded on ``ax`` (minutes), labelled "90 % ``what``"."""
    ax.fill_between(band.time_s / 60.0, band.lower_C, band.upper_C, color=color, alpha=0.15, lw=0,
                    label=f"{band.level * 100:g} % {what}")  # fmt: skip


def plot_simulation(result, path=None, title=None, outputs=None, events=None):
    """Four panels: temperatures (BT/ET and the model's states), rate of rise, moisture, heat flows."""
    fig = new_figure(figsize=(8.5, 10), layout="constrained")
    axes = fig.subplots(4, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.3, 1.1, 1.4]})
    t_min = result.time_s / 60.0
    ax = axes[0]
    ax.plot(t_min, result.Ta_C, label="BT predicted (model Ta, probe)", color="tab:orange", lw=2)
    if result.band is not None:
        _shade_band(ax, result.band, "tab:orange", "prediction band")
    if result.Ta_measured_C is not None:
        ax.plot(t_min, result.Ta_measured_C, "k.", ms=3, label="BT measured (log)")
    if result.ET_measured_C is not None:
        ax.plot(t_min, result.ET_measured_C, ".", ms=2, color="tab:purple", label="ET measured (log)")
    ax.plot(t_min, result.Tb_C, label="bean core (model Tb)", color="tab:brown")
    ax.plot(t_min, result.Tm_C, label="drum metal (model Tm)", color="tab:gray")
    _, tgi_seen = result.gas_seen()
    ax.plot(t_min, tgi_seen, "--", label="inlet gas the model sees (Tgi, heater included)", color="tab:red")
    ax.plot(t_min, result.Tgo_C, ":", label="outlet gas (model Tgo)", color="tab:red")
    ax.set_ylabel("temperature [°C]")
    ax.legend(fontsize=7, ncol=2, loc="lower right")
    ax.grid(alpha=0.3)
    ax.set_xlim(t_min[0], t_min[-1])
    _events(ax, events)
    for warning in implausible_states(result):
        import textwrap

        note = ax.text(
            0.01,
            0.98,
            textwrap.fill("warning: " + warning, 95),
            transform=ax.transAxes,
            fontsize=7,
            color="tab:red",
            va="top",
            bbox={"facecolor": "white", "alpha": 0.8, "lw": 0},
        )
        note.set_in_layout(False)
    ror = axes[1]
    ror.plot(t_min, rate_of_rise_C_per_min(result.time_s, result.Ta_C), color="tab:orange", label="RoR predicted")
    if result.Ta_measured_C is not None:
        ror.plot(t_min, rate_of_rise_C_per_min(result.time_s, result.Ta_measured_C), "k-", lw=0.8, label="RoR measured")
    ror_limits(ror, result.time_s, result.Ta_C, result.Ta_measured_C)
    ror.set_ylabel(f"BT rate of rise\n[°C/min, {ROR_SPAN_S:g} s]")
    ror.legend(fontsize=7)
    ror.grid(alpha=0.3)
    axes[2].plot(t_min, result.X_kg_kg, color="tab:blue")
    axes[2].set_ylabel("moisture X\n[kg/kg dry]")
    axes[2].grid(alpha=0.3)
    q = result.heat_flows()
    labels = {
        "Qgb_kW": "Qgb gas→beans+drum",
        "Qgm_kW": "Qgm gas→drum",
        "Qbm_kW": "Qbm drum→beans",
        "Qr_kW": "Qr roast reaction",
    }
    for key, style in (("Qgb_kW", "-"), ("Qgm_kW", "--"), ("Qbm_kW", "-."), ("Qr_kW", ":")):
        axes[3].plot(t_min, q[key], style, label=labels[key])
    axes[3].set_ylabel("heat flow [kW]")
    time_axis(axes[3])
    axes[3].legend(fontsize=7, ncol=2)
    axes[3].grid(alpha=0.3)
    return finish_figure(fig, path, title, outputs)


def plot_fit(result, path=None, title=None, max_panels: int = 8, outputs=None, bands=None, units: str = "C",
             which=None, labels=None):  # fmt: skip
    """Measured vs predicted BT per batch of a ValidationResult, each with its residual below;
    ``bands`` (:func:`roastlab.evaluate.bands.prediction_bands`, one per batch) shaded; the
    temperatures' scales and each panel's MAE in ``units`` ("C" or "F"; the curves are degC).
    ``which``: ``(positions, why)``, the batches to draw in that order and what chose them (the title
    says it when they are not all), else the first ``max_panels``; ``labels``: a panel's title by position,
    in place of the batch's name."""
    shown, why = which if which is not None else (list(range(len(result.names))), "first")
    shown = list(shown)[:max_panels]
    k = len(shown)
    cols = 2 if k > 1 else 1
    rows = (k + cols - 1) // cols
    fig = new_figure(figsize=(6.5 * cols, 4.6 * rows), layout="constrained")
    grid = fig.add_gridspec(rows * 2, cols, height_ratios=[3, 1] * rows)
    entries = {}  # one legend for all panels, below them: in a panel it covered the curves' ends or the RoR's peak
    for at, i in enumerate(shown):
        r, c = divmod(at, cols)
        ax = fig.add_subplot(grid[2 * r, c])
        res = fig.add_subplot(grid[2 * r + 1, c], sharex=ax)
        _profile_panel(ax, result, i, label=(labels or {}).get(i), legend=False, units=units)
        if bands is not None:
            _shade_band(ax, bands[i], "tab:green", "prediction band")
        t = result.time_s[i] / 60.0
        res.plot(
            t,
            result.measured[i] - result.predicted[i],
            color="tab:purple",
            lw=1,
            label="residual BT meas − pred (below)",
        )
        sim = result.results[i] if i < len(result.results) else None
        # named and drawn as the page and the what-if figure do: a curve, or the first-crack mark as a marker
        reading = None if sim is None else second_bean_reading(_readings_of(sim), units)
        if reading is not None:  # the second bean reading and the model's Tb
            label, few = reading
            second = sim.Tb2_measured_C
            ax.plot(t, sim.Tb_C, color="tab:orange", lw=1.2, label="bean predicted (model Tb)")
            style = {"ls": "none", "marker": "D", "ms": 6, "mfc": "none"} if few else {"ls": ":", "lw": 1.6}
            ax.plot(t, second, color="tab:brown", label=label, **style)
            res.plot(t, second - sim.Tb_C, color="tab:brown", label="residual beans meas − model Tb (below)",
                     **({"ls": "none", "marker": "D", "ms": 5, "mfc": "none"} if few else {"ls": ":", "lw": 1}))  # fmt: skip
        for h, text in zip(*_ror_overlay(ax, result.time_s[i], result.measured[i], result.predicted[i], units)):
            entries.setdefault(text, h)  # every panel draws the same curves; a second bean reading on some
        if reading is not None:  # its residual beside BT's, which the axis names
            for h, text in zip(*res.get_legend_handles_labels()):
                entries.setdefault(text, h)
        res.axhline(0.0, color="k", lw=0.6)
        temperature_axis(res, "residual\nBT meas − pred [{u}]", units, delta=True).yaxis.label.set_fontsize(8)
        time_axis(res)
        res.grid(alpha=0.3)
    if entries:
        fig.legend(list(entries.values()), list(entries), loc="outside lower center", ncol=4, fontsize=8)
    if len(result.names) > k:
        title = f"{title or ''} ({why} {k} of {len(result.names)} batches)".strip()
    return finish_figure(fig, path, title, outputs)


def _ror_overlay(ax, time_s, measured, predicted, units: str = "C") -> tuple[list, list]:
    """Measured and predicted rate of rise [degC/min] on a right-hand axis of a BT panel, as
    Artisan draws it (the one RoR definition; the axis clipped past the charge drop), its scale in
    ``units``. Returns the handles and labels of both axes, for one legend."""
    ror = ax.twinx()
    t = np.asarray(time_s, dtype=float)
    ror.plot(t / 60.0, rate_of_rise_C_per_min(t, predicted), color="tab:blue", lw=1.0, alpha=0.8,
             label="RoR predicted")  # fmt: skip
    ror.plot(t / 60.0, rate_of_rise_C_per_min(t, measured), ":", color="tab:blue", lw=1.2, label="RoR measured")
    ror_limits(ror, t, measured, predicted)
    scale = temperature_axis(ror, "RoR [{u}/min]", units, delta=True, side="right")
    scale.yaxis.label.set(color="tab:blue", fontsize=8)
    scale.tick_params(axis="y", labelcolor="tab:blue", labelsize=8)
    # the BT axis drawn above the RoR axis, its curves over the RoR's
    handles, labels = ax.get_legend_handles_labels()
    more, more_labels = ror.get_legend_handles_labels()
    ax.set_zorder(ror.get_zorder() + 1)
    ax.patch.set_visible(False)
    return handles + more, labels + more_labels


def _profile_panel(ax, result, i, label=None, legend: bool = True, units: str = "C"):
    from ..metrics.profile import delta_text

    t = result.time_s[i] / 60.0
    row = result.rows[i]
    ax.plot(t, result.predicted[i], color="tab:green", lw=2, label="BT predicted (model Ta)")
    ax.plot(t, result.measured[i], "--", color="tab:pink", lw=2, label="BT measured (Ta)")
    mae = delta_text(row["MAE"], units, 2)
    ax.set_title(f"{label or result.names[i]}: FIT {row['FIT']:.1f} %, MAE {mae}", fontsize=10)
    temperature_axis(ax, "BT [{u}]", units)
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=8)


def plot_fig2(ident, valid, path, note="synthetic data", outputs=None):
    """Paper Fig. 2: worst (left) and best (right) batch by FIT of each dataset."""
    fig = new_figure(figsize=(12, 7.5), layout="constrained")
    axes = fig.subplots(2, 2)
    for r, (res, label) in enumerate(((ident, "dataset-I"), (valid, "dataset-V"))):
        fits = [row["FIT"] for row in res.rows]
        worst, best = int(np.argmin(fits)), int(np.argmax(fits))
        left, right = ("a", "b") if r == 0 else ("c", "d")
        _profile_panel(axes[r][0], res, worst, f"{left}) {label} {res.names[worst]} (worst)")
        _profile_panel(axes[r][1], res, best, f"{right}) {label} {res.names[best]} (best)")
        for ax in axes[r]:
            ax.set_xlabel("time [min]")
    return finish_figure(fig, path, f"Temperature profiles, measured vs simulated ({note})", outputs)


def plot_fig3(ident, valid, path, note="synthetic data", outputs=None):
    """Paper Fig. 3: distribution of the absolute prediction error per dataset."""
    from matplotlib.lines import Line2D

    fig = new_figure(figsize=(7.5, 4.8), layout="constrained")
    ax = fig.subplots()
    data = [np.abs(np.concatenate(ident.errors)), np.abs(np.concatenate(valid.errors))]
    parts = ax.violinplot(data, showmeans=True, showextrema=True)
    for body in parts["bodies"]:
        body.set_alpha(0.4)
    ax.boxplot(data, widths=0.12)
    ax.set_xticks([1, 2], [f"identification\n(dataset-I, {ident.plant})", f"validation\n(dataset-V, {valid.plant})"])
    ax.set_ylabel("absolute error |Ta − T̂a| [°C]")
    for x, d in zip((1, 2), data):
        ax.annotate(f"mean {d.mean():.2f}\nvar {d.var(ddof=1):.2f}", (x + 0.18, d.mean()), fontsize=8)
    handles = [
        Line2D([], [], color="tab:blue", alpha=0.6, lw=6, label="distribution (violin), whiskers: min/max"),
        Line2D([], [], color="tab:blue", lw=1.5, label="mean (violin's middle bar)"),
        Line2D([], [], color="tab:orange", lw=1.5, label="median (box's orange line), box: quartiles"),
    ]
    ax.legend(handles=handles, fontsize=7, loc="upper right")
    ax.set_title(f"Absolute error distribution ({note})")
    ax.grid(alpha=0.3, axis="y")
    return finish_figure(fig, path, None, outputs)


def setting_axis_label(name: str, unit: str) -> str:
    """A setting's axis label in the unit it is logged in: "heater [%]", "fan [kPa]", "heater [level]"
    (also a level shown in tens), "heater (as logged)" for a reading whose unit nobody named."""
    if unit == "reading":
        return f"{name} (as logged)"
    return f"{name} [{ {'percent': '%', 'tens': 'level x10'}.get(unit, unit) }]"


def _readings_of(sim):
    """A simulated batch's measured second bean reading and events as :func:`second_bean_reading` reads
    a batch's."""
    return types.SimpleNamespace(Tb2_C=sim.Tb2_measured_C, events=(getattr(sim, "meta", None) or {}).get("events", {}))


def second_bean_reading(b, units: str = "C") -> tuple[str, bool] | None:
    """How a batch's second bean reading is named on a figure or the page: ``(label, few)``, ``few``
    where it is a few readings (drawn as markers that stand out), or None where it has none. A curve
    of readings (the Bullet's IR) is "beans measured (second reading)"; the first-crack mark read as
    the beans (a map's ``[Tb2] first_crack``) says so, its temperature in ``units`` ("C" or "F")."""
    from ..metrics.profile import display_temp, temp_symbol

    marked = np.isfinite(b.Tb2_C) if b.Tb2_C is not None else np.zeros(0, dtype=bool)
    if not marked.any():
        return None
    if np.count_nonzero(marked) > 3:
        return "beans measured (second reading)", False
    at_crack = np.all(b.Tb2_C[marked] == FIRST_CRACK_BEAN_C) and "FCs" in b.events
    crack = f"{display_temp(FIRST_CRACK_BEAN_C, units):g} {temp_symbol(units)}"
    return (f"beans at first crack ({crack}, the FCs mark)" if at_crack else "beans measured"), True


def plot_whatif(w, path=None, outputs=None, units: str = "C"):
    """Artisan-style: measured BT, the model's probe BT and bean temperature as run and with the
    changes, the log's event marks; below, BT's rate of rise (clipped to the roast after the
    turning point); bottom, the settings as run and changed. Times in m:ss, temperatures in
    ``units`` ("C" or "F", :func:`temperature_axis`).

    ``w`` is a :class:`roastlab.workflows.whatif.WhatIf`.
    """
    b = w.batch
    t = b.time_s
    t_min = t / 60.0
    tc = w.changed.time_s  # the changed roast's own times: it may drop elsewhere (--drop-at, --drop-bt)
    tc_min = tc / 60.0
    fig = new_figure(figsize=(9, 8.5), layout="constrained")
    ax, ax_r, ax2 = fig.subplots(3, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.3, 1.1]})
    if b.Ta_C is not None:
        ax.plot(t_min, b.Ta_C, ".", ms=3, color="0.3", label="BT measured (probe)")
    if (reading := second_bean_reading(b, units)) is not None:
        label, few = reading
        marked = np.isfinite(b.Tb2_C)
        if few:  # the first-crack mark read as the beans: a marker that stands out
            ax.plot(t_min[marked], b.Tb2_C[marked], "D", ms=6, mfc="none", color="tab:brown", label=label)
        else:
            ax.plot(t_min, b.Tb2_C, ".", ms=2, color="tab:brown", alpha=0.5, label=label)
    if b.ET_C is not None:
        ax.plot(t_min, b.ET_C, ".", ms=2, color="tab:purple", alpha=0.6, label="ET measured (log)")
    change = "; ".join(w.changes) or "no change"
    ax.plot(t_min, w.as_run.Ta_C, color="tab:blue", lw=1.8, label="BT model, as run")
    ax.plot(tc_min, w.changed.Ta_C, color="tab:orange", lw=1.8, label=f"BT model, {change}")
    if w.band is not None:
        _shade_band(ax, w.band, "tab:orange", "band, changed")
    ax.plot(t_min, w.as_run.Tb_C, color="tab:blue", lw=1.0, ls="--", label="beans model (Tb), as run")
    ax.plot(tc_min, w.changed.Tb_C, color="tab:orange", lw=1.0, ls="--", label="beans model (Tb), changed")
    temperature_axis(ax, "temperature [{u}]", units)
    ax.legend(loc="lower right", fontsize=7)
    ax.grid(alpha=0.3)
    ax.set_xlim(min(t_min[0], tc_min[0]), max(t_min[-1], tc_min[-1]))
    marks = dict(b.events)
    if w.drop_s is not None:  # the changed roast's own DROP; the log's marks after its DROP (COOL) are no roast's
        marks = {k: v for k, v in marks.items() if v is not None and v <= t[-1] + 5.0} | {"DROP changed": w.drop_s}
    _events(ax, marks)
    for tt, bt, color, label in (
        (t, b.Ta_C, "0.3", "measured"),
        (t, w.as_run.Ta_C, "tab:blue", "as run"),
        (tc, w.changed.Ta_C, "tab:orange", "changed"),
    ):
        if bt is not None:
            ax_r.plot(tt / 60.0, rate_of_rise_C_per_min(tt, bt), color=color, lw=1.0, label=f"BT RoR {label}")
    ror_limits(ax_r, t, b.Ta_C, w.as_run.Ta_C, (tc, w.changed.Ta_C))
    temperature_axis(ax_r, f"RoR [{{u}}/min]\n({ROR_SPAN_S:g} s)", units, delta=True)
    ax_r.legend(loc="upper right", fontsize=7, ncol=3)
    ax_r.grid(alpha=0.3)
    logged = [(n, c) for n, c in (("heater", "tab:red"), ("fan", "tab:green")) if getattr(b, n) is not None]
    units = {n: w.actuators[n].unit if n in w.actuators else "percent" for n, _ in logged}
    # settings in different units (a heater in kPa, a fan in %) each on its own scale: the fan on the right
    two = len(set(units.values())) > 1
    axes = {n: ax2 for n, _ in logged} | ({"fan": ax2.twinx()} if two else {})
    handles = []
    for name, color in logged:
        before, after, on = getattr(b, name), getattr(w.changed, name), axes[name]
        handles += on.step(t_min, before, where="post", color=color, lw=1.2, label=f"{name} as run")
        if after is not None and not (len(after) == len(before) and np.array_equal(after, before)):
            handles += on.step(tc_min, after, where="post", color=color, lw=1.2, ls="--", label=f"{name} changed")
    if two:
        ax2.set_ylabel(setting_axis_label("heater", units["heater"]), color="tab:red")
        axes["fan"].set_ylabel(setting_axis_label("fan", units["fan"]), color="tab:green")
    elif logged:
        ax2.set_ylabel(setting_axis_label("setting", next(iter(units.values()))))
    if not logged:
        handles += ax2.plot(t_min, w.as_run.Tgi_C, color="tab:red", label="inlet gas Tgi as run")
        handles += ax2.plot(tc_min, w.changed.Tgi_C, color="tab:red", ls="--", label="inlet gas Tgi changed")
        temperature_axis(ax2, "Tgi [{u}]", units)
    time_axis(ax2)
    room_for_legend(ax2, *axes.values())  # a fan at its top step ran under the legend
    ax2.legend(handles=handles, loc="upper right", fontsize=7, ncol=2, framealpha=0.9)
    ax2.grid(alpha=0.3)
    return finish_figure(fig, path, f"what if: {b.name}", outputs)


def plot_transfer(r, path=None, outputs=None):
    """Target vs predicted BT on plant B with the baselines; below, the program with its limits
    shaded and the baselines' inputs; bottom, the tracking error. Temperatures in ``r.units``
    (:func:`temperature_axis`; a Tgi program's axis stays in degC, as its limits are).

    ``r`` is a :class:`roastlab.workflows.transfer.TransferResult`.
    """
    from ..metrics.profile import delta_text

    units = r.units

    def d(v, digits: int = 1):  # an error in the figure's unit, with it
        return delta_text(v, units, digits)

    t_min = r.time_s / 60.0
    lim = r.limits
    fig = new_figure(figsize=(9, 8.5), layout="constrained")
    ax, ax2, ax3 = fig.subplots(3, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.6, 1]})
    ax.plot(t_min, r.target_C, color="0.2", lw=2.4, label=f"target BT ({r.reference} on {r.plant_from})")
    m = r.metrics
    ax.plot(
        t_min,
        r.program.Ta_pred_C,
        color="tab:blue",
        lw=1.6,
        label=f"predicted on {r.plant_to}, {'runnable' if 'runnable' in m else 'optimised'} program "
        f"(RMSE {d(m['rmse_C'], 2)})",
    )
    if r.band is not None:  # where a roast run with the program is expected (transfer --band)
        ax.fill_between(t_min, r.band.lower_C, r.band.upper_C, color="tab:blue", alpha=0.12, lw=0,
                        label=f"{r.band.level * 100:g} % prediction band")  # fmt: skip
    styles = {"A's inputs unchanged": ("tab:orange", "--"), "A's inputs retimed": ("tab:green", ":")}
    keys = {"A's inputs unchanged": "baseline_same_inputs", "A's inputs retimed": "baseline_retimed"}
    for name, ta in r.baselines.items():
        color, ls = styles[name]
        rm = m[keys[name]]["rmse_C"]
        if rm is not None:
            ax.plot(t_min, ta, color=color, ls=ls, lw=1.3, label=f"{name} (RMSE {d(rm)})")
    temperature_axis(ax, "bean temperature BT [{u}]", units)
    ax.set_title(
        f"{r.plant_from} -> {r.plant_to}, {r.batch_kg:g} kg: "
        + ("feasible" if m["feasible"] else f"NOT feasible (max |e| {d(m['max_abs_C'])})"),
        fontsize=10,
    )
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    ax.set_xlim(t_min[0], t_min[-1])
    _events(ax, {k: v for k, v in r.events.items() if k != "CHARGE"})

    u = r.program.Tgi_C if lim.decide == "Tgi" else r.program.heater
    span = lim.high - lim.low
    ax2.axhspan(lim.high, lim.high + 0.08 * span, color="tab:red", alpha=0.15, lw=0)
    ax2.axhspan(lim.low - 0.08 * span, lim.low, color="tab:red", alpha=0.15, lw=0, label="outside the limits")
    for j, s in enumerate(m["on_limits"]):
        label = "program on a limit" if j == 0 else None
        ax2.axvspan(s["from_s"] / 60.0, s["to_s"] / 60.0, color="tab:purple", alpha=0.10, lw=0, label=label)
    for name, inp in r.baseline_inputs.items():
        color, ls = styles[name]
        ax2.plot(t_min, inp, color=color, ls=ls, lw=1.0, label=name)
    if r.continuous is not None and r.continuous is not r.program:
        uc = r.continuous.Tgi_C if lim.decide == "Tgi" else r.continuous.heater
        ax2.plot(t_min, uc, color="tab:blue", lw=0.8, alpha=0.5, label="continuous (before rounding)")
        ax2.step(t_min, u, where="post", color="tab:blue", lw=1.6, label="runnable program (machine steps)")
    else:
        ax2.plot(t_min, u, color="tab:blue", lw=1.6, label="optimised program")
    ax2.set_ylim(lim.low - 0.08 * span, lim.high + 0.08 * span)
    ax2.set_ylabel("Tgi [°C]" if lim.decide == "Tgi" else setting_axis_label("heater", lim.unit))
    room_for_legend(ax2, share=0.35)  # a program at its floor ran under the legend in the lower corner
    ax2.legend(loc="upper right", fontsize=7, ncol=3, framealpha=0.9)
    ax2.grid(alpha=0.3)

    ax3.axhspan(-m["tolerance_C"], m["tolerance_C"], color="tab:blue", alpha=0.1, lw=0, label="tolerance")
    ax3.plot(t_min, r.program.Ta_pred_C - r.target_C, color="tab:blue", lw=1.2, label="predicted - target")
    temperature_axis(ax3, "error [{u}]", units, delta=True)
    time_axis(ax3)
    ax3.legend(loc="upper right", fontsize=7)
    ax3.grid(alpha=0.3)
    return finish_figure(fig, path, f"transfer: {r.reference}", outputs)


def plot_closed_loop(r, path=None, title=None, outputs=None):
    """One closed-loop roast: reference, the roaster's BT and what the controller read; the rate of
    rise; the decided input (requested and applied, limits shaded); the drum temperature with the
    estimator's view when there is one.

    ``r`` is a :class:`roastlab.control.loop.ClosedLoopResult`.
    """
    t_min = r.time_s / 60.0
    lim = r.setup.limits
    m = r.metrics
    fig = new_figure(figsize=(9, 9), layout="constrained")
    ax, ax_r, ax_u, ax_m = fig.subplots(4, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.3, 1.5, 1.3]})
    ax.plot(t_min, r.reference_C, color="0.2", lw=2.4, label="reference BT")
    ax.plot(t_min, r.measured_C, color="tab:gray", lw=0.8, alpha=0.7, label="probe as read by the controller")
    ax.plot(t_min, r.bt_C, color="tab:blue", lw=1.6, label=f"roaster BT (RMSE {m['rmse_C']:.2f} °C)")
    if "Tb_C_est" in r.estimates:
        ax.plot(t_min, r.states[:, S_TB], color="tab:brown", lw=1.0, label="bean Tb (true)")
        ax.plot(t_min, r.estimates["Tb_C_est"], color="tab:brown", lw=1.0, ls="--", label="bean Tb (estimated)")
    ax.set_ylabel("temperature [°C]")
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    ax_r.plot(t_min, rate_of_rise_C_per_min(r.time_s, r.reference_C), color="0.2", lw=1.8, label="reference")
    ax_r.plot(t_min, rate_of_rise_C_per_min(r.time_s, r.bt_C), color="tab:blue", lw=1.2, label="roaster")
    ror_limits(ax_r, r.time_s, r.reference_C, r.bt_C)
    ax_r.set_ylabel("RoR [°C/min]")
    ax_r.legend(loc="upper right", fontsize=7)
    ax_r.grid(alpha=0.3)
    span = lim.high - lim.low
    ax_u.axhspan(lim.high, lim.high + 0.08 * span, color="tab:red", alpha=0.15, lw=0)
    ax_u.axhspan(lim.low - 0.08 * span, lim.low, color="tab:red", alpha=0.15, lw=0, label="outside the limits")
    if r.setup.reference_u is not None:
        ax_u.plot(r.setup.time_s / 60.0, r.setup.reference_u, color="0.5", lw=1.0, ls=":", label="reference's own")
    ax_u.step(
        t_min,
        np.clip(r.u_requested, lim.low - 0.08 * span, lim.high + 0.08 * span),
        where="post",
        color="tab:orange",
        lw=0.8,
        alpha=0.8,
        label=f"requested ({m['constraint_violations']} clipped)",
    )
    ax_u.step(t_min, r.u_applied, where="post", color="tab:blue", lw=1.4, label="applied")
    ax_u.set_ylim(lim.low - 0.08 * span, lim.high + 0.08 * span)
    ax_u.set_ylabel("Tgi [°C]" if lim.decide == "Tgi" else "heater setting")
    room_for_legend(ax_u, share=0.3)  # an input at its ceiling ran under the legend
    ax_u.legend(loc="upper right", fontsize=7, ncol=4)
    ax_u.grid(alpha=0.3)
    ax_m.plot(t_min, r.states[:, S_TM], color="tab:red", lw=1.4, label="drum metal Tm (true)")
    if "Tm_C_est" in r.estimates:
        ax_m.plot(t_min, r.estimates["Tm_C_est"], color="tab:red", lw=1.0, ls="--", label="Tm estimated")
    ax_m.set_ylabel("Tm [°C]")
    time_axis(ax_m)
    ax_m.legend(loc="lower right", fontsize=7)
    ax_m.grid(alpha=0.3)
    title = title or f"{r.controller} on '{r.scenario}'"
    return finish_figure(fig, path, title, outputs)


def plot_control_comparison(rows, results, path=None, outputs=None):
    """Every controller on every scenario: RMSE bars (the oracle's as a line when computed) and, below, each scenario's BT error over time per controller.

    ``rows`` are the comparison's metric dicts, ``results`` {(scenario, controller): result}.
    """
    scenarios = list(dict.fromkeys(r["scenario"] for r in rows))
    controllers = list(dict.fromkeys(r["controller"] for r in rows))
    colors = {c: col for c, col in zip(controllers, ("tab:orange", "tab:blue", "tab:green", "tab:purple", "tab:red"))}
    fig = new_figure(figsize=(11, 9), layout="constrained")
    top, bottom = fig.subfigures(2, 1, height_ratios=[1.1, 2])
    ax = top.subplots()
    x = np.arange(len(scenarios))
    w = 0.8 / max(1, len(controllers))
    for j, c in enumerate(controllers):
        vals = [
            next((r["rmse_C"] for r in rows if r["scenario"] == s and r["controller"] == c), np.nan) for s in scenarios
        ]
        ax.bar(x + (j - (len(controllers) - 1) / 2) * w, vals, w, color=colors[c], label=c)
    best = [next((r.get("oracle_rmse_C") for r in rows if r["scenario"] == s), None) for s in scenarios]
    if any(b is not None for b in best):
        ax.scatter(
            x,
            [np.nan if b is None else b for b in best],
            marker="_",
            s=600,
            color="k",
            zorder=3,
            label="oracle (open-loop optimum, roaster known)",
        )
    ax.set_xticks(x, scenarios, rotation=20, ha="right", fontsize=8)
    ax.set_ylabel("BT RMSE [°C]")
    ax.set_yscale("symlog", linthresh=1.0)
    ax.set_ylim(0, 10 ** np.ceil(np.log10(max(1.0, max(r["rmse_C"] for r in rows))) + 0.6))
    ax.legend(fontsize=8, ncol=4, loc="upper left")
    ax.grid(alpha=0.3, axis="y")
    ncol = 3
    nrow = int(np.ceil(len(scenarios) / ncol))
    axes = np.atleast_1d(bottom.subplots(nrow, ncol, sharex=True, sharey=True)).ravel()
    for a, s in zip(axes, scenarios):
        for c in controllers:
            r = results.get((s, c))
            if r is not None:
                a.plot(r.time_s / 60.0, r.bt_C - r.reference_C, color=colors[c], lw=1.0, label=c)
        a.axhline(0.0, color="0.3", lw=0.6)
        a.set_title(s, fontsize=8)
        a.grid(alpha=0.3)
    for a in axes[len(scenarios) :]:
        a.set_visible(False)
    axes[0].legend(fontsize=7)
    bottom.supylabel("BT - reference [°C]", fontsize=9)
    bottom.supxlabel("time after CHARGE [min]", fontsize=9)
    return finish_figure(fig, path, "closed-loop comparison (synthetic scenarios)", outputs)


def plot_fleet_history(m, path=None, outputs=None):
    """A machine's identified coefficients batch by batch (:class:`roastlab.fleet.report.MachineHistory`).

    One panel per coefficient: each batch's value with its standard error, the median of each
    period between changes, outlier batches as red crosses, drift alarms as arrows at the batch
    that raised them with a dotted line where the change was dated.
    """
    params = m.params
    a = m.analysis
    fig = new_figure(figsize=(10, 2.3 * len(params) + 0.6), layout="constrained")
    axes = fig.subplots(len(params), 1, sharex=True, squeeze=False)[:, 0]
    idx = np.arange(len(m.frame))
    good = a["good"]
    small = len(idx) > 2000
    for ax, p in zip(axes, params):
        x = m.wide[p].to_numpy(dtype=float)
        e = m.stderr[p].to_numpy(dtype=float)
        if small:
            ax.plot(idx[good], x[good], ".", ms=1.5, color="C0", alpha=0.5, label="batch")
        else:
            ax.errorbar(
                idx[good],
                x[good],
                yerr=np.where(np.isfinite(e[good]), e[good], 0),
                fmt=".",
                ms=4,
                color="C0",
                ecolor="0.7",
                lw=0.8,
                label="batch (± std. error)",
            )
        if (~good).any():
            ax.plot(idx[~good], x[~good], "x", color="C3", ms=5, label="outlier")
        for per in a["periods"]:
            st = per["values"].get(p)
            if st:
                ax.hlines(st["median"], per["first_index"], per["last_index"], color="k", lw=1.2, label="median")
        for al in a["alarms"]:
            if al["parameter"] != p:
                continue
            i = al["batch_index"]
            mark = "^" if al["direction"] == "up" else "v"
            ax.plot(i, x[i], mark, color="C1", ms=10, mec="k", label=f"alarm {al['direction']}")
            if al["change_index"] is not None:
                ax.axvline(al["change_index"], color="C1", ls=":", lw=1)
        unit = REGISTRY[p].unit if p in REGISTRY else ""
        ax.set_ylabel(f"{p} [{unit}]" if unit and unit != "-" else p)
        handles, labels = ax.get_legend_handles_labels()
        uniq = dict(zip(labels, handles))
        ax.legend(uniq.values(), uniq.keys(), fontsize=7, loc="upper right")
    axes[-1].set_xlabel("batch (in order of started_at)")
    title = f"{m.name} ({m.plant_name or Path(m.plant).name}): {len(idx)} batches, {len(a['alarms'])} alarm(s), {len(a['outliers'])} outlier(s)"
    return finish_figure(fig, path, title, outputs)
