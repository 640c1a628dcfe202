"""The controller interface and what a controller is told before a roast.

A controller is any object with

* ``name`` (a short label for tables),
* ``reset(setup)`` -- called once before each roast with a :class:`LoopSetup`,
* ``step(time_s, measurement_C) -> float`` -- called every ``setup.sample_s`` seconds from
  CHARGE (t = 0) with the probe reading the roaster shows (BT, noisy and late in some
  scenarios); returns the decided input (the inlet gas temperature Tgi [degC] or the heater
  setting, ``setup.limits.decide``) to hold until the next call.

Optionally ``estimate`` (a dict of estimated states, or None) for the trace. The testbench
applies the input clipped to the actuator's level and rate limits and counts every request it
had to clip as a constraint violation; a controller that respects ``setup.limits`` has none.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from ..fit.program import ProgramLimits


@runtime_checkable
class Controller(Protocol):
    """What :func:`roastlab.control.run_closed_loop` needs of a controller (see module docstring)."""

    name: str

    def reset(self, setup: LoopSetup) -> None: ...

    def step(self, time_s: float, measurement_C: float) -> float: ...


@dataclass
class LoopSetup:
    """What a controller is told before a roast.

    Attributes
    ----------
    time_s, reference_C : the reference roast's BT curve [s], [degC] from CHARGE to DROP
    reference_u : the reference's own recorded decided input on ``time_s`` (Tgi [degC] or the
        heater setting), or None when the reference has none
    sample_s : control interval [s]
    limits : the decided input's level and rate limits
    u_initial : the actuator's position at CHARGE
    params : the controller's model: parameter vector on this plant
        (:func:`roastlab.model.rhs.pack_params` layout), batch mass included when it is known
    x0 : the controller's model's nominal state at CHARGE [Tb, Tm, X, He, Ta, H]
    Gg_kg_s : the gas flow set on ``time_s`` [kg/s] (the reference's, or the scenario's constant)
    Tgi_C : the inlet gas temperature on ``time_s`` [degC] (used when the heater is decided)
    fan : the reference's fan setting on ``time_s`` (as logged), or None
    """

    time_s: np.ndarray
    reference_C: np.ndarray
    reference_u: np.ndarray | None
    sample_s: float
    limits: ProgramLimits
    u_initial: float
    params: np.ndarray
    x0: np.ndarray
    Gg_kg_s: np.ndarray
    Tgi_C: np.ndarray
    fan: np.ndarray | None = None

    @property
    def end_s(self) -> float:
        """DROP: the reference's last time [s]."""
        return float(self.time_s[-1])

    @property
    def ticks(self) -> np.ndarray:
        """The control instants 0, sample_s, ... up to DROP [s]."""
        return self.sample_s * np.arange(int(self.end_s / self.sample_s + 1e-9) + 1)

    def reference_at(self, t) -> np.ndarray:
        """The reference BT at times ``t`` [s], held at its first and last value outside it."""
        return np.interp(t, self.time_s, self.reference_C)

    def fan_at(self, t) -> np.ndarray:
        """The fan setting at times ``t`` (zeros without one)."""
        if self.fan is None:
            return np.zeros(np.shape(t))
        return np.interp(t, self.time_s, self.fan)

    def model_inputs(self, t, u):
        """The model's four input series (Gg, Tgi, heater, fan) at times ``t`` for the decided
        input ``u`` (an array on ``t``)."""
        t = np.asarray(t, dtype=np.float64)
        u = np.asarray(u, dtype=np.float64)
        gg = np.interp(t, self.time_s, self.Gg_kg_s)
        fan = self.fan_at(t)
        if self.limits.decide == "Tgi":
            return gg, u, np.zeros(t.shape), fan
        return gg, np.interp(t, self.time_s, self.Tgi_C), u, fan

    def input_vector(self, t: float, u: float) -> np.ndarray:
        """The model's inputs [Gg, Tgi, heater, fan] at one time ``t`` for the decided input ``u``."""
        gg, tgi, q, fan = self.model_inputs(np.array([t]), np.array([u]))
        return np.array([gg[0], tgi[0], q[0], fan[0]])
