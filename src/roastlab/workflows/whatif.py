"""What if: a logged roast, a fitted model and changes -> the prediction as run and as changed.

Changes act on what a roaster controls: a setting shifted or scaled (heater, fan), from CHARGE
or from a time (``+1@4:00``), a setting set from a time on (``heater=6@2:00``; ``heater=+1@4:00``
is relative), the inlet gas temperature (``Tgi_offset_C``), the batch mass (``batch_kg``) and
the drum's temperature at charge (``Tm0_C``). Both predictions go through
:meth:`FittedModel.predict`, the one place a model meets data. The table has three columns per
milestone (measured, as run, changed) and the model's own error on the log beside the change,
judged on the beans (a batch-size change moves the probe's immersion too), the probe below.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, ParameterError
from ..evaluate import bands
from ..io.batch import Batch
from ..metrics.profile import (  # noqa: F401  (re-exported)
    clock_s,
    crossing_or_projected_s,
    crossing_time_s,
    display_temp,
    display_temp_delta,
    milestone_levels,
    milestones,
    mmss,
    temp_symbol,
)
from ..model.actuators import DROP_LATER_MAX_S, SETTING_GAINS, inert_settings  # noqa: F401 (re-exported)
from ..report.result import Result, draw_curves
from ..sim.simulate import SimulationResult
from .model import FittedModel

#: The milestone rows of a what-if table, in order: (key of :func:`milestones`, label, kind).
ROWS = (
    ("TP_s", "turning point", "time"),
    ("TP_C", "turning-point temperature", "temp"),
    ("DRY_s", "DRY END", "time"),
    ("FCs_s", "first crack", "time"),
    ("DROP_C", "temperature at DROP", "temp"),
    ("development_s", "development time (FCs to DROP)", "time"),
    ("DTR_pct", "development time ratio", "pct"),
    ("AUC_C_min", "AUC (TP to DROP, above BT at TP)", "auc"),
)
#: The rows when the changed roast drops elsewhere: DROP's time beside first crack.
ROWS_WITH_DROP = ROWS[:4] + (("DROP_s", "DROP", "time"),) + ROWS[4:]
#: Rows of the probe's curve alone: the beans only warm, so the turning point (the charge drop) and
#: the area Artisan counts from it are BT's.
PROBE_ONLY = ("TP_s", "TP_C", "AUC_C_min")
#: Each kind of row: (unit of its stored value, unit a table shows it in; "T" the temperature's symbol).
ROW_UNITS = {
    "time": ("s", "m:ss"),
    "temp": ("degC", "T"),
    "pct": ("%", "%"),
    "auc": ("degC min", "T·min"),
}
#: Rows that need first crack within the roast (not when it is projected past DROP).
DEVELOPMENT = ("development_s", "DTR_pct")
#: The two readings a what-if compares: the beans (what it judges) and the bean probe (what the
#: roaster's BT shows); the probe's immersion in the bed changes with the batch mass, so across
#: batch sizes it can move against the beans.
READINGS = {"beans": "beans (model Tb; measured: a second bean reading where logged)", "probe": "probe BT (model Ta)"}


def drop_time_s(text: str, logged_drop_s: float) -> float:
    """The changed roast's DROP [s after CHARGE] from ``--drop-at``: ``"9:30"`` or ``"570"`` after CHARGE,
    or with a sign relative to the logged DROP (``"+0:20"`` later, ``"-15"`` earlier)."""
    text = text.strip()
    when = parse_time_s(text)
    return float(logged_drop_s + when) if text[:1] in "+-" else when


def roast_until(batch: Batch, drop_s: float) -> Batch:
    """``batch`` dropped at ``drop_s`` [s after CHARGE] instead of at its logged DROP: cut there (each input
    interpolated at the cut, as the simulator holds it between samples), or carried on past its DROP, on its
    own median sampling step, with every input held at its last logged value, up to :data:`DROP_LATER_MAX_S`.
    A roast that was not run has no readings: the probe, second bean reading and ET are dropped, the probe
    starting where the log's did (``initial["Ta0_C"]``). Marks after the new DROP go; DROP moves."""
    src = batch.source or batch.name
    t = np.asarray(batch.time_s, dtype=float)
    end = float(t[-1])
    if not np.isfinite(drop_s) or drop_s <= t[0] + 2 * float(np.min(np.diff(t))):
        raise ParameterError(f"DROP at {mmss(drop_s)}: give a time after CHARGE and after the log's first samples", src)
    if drop_s > end + DROP_LATER_MAX_S + 1e-9:
        raise ParameterError(
            f"DROP at {mmss(drop_s)} is more than {mmss(DROP_LATER_MAX_S)} after the logged DROP ({mmss(end)}): past "
            "it the settings are held at their last values, a few minutes of a roast, not a longer one",
            src,
        )
    if drop_s <= end:
        keep = t < drop_s - 1e-9
        new_t = np.append(t[keep], drop_s)

        def series(a):
            return None if a is None else np.append(np.asarray(a, float)[keep], np.interp(drop_s, t, a))

    else:
        step = float(np.median(np.diff(t)))
        extra = np.arange(end + step, drop_s - 1e-9, step)
        extra = np.append(extra, drop_s) if not extra.size or extra[-1] < drop_s - 1e-9 else extra
        new_t = np.concatenate([t, extra])

        def series(a):
            return None if a is None else np.concatenate([np.asarray(a, float), np.full(extra.size, a[-1])])

    initial = dict(batch.initial)
    if batch.Ta_C is not None:
        initial.setdefault("Ta0_C", float(batch.Ta_C[0]))
    events = {k: v for k, v in batch.events.items() if v is not None and v < drop_s - 1e-9} | {"DROP": float(drop_s)}
    return dataclasses.replace(
        batch,
        time_s=new_t,
        Gg_kg_s=series(batch.Gg_kg_s),
        Tgi_C=series(batch.Tgi_C),
        heater=series(batch.heater),
        fan=series(batch.fan),
        Ta_C=None,
        Tb2_C=None,
        ET_C=None,
        initial=initial,
        events=events,
    )


def drop_at_bt_s(model: FittedModel, batch: Batch, bt_C: float, miss=None, **changes) -> tuple[float, float]:
    """When the changed roast (``batch`` with ``changes``, carried on up to :data:`DROP_LATER_MAX_S` past
    its DROP) reads ``bt_C`` on the roaster's BT after its turning point [s after CHARGE], and the model's
    miss added there [degC]: ``miss``, ``(time_s, miss_C)``, the log's BT less the model's as run
    (:func:`whatif`), reads the model as the roaster's probe would, the model's own miss at each time of this
    roast and past its DROP the miss at DROP carried a few minutes on (as the band's spread carries a log's
    error past its DROP, :func:`roastlab.evaluate.bands.roast_spread`). Unchanged, the roast then drops
    where the log read ``bt_C``. A ParameterError naming how far it gets where it never does."""
    longest = roast_until(batch, float(batch.time_s[-1]) + DROP_LATER_MAX_S)
    res = model.predict(longest, **changes)
    added = np.zeros_like(res.Ta_C) if miss is None else np.interp(res.time_s, *miss)  # held past its end
    reads = res.Ta_C + added
    hit = crossing_time_s(res.time_s, reads, bt_C)
    if hit is None:
        raise ParameterError(
            f"DROP at BT {bt_C:.1f} °C: the changed roast's BT reaches {float(np.max(reads)):.1f} °C at most by "
            f"{mmss(res.time_s[-1])}, {mmss(DROP_LATER_MAX_S)} past the logged DROP with the last settings held",
            batch.source or batch.name,
        )
    return hit, float(np.interp(hit, res.time_s, added))


@dataclass
class SettingChange:
    """One change of a logged setting from ``from_s`` [s after CHARGE] on (until ``until_s``,
    default the end of the roast): ``shift`` (add ``value``), ``scale`` (multiply) or ``set``
    (the setting becomes ``value``); ``unit`` is the setting's unit as the map declares it
    ("percent", "level", ...). Changes apply in the order given, so a program drawn as steps
    is a list of ``set`` changes, each from its step's start to its end."""

    setting: str
    how: str  # "shift" | "scale" | "set"
    value: float
    from_s: float = 0.0
    unit: str = ""
    until_s: float = float("inf")

    def apply(self, t: np.ndarray, series: np.ndarray) -> np.ndarray:
        out = series.copy()
        after = (t >= self.from_s) & (t < self.until_s)
        if self.how == "shift":
            out[after] += self.value
        elif self.how == "scale":
            out[after] *= self.value
        else:
            out[after] = self.value
        return out

    def __str__(self) -> str:
        steps = " step" if abs(self.value) == 1 else " steps"
        unit = {"percent": " %", "level": steps, "tens": "", "reading": "", "": ""}.get(self.unit, f" {self.unit}")
        when = f" from {mmss(self.from_s)}" if self.from_s > 0 else ""
        if np.isfinite(self.until_s):
            when = f" from {mmss(self.from_s)} to {mmss(self.until_s)}"
        if self.how == "set":
            unit = {"percent": " %", "level": "", "tens": "", "reading": ""}.get(self.unit, unit)
            return f"{self.setting} = {self.value:g}{unit}{when or ' from CHARGE'}"
        if self.how == "scale":
            return f"{self.setting} x{self.value:g}{when}"
        return f"{self.setting} {self.value:+g}{unit}{when}"


_NUMBER = r"(\d+(?:\.\d*)?(?:[eE][+-]?\d+)?)"
_WHEN = r"(?:\s*@\s*(\d+(?::\d{1,2})?(?:\.\d*)?))?"
_CHANGE = re.compile(r"^\s*(x|\*|[+-])?\s*" + _NUMBER + _WHEN + r"\s*$")
_SET = re.compile(r"^\s*(heater|fan)\s*=\s*([+-])?\s*" + _NUMBER + _WHEN + r"\s*$")


def parse_time_s(text: str | None) -> float:
    """A time after CHARGE as seconds (``"240"``) or the roaster's m:ss (``"4:00"``) -> [s]."""
    if not text:
        return 0.0
    try:
        return clock_s(text)
    except ValueError as exc:
        raise ParameterError(str(exc)) from None


def _finite(value: float, what: str) -> float:
    """``value``, refused where the text wrote a number beyond floating point (1e400 reads as inf)."""
    if not np.isfinite(value):
        raise ParameterError(f"{what}: {value} is not a finite number")
    return value


def parse_setting_change(setting: str, text: str, unit: str = "") -> SettingChange:
    """``"+1"``, ``"-2"`` (shift), ``"x1.1"`` (scale), each optionally from a time: ``"+1@4:00"``
    (m:ss) or ``"+1@240"`` (s). A number with no sign or ``x`` is refused: a relative change
    needs its ``+``/``-``; a setting's new value goes through ``--set``."""
    m = _CHANGE.match(text)
    if not m or not m.group(1):
        raise ParameterError(
            f"--{setting} {text!r}: give a shift such as +1 or -2, or a factor such as x1.1, "
            "optionally from a time: +1@4:00 (to set a value use --set)"
        )
    sign = m.group(1)
    value = _finite(float(m.group(2)), f"--{setting} {text!r}")
    if sign in ("x", "*"):
        return SettingChange(setting, "scale", value, parse_time_s(m.group(3)), unit)
    return SettingChange(setting, "shift", -value if sign == "-" else value, parse_time_s(m.group(3)), unit)


def parse_set(text: str, units: dict | None = None) -> SettingChange:
    """``"heater=6@2:00"``: the setting becomes 6 from 2:00 after CHARGE on; with an explicit
    sign, ``"heater=+1@4:00"``, it is a change relative to the log (+1 from 4:00)."""
    m = _SET.match(text)
    if not m:
        raise ParameterError(
            f"--set {text!r}: expected SETTING=VALUE@TIME, e.g. heater=6@2:00 (absolute) or heater=+1@4:00 "
            "(relative; heater or fan, TIME as m:ss or seconds)"
        )
    name, sign, value = m.group(1), m.group(2), _finite(float(m.group(3)), f"--set {text!r}")
    unit = (units or {}).get(name, "")
    when = parse_time_s(m.group(4))
    if sign:
        return SettingChange(name, "shift", -value if sign == "-" else value, when, unit)
    return SettingChange(name, "set", value, when, unit)


COLUMNS = ("measured", "as_run", "changed")


def _fmt(value, kind: str, units: str) -> str:
    if value is None or not np.isfinite(value):
        return "-"
    if kind == "time":
        return mmss(value)
    if kind == "pct":
        return f"{value:.1f}"
    if kind == "auc":  # an area of temperature differences, whole degree-minutes as Artisan shows it
        return f"{display_temp_delta(value, units):.0f}"
    return f"{display_temp(value, units):.1f}"


def _unit(kind: str, units: str) -> str:
    """The unit a table shows a row of ``kind`` in (:data:`ROW_UNITS`), temperatures in ``units``."""
    return ROW_UNITS[kind][1].replace("T", temp_symbol(units))


def _fmt_delta(a, b, kind: str, units: str) -> str:
    if a is None or b is None or not (np.isfinite(a) and np.isfinite(b)):
        return "-"
    d = b - a
    if kind == "time":
        return ("+" if d >= 0 else "-") + mmss(abs(d))
    if kind == "pct":
        return f"{d:+.1f}"
    if kind == "auc":
        return f"{display_temp_delta(d, units):+.0f}"
    return f"{display_temp_delta(d, units):+.1f}"


@dataclass
class WhatIf(Result):
    """The log, its prediction as run and with the changes, and the milestone table: one row
    per milestone and reading (beans, probe) with the measured value, the model as run, the
    model with the changes, the change, and the model's own error on this log."""

    batch: Batch
    as_run: SimulationResult
    changed: SimulationResult
    changes: list[str]
    rows: list[dict]
    levels: dict = field(default_factory=dict)
    #: the changed probe BT's prediction band (:class:`roastlab.evaluate.bands.Band`) when asked for
    band: object | None = None
    #: why the band may hold fewer samples than its level (a batch size the spread was not measured
    #: at, a roaster it was not measured on: :func:`roastlab.evaluate.bands.band_note`), else None
    band_note: str | None = None
    #: the changed settings the model does not respond to (its gains for them are 0:
    #: :func:`roastlab.model.actuators.inert_settings`), with the gains' names
    inert: dict = field(default_factory=dict)
    #: the settings' actuators (name -> :class:`~roastlab.model.actuators.Actuator`), for the background's events
    actuators: dict = field(default_factory=dict)
    #: what the machine's ET measures (:func:`roastlab.workflows.transfer.et_source`): the background's ET curve
    et_source: str = "Tgi"
    #: the machine's name and the changed roast's green batch [kg], for the background
    roaster: str = ""
    batch_kg: float | None = None
    #: changed settings that a log at the knob's end leaves unchanged, and when (:func:`_at_the_end`)
    held_at_end: list = field(default_factory=list)
    #: the changed roast's DROP [s after CHARGE] where it drops elsewhere than the log (:func:`roast_until`)
    drop_s: float | None = None
    #: with DROP at a BT: the log's BT less the model's at the new DROP (past the logged DROP, at it), by which
    #: the model was read as the roaster's probe (:func:`drop_at_bt_s`)
    drop_offset_C: float | None = None

    def band_line(self, units: str = "C") -> str | None:
        """The changed probe BT's band in one line: its level, median width and BT at DROP."""
        from ..evaluate.bands import band_words

        return None if self.band is None else band_words(self.band, "the changed probe BT", units)

    def table(self, units: str = "C") -> str:
        """The milestone table as text; ``units`` "C" or "F" for temperatures."""
        u = temp_symbol(units)
        lines = [f"what if ({'; '.join(self.changes) or 'no change'}) on {self.batch.name}"]
        lines.append("judged on the beans (the model's bean temperature); the probe BT, what the roaster sees, below")
        head = f"{'':40s}{'measured':>10s}{'as run':>10s}{'changed':>10s}{'change':>10s}{'model err':>11s}"
        for reading, title in READINGS.items():
            lines += ["", title, head]
            for r in (r for r in self.rows if r["reading"] == reading):
                kind = r["kind"]
                what = f"  {r['what']} [{_unit(kind, units)}]"
                cells = {k: _fmt(r[k], kind, units) + ("*" if k in r["projected"] else "") for k in COLUMNS}
                lines.append(
                    f"{what:40s}{cells['measured']:>10s}{cells['as_run']:>10s}{cells['changed']:>10s}"
                    f"{_fmt_delta(r['as_run'], r['changed'], kind, units):>10s}"
                    f"{_fmt_delta(r['measured'], r['as_run'], kind, units):>11s}"
                )
        lv = self.levels
        lines.append("")
        lines.append(
            "DRY END and first crack: when a curve reaches the temperature the log marks them at "
            + ", ".join(
                f"{name} {display_temp(lv[r][name], units):.1f} {u} ({r})"
                for r in ("probe", "beans")
                for name in ("DRY", "FCs")
                if name in lv.get(r, {})
            )
        )
        if self.band is not None:
            lines.append(self.band_line(units))
            if self.band_note:
                lines.append(f"note: {self.band_note}")
        if any(r["projected"] for r in self.rows):
            lines.append("* past the logged DROP: where the curve would reach it at the rate of rise of its last 2 min")
        lines += [f"note: {w}" for w in self.warnings(units)]
        return "\n".join(lines)

    def warnings(self, units: str = "C") -> list[str]:
        """What the table alone would hide: a changed setting the model does not respond to (its
        "+0.0" is the model file's, not the roast's), a shift that the log at the knob's end leaves
        without effect for a while, milestones a curve reaches only past DROP, and
        rows where the change is smaller than the model's own error on this log (the change may be
        real, but this log cannot confirm the model that close). Temperatures in ``units`` ("C" or "F")."""
        u = temp_symbol(units)
        out = [
            f"the model does not respond to the {setting} ({' and '.join(gains)} = 0 in this model file, or "
            f"negligibly above: its fit spec held {'them' if len(gains) > 1 else 'it'} at 0, or the fit found "
            "no effect), so the change "
            f"to it shows none; free {' or '.join(gains)} in the fit spec and refit to ask this"
            for setting, gains in self.inert.items()
        ]
        out += self.held_at_end
        logged_drop = float(self.batch.time_s[-1])
        if self.drop_offset_C:
            d = display_temp_delta(self.drop_offset_C, units)
            when = "at the logged DROP, a miss carried on" if self.drop_s > logged_drop else f"at {mmss(self.drop_s)}"
            out.append(
                f"DROP at a BT reads the model's BT as this log's probe: the model read {abs(d):.1f} {u} "
                f"{'below' if d > 0 else 'above'} the log {when}"
            )
        if self.drop_s is not None and self.drop_s > logged_drop:
            held = [
                f"{k} {self.actuators[k].label(getattr(self.changed, k)[-1])}"
                if k in self.actuators
                else f"{k} as logged"
                for k in ("heater", "fan")
                if getattr(self.changed, k) is not None
            ]
            out.append(
                f"from the logged DROP ({mmss(logged_drop)}) to {mmss(self.drop_s)} the roast is the model's alone, "
                f"its inputs held at their last values{' (' + ', '.join(held) + ')' if held else ''}"
            )
        for r in self.rows:
            level = self.levels.get(r["reading"], {}).get("FCs")
            for col in r["projected"]:
                who = "the model as run" if col == "as_run" else "the changed roast"
                drop = "its DROP" if col == "changed" and self.drop_s is not None else "the logged DROP"
                out.append(
                    f"{r['reading']}: {who} reaches the first-crack temperature ({display_temp(level, units):.1f} {u}) only after "
                    f"{drop} (at {mmss(r[col])}, projected){': it runs cooler than this log late in the roast' if col == 'as_run' else ''}"
                )
        small = []
        for r in self.rows:
            a, c, m = r["as_run"], r["changed"], r["measured"]
            if a is None or c is None or m is None or r["key"].startswith("TP"):
                continue
            if self.drop_s is not None and r["key"] in ("DROP_s", *DEVELOPMENT):
                continue  # set by the DROP asked for, not predicted
            if 1e-6 < abs(c - a) < abs(a - m):  # a change there is, smaller than the model's own error
                unit = {"time": "s", "pct": "points"}.get(r["kind"]) or _unit(r["kind"], units)
                scale = display_temp_delta(1.0, units) if r["kind"] in ("temp", "auc") else 1.0
                small.append(
                    f"{r['reading']} {r['what']} {scale * (c - a):+.1f} {unit} against {scale * (a - m):+.1f} {unit}"
                )
        if small:  # one line for them all: a roaster reads which, not the same sentence eight times
            out.append(
                "within the model's own error on this log, so this log cannot confirm "
                f"{'it' if len(small) == 1 else 'them'} (the change against the model's error): " + "; ".join(small)
            )
        return out

    def summary(self) -> str:
        """The comparison table (:meth:`table`)."""
        return self.table()

    def to_json_dict(self, units: str = "C") -> dict:
        """The table as JSON: every number in degC and s; the warnings, sentences, in ``units``."""
        return {
            "batch": self.batch.name,
            "changes": self.changes,
            "judged_on": "beans",
            "levels_C": self.levels,
            "rows": self.rows,
            "warnings": self.warnings(units),
            **({"band": bands.band_summary(self.band, self.band_note)} if self.band is not None else {}),
            **({"drop_s": self.drop_s} if self.drop_s is not None else {}),
            **({"drop_offset_C": self.drop_offset_C} if self.drop_offset_C is not None else {}),
        }

    def alog_text(self) -> str:
        """The changed roast as an Artisan background (:func:`roastlab.io.background.background_alog_text`):
        BT the changed probe prediction, ET the model's curve for what the machine's ET measures, DRY
        and first crack where the changed probe reaches the log's marks (none past DROP), DROP at the
        log's, and the changed heater and fan settings as Burner and Air events."""
        from ..io.background import background_alog_text, setting_events
        from .transfer import ET_CURVE, model_et_C

        ch = self.changed
        et = model_et_C(ch, self.et_source)
        probe = {r["key"]: r for r in self.rows if r["reading"] == "probe"}
        marks = {
            name: probe[key]["changed"]
            for name, key in (("DRY", "DRY_s"), ("FCs", "FCs_s"))
            if key in probe and probe[key]["changed"] is not None and "changed" not in probe[key]["projected"]
        }
        what = "; ".join(self.changes) or "no change"
        return background_alog_text(
            ch.time_s,
            ch.Ta_C,
            et,
            marks,
            setting_events(ch.time_s, self.setting_series()),
            title=f"roastlab whatif: {self.batch.name} ({what}, predicted)",
            notes=(
                f"Computed by roastlab whatif from {self.batch.name} with {what}. BT is the model's prediction of "
                f"the changed roast, ET the model's {ET_CURVE[self.et_source]}; DRY and FCs where the predicted "
                "BT reaches the log's marks; Burner and Air events = the changed heater and fan settings."
            ),
            roaster=self.roaster,
            batch_kg=self.batch_kg or 0.0,
            mode=self.batch.temp_unit,  # the roaster's own unit, as Artisan recorded the log
        )

    def alarms_text(self) -> str:
        """The changed heater and fan settings as an Artisan alarm set (:func:`roastlab.io.background.alarms_text`):
        loaded in Artisan (Config > Alarms > Load), it moves the Burner and Air sliders at each change of
        the settings after CHARGE, on a machine Artisan controls, to roast the change as predicted."""
        from ..io.background import alarms_text

        series = self.setting_series()
        if not series:
            raise InputError(
                "Artisan alarms move the machine's sliders: the model's map reads no heater or fan", "--alarms"
            )
        return alarms_text(self.changed.time_s, series, note="roastlab whatif")

    def setting_series(self) -> list:
        """The changed settings for :func:`roastlab.io.background.setting_events`: ``(setting, values,
        actuator, thin=False)``, each the machine's (its map's) and logged."""
        ch = self.changed
        return [
            (k, getattr(ch, k), self.actuators[k], False)
            for k in ("heater", "fan")
            if getattr(ch, k) is not None and k in self.actuators
        ]

    def to_frame(self):
        """One row per milestone and reading: measured, as run, changed, change, model error."""
        import pandas as pd

        df = pd.DataFrame(self.rows)
        df["change"] = df["changed"] - df["as_run"]
        df["model_error"] = df["as_run"] - df["measured"]
        return df

    def _figure(self, path, outputs, units: str | None = None):
        """``units``: "C" or "F" for the temperatures (default: the log's own, :attr:`Batch.temp_unit`)."""
        from ..report.figures import plot_whatif

        return plot_whatif(self, path, outputs=outputs, units=units or self.batch.temp_unit)

    def _draw(self, ax) -> None:
        t = self.as_run.time_s
        curves = {"BT measured": (t, self.batch.Ta_C), "BT as run (model)": (t, self.as_run.Ta_C)}
        curves["BT changed (model)"] = (self.changed.time_s, self.changed.Ta_C)
        draw_curves(ax, curves, "BT [°C]")


def _at_the_end(t, logged, wanted, held, act, most: int = 3) -> str:
    """Where a change past the knob's end changes nothing, because the log is at that end already: "the
    log is at P9 there 4:00-8:00, the end of its range, so the change acts only outside those times" (at
    most ``most`` spans), or "... wherever it applies, the end of its range, so it changes nothing"; ""
    where it acts wherever it applies."""
    from ..fit.program import true_runs

    meant = wanted != logged
    runs = true_runs(meant & (held == logged))
    if not runs:
        return ""
    ends = "/".join(sorted({act.label(logged[a]) for a, _ in runs}))
    if sum(b - a + 1 for a, b in runs) == int(meant.sum()):
        return f"the log is at {ends} wherever it applies, the end of its range, so it changes nothing"
    spans = ", ".join(f"{mmss(t[a])}-{mmss(t[b])}" for a, b in runs[:most]) + (", ..." if len(runs) > most else "")
    return f"the log is at {ends} there {spans}, the end of its range, so the change acts only outside those times"


def whatif(
    model: FittedModel,
    batch: Batch,
    setting_changes: list[SettingChange] = (),
    *,
    actuators: dict | None = None,
    band_level: float | None = None,
    drop_s: float | None = None,
    drop_bt_C: float | None = None,
    **changes,
) -> WhatIf:
    """Predict ``batch`` as logged and with the changes; compare the roaster's milestones
    (:func:`roastlab.metrics.profile.milestones`) on the beans and on the probe.

    ``setting_changes`` change the logged heater/fan series; ``changes`` are those of
    :meth:`FittedModel.apply` (``Tgi_offset_C``, ``batch_kg``, ``Tm0_C`` ...). A changed
    setting must stay within the machine's range (``actuators``: name -> Actuator, default
    the model's map's :meth:`~roastlab.io.importers.mapping.ColumnMap.actuator`). The probe's
    milestones are judged at the temperatures the log marks (its DRY and FCs); the beans' at
    the model's bean temperature at those marks as run. ``band_level`` (e.g. 0.9): also the
    changed probe BT's prediction band (:func:`roastlab.evaluate.bands.prediction_bands`); a
    model file that cannot carry one is a ParameterError saying why. ``drop_s`` [s after CHARGE] or
    ``drop_bt_C`` (when the changed probe BT reaches it) drop the changed roast there instead of at the
    logged DROP (:func:`roast_until`: cut, or carried on with the last settings held); its milestones
    (development time, temperature at DROP, ...) are then those of its own DROP, a row DROP added.
    """
    if band_level is not None:
        from ..evaluate.bands import check_level, require_band

        band_level = check_level(band_level)
        require_band(model)
    cmap = model.column_map
    if actuators is None:  # the machine's ranges, as the model's map declares them
        actuators = {k: cmap.actuator(k) for k in ("heater", "fan") if cmap is not None and getattr(cmap, k)}
    changed_batch = batch
    labels = [str(c) for c in setting_changes]
    at_end = []
    for c in setting_changes:
        series = getattr(changed_batch, c.setting)
        if series is None:
            raise ParameterError(
                f"{c}: the log has no {c.setting} setting (its map reads none), so it cannot change",
                batch.source or batch.name,
            )
        if c.from_s > batch.time_s[-1] and not np.isfinite(c.until_s):  # a step of a drawn program may run off
            raise ParameterError(
                f"{c}: {mmss(c.from_s)} is after the log ends ({mmss(batch.time_s[-1])} after CHARGE), so it changes "
                "nothing",
                batch.source or batch.name,
            )
        new = c.apply(batch.time_s, series)
        act = actuators.get(c.setting)
        if act is not None and (new.min() < act.low - 1e-9 or new.max() > act.high + 1e-9):
            if c.how == "set":
                raise ParameterError(
                    f"{c}: outside the machine's {c.setting} range {act.label(act.low)}-{act.label(act.high)}"
                )
            held = np.clip(new, act.low, act.high)  # a shift past the knob's end stays at the end
            labels[labels.index(str(c))] += f" (held within {act.label(act.low)}-{act.label(act.high)})"
            if idle := _at_the_end(batch.time_s, series, new, held, act):
                at_end.append(f"{c}: {idle}")
            new = held
        changed_batch = dataclasses.replace(changed_batch, **{c.setting: new})
    # four digits: a drum given as 400F is "drum at charge 204.4 °C", not 204.444
    names = {
        "Tgi_offset_C": "Tgi {:+.4g} °C",
        "batch_kg": "batch {:g} kg",
        "Tm0_C": "drum at charge {:.4g} °C",
        "Tb0_C": "beans at charge {:.4g} °C",
    }
    labels += [names.get(k, k + " = {:g}").format(float(v)) for k, v in changes.items()]
    if drop_s is not None and drop_bt_C is not None:
        raise ParameterError("DROP is either at a time or at a BT, not both", batch.source or batch.name)
    logged_drop_s = float(batch.time_s[-1])
    as_run = model.predict(batch)
    drop_offset_C = None
    if drop_bt_C is not None:
        # the BT the roaster reads: the model's, as far off as it was from the log then (past DROP, at DROP)
        miss = (batch.time_s, batch.Ta_C - as_run.Ta_C) if batch.Ta_C is not None else None
        drop_s, drop_offset_C = drop_at_bt_s(model, changed_batch, drop_bt_C, miss, **changes)
        labels.append(f"DROP at BT {drop_bt_C:.1f} °C ({mmss(drop_s)})")
    elif drop_s is not None:
        sign = "-" if drop_s < logged_drop_s else "+"
        labels.append(f"DROP at {mmss(drop_s)} ({sign}{mmss(abs(drop_s - logged_drop_s))})")
    if drop_s is not None:
        changed_batch = roast_until(changed_batch, drop_s)
    changed = model.predict(changed_batch, **changes)
    t, tc = batch.time_s, changed.time_s
    events = batch.events
    measured = {"probe": batch.Ta_C, "beans": batch.Tb2_C}
    # each model curve on its own times: a changed DROP ends the changed roast elsewhere
    model_curves = {
        "probe": ((t, as_run.Ta_C), (tc, changed.Ta_C)),
        "beans": ((t, as_run.Tb_C), (tc, changed.Tb_C)),
    }
    levels = {
        "probe": milestone_levels(t, batch.Ta_C, events) if batch.Ta_C is not None else {},
        "beans": milestone_levels(t, as_run.Tb_C, events),
    }
    if not levels["probe"]:
        levels["probe"] = milestone_levels(t, as_run.Ta_C, events)
    rows = []
    for reading in READINGS:
        lv = levels[reading]
        ms_meas = milestones(t, measured[reading], lv) if measured[reading] is not None else {}
        ms_run, ms_chg = (milestones(tt, y, lv) for tt, y in model_curves[reading])
        projected = {}
        for name, ms, (tt, y) in (
            ("as_run", ms_run, model_curves[reading][0]),
            ("changed", ms_chg, model_curves[reading][1]),
        ):
            if ms["FCs_s"] is None:  # a model curve that stops short: where it would get there
                ms["FCs_s"] = crossing_or_projected_s(tt, y, lv["FCs"])
                projected[name] = ms["FCs_s"] is not None
        for key, what, kind in ROWS if drop_s is None else ROWS_WITH_DROP:
            if reading == "beans" and key in PROBE_ONLY:
                continue
            rows.append(
                {
                    "reading": reading,
                    "key": key,
                    "what": what,
                    "kind": kind,
                    "unit": ROW_UNITS[kind][0],
                    "measured": ms_meas.get(key),
                    "as_run": ms_run[key] if not (key in DEVELOPMENT and projected.get("as_run")) else None,
                    "changed": ms_chg[key] if not (key in DEVELOPMENT and projected.get("changed")) else None,
                    "projected": [k for k, v in projected.items() if v] if key == "FCs_s" else [],
                }
            )
    band, note = None, None
    if band_level is not None:
        from ..evaluate.bands import band_note, prediction_bands

        band = prediction_bands(model, [changed_batch], band_level, **changes)[0]
        note = band_note(model, [changed_batch], changes.get("batch_kg"))
    inert = {s: SETTING_GAINS[s] for s in inert_settings(model.values, [c.setting for c in setting_changes])}
    from .transfer import et_source

    return WhatIf(
        batch,
        as_run,
        changed,
        labels,
        rows,
        levels,
        band,
        note,
        inert,
        actuators=dict(actuators),
        et_source=et_source(cmap),
        roaster=model.plant.name if model.plant is not None else "",
        batch_kg=changes.get("batch_kg") or batch.Mb_kg or (model.plant.Mb_kg if model.plant is not None else None),
        held_at_end=at_end,
        drop_s=drop_s,
        drop_offset_C=drop_offset_C,
    )
