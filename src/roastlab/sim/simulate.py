"""Simulation from Python: :func:`simulate`, the steppable :class:`Simulator`, results.

Both run the compiled kernels of :mod:`roastlab.sim.kernels` on the parameter vector of
:func:`roastlab.model.rhs.pack_params`; see that module for the integrator.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..metrics.profile import mmss
from ..model.layout import N_STATES, PAPER_STATE_NAMES, S_H, S_HE, S_TA, S_TB, S_TM, S_X, STATE0, S
from ..model.limits import check_array, check_value
from ..model.quantities import default
from ..model.rhs import (
    HEATER_STATE,
    STATE_NAMES,
    P,
    gas_inputs,
    heat_flows,
    heater_drive,
    heater_power_kW,
    pack_params,
    reaction_heat_rate_kW_kg,
    shell_loss_kW,
)
from ..report.result import Result, draw_curves
from .kernels import H0_S, H_MAX_S, I_TGO, NS, failure, simulate_one, step_kernel


@dataclass(frozen=True)
class InitialState:
    """Initial state of a batch (paper section 5.1; defaults from the quantity table).

    Tb0_C : charge (bean) temperature [degC]; Tm0_C : drum metal [degC];
    X0 : moisture [kg/kg dry]; He0_kJ_kg : exothermic heat so far [kJ/kg dry];
    Ta0_C : probe reading [degC], ``None`` = the batch's first measured Ta, else Tb0.
    """

    Tb0_C: float = default("Tb0_C")
    Tm0_C: float = default("Tm0_C")
    X0: float = default("X0")
    He0_kJ_kg: float = default("He0_kJ_kg")
    Ta0_C: float | None = None

    def vector(self, Ta_measured0: float | None = None, heater0: float = 0.0) -> np.ndarray:
        """The state vector (:data:`roastlab.model.layout.STATE_NAMES`); Ta from ``Ta_measured0`` (the
        log's first reading) if set, else Tb0; the lagged heater H starts at the setting at charge
        ``heater0`` (settled)."""
        Ta0 = self.Ta0_C if self.Ta0_C is not None else (Ta_measured0 if Ta_measured0 is not None else self.Tb0_C)
        x = np.empty(N_STATES)
        for name, i in STATE0.items():
            x[i] = Ta0 if name == "Ta0_C" else getattr(self, name)
        x[S_H] = heater0
        return x


def check_hold(hold: str) -> bool:
    from ..model.constants import INPUT_HOLDS

    if hold not in INPUT_HOLDS:
        raise ParameterError(f"unknown input hold {hold!r} (allowed: {', '.join(INPUT_HOLDS)})")
    return hold == "zoh"


@dataclass
class SimulationResult(Result):
    """States and outputs of one simulated batch, sampled at the input times.

    Attributes
    ----------
    time_s : (n,) array
    states : (n, 6) array, columns :data:`roastlab.model.STATE_NAMES` and the lagged heater
    Tgo_C : (n,) array, outlet gas temperature (eq. 15e)
    Gg_kg_s, Tgi_C : (n,) arrays, the logged (or placeholder) gas inputs
    params : the parameter vector used
    Ta_measured_C : (n,) array or None, the measured probe reading if the batch had one
    heater, fan : (n,) arrays or None, the logged settings (actuator extension)
    Tb2_measured_C : (n,) array or None, a second measured bean reading compared with Tb
        (NaN where not measured), when the batch had one
    ET_measured_C : (n,) array or None, the roaster's ET as logged (drawn, never an input)
    band : :class:`roastlab.evaluate.bands.Band` or None, the probe prediction's band when asked
        for (``Ta_lower_C``, ``Ta_upper_C`` columns in the CSV, shaded in the figure)
    """

    time_s: np.ndarray
    states: np.ndarray
    Tgo_C: np.ndarray
    Gg_kg_s: np.ndarray
    Tgi_C: np.ndarray
    params: np.ndarray
    name: str = "batch"
    Ta_measured_C: np.ndarray | None = None
    meta: dict = field(default_factory=dict)
    heater: np.ndarray | None = None
    fan: np.ndarray | None = None
    Tb2_measured_C: np.ndarray | None = None
    ET_measured_C: np.ndarray | None = None
    band: object | None = None

    @property
    def uses_actuators(self) -> bool:
        """True when the run had heater or fan settings as inputs (the actuator extension)."""
        return self.heater is not None or self.fan is not None

    def _settings(self):
        n = len(self.time_s)
        q = self.heater if self.heater is not None else np.zeros(n)
        f = self.fan if self.fan is not None else np.zeros(n)
        return q, f

    def gas_seen(self) -> tuple[np.ndarray, np.ndarray]:
        """Gas flow [kg/s] and inlet temperature [degC] the chamber saw (after the actuator maps)."""
        _, f = self._settings()
        pairs = [
            gas_inputs(g, T, heater_drive(H, self.params), fi, self.params)
            for g, T, H, fi in zip(self.Gg_kg_s, self.Tgi_C, self.states[:, S_H], f)
        ]
        a = np.array(pairs, dtype=float).reshape(-1, 2)
        return a[:, 0], a[:, 1]

    @property
    def Tb_C(self) -> np.ndarray:
        return self.states[:, S_TB]

    @property
    def Tm_C(self) -> np.ndarray:
        return self.states[:, S_TM]

    @property
    def X_kg_kg(self) -> np.ndarray:
        return self.states[:, S_X]

    @property
    def He_kJ_kg(self) -> np.ndarray:
        return self.states[:, S_HE]

    @property
    def Ta_C(self) -> np.ndarray:
        return self.states[:, S_TA]

    def heat_flows(self) -> dict[str, np.ndarray]:
        """Qgb, Qgm, Qbm [kW] (eqs. 9-11), Qr [kW, whole batch] (eq. 14) and, with actuator
        inputs, the heater's Qe [kW] (eq. 12) and, with a shell loss, Qloss [kW] at each sample."""
        n = len(self.time_s)
        q = np.empty((n, 6))
        Mbd = self.params[P["Mbd"]]
        g, T = self.gas_seen()
        for i in range(n):
            Tb, Tm, X, He, _, H = self.states[i]
            _, Qgb, Qgm, Qbm = heat_flows(Tb, Tm, X, He, g[i], T[i], self.params)
            Qr = Mbd * reaction_heat_rate_kW_kg(Tb, He, self.params)
            q[i] = (
                Qgb,
                Qgm,
                Qbm,
                Qr,
                heater_power_kW(heater_drive(H, self.params), self.params),
                shell_loss_kW(Tm, self.params),
            )
        out = {"Qgb_kW": q[:, 0], "Qgm_kW": q[:, 1], "Qbm_kW": q[:, 2], "Qr_kW": q[:, 3]}
        if self.uses_actuators:
            out["Qe_kW"] = q[:, 4]
        if self.params[P["U_shell"]] > 0.0:
            out["Qloss_kW"] = q[:, 5]
        return out

    def columns(self, heat_flows: bool = False) -> dict[str, np.ndarray]:
        """The trace's columns by name, in the CLI contract's order: time, states, Tgo, the band where
        one was drawn, the actuators' settings and what the gas saw where the model has them (and the
        heat flows if ``heat_flows``). :meth:`to_frame`, :meth:`to_csv_text` and
        :meth:`to_json_dict` all write these."""
        data = {"time_s": self.time_s}
        for name in PAPER_STATE_NAMES:
            data[name] = self.states[:, S[name]]
        data["Tgo_C"] = self.Tgo_C
        if self.band is not None:
            data["Ta_lower_C"], data["Ta_upper_C"] = self.band.lower_C, self.band.upper_C
        if self.uses_actuators:
            q, f = self._settings()
            g, T = self.gas_seen()
            data.update({"heater": q, "fan": f, HEATER_STATE: self.states[:, S_H], "Gg_seen_kg_s": g, "Tgi_seen_C": T})
        if heat_flows:
            data.update(self.heat_flows())
        return data

    def to_frame(self, heat_flows: bool = False):
        """A pandas DataFrame of :meth:`columns` (``heat_flows`` adds the heat flows)."""
        import pandas as pd

        return pd.DataFrame(self.columns(heat_flows))

    def to_csv_text(self, heat_flows: bool = False) -> str:
        """The CSV of the CLI contract as text (6 decimals, a missing value empty: what pandas'
        ``to_csv(float_format="%.6f")`` of :meth:`to_frame` writes, without importing pandas, half a
        second of a command's start); ``heat_flows`` adds Qgb, Qgm, Qbm, Qr."""
        data = {k: np.asarray(v) for k, v in self.columns(heat_flows).items()}
        whole = [v.dtype.kind in "iub" for v in data.values()]  # pandas writes these as they are
        rows = zip(*(v.tolist() for v in data.values()))
        lines = [
            ",".join(data),
            *(",".join(str(v) if w else "" if v != v else f"{v:.6f}" for v, w in zip(row, whole)) for row in rows),
        ]
        return "\n".join(lines) + "\n"

    def to_json_dict(self, heat_flows: bool = False) -> dict:
        """``{"name", "columns": {column: values}}`` (6 decimals); ``heat_flows`` adds the heat flows."""
        data = self.columns(heat_flows)
        return {
            "name": self.name,
            "columns": {c: np.round(np.asarray(v), 6).tolist() for c, v in data.items()},
        }

    def to_json_text(self, heat_flows: bool = False) -> str:
        """A JSON object of column arrays as text; ``heat_flows`` adds the heat flows."""
        import json

        return json.dumps(self.to_json_dict(heat_flows), indent=1, allow_nan=False) + "\n"

    def summary(self) -> str:
        """One line: the run's length and its end state, in the roaster's words."""
        return (
            f"{self.name}: {len(self.time_s)} samples over {mmss(self.time_s[-1] - self.time_s[0])}; at the end "
            f"BT (probe) {self.Ta_C[-1]:.1f} °C, beans {self.Tb_C[-1]:.1f} °C, drum metal {self.Tm_C[-1]:.1f} °C, "
            f"moisture {self.X_kg_kg[-1]:.3f} kg/kg dry"
        )

    def to_csv(self, path, heat_flows: bool = False) -> None:
        """Write the CSV of the CLI contract to ``path`` atomically (``heat_flows`` as in :meth:`to_csv_text`)."""
        from ..io.files import atomic_write_text

        atomic_write_text(path, self.to_csv_text(heat_flows))

    def to_json(self, path, heat_flows: bool = False) -> None:
        """Write a JSON object of column arrays to ``path`` atomically (``heat_flows`` adds the heat flows)."""
        from ..io.files import atomic_write_text

        atomic_write_text(path, self.to_json_text(heat_flows))

    def _figure(self, path, outputs, title: str | None = None, events=None):
        """BT/ET, rate of rise, moisture and heat flows, titled ``title``."""
        from ..report.figures import plot_simulation

        return plot_simulation(self, path=path, title=title, outputs=outputs, events=events)

    def _draw(self, ax) -> None:
        t = self.time_s
        curves = {"BT, probe Ta (model)": (t, self.Ta_C), "beans Tb (model)": (t, self.Tb_C)}
        curves.update({"drum metal Tm (model)": (t, self.Tm_C), "BT measured": (t, self.Ta_measured_C)})
        draw_curves(ax, curves)


def simulate(
    plant,
    time_s,
    Gg_kg_s,
    Tgi_C,
    theta=None,
    initial: InitialState | None = None,
    Ta_measured_C=None,
    moisture: str = "schwartzberg",
    hold: str = "linear",
    h_max_s: float = H_MAX_S,
    name: str = "batch",
    heater=None,
    fan=None,
    values: dict | None = None,
    bed=None,
) -> SimulationResult:
    """Simulate one batch.

    Parameters
    ----------
    plant : Plant or preset name
    time_s, Gg_kg_s, Tgi_C : arrays of the input samples [s], [kg/s], [degC]
    theta : Theta, (hgm, hbm, Pbm) or None for the paper's theta*
    initial : InitialState, default the paper's section 5.1 state (the quantity table's defaults, Ta0 from the log)
    Ta_measured_C : measured probe reading; its first value sets Ta(0) unless given
    moisture : ``"schwartzberg"`` (default) or ``"printed"`` (eq. 13 variants)
    hold : ``"linear"`` (default) or ``"zoh"`` input hold between samples
    h_max_s : largest integration step [s]
    heater, fan : arrays of logged settings (the actuator extension; None = not used)
    values : {registry name: value} for the other parameter-vector entries (e.g. the
        actuator gains ``Qe_gain_kW``, a process constant ``Kt``)
    bed : bed laws (:class:`roastlab.model.bed.BedLaws` or its text; None = the paper's)

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 901, 30.0)
    >>> r = simulate("120kg", t, np.full_like(t, 0.4), np.full_like(t, 450.0))
    >>> round(float(r.Tb_C[-1]), 2)
    218.31
    """
    from ..io.plants import load_plant
    from ..model.parameters import THETA_PAPER

    plant = load_plant(plant)
    theta = THETA_PAPER if theta is None else theta
    initial = initial or InitialState()
    zoh = check_hold(hold)
    t, g, T = (_input_array(n, v) for n, v in (("time_s", time_s), ("Gg_kg_s", Gg_kg_s), ("Tgi_C", Tgi_C)))
    Ta_meas = None if Ta_measured_C is None else _input_array("Ta_C", Ta_measured_C)
    q = None if heater is None else _input_array("heater", heater)
    f = None if fan is None else _input_array("fan", fan)
    optional = (("Ta_C", Ta_meas), ("heater", q), ("fan", f))
    for label, arr in (("Gg_kg_s", g), ("Tgi_C", T)) + tuple((k, a) for k, a in optional if a is not None):
        if arr.shape != t.shape:
            raise ParameterError(
                f"{label} has {arr.size} values, time_s has {t.size}: inputs must have one value per time"
            )
    if t.size < 2:
        raise ParameterError(f"need at least 2 time samples, got {t.size}")
    check_array("dt_s", np.diff(t), "simulate()", "time_s")
    check_value_h = check_value("dt_s", h_max_s, "h_max_s")
    x0 = initial.vector(None if Ta_meas is None else float(Ta_meas[0]), 0.0 if q is None else float(q[0]))
    _check_initial(x0)
    p = pack_params(plant, theta, initial.X0, moisture, bed)
    if values:
        from ..model.parameters import set_values

        set_values(p, values)
    zeros = np.zeros_like(t)
    out = simulate_one(t, g, T, zeros if q is None else q, zeros if f is None else f, x0, p, zoh, check_value_h)
    _check_finite(out, t)
    return SimulationResult(t, out[:, :NS].copy(), out[:, I_TGO].copy(), g, T, p, name, Ta_meas, heater=q, fan=f)


def _input_array(name: str, values) -> np.ndarray:
    """A private float64 copy of an input, every value finite and plausible (LIMITS)."""
    if np.iscomplexobj(values):
        raise ParameterError(f"{name} must be real numbers, got complex values")
    try:
        a = np.array(values, dtype=np.float64).reshape(-1) if np.ndim(values) <= 1 else None
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be numbers") from None
    if a is None:
        raise ParameterError(f"{name} must be one-dimensional")
    check_array(name, a, "simulate()", name)
    return a


def _check_initial(x0: np.ndarray) -> None:
    for name, i in STATE0.items():
        check_value(name, x0[i], "initial state")


def _check_finite(out: np.ndarray, t: np.ndarray) -> None:
    why = failure(out[:, :NS], t)
    if why is not None:
        raise ParameterError(f"{why}: inputs, initial state or values out of the model's range")


def _u4(Gg_kg_s, Tgi_C, heater=0.0, fan=0.0) -> np.ndarray:
    """Inputs of one instant as the kernel's [Gg, Tgi, heater, fan] vector."""
    u = np.array([Gg_kg_s, Tgi_C, heater, fan], dtype=np.float64)
    if not np.all(np.isfinite(u)):
        raise ParameterError(f"inputs must be finite, got {u.tolist()}")
    return u


def advance(x, u0, u1, dt_s: float, params, zoh: bool = True, h_max_s: float = H_MAX_S, h_s: float = H0_S):
    """The one stepper: state ``x`` (:data:`~roastlab.model.layout.STATE_NAMES`) advanced by
    ``dt_s`` seconds with inputs ``u0`` at the start and ``u1`` at the end (each
    [Gg kg/s, Tgi degC, heater, fan]; held at ``u1`` when ``zoh``) on the parameter vector
    ``params``, by the compiled integrator over the one right-hand side.

    ``h_s`` is the integrator's trial step [s]; pass back the one returned to carry the adapted
    step over, so that stepping equals a batch run. Returns ``(x [new array], Tgo_C, h_s)``.
    :class:`Simulator`, the closed loop, the estimator and the Gymnasium environment all step
    through here (the vectorised environment steps many roasts through the population twin,
    :func:`roastlab.sim.kernels.step_population_kernel`). Inputs are not range-checked here:
    callers check them once, not per step.
    """
    return step_kernel(x, u0, u1, dt_s, params, zoh, h_max_s, h_s)


class Simulator:
    """A steppable simulator for closed-loop use (controllers, MPC).

    Holds the state; :meth:`step` advances by ``dt_s`` with inputs held over the step
    (``zoh``, the default, as a digital controller applies them) or ramped from the previous
    to the new value (``linear``; ``u0`` gives the inputs before the first step).

    >>> sim = Simulator("120kg")
    >>> for _ in range(30):
    ...     x = sim.step(30.0, Gg_kg_s=0.4, Tgi_C=450.0)
    >>> round(sim.state["Tb_C"], 2)
    218.31
    """

    def __init__(
        self,
        plant,
        theta=None,
        initial: InitialState | None = None,
        moisture: str = "schwartzberg",
        hold: str = "zoh",
        h_max_s: float = H_MAX_S,
        u0=None,
        bed=None,
    ):
        from ..io.plants import load_plant
        from ..model.parameters import THETA_PAPER

        self.plant = load_plant(plant)
        self.initial = initial or InitialState()
        self.params = pack_params(self.plant, THETA_PAPER if theta is None else theta, self.initial.X0, moisture, bed)
        self.zoh = check_hold(hold)
        self.h_max_s = float(h_max_s)
        self.x = self.initial.vector()  # heater lag starts settled at 0
        _check_initial(self.x)
        self.t_s = 0.0
        self.Tgo_C = float("nan")
        self._h = H0_S  # the integrator's step size carries over, so stepping equals a batch run
        # with a linear hold, each step ramps from the previous inputs (u0 before the first)
        self._u_prev: np.ndarray | None = None if u0 is None else _u4(*u0)

    @property
    def state(self) -> dict[str, float]:
        """Every state by name (:data:`roastlab.model.layout.STATE_NAMES`, the lagged heater included)."""
        return {name: float(v) for name, v in zip(STATE_NAMES, self.x)}

    def step(self, dt_s: float, Gg_kg_s: float, Tgi_C: float, heater: float = 0.0, fan: float = 0.0) -> np.ndarray:
        """Advance by ``dt_s`` seconds; return the new state vector (six states).

        ``Gg_kg_s`` [kg/s] and ``Tgi_C`` [degC] are the gas inputs; ``heater`` and ``fan`` the
        actuator settings (the actuator extension; 0 when not used).
        """
        dt_s = check_value("dt_s", dt_s, "Simulator.step")
        Gg_kg_s = check_value("Gg_kg_s", Gg_kg_s, "Simulator.step")
        Tgi_C = check_value("Tgi_C", Tgi_C, "Simulator.step")
        u1 = _u4(Gg_kg_s, Tgi_C, heater, fan)
        u0 = self._u_prev if (self._u_prev is not None and not self.zoh) else u1
        x, Tgo, h = advance(self.x, u0, u1, dt_s, self.params, self.zoh, self.h_max_s, self._h)
        if not np.all(np.isfinite(x)):
            raise ParameterError(
                f"the simulation went non-finite at t = {self.t_s + dt_s:g} s (state kept at {self.t_s:g} s)"
            )
        self.x, self.Tgo_C, self._h = x, Tgo, h
        self._u_prev = u1
        self.t_s += dt_s
        return self.x.copy()
