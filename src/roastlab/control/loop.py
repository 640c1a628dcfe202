"""The closed-loop testbench: a controller, a simulated roaster that differs from the
controller's model as a scenario says, a probe, an actuator, and the metrics.

Every ``sample_s`` seconds from CHARGE to the reference's DROP:

1. the probe reading: the simulated roaster's Ta (eq. 17) ``delay_s`` ago plus white noise;
2. the controller returns the decided input; the actuator clips it to its level limits and
   to its rate limit from the input it holds (a request it has to clip is a constraint
   violation), rounds it to the machine's steps where the map declares them (P0-P9 on the
   Bullet) and holds it over the interval (zero-order hold);
3. the roaster -- the same model file on the same plant with the scenario's changes (batch
   mass, moisture, drum temperature at CHARGE, coefficients, gas supply) -- advances through the
   compiled integrator (:func:`roastlab.sim.simulate.advance`, the one right-hand side).

Metrics (``METRICS.json``): ``rmse_C`` and ``max_abs_C`` of the true probe reading against the
reference over the roast; ``ror_rmse_C_per_min`` of the rate of rise (the one RoR of
:mod:`roastlab.metrics.profile`, which the MPC's RoR term uses too) from 1:00 on; ``drop_time_error_s``: when the roaster's BT reaches the reference's DROP
temperature minus the reference's DROP time (projected from the last two minutes' rate of rise
when it does not get there; None when it is not rising); ``actuator_travel``: the sum of the
applied input's changes (degC or setting); ``constraint_violations``: requests clipped by the
actuator; ``step_ms_median`` and ``step_ms_p99``: the controller's own time per step.
"""

from __future__ import annotations

import dataclasses
import io
import math
import time
from pathlib import Path

import numpy as np

from ..errors import InputError, RoastlabError
from ..fit.program import ProgramLimits, optimise_program
from ..io.batch import Batch
from ..io.plants import load_plant
from ..io.scenario import Scenario, load_scenario
from ..metrics.profile import crossing_or_projected_s, rate_of_rise_C_per_min
from ..model.layout import S_HE, S_TA, S_TB, S_TM, S_X
from ..model.parameters import REGISTRY
from ..model.rhs import N_STATES, P
from ..report.result import Result, aligned, draw_curves
from ..sim.kernels import H0_S
from ..sim.simulate import advance
from .base import LoopSetup
from .mpc import MPC
from .pid import PID
from .replay import Replay

#: The controllers ``roastlab control --controller`` knows, by name: Artisan's PID as Artisan starts
#: it (integral from 0) and started bumpless (integral at the actuator's position), MPC, replay.
CONTROLLERS = {"pid": PID, "pid-bumpless": lambda: PID(bumpless=True), "mpc": MPC, "replay": Replay}
#: Time from which the rate of rise is scored [s] (the one RoR of :mod:`roastlab.metrics.profile`).
ROR_FROM_S = 60.0
SCENARIO_DIR = Path(__file__).parent / "scenarios"


def standard_scenarios() -> list[Path]:
    """The shipped scenario files (``roastlab/control/scenarios/*.toml``), in order."""
    return sorted(SCENARIO_DIR.glob("*.toml"))


def find_scenario(name_or_path) -> Path:
    """A scenario file: a path that exists, or a shipped scenario by name, with or without its
    number (``cold-drum``, ``05-cold-drum``); else one error listing the shipped names."""
    path = Path(name_or_path)
    if path.exists() or path.suffix.lower() == ".toml" or len(path.parts) > 1:
        return path
    for p in standard_scenarios():
        if str(name_or_path) in (p.stem, p.stem.split("-", 1)[-1]):
            return p
    names = ", ".join(p.stem.split("-", 1)[-1] for p in standard_scenarios())
    raise InputError(f"no such file, and no shipped scenario of that name (shipped: {names})", str(name_or_path))


def make_controller(name: str):
    """A controller by name (``pid``, ``mpc``, ``replay``) with its defaults."""
    if name not in CONTROLLERS:
        raise InputError(f"unknown controller {name!r} (allowed: {', '.join(CONTROLLERS)})", "controller")
    return CONTROLLERS[name]()


@dataclasses.dataclass
class SimulatedRoaster:
    """The simulated roaster of one scenario run: parameters, state at CHARGE, gas factor."""

    params: np.ndarray
    x0: np.ndarray
    Gg_factor: float
    mass_kg: float


def _value(p: np.ndarray, name: str) -> float:
    return float(p[P[REGISTRY[name].slot]])


def prepare(
    model, reference: Batch, scenario: Scenario | None = None, plant=None
) -> tuple[LoopSetup, SimulatedRoaster]:
    """The controller's :class:`LoopSetup` and the :class:`SimulatedRoaster` of one scenario.

    ``model`` is a FittedModel, ``reference`` a Batch with Ta_C (the BT curve to follow) and the
    inputs it was roasted with, ``plant`` the roaster's geometry (default: the model's).
    """
    scenario = scenario or Scenario()
    src = reference.source or reference.name
    if reference.Ta_C is None:
        raise InputError("the reference has no bean-probe curve (Ta_C): nothing to track", src)
    act, pc = scenario.actuator, scenario.plant
    if reference.time_s[-1] - reference.time_s[0] < 3 * act.sample_s:
        raise InputError(
            f"the reference spans {reference.time_s[-1] - reference.time_s[0]:g} s, shorter than three "
            f"{act.sample_s:g} s control intervals",
            src,
        )
    limits = ProgramLimits.for_model(model.column_map, act.decide, act.low, act.high, act.rate_per_min)
    if limits.decide == "heater" and reference.heater is None:
        raise InputError("the controller decides the heater, but the reference has no heater setting", src)
    target_plant = load_plant(plant) if plant is not None else model.plant
    if target_plant is None:
        raise InputError("the model names no plant geometry: give the plant (--plant)", model.source)
    nominal = model.predict(reference, plant=plant)
    mass_ref = reference.Mb_kg or target_plant.Mb_kg
    mass = mass_ref * pc.mass_factor
    # the controller knows a weighed batch; at the reference's own mass that is the nominal run
    weighed = pc.mass_known and pc.mass_factor != 1.0
    controller_view = model.predict(reference, plant=plant, batch_kg=mass) if weighed else nominal
    x_model = controller_view.states[0, :N_STATES].copy()

    changes: dict = {"batch_kg": mass}
    changes["X0"] = pc.X0 if pc.X0 is not None else float(x_model[S_X])
    changes["Tm0_C"] = pc.Tm0_C if pc.Tm0_C is not None else float(x_model[S_TM]) + pc.Tm0_offset_C
    changes["Tb0_C"] = pc.Tb0_C if pc.Tb0_C is not None else float(x_model[0]) + pc.Tb0_offset_C
    for name, v in pc.theta.items():
        changes[name] = v
    for name, f in pc.theta_factor.items():
        changes[name] = f * _value(nominal.params, name)
    truth = model.predict(reference, plant=plant, **changes)
    if not np.all(np.isfinite(truth.states)):
        raise InputError(f"scenario {scenario.name!r}: the roaster cannot be simulated with these changes", src)

    t = np.asarray(reference.time_s, dtype=np.float64) - reference.time_s[0]
    gg = np.asarray(controller_view.Gg_kg_s if act.Gg_kg_s is None else np.full(t.shape, act.Gg_kg_s), dtype=float)
    ref_u = np.asarray(reference.Tgi_C if limits.decide == "Tgi" else reference.heater, dtype=float)
    u0 = float(np.clip(ref_u[0], limits.low, limits.high))
    setup = LoopSetup(
        time_s=t,
        reference_C=np.asarray(reference.Ta_C, dtype=float),
        reference_u=ref_u,
        sample_s=act.sample_s,
        limits=limits,
        u_initial=u0,
        params=controller_view.params.copy(),
        x0=x_model,
        Gg_kg_s=gg,
        Tgi_C=np.asarray(reference.Tgi_C, dtype=float),
        fan=None if reference.fan is None else np.asarray(reference.fan, dtype=float),
    )
    roaster = SimulatedRoaster(truth.params.copy(), truth.states[0, :N_STATES].copy(), pc.Gg_factor, mass)
    return setup, roaster


@dataclasses.dataclass
class ClosedLoopResult(Result):
    """One closed-loop roast: the trace, the metrics and what was noted."""

    controller: str
    scenario: str
    setup: LoopSetup
    time_s: np.ndarray
    reference_C: np.ndarray
    bt_C: np.ndarray  # the roaster's true probe reading
    measured_C: np.ndarray  # what the controller read
    u_requested: np.ndarray
    u_applied: np.ndarray
    states: np.ndarray  # (n, 6) the roaster's states
    estimates: dict
    step_ms: np.ndarray
    metrics: dict
    notes: list

    @property
    def input_name(self) -> str:
        return "Tgi_C" if self.setup.limits.decide == "Tgi" else "heater"

    def to_frame(self):
        import pandas as pd

        cols = {
            "time_s": self.time_s,
            "reference_C": self.reference_C,
            "BT_C": self.bt_C,
            "measured_C": self.measured_C,
            f"{self.input_name}_requested": self.u_requested,
            f"{self.input_name}_applied": self.u_applied,
            "Tb_C": self.states[:, S_TB],
            "Tm_C": self.states[:, S_TM],
            "X_kg_kg": self.states[:, S_X],
            "He_kJ_kg": self.states[:, S_HE],
        }
        cols.update(self.estimates)
        return pd.DataFrame(cols)

    def trace_csv_text(self) -> str:
        buf = io.StringIO()
        buf.write(f"## roastlab control trace: controller {self.controller}, scenario {self.scenario}\n")
        self.to_frame().to_csv(buf, index=False, float_format="%.6f", lineterminator="\n")
        return buf.getvalue()

    def summary(self) -> str:
        """One line of the run's metrics."""
        m = self.metrics
        ror = m.get("ror_rmse_C_per_min")
        drop = m.get("drop_time_error_s")
        return (
            f"{self.controller} on {self.scenario}: BT RMSE {m['rmse_C']:.2f} °C (max {m['max_abs_C']:.2f} °C), "
            f"RoR RMSE {'-' if ror is None else f'{ror:.2f}'} °C/min, DROP {'-' if drop is None else f'{drop:+.0f}'} s, "
            f"{m['constraint_violations']} clipped request(s)"
        )

    def to_json_dict(self) -> dict:
        """The metrics (``METRICS.json``) and the notes."""
        return {**self.metrics, "notes": list(self.notes)}

    def _figure(self, path, outputs, title: str | None = None):
        from ..report.figures import plot_closed_loop

        return plot_closed_loop(self, path, title, outputs)

    def _draw(self, ax) -> None:
        t = self.time_s
        draw_curves(ax, {"reference BT": (t, self.reference_C), "roaster BT": (t, self.bt_C)}, "BT [°C]")


def _metrics(t, ref, bt, u_applied, u0, violations, step_ms, end_s) -> dict:
    e = bt - ref
    ror_e = rate_of_rise_C_per_min(t, bt) - rate_of_rise_C_per_min(t, ref)
    ror_e = ror_e[(t >= ROR_FROM_S) & np.isfinite(ror_e)]
    drop = crossing_or_projected_s(t, bt, float(ref[-1]))
    return {
        "rmse_C": float(np.sqrt(np.mean(e**2))),
        "max_abs_C": float(np.max(np.abs(e))),
        "ror_rmse_C_per_min": float(np.sqrt(np.mean(ror_e**2))) if ror_e.size else None,
        "drop_time_error_s": None if drop is None else float(drop - end_s),
        "actuator_travel": float(np.sum(np.abs(np.diff(np.concatenate([[u0], u_applied]))))),
        "constraint_violations": int(violations),
        "step_ms_median": float(np.median(step_ms)),
        "step_ms_p99": float(np.percentile(step_ms, 99)),
    }


def run_closed_loop(model, reference: Batch, controller, scenario: Scenario | str | Path | None = None, plant=None):
    """Run ``controller`` against the roaster of ``scenario`` following ``reference``.

    ``controller`` is an object with ``reset(setup)`` and ``step(time_s, measurement_C)`` (see
    :mod:`roastlab.control.base`) or a name (``pid``, ``mpc``, ``replay``); ``scenario`` a
    :class:`~roastlab.io.scenario.Scenario` or a TOML path (default: nominal). Returns a
    :class:`ClosedLoopResult`.
    """
    if isinstance(scenario, (str, Path)):
        scenario = load_scenario(scenario)
    scenario = scenario or Scenario()
    if isinstance(controller, str):
        controller = make_controller(controller)
    setup, roaster = prepare(model, reference, scenario, plant)
    lim, dt = setup.limits, setup.sample_s
    t = setup.ticks
    n = t.size
    sensor = scenario.sensor
    rng = np.random.default_rng(sensor.seed)
    noise = rng.normal(0.0, sensor.noise_C, n) if sensor.noise_C > 0 else np.zeros(n)
    states = np.empty((n, N_STATES))
    states[0] = roaster.x0
    measured = np.empty(n)
    u_req = np.empty(n)
    u_app = np.empty(n)
    step_ms = np.empty(n)
    estimates: dict[str, list] = {}
    tol = 1e-6 * (lim.high - lim.low)
    violations = 0
    u_prev = setup.u_initial
    x = roaster.x0.copy()
    h = H0_S
    controller.reset(setup)
    name = getattr(controller, "name", type(controller).__name__)
    for k in range(n):
        seen_t = max(t[k] - sensor.delay_s, 0.0)
        measured[k] = np.interp(seen_t, t[: k + 1], states[: k + 1, S_TA]) + noise[k]
        c0 = time.perf_counter()
        u = controller.step(float(t[k]), float(measured[k]))
        step_ms[k] = (time.perf_counter() - c0) * 1e3
        try:
            u = float(u)
        except (TypeError, ValueError):
            u = math.nan
        if not math.isfinite(u):
            raise RoastlabError(f"controller {name!r} returned a non-finite input ({u!r}) at t = {t[k]:g} s")
        u_req[k] = u
        cap = lim.rate_per_min / 60.0 * dt
        lo, hi = max(lim.low, u_prev - cap), min(lim.high, u_prev + cap)
        applied = min(max(u, lo), hi)
        violations += abs(applied - u) > tol
        u_prev = applied  # the rate-limited path, before the knob's steps
        if lim.actuator is not None and lim.actuator.stepped:
            # the machine's knob has steps: it takes the setting nearest the rate-limited path, so a
            # rate below one step per sample still moves it (one step each time the path has gone
            # half a step), where rounding each sample's move would hold it still for ever
            applied = float(np.clip(lim.actuator.quantise(applied), lim.low, lim.high))
        u_app[k] = applied
        est = getattr(controller, "estimate", None)
        if est:
            for key, v in est.items():
                estimates.setdefault(key, [math.nan] * k).append(v)
        if k == n - 1:
            break
        vec = setup.input_vector(float(t[k]), applied)
        vec[0] *= roaster.Gg_factor
        x, _, h = advance(x, vec, vec, dt, roaster.params, h_s=h)
        if not np.all(np.isfinite(x)):
            raise RoastlabError(f"the simulated roaster went non-finite at t = {t[k + 1]:g} s under {name!r}")
        states[k + 1] = x
    ref = setup.reference_at(t)
    bt = states[:, S_TA]
    metrics = {
        "controller": name,
        "scenario": scenario.name,
        "decide": lim.decide,
        "unit": lim.unit,
        "sample_s": dt,
        **_metrics(t, ref, bt, u_app, setup.u_initial, violations, step_ms, setup.end_s),
        "batch_kg": roaster.mass_kg,
        "final_Tb_C": float(states[-1, S_TB]),
        "final_X_kg_kg": float(states[-1, S_X]),
    }
    est_arrays = {k: np.asarray(v + [math.nan] * (n - len(v))) for k, v in estimates.items()}
    if "Tm_C_est" in est_arrays:
        late = t >= min(180.0, t[-1] / 2)
        for key, col in (("Tb_C_est", 0), ("Tm_C_est", 1)):
            err = est_arrays[key][late] - states[late, col]
            metrics[f"estimator_rmse_{key[:-4]}"] = float(np.sqrt(np.nanmean(err**2)))
    return ClosedLoopResult(
        controller=name,
        scenario=scenario.name,
        setup=setup,
        time_s=t,
        reference_C=ref,
        bt_C=bt.copy(),
        measured_C=measured,
        u_requested=u_req,
        u_applied=u_app,
        states=states,
        estimates=est_arrays,
        step_ms=step_ms,
        metrics=metrics,
        notes=[],
    )


#: Solver budget of the oracle (:func:`oracle_rmse_C`).
ORACLE_ITERATIONS = 300


def oracle_rmse_C(setup: LoopSetup, roaster: SimulatedRoaster) -> float:
    """The BT RMSE of the open-loop program the one program optimiser finds for the roaster itself
    (its true parameters and state, the actuator's limits, :data:`ORACLE_ITERATIONS`): a reference
    for what is reachable in the scenario, not a proven bound (a longer solve can go lower)."""
    t = setup.ticks
    gg, tgi, q, fan = setup.model_inputs(t, np.interp(t, setup.time_s, setup.reference_u))
    res = optimise_program(
        t,
        setup.reference_at(t),
        roaster.x0,
        roaster.params,
        gg * roaster.Gg_factor,
        tgi,
        setup.limits,
        heater=q,
        fan=fan,
        zoh=True,
        u_prev=setup.u_initial,
        max_iterations=ORACLE_ITERATIONS,
    )
    return float(np.sqrt(np.mean((res.Ta_pred_C - setup.reference_at(t)) ** 2)))


#: Columns of the comparison table: (metric key, header, format).
TABLE = (
    ("rmse_C", "RMSE °C", "{:.2f}"),
    ("max_abs_C", "max °C", "{:.1f}"),
    ("ror_rmse_C_per_min", "RoR RMSE °C/min", "{:.2f}"),
    ("drop_time_error_s", "drop Δt s", "{:+.0f}"),
    ("actuator_travel", "travel", "{:.0f}"),
    ("constraint_violations", "clipped", "{:d}"),
    ("step_ms_median", "step ms p50", "{:.2f}"),
    ("step_ms_p99", "p99", "{:.2f}"),
)


class _SummaryText(str):
    """The comparison's summary text; indexing it by a key of :meth:`Comparison.statistics`
    still works for one release, with a DeprecationWarning (``summary()`` returned that dict)."""

    def __new__(cls, text: str, statistics: dict):
        obj = super().__new__(cls, text)
        obj._statistics = statistics
        return obj

    def __getitem__(self, key):
        if isinstance(key, str):
            import warnings

            warnings.warn(
                "Comparison.summary() is text now; use Comparison.statistics() for the numbers",
                DeprecationWarning,
                stacklevel=2,
            )
            return self._statistics[key]
        return super().__getitem__(key)


@dataclasses.dataclass
class Comparison(Result):
    """Every controller on every scenario: the metric rows and the runs behind them."""

    rows: list[dict]
    results: dict

    def summary(self) -> str:
        """The comparison table (:meth:`table`)."""
        return _SummaryText(self.table(), self.statistics())

    def to_frame(self):
        """One row per scenario and controller: the metrics."""
        import pandas as pd

        return pd.DataFrame(self.rows)

    def _draw(self, ax) -> None:
        stats = self.statistics()["mean_rmse_C"]
        ax.bar(list(stats), list(stats.values()), color="tab:blue")
        ax.set_ylabel("mean BT RMSE over the scenarios [°C]")

    def statistics(self) -> dict:
        """Mean RMSE per controller, and on the disturbed scenarios (all but 'nominal') each
        controller's RMSE over the PID's (Artisan's start), worst case."""
        out: dict = {"mean_rmse_C": {}, "worst_ratio_to_pid_disturbed": {}}
        ctrls = list(dict.fromkeys(r["controller"] for r in self.rows))
        for c in ctrls:
            out["mean_rmse_C"][c] = float(np.mean([r["rmse_C"] for r in self.rows if r["controller"] == c]))
        if "pid" in ctrls:
            for c in ctrls:
                if c != "pid":
                    out["worst_ratio_to_pid_disturbed"][c] = self.worst_ratio(c, "pid")
        return out

    def worst_ratio(self, controller: str, baseline: str) -> float | None:
        """The largest RMSE of ``controller`` over ``baseline``'s on the disturbed scenarios (all but
        'nominal'); None when no scenario has both."""
        base = {r["scenario"]: r["rmse_C"] for r in self.rows if r["controller"] == baseline}
        ratios = [
            r["rmse_C"] / base[r["scenario"]]
            for r in self.rows
            if r["controller"] == controller and r["scenario"] != "nominal" and base.get(r["scenario"], 0) > 0
        ]
        return float(max(ratios)) if ratios else None

    def table(self) -> str:
        """A plain-text table, one line per scenario and controller."""
        head = ["scenario", "controller", *(h for _, h, _ in TABLE), "oracle °C"]
        lines = [head]
        for r in self.rows:
            cells = [r["scenario"], r["controller"]]
            for key, _, fmt in TABLE:
                v = r.get(key)
                cells.append("-" if v is None else fmt.format(v))
            a = r.get("oracle_rmse_C")
            cells.append("-" if a is None else f"{a:.2f}")
            lines.append(cells)
        text = aligned(lines, left=2)
        s = self.statistics()
        text.append("")
        text.append("mean RMSE: " + ", ".join(f"{c} {v:.2f} °C" for c, v in s["mean_rmse_C"].items()))
        for c, v in s["worst_ratio_to_pid_disturbed"].items():
            if v is not None:
                text.append(f"{c}: at most {v:.2f}x the PID's RMSE on the disturbed scenarios")
        return "\n".join(text)

    def to_json_dict(self) -> dict:
        return {"rows": self.rows, "summary": self.statistics(), "note": "synthetic closed-loop runs on the model"}

    def _figure(self, path, outputs):
        from ..report.figures import plot_control_comparison

        return plot_control_comparison(self.rows, self.results, path, outputs)


def compare(
    model,
    reference: Batch,
    scenarios=None,
    controllers=("replay", "pid", "pid-bumpless", "mpc"),
    plant=None,
    oracle: bool = False,
    progress=None,
) -> Comparison:
    """Run every controller on every scenario (default: :func:`standard_scenarios`).

    ``controllers`` are names or controller objects; ``oracle`` adds each scenario's
    :func:`oracle_rmse_C` (seconds per scenario); ``progress(done, total)`` is called after each run.
    """
    scen = [s if isinstance(s, Scenario) else load_scenario(s) for s in (scenarios or standard_scenarios())]
    if not scen:
        raise InputError("no scenarios to compare", "--scenarios")
    rows, results = [], {}
    total, done = len(scen) * len(controllers), 0
    for s in scen:
        best = None
        if oracle:
            setup, roaster = prepare(model, reference, s, plant)
            best = oracle_rmse_C(setup, roaster) if setup.reference_u is not None else None
        for c in controllers:
            ctrl = make_controller(c) if isinstance(c, str) else c
            res = run_closed_loop(model, reference, ctrl, s, plant)
            results[(s.name, res.controller)] = res
            rows.append({**res.metrics, "oracle_rmse_C": best})
            done += 1
            if progress is not None:
                progress(done, total)
    return Comparison(rows, results)
