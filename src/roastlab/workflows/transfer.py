"""Profile transfer: the input program that reproduces a roast's bean-probe curve on another
plant or at another batch size (``roastlab transfer``, ``model.transfer``).

The target is the reference's probe curve from CHARGE to DROP, resampled to the program's
knots (every ``interval_s``). The fitted model is applied to plant B (values that carry over
stay, plant-specific ones are dropped, as everywhere: :meth:`FittedModel.apply`) with the
reference's inputs, which gives plant B's parameter vector, its charge state and the first
baseline (B run with A's inputs unchanged). :func:`roastlab.fit.program.optimise_program`
then finds the program within the limits. A second baseline retimes A's inputs by the phase
times the first baseline gives on B, as a person does with Artisan's Transposer.
"""

from __future__ import annotations

import dataclasses
import io
import math

import numpy as np

from ..errors import InputError
from ..fit.program import (
    ProgramLimits,
    ProgramResult,
    input_reach_C,
    level_labels,
    limit_spans,
    optimise_program,
    runnable_program,
    true_runs,
)
from ..io.batch import Batch
from ..metrics.profile import (
    DRY_END_C,
    FIRST_CRACK_C,
    area_under_curve_C_min,
    auc_base_C,
    crossing_or_projected_s,
    crossing_time_s,
    display_units,
    mmss,
    turning_point,
)
from ..model.actuators import MIN_HOLD_S, SETTING_GAINS, inert_settings
from ..model.layout import S_TB, S_TM, STATE0
from ..model.limits import check_value
from ..model.plant import Plant
from ..model.rhs import P, drum_start_reading_C
from ..report.result import Result, draw_curves
from ..sim.population import PARAM_SLOTS

#: Probe temperatures [degC] whose crossing times define the phases of the retimed baseline:
#: end of drying (~150 degC, Artisan's DRY) and start of first crack (~196 degC, FCs).
PHASE_LEVELS_C = (DRY_END_C, FIRST_CRACK_C)


def _errors(pred, target) -> dict:
    e = np.asarray(pred) - np.asarray(target)
    if not np.all(np.isfinite(e)):
        return {"rmse_C": None, "max_abs_C": None}
    return {"rmse_C": float(np.sqrt(np.mean(e**2))), "max_abs_C": float(np.max(np.abs(e)))}


def _auc(t, y, base_C) -> float | None:
    """``y``'s area under the curve from its turning point above ``base_C``, the target's
    (:func:`~roastlab.metrics.profile.auc_base_C`: one base for the target and every program, as the
    what-if table takes one); None for a curve that could not be simulated."""
    return area_under_curve_C_min(t, y, turning_point(t, y)[0], base_C)


def _scored(pred, target, t, base_C) -> dict:
    """:func:`_errors` of ``pred`` against ``target`` and its :func:`_auc` as ``AUC_C_min``."""
    return _errors(pred, target) | {"AUC_C_min": _auc(t, pred, base_C)}


@dataclasses.dataclass
class TransferResult(Result):
    """The program, its predicted curve, the baselines and the metrics of a transfer."""

    reference: str
    plant_from: str
    plant_to: str
    batch_kg: float
    time_s: np.ndarray
    target_C: np.ndarray
    program: ProgramResult
    limits: ProgramLimits
    baselines: dict  # name -> predicted Ta on B [degC]
    baseline_inputs: dict  # name -> the decided input's program [u units]
    metrics: dict
    model_fits_flow: bool = False
    actuators: bool = False
    #: the optimiser's continuous program, when ``program`` is it rounded to the machine's settings
    continuous: ProgramResult | None = None
    #: the reference's event marks [s from CHARGE] (CHARGE, DRY, FCs, DROP ...)
    events: dict = dataclasses.field(default_factory=dict)
    #: what ET is on the target machine: "Tgi" (inlet gas) or "Tm" (drum)
    et_source: str = "Tgi"
    #: the machine's fan (for the background's Air events), when the map declares one
    fan_actuator: object = None
    #: "C" or "F": the unit the summary and the figure give temperatures in (the reference log's own
    #: unless asked otherwise); the arrays and the metrics stay in degC
    units: str = "C"
    #: "C" or "F": the unit the reference log was recorded in, its Artisan background's mode
    log_unit: str = "C"
    #: the predicted probe BT's prediction band (:class:`roastlab.evaluate.bands.Band`) when asked for
    band: object | None = None
    #: why the band may hold fewer samples than its level (:func:`roastlab.evaluate.bands.band_note`)
    band_note: str | None = None

    # ------------------------------------------------------------------ text outputs
    def summary(self) -> str:
        from ..metrics.profile import display_temp, display_temp_delta, temp_symbol

        m, units = self.metrics, self.units
        u = temp_symbol(units)

        def d(v):  # an error or a tolerance in the summary's unit
            return display_temp_delta(v, units)

        head = (
            f"transfer of {self.reference}: {self.plant_from} -> {self.plant_to} ({self.batch_kg:g} kg), "
            f"{len(self.time_s)} knots every {self.time_s[1] - self.time_s[0]:g} s"
        )

        def auc(v):  # Artisan's area under the curve, whole degree-minutes in the summary's unit
            return f"{d(v):>13.0f}" if v is not None else f"{'-':>13}"

        rows = [head, "", f"{'program':<24} {'RMSE ' + u:>9} {'max |e| ' + u:>11} {'AUC ' + u + '·min':>13}"]
        rows.append(f"{'target':<24} {'':>9} {'':>11} {auc(m.get('target_AUC_C_min'))}")
        label = "runnable (machine steps)" if "runnable" in m else "optimised"
        rows.append(f"{label:<24} {d(m['rmse_C']):>9.3f} {d(m['max_abs_C']):>11.3f} {auc(m.get('AUC_C_min'))}")
        if "continuous" in m and m["continuous"]["rmse_C"] is not None:
            c = m["continuous"]
            rows.append(
                f"{'continuous (optimiser)':<24} {d(c['rmse_C']):>9.3f} {d(c['max_abs_C']):>11.3f} {auc(c.get('AUC_C_min'))}"
            )
        for key, label in (
            ("baseline_same_inputs", "A's inputs unchanged"),
            ("baseline_retimed", "A's inputs retimed"),
            ("reference_own_inputs_on_A", "A's inputs on A"),
        ):
            b = m[key]
            if b["rmse_C"] is None:
                rows.append(f"{label:<24} {'(could not be simulated)':>21}")
            else:
                rows.append(f"{label:<24} {d(b['rmse_C']):>9.3f} {d(b['max_abs_C']):>11.3f} {auc(b.get('AUC_C_min'))}")
        if m.get("AUC_base_C") is not None:
            rows.append(
                "AUC: from each curve's turning point to DROP, above the target's BT at its turning point "
                f"({display_temp(m['AUC_base_C'], units):.1f} {u})"
            )
        rows.append(
            f"A's inputs on A: the model on {self.plant_from} as the reference was run; the program is judged by "
            "the model, which misses the target by this much before any change (a roast's own miss does not "
            "carry over to the next: docs/profile-transfer.md)"
        )
        rows.append("")
        verdict = "feasible" if m["feasible"] else "NOT feasible"
        rows.append(
            f"{verdict} (max |e| {'<=' if m['feasible'] else '>'} {d(m['tolerance_C']):g} {u}); "
            f"solved in {m['solve_s']:.2f} s ({m['simulations']} simulations)"
        )
        rows += [f"  {s}" for s in m["explanation"]]
        after, tp_s = m.get("max_abs_from_turning_point_C"), m.get("turning_point_s")
        if not m["feasible"] and after is not None and tp_s:  # a turning point at CHARGE says nothing new
            line = f"  from the target's turning point ({mmss(tp_s)}) on: max |e| {d(after):.1f} {u}"
            if after <= m["tolerance_C"]:
                line += (
                    ", within the tolerance: the misses are the charge's dip, which the drum and the probe at "
                    "CHARGE set more than the program does"
                )
                if not m.get("Tm0_chosen"):
                    line += " (--tm0 free lets the optimiser choose the drum at CHARGE)"
            rows.append(line)
        if m.get("Tm0_chosen"):
            rows.append(f"drum at CHARGE (chosen by the optimiser): {display_temp(m['Tm0_C'], units):.0f} {u}")
        if self.band is not None:
            from ..evaluate.bands import band_words

            rows.append(band_words(self.band, "the predicted BT", units))
            rows.append(
                "  (a roast run with the program is expected inside it; the tolerance above is the model against "
                "the target, not the roast against the model)"
            )
            if self.band_note:
                rows.append(f"note: {self.band_note}")
        if "runnable" in m:
            r = m["runnable"]
            rows.append(f"program ({r['what']}):")
            rows.append("  " + ", ".join(f"{c['setting']} at {mmss(c['time_s'])}" for c in r["changes"]))
        return "\n".join(rows)

    def to_json_dict(self) -> dict:
        return self.metrics

    def program_batch(self) -> Batch:
        """The program as a batch on plant B: its inputs, the batch mass and the charge state it was
        optimised for, so that the model applied to it (``model.predict(batch, plant=B)``) gives
        ``Ta_pred_C``; what PROGRAM.csv holds (:meth:`program_csv_text`). A model that fitted a constant
        flow gets its 1 kg/s placeholder (it applies its own). The drum at CHARGE is the reading that
        implies it (:func:`roastlab.model.rhs.drum_at_charge_C`), as a log gives it."""
        pr = self.program
        x0 = pr.states[0].copy()  # the charge state the program was optimised for (Tm0 possibly chosen)
        x0[S_TM] = drum_start_reading_C(x0[S_TM], pr.params[P["Tm0_share"]], pr.params[P["T_room"]])
        return Batch(
            f"{self.reference} program",
            pr.time_s.copy(),
            np.ones_like(pr.Gg_kg_s) if self.model_fits_flow else pr.Gg_kg_s.copy(),
            pr.Tgi_C.copy(),
            initial={key: float(x0[STATE0[key]]) for key in ("Tm0_C", "Tb0_C", "X0", "Ta0_C")},
            Mb_kg=self.batch_kg,
            heater=pr.heater.copy() if self.actuators else None,
            fan=pr.fan.copy() if self.actuators else None,
        )

    def program_csv_text(self) -> str:
        """PROGRAM.csv: :meth:`program_batch` and the predicted probe; metadata lines carry the charge
        state and batch mass, so ``roastlab simulate --inputs`` reproduces ``Ta_pred_C``."""
        b = self.program_batch()
        out = io.StringIO()
        out.write(f"## roastlab transfer program: {self.plant_from} -> {self.plant_to}\n")
        if self.model_fits_flow:
            out.write("## Gg_kg_s is the model's placeholder: the flow is the model's fitted Gg_kg_s\n")
        out.write(f"# Mb_kg = {b.Mb_kg:.6g}\n")
        for key, value in b.initial.items():
            out.write(f"# {key} = {value:.10g}\n")
        cols = ["time_s", "Gg_kg_s", "Tgi_C"] + (["heater", "fan"] if self.actuators else []) + ["Ta_pred_C"]
        out.write(",".join(cols) + "\n")
        for i, t in enumerate(b.time_s):
            vals = [f"{t:.6g}", f"{b.Gg_kg_s[i]:.10g}", f"{b.Tgi_C[i]:.10g}"]
            if self.actuators:
                vals += [f"{b.heater[i]:.10g}", f"{b.fan[i]:.10g}"]
            vals.append(f"{self.program.Ta_pred_C[i]:.6f}")
            out.write(",".join(vals) + "\n")
        return out.getvalue()

    def background_events(self) -> list[tuple[int, str, float, str]]:
        """The program as Artisan special events (:func:`roastlab.io.background.setting_events`):
        ``Burner`` for the heater or the decided inlet temperature, ``Air`` for the fan or a chosen
        gas flow, in the machine's units (a level as the level, the inlet temperature and a flow as %
        of their range in 5 % steps); what the optimiser decided at most one change every
        :data:`~roastlab.model.actuators.MIN_HOLD_S` seconds, a held, logged setting with its own."""
        from ..io.background import setting_events

        return setting_events(self.program.time_s, self.setting_series())

    def alarms_text(self) -> str:
        """The heater program (and the fan, where it is the machine's) as an Artisan alarm set
        (:func:`roastlab.io.background.alarms_text`): loaded in Artisan (Config > Alarms > Load), it
        moves the Burner and Air sliders at the program's changes after CHARGE, on a machine Artisan
        controls. Only a program that sets the machine's heater: an inlet temperature or a gas flow has
        no slider of the machine's to move."""
        from ..io.background import alarms_text

        if self.limits.decide != "heater":
            raise InputError(
                "Artisan alarms move the machine's heater slider: this program sets the inlet gas temperature "
                "(a model whose map reads a heater decides the heater)",
                "--alarms",
            )
        # the heater, and the fan where it is the machine's own (not a chosen flow as % of its range)
        series = [s for s in self.setting_series() if s[0] == "heater" or s[2] is self.fan_actuator]
        return alarms_text(self.program.time_s, series, note="roastlab transfer")

    def setting_series(self) -> list:
        """The program's settings for :func:`roastlab.io.background.setting_events`:
        ``(setting, values, actuator for labels, thin?)`` (see :meth:`background_events`)."""
        from ..model.actuators import Actuator

        pr, lim = self.program, self.limits
        series = []  # (setting, values, actuator for labels, thin?)
        if lim.decide == "heater":
            act = lim.actuator or Actuator("heater", "percent", lim.low, lim.high)
            series.append(("heater", pr.heater, act, lim.actuator is None or not lim.actuator.stepped))
        else:
            pct = Actuator("heater", "percent", 0.0, 100.0, 5.0)
            series.append(("heater", pct.quantise(100.0 * (pr.Tgi_C - lim.low) / (lim.high - lim.low)), pct, True))
        if self.actuators and np.any(pr.fan != 0):
            fan = self.fan_actuator or Actuator("fan", "percent", 0.0, 100.0)
            series.append(("fan", pr.fan, fan, False))
        elif lim.gg_free:
            pct = Actuator("fan", "percent", 0.0, 100.0, 5.0)
            span = lim.Gg_max_kg_s - lim.Gg_min_kg_s
            series.append(("fan", pct.quantise(100.0 * (pr.Gg_kg_s - lim.Gg_min_kg_s) / span), pct, True))
        return series

    def alog_text(self) -> str:
        """An Artisan profile (Python-literal .alog, as Artisan writes) to load as a background
        (:func:`roastlab.io.background.background_alog_text`): BT the predicted probe, ET the model's
        ET (the inlet gas or the drum, as the machine's map defines ET), the reference's event marks
        (CHARGE, DRY, FCs, ..., DROP) and the program as events (:meth:`background_events`)."""
        from ..io.background import background_alog_text

        pr, lim = self.program, self.limits
        et = {"Tm": pr.states[:, S_TM], "Tb": pr.states[:, S_TB]}.get(self.et_source, pr.Tgi_C)
        decided = (
            lim.actuator.describe()
            if lim.actuator is not None
            else f"{lim.decide} {lim.low:g}..{lim.high:g} {lim.unit}"
        )
        return background_alog_text(
            pr.time_s,
            pr.Ta_pred_C,
            et,
            self.events,
            self.background_events(),
            title=f"roastlab transfer: {self.reference} on {self.plant_to} (predicted)",
            notes=(
                f"Computed by roastlab transfer from {self.reference} ({self.plant_from} -> {self.plant_to}, "
                f"{self.batch_kg:g} kg). BT is the model's prediction, ET the model's {ET_CURVE[self.et_source]}; "
                f"Burner events = the decided {decided}."
            ),
            roaster=self.plant_to,
            batch_kg=self.batch_kg,
            mode=self.log_unit,  # the roaster's own unit, as Artisan recorded the reference
        )

    def to_frame(self):
        """The program on its knots: time, the inputs, the target and the predicted probe."""
        import pandas as pd

        pr = self.program
        cols = {"time_s": pr.time_s, "Gg_kg_s": pr.Gg_kg_s, "Tgi_C": pr.Tgi_C}
        if self.actuators:
            cols["heater"] = pr.heater
        cols.update({"target_C": self.target_C, "Ta_pred_C": pr.Ta_pred_C})
        return pd.DataFrame(cols)

    def _figure(self, path, outputs):
        from ..report.figures import plot_transfer

        return plot_transfer(self, path, outputs=outputs)

    def _draw(self, ax) -> None:
        t = self.time_s
        draw_curves(ax, {"reference BT": (t, self.target_C), "predicted BT": (t, self.program.Ta_pred_C)}, "BT [°C]")


def default_limits(model, plant_from=None, plant_to=None) -> ProgramLimits:
    """The input a program decides for ``model`` by default: on the model's own machine, the
    control its map has (:meth:`ProgramLimits.for_model`: the heater on a machine whose inlet is
    room air); on another plant, whose controls the map does not describe, the inlet gas
    temperature (the paper's input)."""
    from ..io.plants import load_plant

    pa = load_plant(plant_from) if plant_from is not None else model.plant
    pb = load_plant(plant_to) if plant_to is not None else pa
    if pa != pb:
        return ProgramLimits()
    return ProgramLimits.for_model(getattr(model, "column_map", None))


#: The model quantity a background's ET curve carries, per :func:`et_source`, as its notes name it.
ET_CURVE = {"Tm": "drum temperature", "Tgi": "inlet gas temperature", "Tb": "bean temperature"}


def et_source(cmap) -> str:
    """What ET is on this machine, for the background's ET curve: the inlet gas where the map
    reads ET as the inlet (``[Tgi] column = "ET"``); the beans where it reads ET as a bean reading
    (``[Tb2] column = "ET"``: an infrared bean sensor, as Artisan's Aillio Bullet R1 IBTS device
    logs ET), so the background's ET lies over the roaster's own ET curve; else the drum (the
    Skywalker's and the Bullet's ET is the drum's temperature, as their maps' [initial] Tm0_C says)."""
    if cmap is not None and cmap.Tgi.get("column") == "ET":
        return "Tgi"
    if cmap is not None and cmap.et_is_bean_reading:
        return "Tb"
    return "Tm" if cmap is not None and cmap.inlet_is_constant else "Tgi"


def model_et_C(result, source: str) -> np.ndarray:
    """The model's curve for what the machine's ET measures (``source`` from :func:`et_source`) on a
    :class:`~roastlab.sim.simulate.SimulationResult`: the drum (Tm), the beans (Tb), or the inlet gas
    the model sees (after the heater's air path, :meth:`~roastlab.sim.simulate.SimulationResult.gas_seen`)."""
    if source == "Tm":
        return result.Tm_C
    if source == "Tb":
        return result.Tb_C
    return result.gas_seen()[1]


def aim_at(reference: Batch, target: Batch) -> Batch:
    """``reference`` (a log of the model's machine: its inputs, batch and charge state) with ``target``'s
    probe curve as the one to follow: a roast of another machine, one drawn in Artisan's Designer, a
    competitor's. On the target's time from its CHARGE to its DROP, with its marks; the reference's inputs
    interpolated there (settings held, the last value held past the reference's end) as the program's
    start and the baselines' inputs."""
    if target.Ta_C is None:
        raise InputError("the target has no bean-probe curve (BT): nothing to follow", target.source or target.name)
    t = np.asarray(target.time_s, dtype=float) - float(target.time_s[0])
    tr = np.asarray(reference.time_s, dtype=float) - float(reference.time_s[0])

    def held(series):
        return _held(series, tr, t)

    return dataclasses.replace(
        reference,
        name=target.name,
        source=target.source or target.name,
        time_s=t,
        Gg_kg_s=np.interp(t, tr, reference.Gg_kg_s),
        Tgi_C=np.interp(t, tr, reference.Tgi_C),
        Ta_C=np.asarray(target.Ta_C, dtype=float).copy(),
        heater=held(reference.heater),
        fan=held(reference.fan),
        Tb2_C=None,
        ET_C=None,
        events=dict(target.events),
        initial=dict(reference.initial),
        notes=[
            f"the curve to follow is {target.name}'s BT ({mmss(t[-1])} from CHARGE to DROP); the program starts "
            f"from {reference.name}'s inputs, batch and charge state"
        ],
    )


def _held(series, time_s, at_s):
    """A setting logged at ``time_s`` as held between its changes, at the times ``at_s`` (the first
    value before the log, the last after it); None for no series."""
    if series is None:
        return None
    j = np.clip(np.searchsorted(time_s, at_s, side="right") - 1, 0, len(time_s) - 1)
    return np.asarray(series, dtype=np.float64)[j]


def _grid_batch(ref: Batch, interval_s: float) -> Batch:
    """The reference on the program's knots: inputs and probe interpolated, settings held."""
    t_end = float(ref.time_s[-1])
    t = np.arange(0.0, t_end + 1e-9, interval_s) + float(ref.time_s[0])

    def held(series):
        return _held(series, ref.time_s, t)

    return dataclasses.replace(
        ref,
        time_s=t - t[0],
        Gg_kg_s=np.interp(t, ref.time_s, ref.Gg_kg_s),
        Tgi_C=np.interp(t, ref.time_s, ref.Tgi_C),
        Ta_C=np.interp(t, ref.time_s, ref.Ta_C),
        heater=held(ref.heater),
        fan=held(ref.fan),
        Tb2_C=None,
        ET_C=None,
        initial=dict(ref.initial),
    )


def _retime(t, u, t_ref_marks, t_same_marks):
    """``u`` retimed so that at the reference's phase time t_ref_i the program has reached
    what it had at t_same_i (piecewise linear, the last ratio held after the last mark)."""
    xs, ys = [0.0], [0.0]
    for a, b in zip(t_ref_marks, t_same_marks):
        if a > xs[-1] and b > ys[-1]:
            xs.append(a)
            ys.append(b)
    ratio = ys[-1] / xs[-1] if xs[-1] > 0 else 1.0
    phi = np.where(t <= xs[-1], np.interp(t, xs, ys), ys[-1] + (t - xs[-1]) * ratio)
    return np.interp(phi, t, u), list(zip(xs[1:], ys[1:]))


def transfer(
    model,
    reference: Batch,
    plant_from=None,
    plant_to=None,
    *,
    limits: ProgramLimits | None = None,
    batch_kg: float | None = None,
    gg_kg_s: float | None = None,
    interval_s: float = 5.0,
    tm0_free: tuple[float, float] | None = None,
    tolerance_C: float = 2.0,
    initial: dict | None = None,
    band_level: float | None = None,
    units: str | None = None,
) -> TransferResult:
    """Compute the program that reproduces ``reference``'s probe curve on ``plant_to``.

    Parameters
    ----------
    model : FittedModel (its carried-over values are applied on ``plant_to``)
    reference : Batch with ``Ta_C`` from CHARGE (t = 0) to DROP, and the inputs it was run with
    plant_from, plant_to : Plant, preset name or PLANT.toml (default: the model's plant)
    limits : :class:`ProgramLimits` (default: :func:`default_limits`, the heater on a room-air
        machine whose map reads one, else the inlet gas within ``TGI_LIMITS``)
    batch_kg : green batch mass on B [kg] (default: B's nominal batch when B differs from A,
        else the reference's)
    gg_kg_s : fixed gas flow on B [kg/s] (default: A's flow scaled by the batch-mass ratio);
        ignored when ``limits`` gives a Gg range (then a constant Gg is a decision)
    interval_s : spacing of the program's knots [s]
    tm0_free : (lo, hi) [degC] to make the drum temperature at CHARGE a decision
    tolerance_C : the program is ``feasible`` when max |Ta_pred - target| is at most this
    initial : charge state changes on B (``Tb0_C``, ``Tm0_C``, ``X0``)
    band_level : e.g. 0.9: also the predicted probe BT's prediction band, the program's batch
        (:meth:`TransferResult.program_batch`) through :func:`roastlab.evaluate.bands.prediction_bands`
    units : "C" or "F", the unit of the summary's and the figure's temperatures (default: the reference
        log's own, :attr:`Batch.temp_unit`); every array and metric stays in degC
    """
    from ..io.plants import load_plant

    if band_level is not None:
        from ..evaluate.bands import check_level, require_band

        band_level = check_level(band_level)
        require_band(model)

    limits = limits or default_limits(model, plant_from, plant_to)
    src = reference.source or reference.name
    if reference.Ta_C is None:
        raise InputError("the reference has no bean-probe curve (Ta_C): nothing to transfer", src)
    interval_s = check_value("dt_s", interval_s, "--interval-s")
    span = float(reference.time_s[-1] - reference.time_s[0])
    if span < 2 * interval_s:
        raise InputError(
            f"the reference spans {span:g} s from CHARGE to DROP, shorter than two {interval_s:g} s intervals", src
        )
    if not tolerance_C > 0 or not math.isfinite(tolerance_C):
        raise InputError(f"tolerance must be a positive number of degC, got {tolerance_C!r}", "--tolerance")
    pa: Plant = load_plant(plant_from) if plant_from is not None else model.plant
    pb: Plant = load_plant(plant_to) if plant_to is not None else pa
    if pa is None:
        raise InputError("the model names no plant: give the reference's plant (--from)", model.source)
    if limits.decide == "heater" and reference.heater is None:
        raise InputError("the program is to decide the heater, but the reference has no heater setting", src)
    same_plant = pa == pb
    cmap = model.column_map
    if limits.decide == "Tgi" and same_plant and cmap is not None and cmap.inlet_is_constant and cmap.heater:
        raise InputError(
            f"this machine's inlet is room air (the map's [Tgi] constant_C = {cmap.Tgi['constant_C']:g}): "
            "a program cannot set it; decide the heater (the default for this model)",
            "--decide Tgi",
        )
    mass_a = reference.Mb_kg or pa.Mb_kg
    mass_b = (
        check_value("batch_kg", batch_kg, "--batch-kg")
        if batch_kg is not None
        else (mass_a if same_plant else pb.Mb_kg)
    )
    if batch_kg is not None:
        pb.check_batch_mass(mass_b)
    grid = _grid_batch(reference, interval_s)
    ta0 = float(grid.Ta_C[0])
    changes = dict(initial or {})
    changes["Ta0_C"] = ta0
    res_a = model.predict(grid, plant=pa, **changes)

    # B with A's inputs, unchanged (baseline 1); it also gives B's parameters and charge state.
    # On another plant a flow the model fitted for A is dropped, so B gets A's flow as applied.
    grid_b = dataclasses.replace(grid, Mb_kg=mass_b)
    if not same_plant:
        grid_b.Gg_kg_s = res_a.Gg_kg_s.copy()
    res_same = model.predict(grid_b, plant=pb, **changes)
    p_b = res_same.params
    gains = SETTING_GAINS.get(limits.decide, ())
    if gains and inert_settings({g: p_b[PARAM_SLOTS[g]] for g in gains}, [limits.decide]):
        raise InputError(
            f"the {limits.decide} has no effect on {pb.name}: its gains ({', '.join(gains)}) are 0 or negligible there "
            "(plant-specific values do not carry over to another plant); decide Tgi",
            f"--decide {limits.decide}",
        )
    x0 = res_same.states[0].copy()
    # on its own plant a model that fitted a constant flow applies it; elsewhere that value is dropped
    fits_flow = same_plant and "Gg_kg_s" in model.parameters
    if limits.gg_free or fits_flow:
        gg_b = res_same.Gg_kg_s.copy()
    elif gg_kg_s is not None:
        gg_b = np.full(grid.n, check_value("Gg_kg_s", gg_kg_s, "--gg"))
    else:
        gg_b = res_a.Gg_kg_s * (mass_b / mass_a)
    target = grid.Ta_C

    program = optimise_program(
        grid.time_s,
        target,
        x0,
        p_b,
        gg_b,
        res_a.Tgi_C,
        limits,
        heater=grid.heater,
        fan=grid.fan,
        zoh=model.hold == "zoh",
        tm0_bounds=tm0_free,
    )
    continuous = program
    if limits.actuator is not None and limits.actuator.stepped:
        # the machine's settings, changed a few times a minute: the program a roaster can run
        program = runnable_program(continuous, target, limits.actuator)
    t = grid.time_s
    auc_base = auc_base_C(t, target)
    err = _scored(program.Ta_pred_C, target, t, auc_base)
    # the model's own run of the reference on A: how far the model is from the target before any program
    own = {**_scored(res_a.Ta_C, target, t, auc_base), "what": "plant A run with its own inputs (the model as logged)"}

    # baseline 2: A's inputs retimed by the phase times baseline 1 gives on B
    levels = [lv for lv in PHASE_LEVELS_C if crossing_time_s(t, target, lv) is not None]
    if not levels:  # a light or short roast: the level 80 % of the way from the turning point to DROP
        levels = [float(np.min(target) + 0.8 * (target[-1] - np.min(target)))]
    marks_ref = [crossing_time_s(t, target, lv) for lv in levels]
    marks_same = [crossing_or_projected_s(t, res_same.Ta_C, lv) for lv in levels]
    pairs = [(a, b) for a, b in zip(marks_ref, marks_same) if b is not None]
    decided = res_a.Tgi_C if limits.decide == "Tgi" else grid.heater
    retimed, used = _retime(t, decided, [a for a, _ in pairs], [b for _, b in pairs])
    kw = {"Tgi_C": retimed} if limits.decide == "Tgi" else {"heater": retimed}
    try:
        res_ret = model.predict(grid_b, plant=pb, **changes, **kw)
        ta_ret = res_ret.Ta_C
    except InputError:
        ta_ret = np.full(grid.n, np.nan)
    base_same = {**_scored(res_same.Ta_C, target, t, auc_base), "what": "plant B run with plant A's inputs unchanged"}
    base_ret = {
        **_scored(ta_ret, target, t, auc_base),
        "what": "plant A's inputs retimed by the phase times the same-input run gives on B (Transposer-style)",
        "phase_marks_s": [{"reference_s": a, "same_inputs_s": b} for a, b in used],
    }
    spans = limit_spans(t, program.Tgi_C if limits.decide == "Tgi" else program.heater, limits)
    feasible = err["max_abs_C"] is not None and err["max_abs_C"] <= tolerance_C
    # the curve before the target's turning point is the charge's (the probe falling from its soak
    # to the beans, the drum's heat at CHARGE) more than the program's: said apart, judged as a whole
    tp_s = turning_point(t, target)[0]
    from_tp = _errors(program.Ta_pred_C[t >= tp_s], target[t >= tp_s]) if tp_s is not None else None
    units = display_units(units or reference.temp_unit)
    explanation = _explain(
        t, program.Ta_pred_C - target, spans, tolerance_C, pb.name, mass_b, feasible, units,
        limits=limits, reach=None if feasible else input_reach_C(program, limits), tp_s=tp_s,
    )  # fmt: skip
    baselines_best = min((b["rmse_C"] for b in (base_same, base_ret) if b["rmse_C"] is not None), default=None)
    metrics = {
        "reference": src,
        "plant_from": pa.name,
        "plant_to": pb.name,
        "batch_kg": mass_b,
        "decide": limits.decide,
        **err,
        "feasible": bool(feasible),
        "tolerance_C": tolerance_C,
        "turning_point_s": tp_s,
        "target_AUC_C_min": _auc(t, target, auc_base),
        "AUC_base_C": auc_base,
        "max_abs_from_turning_point_C": from_tp["max_abs_C"] if from_tp else None,
        "solve_s": program.solve_s,
        "iterations": program.iterations,
        "simulations": program.simulations,
        "knots": int(grid.n),
        "interval_s": interval_s,
        "limits": {
            "low": limits.low,
            "high": limits.high,
            "rate_per_min": limits.rate_per_min,
            "unit": limits.unit,
            "Gg_min_kg_s": limits.Gg_min_kg_s,
            "Gg_max_kg_s": limits.Gg_max_kg_s,
        },
        "on_limits": spans,
        "Gg_kg_s": float(np.mean(program.Gg_kg_s)),
        "Tm0_C": program.Tm0_C,
        "Tm0_chosen": tm0_free is not None,
        "reference_own_inputs_on_A": own,
        "baseline_same_inputs": base_same,
        "baseline_retimed": base_ret,
        "improvement_over_best_baseline": (
            None if baselines_best is None or not err["rmse_C"] else baselines_best / err["rmse_C"]
        ),
        "explanation": explanation,
        "notes": list(res_same.meta.get("notes", [])) + program.notes,
    }
    if program is not continuous:
        act = limits.actuator
        steps = np.flatnonzero(np.diff(program.heater)) + 1
        metrics["runnable"] = {
            "what": f"{act.describe()}, held at least {MIN_HOLD_S:g} s between changes",
            "changes": [{"time_s": float(t[k]), "setting": act.label(program.heater[k])} for k in [0, *steps]],
        }
        metrics["continuous"] = {
            **_scored(continuous.Ta_pred_C, target, t, auc_base),
            "what": "the optimiser's continuous program, before rounding to the machine's settings",
        }
    result = TransferResult(
        reference=reference.name,
        plant_from=pa.name,
        plant_to=pb.name,
        batch_kg=mass_b,
        time_s=t,
        target_C=target,
        program=program,
        limits=limits,
        baselines={"A's inputs unchanged": res_same.Ta_C, "A's inputs retimed": ta_ret},
        baseline_inputs={"A's inputs unchanged": decided, "A's inputs retimed": retimed},
        metrics=metrics,
        model_fits_flow=fits_flow,
        actuators=grid.heater is not None or grid.fan is not None,
        continuous=continuous,
        events=dict(reference.events),
        et_source=et_source(cmap),
        fan_actuator=cmap.actuator("fan") if cmap is not None and cmap.fan else None,
        units=units,
        log_unit=reference.temp_unit,
    )
    if band_level is not None:
        from ..evaluate.bands import band_note, band_summary, prediction_bands

        run = result.program_batch()
        result.band = prediction_bands(model, [run], band_level, plant=pb)[0]
        result.band_note = band_note(model, [run], mass_b)
        metrics["band"] = band_summary(result.band, result.band_note)
    return result


def _spans_in_words(spans, listed: int = 3) -> str:
    """The spans a program sits on its limits, by limit: each span where a limit holds up to
    ``listed`` times, else how often, from when to when and for how long in all (a stepped program
    meets its rate limit at every step)."""
    words = []
    for limit in dict.fromkeys(s["limit"] for s in spans):
        own = [s for s in spans if s["limit"] == limit]
        if len(own) <= listed:
            words.append(f"{limit} " + ", ".join(f"{mmss(s['from_s'])}-{mmss(s['to_s'])}" for s in own))
        else:
            total = sum(s["to_s"] - s["from_s"] for s in own)
            words.append(
                f"{limit} {len(own)} times from {mmss(own[0]['from_s'])} to {mmss(own[-1]['to_s'])} "
                f"({mmss(total)} in all)"
            )
    return "; ".join(words)


def _explain(
    t, e, spans, tol, plant, mass, feasible, units: str = "C", *, limits=None, reach=None, tp_s=None
) -> list[str]:
    """Where the program misses the target by more than ``tol`` and why, the misses in ``units``
    ("C" or "F"). A miss larger at its worst knot than the decided input of ``limits`` can move the
    probe there at all (``reach`` [degC per knot], :func:`roastlab.fit.program.input_reach_C`) is no
    program's to close, and one at or before the target's turning point ``tp_s`` [s] is the charge's.
    Any other is explained by the limits that hold the program back in the direction of the miss
    (below the target: a ceiling or a rising rate; above it: a floor or a falling rate), so an
    explanation never contradicts the error it explains."""
    from ..metrics.profile import display_temp_delta, temp_symbol

    out = []
    bad = np.abs(e) > tol
    if feasible:
        if spans:
            out.append("on a limit: " + _spans_in_words(spans))
        return out
    for i, j in true_runs(bad):
        worst = int(i + np.argmax(np.abs(e[i : j + 1])))
        below = e[worst] < 0
        need = "up" if below else "down"
        active = [s for s in spans if s["holds_back"] == need and s["from_s"] <= t[j] and s["to_s"] >= t[i] - 60.0]
        side = "below" if below else "above"
        moved = None if reach is None else abs(float(reach[worst]))
        if moved is not None and moved < abs(e[worst]):  # at its worst, more than any program moves the probe
            low, high = level_labels(limits)
            why = (
                f"no program closes it: the {limits.decide} over its whole range ({low} against {high} from CHARGE "
                f"on) moves the predicted BT at {mmss(t[worst])} by at most "
                f"{display_temp_delta(moved, units):.1f} {temp_symbol(units)}"
            )
            if tp_s is not None and t[worst] <= tp_s:
                why += "; before the turning point the charge sets it (the drum's heat at CHARGE, the probe's fall onto the beans)"
        elif active:
            why = "; ".join(f"{s['limit']} from {mmss(s['from_s'])} to {mmss(s['to_s'])}" for s in active)
            verb = "cannot heat that fast" if below else "cannot cool that fast"
            why += f": the {mass:g} kg batch on {plant} {verb}"
        else:
            why = "no limit holds the program back here: the model cannot follow the target's shape"
        miss = display_temp_delta(abs(e[worst]), units)
        out.append(
            f"{mmss(t[i])}-{mmss(t[j])}: predicted BT up to {miss:.1f} {temp_symbol(units)} {side} the target; {why}"
        )
    return out
