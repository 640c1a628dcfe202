"""Gymnasium environments of the roaster: ``roastlab/Roast-v0`` (one roast) and a vectorised
version that steps many roasts in one compiled call (``pip install 'roastlab[rl]'``).

An episode is one roast of the testbench (:mod:`roastlab.control.loop`): the same model file,
reference, scenario and actuator, the same compiled integrator over the one right-hand side.

* **Observation** (float32): ``[probe reading BT, reference BT now, reference BT one interval
  ahead, time / DROP time]`` [degC, degC, degC, -]; the probe reading carries the scenario's
  noise (and its delay, up to one interval, interpolated between samples).
* **Action** (float32, shape (1,)): the decided input (inlet gas temperature Tgi [degC] or the
  heater setting) within the actuator's level limits; the actuator also enforces its rate limit
  from the input it holds.
* **Reward**: ``-(e / 1 degC)^2 - move_penalty (du / du_max)^2`` with e the true BT's error
  after the interval and du the applied input's change over the largest the rate limit allows.
* The episode is truncated at the reference's DROP (never terminated).
* ``tm0_spread_C``: each reset draws the drum temperature at CHARGE uniformly within this many
  degC of the scenario's (the hidden disturbance a roaster's controller must cope with).
"""

from __future__ import annotations

import numpy as np

try:
    import gymnasium as gym
    from gymnasium import spaces
    from gymnasium.vector import AutoresetMode, VectorEnv
except ImportError:  # pragma: no cover - the rl extra is optional
    gym = None

from ..errors import InputError
from ..model.layout import S_TA, S_TM
from ..model.rhs import N_PARAMS, N_STATES
from ..sim.kernels import H0_S, H_MAX_S, N_OUT, step_population_kernel
from ..sim.simulate import advance
from .loop import prepare

ENV_ID = "roastlab/Roast-v0"


class _Episode:
    """The parts of a testbench run an environment needs, precomputed on its tick grid."""

    def __init__(self, model, reference, scenario, plant, move_penalty, tm0_spread_C):
        from ..workflows.model import FittedModel
        from .reference import standard_reference

        model = model if model is not None else FittedModel.paper("120kg")
        reference = reference if reference is not None else standard_reference()
        setup, roaster = prepare(model, reference, scenario, plant)
        self.setup, self.roaster = setup, roaster
        self.sensor = (scenario.sensor if scenario is not None else None) or _nominal_sensor()
        lim = setup.limits
        self.dt = setup.sample_s
        self.n = setup.ticks.size - 1  # intervals per episode
        t = self.dt * np.arange(self.n + 2)
        self.t = t
        self.ref = setup.reference_at(t)
        gg, tgi, _, fan = setup.model_inputs(t, np.zeros(t.shape))
        self.inputs = np.stack([gg * roaster.Gg_factor, tgi, np.zeros(t.shape), fan], axis=1)
        self.col = 1 if lim.decide == "Tgi" else 2
        self.low, self.high = float(lim.low), float(lim.high)
        self.cap = lim.rate_per_min / 60.0 * self.dt
        self.move_penalty = float(move_penalty)
        if not (np.isfinite(tm0_spread_C) and tm0_spread_C >= 0):
            raise InputError(f"tm0_spread_C must be >= 0 degC, got {tm0_spread_C!r}", "environment")
        self.tm0_spread = float(tm0_spread_C)
        if not (np.isfinite(move_penalty) and move_penalty >= 0):
            raise InputError(f"move_penalty must be >= 0, got {move_penalty!r}", "environment")
        if self.sensor.delay_s > self.dt:
            raise InputError(
                f"the environment handles a probe delay up to one interval ({self.dt:g} s), got {self.sensor.delay_s:g} s",
                "scenario",
            )
        self.frac_delay = self.sensor.delay_s / self.dt
        big = np.float32(1e4)
        self.observation_space = spaces.Box(
            low=np.array([-big, -big, -big, 0.0], dtype=np.float32),
            high=np.array([big, big, big, 2.0], dtype=np.float32),
            dtype=np.float32,
        )
        self.action_space = spaces.Box(
            low=np.float32(self.low), high=np.float32(self.high), shape=(1,), dtype=np.float32
        )

    def reward(self, err_C, du):
        """-(e / 1 degC)^2 - move_penalty (du / du_max)^2, for one roast or an array of them."""
        return -(err_C * err_C) - self.move_penalty * (du / self.cap) ** 2


def _nominal_sensor():
    from ..io.scenario import Sensor

    return Sensor()


if gym is not None:

    class RoastEnv(gym.Env):
        """One roast (see the module docstring).

        Parameters
        ----------
        model : FittedModel (default: the paper's theta* on 120 kg)
        reference : Batch to follow (default: :func:`roastlab.control.standard_reference`)
        scenario : :class:`~roastlab.io.scenario.Scenario` (default: nominal)
        plant : the roaster's geometry (default: the model's)
        move_penalty : weight of the input-move term of the reward
        tm0_spread_C : half-width of the drum temperature's random draw at each reset [degC]
        """

        metadata = {"render_modes": []}

        def __init__(self, model=None, reference=None, scenario=None, plant=None, move_penalty=0.1, tm0_spread_C=0.0):
            self.ep = _Episode(model, reference, scenario, plant, move_penalty, tm0_spread_C)
            self.observation_space = self.ep.observation_space
            self.action_space = self.ep.action_space
            self._p = self.ep.roaster.params
            self._x = self.ep.roaster.x0.copy()
            self._k = 0

        def _obs(self, measured: float) -> np.ndarray:
            ep, k = self.ep, self._k
            return np.array([measured, ep.ref[k], ep.ref[k + 1], k / ep.n], dtype=np.float32)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            ep = self.ep
            self._x = ep.roaster.x0.copy()
            if ep.tm0_spread:
                self._x[S_TM] += self.np_random.uniform(-ep.tm0_spread, ep.tm0_spread)
            self._k = 0
            self._u = ep.setup.u_initial
            self._h = H0_S
            self._bt_prev = self._x[S_TA]
            noise = self.np_random.normal(0.0, ep.sensor.noise_C) if ep.sensor.noise_C else 0.0
            return self._obs(self._x[S_TA] + noise), {"bt_C": float(self._x[S_TA])}

        def step(self, action):
            ep = self.ep
            a = float(np.asarray(action, dtype=np.float64).reshape(-1)[0])
            if not np.isfinite(a):
                raise InputError(f"action must be finite, got {a!r}", "RoastEnv.step")
            u = min(max(a, ep.low, self._u - ep.cap), ep.high, self._u + ep.cap)
            du = u - self._u
            self._u = u
            vec = ep.inputs[self._k].copy()
            vec[ep.col] = u
            bt_before = self._x[S_TA]
            self._x, _, self._h = advance(self._x, vec, vec, ep.dt, self._p, h_s=self._h)
            self._k += 1
            bt = self._x[S_TA]
            err = bt - ep.ref[self._k]
            reward = ep.reward(err, du)
            seen = bt - ep.frac_delay * (bt - bt_before)
            noise = self.np_random.normal(0.0, ep.sensor.noise_C) if ep.sensor.noise_C else 0.0
            truncated = self._k >= ep.n
            info = {"bt_C": float(bt), "u_applied": u}
            return self._obs(seen + noise), float(reward), False, truncated, info

    class RoastVectorEnv(VectorEnv):
        """``num_envs`` roasts stepped together by one parallel compiled call
        (:func:`roastlab.sim.kernels.step_population_kernel`); all episodes have the roast's
        length, so they end together and reset together on the next step (NEXT_STEP autoreset).
        Parameters as :class:`RoastEnv`."""

        metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

        def __init__(
            self,
            num_envs: int = 64,
            model=None,
            reference=None,
            scenario=None,
            plant=None,
            move_penalty=0.1,
            tm0_spread_C=0.0,
        ):
            if not 1 <= int(num_envs) <= 1_000_000:
                raise InputError(f"num_envs must be 1..1000000, got {num_envs!r}", "RoastVectorEnv")
            self.num_envs = n = int(num_envs)
            self.ep = ep = _Episode(model, reference, scenario, plant, move_penalty, tm0_spread_C)
            self.single_observation_space = ep.observation_space
            self.single_action_space = ep.action_space
            self.observation_space = spaces.Box(
                low=np.tile(ep.observation_space.low, (n, 1)),
                high=np.tile(ep.observation_space.high, (n, 1)),
                dtype=np.float32,
            )
            self.action_space = spaces.Box(low=ep.low, high=ep.high, shape=(n, 1), dtype=np.float32)
            self._PP = np.ascontiguousarray(np.broadcast_to(ep.roaster.params, (n, N_PARAMS)))
            self._X = np.empty((n, N_STATES))
            self._H = np.full(n, H0_S)
            self._U = np.empty((n, 4))
            self._u = np.empty(n)
            self._T2 = np.array([0.0, ep.dt])
            self._UU = np.zeros((n, 4, 2))
            self._scratch = np.empty((n, 2, N_OUT))
            self._k = 0
            self._needs_reset = False

        def _observe(self, seen):
            ep, k, n = self.ep, self._k, self.num_envs
            obs = np.empty((n, 4), dtype=np.float32)
            noise = self.np_random.normal(0.0, ep.sensor.noise_C, n) if ep.sensor.noise_C else 0.0
            obs[:, 0] = seen + noise
            obs[:, 1] = ep.ref[k]
            obs[:, 2] = ep.ref[k + 1]
            obs[:, 3] = k / ep.n
            return obs

        def _restart(self):
            ep = self.ep
            self._X[:] = ep.roaster.x0
            if ep.tm0_spread:
                self._X[:, S_TM] += self.np_random.uniform(-ep.tm0_spread, ep.tm0_spread, self.num_envs)
            self._H[:] = H0_S
            self._u[:] = ep.setup.u_initial
            self._k = 0
            self._needs_reset = False
            return self._observe(self._X[:, S_TA])

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            return self._restart(), {}

        def step(self, actions):
            ep, n = self.ep, self.num_envs
            if self._needs_reset:  # NEXT_STEP autoreset: this step only starts new episodes
                obs = self._restart()
                z = np.zeros(n, dtype=bool)
                return obs, np.zeros(n), z, z.copy(), {}
            a = np.asarray(actions, dtype=np.float64).reshape(n)
            if not np.all(np.isfinite(a)):
                raise InputError("actions must be finite", "RoastVectorEnv.step")
            u = np.clip(a, np.maximum(ep.low, self._u - ep.cap), np.minimum(ep.high, self._u + ep.cap))
            du = u - self._u
            self._u = u
            self._U[:] = ep.inputs[self._k]
            self._U[:, ep.col] = u
            bt_before = self._X[:, S_TA].copy()
            step_population_kernel(
                self._X, self._U, self._PP, True, H_MAX_S, self._H, self._T2, self._UU, self._scratch
            )
            self._k += 1
            bt = self._X[:, S_TA]
            err = bt - ep.ref[self._k]
            rewards = ep.reward(err, du)
            obs = self._observe(bt - ep.frac_delay * (bt - bt_before))
            done = self._k >= ep.n
            self._needs_reset = done
            return obs, rewards, np.zeros(n, dtype=bool), np.full(n, done), {}


def register() -> bool:
    """Register ``roastlab/Roast-v0`` with Gymnasium (done on import of :mod:`roastlab.control`
    when Gymnasium is installed); returns whether it is registered."""
    if gym is None:
        return False
    if ENV_ID not in gym.registry:
        gym.register(
            id=ENV_ID,
            entry_point="roastlab.control.environment:RoastEnv",
            vector_entry_point="roastlab.control.environment:RoastVectorEnv",
        )
    return True
