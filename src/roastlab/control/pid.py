"""A PID controller as Artisan's software PID does it, with ramp/soak and follow-the-background
set values and gain scheduling.

Artisan (``artisanlib/pid.py`` and ``pid_control.py``) and this class, side by side:

=========================  ==========================================  ==========================
option                     Artisan                                     here (default)
=========================  ==========================================  ==========================
gains (degC mode)          Kp 15, Ki 0.01, Kd 20 (% duty per degC,     ``kp=15, ki=0.01, kd=20``
                           per degC s, per degC/s)
output                     duty -100..100 %, positive duty mapped      ``duty_min=-100,
                           onto the heat slider's range                duty_max=100``; 0..100 %
                                                                       -> ``limits.low..high``
duty steps                 a new duty only when it moved by            ``duty_steps=1``
                           >= dutySteps (1), or every 3rd cycle
proportional               on error, setpoint weight beta = 1          ``beta=1``
derivative                 on measurement (no kick when the set        ``gamma=0``; ``gamma=1``
                           value moves) -- Artisan >= 3.1 exposes a    is derivative on error
                           setpoint weight gamma
derivative limit           500                                         ``d_limit=500``
integral                   Ki err dt, clamped to the output range;     same: clamp to
                           with windup prevention it pauses while the  [duty_min, duty_max],
                           output is saturated and the error would     conditional integration,
                           push further, and back-calculates 0.5 of    ``back_calculation=0.5``
                           the clipped excess
cycle                      1 s                                         the scenario's sample_s
set value                  manual, ramp/soak segments, or follow       ``setpoint="background"``
                           the background profile ``svLookahead`` s    (lookahead 0 s) or a
                           ahead (default 0)                           :class:`RampSoak`
start                      the integral is reset to 0 when the PID    ``bumpless=False`` (as
                           is switched on, so the first duty is the   Artisan); ``True`` starts
                           P term alone                               the integral at the
                                                                       actuator's position
gain scheduling            linear between (Schedule0: Kp, Ki, Kd)      ``schedule=[(T0, kp, ki,
                           and (Schedule1: Kp1, ...), quadratic with   kd), (T1, ...)]`` on the
                           a third point, on SV (default) or PV,       set value (``on="sv"``)
                           clamped to the given gains                  or ``"pv"`` (bean temp.)
=========================  ==========================================  ==========================

The output (a duty in percent) is mapped linearly onto the decided input's range, as Artisan
maps it onto a slider (burner, heater), so the gains are in Artisan's units whatever the
input. Artisan's gains are tuned for small roasters' heaters controlled at 1 s; on a model of
another machine they are a starting point, not a tuning (docs/control.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .base import LoopSetup


@dataclass(frozen=True)
class RampSoak:
    """Artisan's ramp/soak program: from the first reading, ramp linearly to ``values[i]`` over
    ``ramps_s[i]`` seconds, then hold it for ``soaks_s[i]`` seconds; after the last segment hold
    the last value."""

    values_C: tuple[float, ...]
    ramps_s: tuple[float, ...]
    soaks_s: tuple[float, ...]

    def __post_init__(self) -> None:
        if not (len(self.values_C) == len(self.ramps_s) == len(self.soaks_s)) or not self.values_C:
            raise InputError("ramp/soak needs as many values as ramps and soaks (at least one)", "RampSoak")
        if any(r < 0 for r in self.ramps_s) or any(s < 0 for s in self.soaks_s):
            raise InputError("ramp and soak times must be >= 0 s", "RampSoak")

    def value_at(self, t: float, start_C: float) -> float:
        """The set value [degC] at ``t`` seconds after the start, from ``start_C``."""
        prev, t0 = start_C, 0.0
        for v, r, s in zip(self.values_C, self.ramps_s, self.soaks_s):
            if t < t0 + r:
                return prev + (v - prev) * (t - t0) / r
            if t < t0 + r + s:
                return v
            prev, t0 = v, t0 + r + s
        return prev


def _fit_gain(schedule, index: int, x: float) -> float:
    """Artisan's gain scheduling: linear through two (value, gain) points or quadratic through
    three, evaluated at ``x`` and clamped to the given gains."""
    xs = [s[0] for s in schedule]
    ys = [s[index] for s in schedule]
    coeffs = np.polyfit(xs, ys, len(schedule) - 1)
    return float(min(max(np.polyval(coeffs, x), min(ys)), max(ys)))


class PID:
    """Artisan-style PID (see the module docstring for every option and its Artisan default).

    Parameters
    ----------
    kp, ki, kd : gains in % duty per degC, per degC s, per degC/s
    beta, gamma : setpoint weights of P and D (gamma 0: derivative on measurement)
    duty_min, duty_max : output range [%]; the integral is clamped to it
    duty_steps : smallest duty change sent to the actuator [%]
    d_limit : largest derivative of the weighted error used [degC/s]
    back_calculation : share of a clipped output taken back from the integral
    setpoint : ``"background"`` (follow the reference) or a :class:`RampSoak`
    lookahead_s : follow the background this many seconds ahead
    schedule : None, or 2 or 3 tuples (schedule value [degC], kp, ki, kd)
    on : the scheduling variable: ``"sv"`` (set value) or ``"pv"`` (the bean reading)
    bumpless : start the integral at the actuator's position at CHARGE (default: at 0, as Artisan)
    """

    name = "pid"

    def __init__(
        self,
        kp: float = 15.0,
        ki: float = 0.01,
        kd: float = 20.0,
        *,
        beta: float = 1.0,
        gamma: float = 0.0,
        duty_min: float = -100.0,
        duty_max: float = 100.0,
        duty_steps: float = 1.0,
        d_limit: float = 500.0,
        back_calculation: float = 0.5,
        setpoint="background",
        lookahead_s: float = 0.0,
        schedule=None,
        on: str = "sv",
        bumpless: bool = False,
    ):
        for label, v in (("kp", kp), ("ki", ki), ("kd", kd), ("lookahead_s", lookahead_s)):
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"{label} must be a finite number >= 0, got {v!r}", "PID")
        if not duty_min < duty_max:
            raise InputError(f"duty_min {duty_min:g} must be below duty_max {duty_max:g}", "PID")
        if schedule is not None and len(schedule) not in (2, 3):
            raise InputError("schedule needs 2 (linear) or 3 (quadratic) points (value, kp, ki, kd)", "PID")
        if on not in ("sv", "pv"):
            raise InputError(f"on must be 'sv' or 'pv', got {on!r}", "PID")
        if not (setpoint == "background" or isinstance(setpoint, RampSoak)):
            raise InputError("setpoint must be 'background' or a RampSoak", "PID")
        self.kp, self.ki, self.kd = kp, ki, kd
        self.beta, self.gamma = beta, gamma
        self.duty_min, self.duty_max, self.duty_steps = duty_min, duty_max, duty_steps
        self.d_limit, self.back_calculation = d_limit, back_calculation
        self.setpoint, self.lookahead_s = setpoint, lookahead_s
        self.schedule = None if schedule is None else [tuple(map(float, s)) for s in schedule]
        self.on = on
        self.bumpless = bool(bumpless)
        self.name = "pid-bumpless" if self.bumpless else "pid"
        self.estimate = None

    def gains(self, sv: float, pv: float) -> tuple[float, float, float]:
        """(kp, ki, kd) at set value ``sv`` and bean reading ``pv`` (gain scheduling)."""
        if self.schedule is None:
            return self.kp, self.ki, self.kd
        x = sv if self.on == "sv" else pv
        return tuple(_fit_gain(self.schedule, i, x) for i in (1, 2, 3))

    def reset(self, setup: LoopSetup) -> None:
        self.setup = setup
        self.i_term = 0.0
        self.last_t: float | None = None
        self.last_pv: float | None = None
        self.last_sv: float | None = None
        self.start_pv: float | None = None
        lim = setup.limits
        self.duty = 100.0 * (setup.u_initial - lim.low) / (lim.high - lim.low)
        if self.bumpless:
            self.i_term = min(max(self.duty, self.duty_min), self.duty_max)
        self.cycles_since_send = 0

    def set_value(self, t: float, pv: float) -> float:
        """The set value SV [degC] at ``t``: the background ``lookahead_s`` ahead, or ramp/soak."""
        if self.setpoint == "background":
            return float(self.setup.reference_at(t + self.lookahead_s))
        if self.start_pv is None:
            self.start_pv = pv
        return self.setpoint.value_at(t, self.start_pv)

    def _to_input(self, duty: float) -> float:
        lim = self.setup.limits
        return lim.low + (lim.high - lim.low) * min(max(duty, 0.0), 100.0) / 100.0

    def step(self, time_s: float, measurement_C: float) -> float:
        pv = float(measurement_C)
        sv = self.set_value(time_s, pv)
        if self.last_t is None:  # the first reading only primes the loop, as in Artisan
            self.last_t, self.last_pv, self.last_sv = time_s, pv, sv
            return self._to_input(self.duty)
        dt = time_s - self.last_t
        kp, ki, kd = self.gains(sv, pv)
        err = sv - pv
        p_term = kp * (self.beta * sv - pv)
        # conditional integration: not while saturated and the error pushes further
        trial = p_term + self.i_term
        if not ((trial > self.duty_max and err > 0) or (trial < self.duty_min and err < 0)):
            self.i_term = min(max(self.i_term + ki * err * dt, self.duty_min), self.duty_max)
        d_err = ((self.gamma * sv - pv) - (self.gamma * self.last_sv - self.last_pv)) / dt
        d_err = min(max(d_err, -self.d_limit), self.d_limit)
        raw = p_term + self.i_term + kd * d_err
        out = min(max(raw, self.duty_min), self.duty_max)
        if raw != out:  # back-calculation: take part of the clipped excess off the integral
            self.i_term = min(max(self.i_term - self.back_calculation * (raw - out), self.duty_min), self.duty_max)
        self.last_t, self.last_pv, self.last_sv = time_s, pv, sv
        self.cycles_since_send += 1
        duty = round(out)
        if abs(duty - self.duty) >= self.duty_steps or self.cycles_since_send >= 3:
            self.duty = duty
            self.cycles_since_send = 0
        return self._to_input(self.duty)
