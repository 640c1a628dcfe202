"""What a roaster's controls can be set to: levels, steps and how fast they may change.

A program a roaster can run is made of the settings the machine has: the Aillio Bullet's power
P0-P9 and fan F0-F12 are whole steps, an Artisan slider is a percentage a roaster moves in
5 % steps, a gas valve or an electric element may be continuous (kW, or the gas pressure a
burner's manometer reads, in kPa). Transfer and MPC decide
programs on these levels, the Artisan background writes them as events, the what-if names the
unit of a change. The column map declares a machine's controls (``[heater]`` / ``[fan]`` with
``unit`` and optionally ``min``, ``max``, ``step``, ``rate_per_min``); what it leaves out comes
from :data:`UNIT_DEFAULTS`, the one table of defaults per unit.

>>> a = Actuator("heater", "level", 0.0, 9.0, 1.0)
>>> a.label(7), a.quantise([6.6, 9.4, -1.0]).tolist()
('P7', [7.0, 9.0, 0.0])
>>> Actuator("fan", "percent", 0, 100, 5).label(35)
'35 %'
>>> Actuator("heater", "kPa", 0, 3.5).label(2.347)
'2.35 kPa'
>>> Actuator("heater", "reading", 0, 3.5).label(2.347)
'2.35'
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .quantities import quantity

#: Per unit: (lowest, highest, step or None for continuous, fastest change per minute).
#: A percentage slider moves in 5 % steps; a level knob in whole steps; kW is continuous.
UNIT_DEFAULTS: dict[str, tuple[float, float, float | None, float]] = {
    "percent": (0.0, 100.0, 5.0, 60.0),
    "level": (0.0, 20.0, 1.0, 12.0),
    # a machine's levels as Artisan's sliders show them, in tens: its Aillio Bullet setups log the
    # fan F1-F12 as 10-120 and the power P0-P9 as 0-90 (machine setup "Bullet R1 IBTS"), the R2's
    # power P0-P14 as 0-140 ("Bullet R2")
    "tens": (0.0, 200.0, 10.0, 120.0),
    "kW": (0.0, 1e4, None, 1e4),
    "W": (0.0, 1e5, None, 1e5),  # a heater's power readout in watts (an Artisan extra device)
    "rpm": (0.0, 1e5, None, 1e5),  # a fan's speed readout (an Artisan extra device such as "Fan RPM")
    # a fan's speed as its drive's frequency (a variable-frequency drive's readout, "Fan Hz"): the air
    # flow in proportion to it, as to the speed (the fan laws)
    "Hz": (0.0, 1e3, None, 1e3),
}
#: A control logged as a gas pressure (a gas burner's pressure at its jet, read off a manometer or a
#: pressure readout; kPa in most of the world, mbar/hPa in Europe, inches or mm of water column in
#: North America and Asia): continuous, no limit on its rate, in the unit the channel names.
PRESSURE_UNITS = ("kPa", "hPa", "mbar", "Pa", "psi", "inWC", "mmWC")
UNIT_DEFAULTS.update({unit: (0.0, 1e5, None, 1e5) for unit in PRESSURE_UNITS})
#: A continuous readout in a unit its name does not give (a burner's "Gas" reading 0.5-3.5, a pressure
#: or a power whose unit nobody wrote down): read as it is, its range the logged one.
UNIT_DEFAULTS["reading"] = (0.0, 1e5, None, 1e5)
#: The units ``roastlab init --heater-unit``/``--fan-unit`` may say a control is logged in: every unit
#: for the heater; not a power for the fan (a fan's power is not its air flow).
CONTROL_UNITS = {"heater": tuple(UNIT_DEFAULTS), "fan": tuple(u for u in UNIT_DEFAULTS if u not in ("kW", "W"))}
#: The power of a gas burner's pressure in the heat it releases (``heater_exp``,
#: :func:`roastlab.model.rhs.heater_drive`): the burner's heat follows its gas flow, and the flow
#: through its jet, an orifice, goes as the square root of the pressure across it.
PRESSURE_HEATER_EXP = 0.5
#: The power of a fan's pressure in the air flow it moves (``fan_exp``, :func:`roastlab.model.rhs.fan_drive`):
#: a fan logged as the pressure it makes across the drum (a draft in Pa) drives the air through a fixed
#: resistance, the drum and its beans, where the flow goes as the square root of the pressure drop.
PRESSURE_FAN_EXP = 0.5
#: How a setting's value reads to a roaster, per control and unit ("P7", "F3", "35 %").
_PREFIX = {("heater", "level"): "P", ("fan", "level"): "F", ("heater", "tens"): "P", ("fan", "tens"): "F"}
#: What a logged value is worth in the machine's own steps, per unit (a level in tens: a tenth).
_STEPS_PER_UNIT = {"tens": 0.1}
#: The fitted gains through which each control moves the model (:func:`roastlab.model.rhs.heater_power_kW`,
#: :func:`roastlab.model.rhs.gas_inputs`): the heater heats the drum metal and the air it heats, the
#: fan adds to the gas flow. A model whose gains of a control are all 0 does not respond to it.
SETTING_GAINS: dict[str, tuple[str, ...]] = {"heater": ("Qe_gain_kW", "Tgi_gain_C"), "fan": ("Gg_fan_kg_s",)}


#: A gain smaller than this share of its quantity's fit range (:data:`roastlab.model.quantities.QUANTITIES`)
#: moves nothing a roaster could see: a fit that drives a gain onto its floor of 0 leaves it at about
#: 1e-44, not 0 (a fan gain of 1e-9 kg/s per % adds 1e-7 kg/s at full fan to a flow near 1e-3 kg/s).
NEGLIGIBLE_GAIN_SHARE = 1e-9


def inert_settings(values: dict, settings) -> list[str]:
    """The ``settings`` ("heater", "fan") that move nothing in a model with these parameter
    ``values`` (registry names): every gain of :data:`SETTING_GAINS` absent, 0 or negligible
    (below :data:`NEGLIGIBLE_GAIN_SHARE` of its fit range, where a fit leaves a gain it put on its floor).

    >>> inert_settings({"Qe_gain_kW": 0.005, "Gg_fan_kg_s": 0.0}, ["heater", "fan"])
    ['fan']
    >>> inert_settings({"Qe_gain_kW": 0.005, "Gg_fan_kg_s": 1.4e-44}, ["fan"])
    ['fan']
    """

    def moves(name: str) -> bool:
        lo, hi = quantity(name).bounds
        return abs(values.get(name, 0.0)) > NEGLIGIBLE_GAIN_SHARE * (hi - lo)

    return [s for s in dict.fromkeys(settings) if not any(moves(k) for k in SETTING_GAINS[s])]


#: The inlet gas temperature as a decided input (the paper's gas roaster): lowest and highest
#: [degC] and fastest change [degC/min] a program may use unless told otherwise.
TGI_LIMITS = (150.0, 550.0, 120.0)
#: Shortest time a runnable program holds a setting before the next change [s]: a person at
#: the machine (or Artisan's playback) acts a few times a minute at most.
MIN_HOLD_S = 30.0
#: How far past a log's DROP a what-if may carry the roast on [s] (``roastlab whatif --drop-at/--drop-bt``):
#: its settings held at their last values, a few minutes of a roast that was not run, not a second roast.
DROP_LATER_MAX_S = 300.0


@dataclass(frozen=True)
class Actuator:
    """One control of a roaster: ``name`` ("heater" or "fan"), its ``unit`` ("percent",
    "level", "tens", "kW", "W", "rpm", "Hz", a gas pressure of :data:`PRESSURE_UNITS`, or "reading": a
    readout in a unit nobody named), the range ``low``..``high`` in that unit, the ``step`` between settings the
    machine offers (None: continuous) and the fastest change ``rate_per_min`` [unit/min]."""

    name: str
    unit: str
    low: float
    high: float
    step: float | None = None
    rate_per_min: float | None = None

    @classmethod
    def from_spec(cls, name: str, spec: dict) -> Actuator:
        """The actuator a map table declares (``unit``, optional ``min``/``max``/``step``/
        ``rate_per_min``), the rest from :data:`UNIT_DEFAULTS`."""
        unit = spec.get("unit", "percent")
        low, high, step, rate = UNIT_DEFAULTS[unit]
        return cls(
            name,
            unit,
            float(spec.get("min", low)),
            float(spec.get("max", high)),
            spec.get("step", step),
            float(spec.get("rate_per_min", rate)),
        )

    @property
    def stepped(self) -> bool:
        return self.step is not None and self.step > 0

    def quantise(self, values) -> np.ndarray:
        """``values`` clipped to the range and rounded to the nearest setting the machine has."""
        v = np.clip(np.asarray(values, dtype=float), self.low, self.high)
        if not self.stepped:
            return v
        return np.clip(self.low + np.round((v - self.low) / self.step) * self.step, self.low, self.high)

    def label(self, value: float) -> str:
        """The setting as a roaster reads it: "P7", "F3" (also logged in tens: 70, 30), "35 %", "2.5 kW"."""
        prefix = _PREFIX.get((self.name, self.unit))
        if prefix:
            return f"{prefix}{value * _STEPS_PER_UNIT.get(self.unit, 1.0):g}"
        if self.unit in PRESSURE_UNITS:  # read off a manometer: to its hundredths
            return f"{round(float(value), 2):g} {self.unit}"
        if self.unit == "reading":  # no unit to name: the number, to its hundredths
            return f"{round(float(value), 2):g}"
        return f"{value:g} %" if self.unit == "percent" else f"{value:g} {self.unit}"

    def artisan_slider(self, value: float) -> float:
        """The value Artisan's slider for this control takes for the setting ``value``: a machine's level
        in tens, as Artisan's Aillio setups have it (P6 is 60, :data:`UNIT_DEFAULTS` "tens"); every other
        unit as it is (a percentage, a level already logged in tens, a power)."""
        return value / _STEPS_PER_UNIT["tens"] if self.unit == "level" else value

    def describe(self) -> str:
        """``heater P0-P9 in steps of 1`` / ``fan 0-100 % in 5 % steps``."""
        if self.stepped:
            step = self.step * _STEPS_PER_UNIT.get(self.unit, 1.0)  # a level shown in tens steps by 1 level
            return f"{self.name} {self.label(self.low)}-{self.label(self.high)} in steps of {step:g}"
        return f"{self.name} {self.label(self.low)}-{self.label(self.high)} (continuous)"


#: Range of the drum temperature at CHARGE when a transfer chooses it (``--tm0 free``) [degC]:
#: from a barely warm drum to the top of the range an identification may give ``Tm0_C``.
TM0_FREE_RANGE_C = (60.0, quantity("Tm0_C").bounds[1])
