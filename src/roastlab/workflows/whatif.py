"""What if: a logged roast, a fitted model and changes -> the prediction as run and as changed.

Changes act on what a roaster controls: a setting shifted or scaled (heater, fan), a setting
set from a time on (``heater=6@120``), the inlet gas temperature (``Tgi_offset_C``), the batch
mass (``batch_kg``) and the drum's temperature at charge (``Tm0_C``). Both predictions go
through :meth:`FittedModel.predict`, the one place a model meets data.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..io.batch import Batch
from ..metrics.profile import crossing_or_projected_s, crossing_time_s  # noqa: F401  (re-exported)
from ..report.result import Result, draw_curves
from ..sim.simulate import SimulationResult
from .model import FittedModel

#: Bean temperatures whose crossing times the table reports [degC].
MILESTONES_C = (150.0, 170.0)


@dataclass
class SettingChange:
    """One change of a logged setting: ``+d`` / ``-d`` (shift), ``xf`` (scale) or ``=v@t`` (set from t)."""

    setting: str
    how: str  # "shift" | "scale" | "set"
    value: float
    from_s: float = 0.0

    def apply(self, t: np.ndarray, series: np.ndarray) -> np.ndarray:
        out = series.copy()
        after = t >= self.from_s
        if self.how == "shift":
            out[after] += self.value
        elif self.how == "scale":
            out[after] *= self.value
        else:
            out[after] = self.value
        return out

    def __str__(self) -> str:
        if self.how == "set":
            return f"{self.setting} = {self.value:g} from {self.from_s:g} s"
        return f"{self.setting} {'x' if self.how == 'scale' else '+' if self.value >= 0 else ''}{self.value:g}"


_CHANGE = re.compile(r"^\s*(x|\*)?\s*([+-]?\d+(?:\.\d*)?(?:[eE][+-]?\d+)?)\s*$")
_SET = re.compile(r"^\s*(heater|fan)\s*=\s*([+-]?\d+(?:\.\d*)?)\s*@\s*(\d+(?:\.\d*)?)\s*$")


def parse_setting_change(setting: str, text: str) -> SettingChange:
    """``"+1"``, ``"-2"`` (shift) or ``"x1.1"`` (scale) for ``setting``."""
    m = _CHANGE.match(text)
    if not m:
        raise ParameterError(f"--{setting} {text!r}: give a shift such as +1 or -2, or a factor such as x1.1")
    value = float(m.group(2))
    return SettingChange(setting, "scale" if m.group(1) else "shift", value)


def parse_set(text: str) -> SettingChange:
    """``"heater=6@120"``: the setting becomes 6 from 120 s after CHARGE on."""
    m = _SET.match(text)
    if not m:
        raise ParameterError(f"--set {text!r}: expected SETTING=VALUE@SECONDS, e.g. heater=6@120 (heater or fan)")
    return SettingChange(m.group(1), "set", float(m.group(2)), float(m.group(3)))


@dataclass
class WhatIf(Result):
    """The log, its prediction as run and with the changes, and the comparison table."""

    batch: Batch
    as_run: SimulationResult
    changed: SimulationResult
    changes: list[str]
    rows: list[dict]

    def table(self) -> str:
        lines = [f"what if ({'; '.join(self.changes) or 'no change'}) on {self.batch.name}"]
        lines.append(f"{'':50s}{'as run':>10s}{'changed':>10s}{'change':>10s}")
        for r in self.rows:
            a, c = r["as_run"], r["changed"]
            fa = "-" if a is None else f"{a:.1f}"
            fc = "-" if c is None else f"{c:.1f}"
            fd = "-" if a is None or c is None else f"{c - a:+.1f}"
            lines.append(f"{r['what'] + ' [' + r['unit'] + ']':50s}{fa:>10s}{fc:>10s}{fd:>10s}")
        return "\n".join(lines)

    def summary(self) -> str:
        """The comparison table (:meth:`table`)."""
        return self.table()

    def to_json_dict(self) -> dict:
        return {"batch": self.batch.name, "changes": self.changes, "rows": self.rows}

    def to_frame(self):
        """One row per figure of the table: what, unit, as run, changed."""
        import pandas as pd

        return pd.DataFrame(self.rows)

    def _figure(self, path, outputs):
        from ..report.figures import plot_whatif

        return plot_whatif(self, path, outputs=outputs)

    def _draw(self, ax) -> None:
        t = self.as_run.time_s
        curves = {"BT measured": (t, self.batch.Ta_C), "BT as run (model)": (t, self.as_run.Ta_C)}
        curves["BT changed (model)"] = (t, self.changed.Ta_C)
        draw_curves(ax, curves, "BT [°C]")


def whatif(
    model: FittedModel,
    batch: Batch,
    setting_changes: list[SettingChange] = (),
    **changes,
) -> WhatIf:
    """Predict ``batch`` as logged and with the changes; compare at the roast's milestones.

    ``setting_changes`` change the logged heater/fan series; ``changes`` are those of
    :meth:`FittedModel.apply` (``Tgi_offset_C``, ``batch_kg``, ``Tm0_C`` ...).
    """
    changed_batch = batch
    labels = [str(c) for c in setting_changes]
    for c in setting_changes:
        series = getattr(changed_batch, c.setting)
        if series is None:
            raise ParameterError(f"the log has no {c.setting} setting (its map reads none), so it cannot change")
        changed_batch = dataclasses.replace(changed_batch, **{c.setting: c.apply(batch.time_s, series)})
    names = {"Tgi_offset_C": "Tgi {:+g} degC", "batch_kg": "batch {:g} kg", "Tm0_C": "drum at charge {:g} degC"}
    labels += [names.get(k, k + " = {:g}").format(float(v)) for k, v in changes.items()]
    as_run = model.predict(batch)
    changed = model.predict(changed_batch, **changes)
    t = batch.time_s
    rows = [
        {
            "what": "BT at the logged DROP time",
            "unit": "degC",
            "as_run": float(as_run.Ta_C[-1]),
            "changed": float(changed.Ta_C[-1]),
        }
    ]
    levels = list(MILESTONES_C)
    fc = batch.events.get("FCs")
    if fc is not None and batch.Ta_C is not None and t[0] <= fc <= t[-1]:
        levels.append(round(float(np.interp(fc, t, batch.Ta_C)), 1))
    for k, level in enumerate(levels):
        what = f"time to BT {level:g} degC" + (" (logged first crack)" if k >= len(MILESTONES_C) else "")
        rows.append(
            {
                "what": what,
                "unit": "s",
                "as_run": crossing_time_s(t, as_run.Ta_C, level),
                "changed": crossing_time_s(t, changed.Ta_C, level),
            }
        )
    return WhatIf(batch, as_run, changed, labels, rows)
