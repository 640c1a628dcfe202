"""roastlab: a scalable physical model of an industrial coffee-roasting drum.

Implements "A scalable model of a coffee roasting chamber" (Procedia Computer Science,
2021, doi:10.1016/j.procs.2021.01.362) as read by MODEL.md: the model, a fast simulator,
identification of (hgm, hbm, Pbm) and validation across plant sizes.
"""

from .errors import InputError, ParameterError, RoastlabError
from .model import INPUT_NAMES, PARAM_NAMES, STATE_NAMES, pack_params, rhs
from .plant import Plant, load_plant, preset_names
from .simulate import InitialState, SimulationResult, Simulator, simulate
from .theta import THETA_BOUNDS, THETA_PAPER, THETA_START, Theta

__version__ = "0.1.0"

__all__ = [
    "INPUT_NAMES",
    "PARAM_NAMES",
    "STATE_NAMES",
    "THETA_BOUNDS",
    "THETA_PAPER",
    "THETA_START",
    "InitialState",
    "InputError",
    "ParameterError",
    "Plant",
    "RoastlabError",
    "SimulationResult",
    "Simulator",
    "Theta",
    "load_plant",
    "pack_params",
    "preset_names",
    "rhs",
    "simulate",
]
