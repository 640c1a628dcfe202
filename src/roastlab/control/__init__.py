"""Closed-loop control on the model: controllers, a state estimator, scenarios, a testbench.

* :class:`PID` -- Artisan's software PID (ramp/soak, follow the background, gain scheduling);
* :class:`MPC` -- receding-horizon control on the compiled model with
  :class:`ExtendedKalmanFilter` (bean, drum, moisture, exothermic heat, a disturbance);
* :class:`Replay` -- the reference's own recorded inputs;
* :func:`run_closed_loop` / :func:`compare` -- the testbench and its metrics, on scenarios
  (:func:`standard_scenarios`, :func:`roastlab.io.scenario.load_scenario`);
* ``roastlab/Roast-v0`` -- a Gymnasium environment, registered here when Gymnasium is
  installed (``pip install 'roastlab[rl]'``).

Any object with ``reset(setup)`` and ``step(time_s, measurement_C)`` is a controller
(:class:`Controller`).
"""

from ..io.scenario import Scenario, load_scenario
from .base import Controller, LoopSetup
from .estimator import ExtendedKalmanFilter
from .loop import ClosedLoopResult, Comparison, compare, make_controller, prepare, run_closed_loop, standard_scenarios
from .mpc import MPC
from .pid import PID, RampSoak
from .reference import standard_reference
from .replay import Replay

__all__ = [
    "Controller",
    "LoopSetup",
    "PID",
    "RampSoak",
    "MPC",
    "Replay",
    "ExtendedKalmanFilter",
    "Scenario",
    "load_scenario",
    "standard_scenarios",
    "make_controller",
    "prepare",
    "run_closed_loop",
    "ClosedLoopResult",
    "Comparison",
    "compare",
    "standard_reference",
]

from .environment import register as _register_environment

_register_environment()
