"""Simulation from Python: :func:`simulate`, the steppable :class:`Simulator`, results.

Both run the compiled kernels of :mod:`roastlab.sim.kernels` on the parameter vector of
:func:`roastlab.model.rhs.pack_params`; see that module for the integrator.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..model.limits import check_array, check_value
from ..model.rhs import STATE_NAMES, heat_flows, pack_params, reaction_heat_rate_kW_kg
from .kernels import H_MAX_S, simulate_one, step_kernel


@dataclass(frozen=True)
class InitialState:
    """Initial state of a batch (paper section 5.1 defaults).

    Tb0_C : charge (bean) temperature [degC]; Tm0_C : drum metal [degC];
    X0 : moisture [kg/kg dry]; He0_kJ_kg : exothermic heat so far [kJ/kg dry];
    Ta0_C : probe reading [degC], ``None`` = the batch's first measured Ta, else Tb0.
    """

    Tb0_C: float = 30.0
    Tm0_C: float = 121.0
    X0: float = 0.1
    He0_kJ_kg: float = 0.0
    Ta0_C: float | None = None

    def vector(self, Ta_measured0: float | None = None) -> np.ndarray:
        """The state vector [Tb, Tm, X, He, Ta]; Ta from ``Ta_measured0`` (the log's first reading) if set."""
        Ta0 = self.Ta0_C if self.Ta0_C is not None else (Ta_measured0 if Ta_measured0 is not None else self.Tb0_C)
        return np.array([self.Tb0_C, self.Tm0_C, self.X0, self.He0_kJ_kg, Ta0], dtype=np.float64)


def check_hold(hold: str) -> bool:
    from ..model.constants import INPUT_HOLDS

    if hold not in INPUT_HOLDS:
        raise ParameterError(f"unknown input hold {hold!r} (allowed: {', '.join(INPUT_HOLDS)})")
    return hold == "zoh"


@dataclass
class SimulationResult:
    """States and outputs of one simulated batch, sampled at the input times.

    Attributes
    ----------
    time_s : (n,) array
    states : (n, 5) array, columns :data:`roastlab.model.STATE_NAMES`
    Tgo_C : (n,) array, outlet gas temperature (eq. 15e)
    Gg_kg_s, Tgi_C : (n,) arrays, the inputs
    params : the parameter vector used
    Ta_measured_C : (n,) array or None, the measured probe reading if the batch had one
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

    @property
    def Tb_C(self) -> np.ndarray:
        return self.states[:, 0]

    @property
    def Tm_C(self) -> np.ndarray:
        return self.states[:, 1]

    @property
    def X_kg_kg(self) -> np.ndarray:
        return self.states[:, 2]

    @property
    def He_kJ_kg(self) -> np.ndarray:
        return self.states[:, 3]

    @property
    def Ta_C(self) -> np.ndarray:
        return self.states[:, 4]

    def heat_flows(self) -> dict[str, np.ndarray]:
        """Qgb, Qgm, Qbm [kW] (eqs. 9-11) and Qr [kW, whole batch] (eq. 14) at each sample."""
        n = len(self.time_s)
        q = np.empty((n, 4))
        Mbd = self.params[5]
        for i in range(n):
            Tb, Tm, X, He, _ = self.states[i]
            _, Qgb, Qgm, Qbm = heat_flows(Tb, Tm, X, self.Gg_kg_s[i], self.Tgi_C[i], self.params)
            q[i] = (Qgb, Qgm, Qbm, Mbd * reaction_heat_rate_kW_kg(Tb, He, self.params))
        return {"Qgb_kW": q[:, 0], "Qgm_kW": q[:, 1], "Qbm_kW": q[:, 2], "Qr_kW": q[:, 3]}

    def to_frame(self, heat_flows: bool = False):
        """A pandas DataFrame with time, states, Tgo (and the heat flows if ``heat_flows``)."""
        import pandas as pd

        data = {"time_s": self.time_s}
        for j, name in enumerate(STATE_NAMES):
            data[name] = self.states[:, j]
        data["Tgo_C"] = self.Tgo_C
        if heat_flows:
            data.update(self.heat_flows())
        return pd.DataFrame(data)

    def to_csv_text(self, heat_flows: bool = False) -> str:
        """The CSV of the CLI contract as text (6 decimals); ``heat_flows`` adds Qgb, Qgm, Qbm, Qr."""
        return self.to_frame(heat_flows=heat_flows).to_csv(index=False, float_format="%.6f", lineterminator="\n")

    def to_json_text(self, heat_flows: bool = False) -> str:
        """A JSON object of column arrays as text; ``heat_flows`` adds the heat flows."""
        import json

        frame = self.to_frame(heat_flows=heat_flows)
        payload = {"name": self.name, "columns": {c: frame[c].round(6).tolist() for c in frame.columns}}
        return json.dumps(payload, indent=1, allow_nan=False) + "\n"

    def to_csv(self, path, heat_flows: bool = False) -> None:
        """Write the CSV of the CLI contract to ``path`` atomically (``heat_flows`` as in :meth:`to_csv_text`)."""
        from ..io.files import atomic_write_text

        atomic_write_text(path, self.to_csv_text(heat_flows))

    def to_json(self, path, heat_flows: bool = False) -> None:
        """Write a JSON object of column arrays to ``path`` atomically (``heat_flows`` adds the heat flows)."""
        from ..io.files import atomic_write_text

        atomic_write_text(path, self.to_json_text(heat_flows))

    def plot(self, path=None, title: str | None = None):
        """Figure of BT/ET, rate of rise, moisture and heat flows, titled ``title``; saved to ``path`` if given."""
        from ..report.figures import plot_simulation

        return plot_simulation(self, path=path, title=title)


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
) -> SimulationResult:
    """Simulate one batch.

    Parameters
    ----------
    plant : Plant or preset name
    time_s, Gg_kg_s, Tgi_C : arrays of the input samples [s], [kg/s], [degC]
    theta : Theta, (hgm, hbm, Pbm) or None for the paper's theta*
    initial : InitialState, default the paper's [30, 121, 0.1, 0, Ta(0)]
    Ta_measured_C : measured probe reading; its first value sets Ta(0) unless given
    moisture : ``"schwartzberg"`` (default) or ``"printed"`` (eq. 13 variants)
    hold : ``"linear"`` (default) or ``"zoh"`` input hold between samples
    h_max_s : largest integration step [s]

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
    for label, arr in (("Gg_kg_s", g), ("Tgi_C", T)) + ((("Ta_C", Ta_meas),) if Ta_meas is not None else ()):
        if arr.shape != t.shape:
            raise ParameterError(
                f"{label} has {arr.size} values, time_s has {t.size}: inputs must have one value per time"
            )
    if t.size < 2:
        raise ParameterError(f"need at least 2 time samples, got {t.size}")
    check_array("dt_s", np.diff(t), "simulate()", "time_s")
    check_value_h = check_value("dt_s", h_max_s, "h_max_s")
    x0 = initial.vector(None if Ta_meas is None else float(Ta_meas[0]))
    _check_initial(x0)
    p = pack_params(plant, theta, initial.X0, moisture)
    out = simulate_one(t, g, T, x0, p, zoh, check_value_h)
    _check_finite(out, t)
    return SimulationResult(t, out[:, :5].copy(), out[:, 5].copy(), g, T, p, name, Ta_meas)


def _input_array(name: str, values) -> np.ndarray:
    """A private float64 copy of an input, every value finite and plausible (LIMITS)."""
    try:
        a = np.array(values, dtype=np.float64).reshape(-1) if np.ndim(values) <= 1 else None
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be numbers") from None
    if a is None:
        raise ParameterError(f"{name} must be one-dimensional")
    check_array(name, a, "simulate()", name)
    return a


def _check_initial(x0: np.ndarray) -> None:
    for name, v in zip(("Tb0_C", "Tm0_C", "X0", "He0_kJ_kg", "Ta0_C"), x0):
        check_value(name, v, "initial state")


def _check_finite(out: np.ndarray, t: np.ndarray) -> None:
    bad = ~np.isfinite(out[:, :5])
    if bad.any():
        i = int(np.argwhere(bad)[0][0])
        raise ParameterError(
            f"the simulation went non-finite after t = {t[max(i - 1, 0)]:g} s: inputs, initial state or values out of the model's range"
        )


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
    ):
        from ..io.plants import load_plant
        from ..model.parameters import THETA_PAPER

        self.plant = load_plant(plant)
        self.initial = initial or InitialState()
        self.params = pack_params(self.plant, THETA_PAPER if theta is None else theta, self.initial.X0, moisture)
        self.zoh = check_hold(hold)
        self.h_max_s = float(h_max_s)
        self.x = self.initial.vector()
        _check_initial(self.x)
        self.t_s = 0.0
        self.Tgo_C = float("nan")
        self._h = 5.0  # the integrator's step size carries over, so stepping equals a batch run
        # with a linear hold, each step ramps from the previous inputs (u0 before the first)
        self._u_prev: tuple[float, float] | None = None if u0 is None else (float(u0[0]), float(u0[1]))

    @property
    def state(self) -> dict[str, float]:
        return {name: float(v) for name, v in zip(STATE_NAMES, self.x)}

    def step(self, dt_s: float, Gg_kg_s: float, Tgi_C: float) -> np.ndarray:
        """Advance by ``dt_s`` seconds; return the new state vector."""
        dt_s = check_value("dt_s", dt_s, "Simulator.step")
        Gg_kg_s = check_value("Gg_kg_s", Gg_kg_s, "Simulator.step")
        Tgi_C = check_value("Tgi_C", Tgi_C, "Simulator.step")
        g0, T0 = self._u_prev if (self._u_prev and not self.zoh) else (Gg_kg_s, Tgi_C)
        x, Tgo, h = step_kernel(self.x, g0, T0, Gg_kg_s, Tgi_C, dt_s, self.params, self.zoh, self.h_max_s, self._h)
        if not np.all(np.isfinite(x)):
            raise ParameterError(
                f"the simulation went non-finite at t = {self.t_s + dt_s:g} s (state kept at {self.t_s:g} s)"
            )
        self.x, self.Tgo_C, self._h = x, Tgo, h
        self._u_prev = (Gg_kg_s, Tgi_C)
        self.t_s += dt_s
        return self.x.copy()
