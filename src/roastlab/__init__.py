"""roastlab: a scalable physical model of an industrial coffee-roasting drum.

Implements "A scalable model of a coffee roasting chamber" (Procedia Computer Science,
2021, doi:10.1016/j.procs.2021.01.362) as read by MODEL.md: the model, a fast simulator,
identification and validation across plant sizes, applied through one fitted-model object.

Layout (imports point one way: cli -> control -> fleet -> workflows -> fit -> evaluate -> sim ->
report -> io -> metrics -> model -> errors; tests/test_layout.py enforces it):

* :mod:`roastlab.model`: the quantity table, the vectors' layout, constants, plant geometry,
  the right-hand side, the identification registry;
* :mod:`roastlab.metrics`: rate of rise and crossing times, defined once;
* :mod:`roastlab.io`: input/output guards, batch files, plants, model files, fit specs, importers;
* :mod:`roastlab.report`: figures;
* :mod:`roastlab.sim`: compiled kernels, :func:`simulate`, :class:`Simulator`, populations;
* :mod:`roastlab.evaluate`: metrics and validation scores;
* :mod:`roastlab.fit`: the objective, global search, the per-batch fitter, uncertainty, the
  program optimiser, the baseline;
* :mod:`roastlab.workflows`: :class:`FittedModel`, :func:`fit`, what-if, transfer, reproduction;
* :mod:`roastlab.fleet`: the fleet store, fleet fits, drift;
* :mod:`roastlab.control`: controllers, the closed-loop testbench, environments;
* :mod:`roastlab.cli`: the command line, one module per command (``roastlab.apps.cli`` is a
  deprecated alias); the benchmark is ``benchmarks/bench.py`` in a checkout.
"""

__version__ = "0.2.0"

import importlib
import sys
import types
from typing import TYPE_CHECKING

from . import sim  # noqa: F401  (light: it sets numba's OpenMP wait policy before anything loads OpenMP)

# The package's names load on first use (PEP 562), so that `import roastlab.cli` costs no numerical
# library: the command line sets up its handling of Ctrl-C before it imports them (roastlab.cli).
_LAZY = {
    "InputError": "errors",
    "ParameterError": "errors",
    "RoastlabError": "errors",
    "Batch": "io.batch",
    "read_batch_csv": "io.batch",
    "read_dataset": "io.batch",
    "load_plant": "io.plants",
    "REGISTRY": "model.parameters",
    "THETA_BOUNDS": "model.parameters",
    "THETA_PAPER": "model.parameters",
    "THETA_START": "model.parameters",
    "Theta": "model.parameters",
    "Plant": "model.plant",
    "preset_names": "model.plant",
    "INPUT_NAMES": "model.rhs",
    "PARAM_NAMES": "model.rhs",
    "STATE_NAMES": "model.rhs",
    "pack_params": "model.rhs",
    "rhs": "model.rhs:checked_rhs",
    "InitialState": "sim.simulate",
    "SimulationResult": "sim.simulate",
    "Simulator": "sim.simulate",
    "simulate": "sim.simulate",
    "FitResult": "workflows.fitting",
    "fit": "workflows.fitting",
    "FittedModel": "workflows.model",
    "load_log": "workflows.model",
    "load_model": "workflows.model",
    "default_dataset_root": "workflows.reproduce",
}

if TYPE_CHECKING:  # the same names for static tools (editors, type checkers); tests/test_api.py holds them alike
    from .errors import InputError, ParameterError, RoastlabError
    from .io.batch import Batch, read_batch_csv, read_dataset
    from .io.plants import load_plant
    from .model.parameters import REGISTRY, THETA_BOUNDS, THETA_PAPER, THETA_START, Theta
    from .model.plant import Plant, preset_names
    from .model.rhs import INPUT_NAMES, PARAM_NAMES, STATE_NAMES, pack_params
    from .model.rhs import checked_rhs as rhs
    from .sim.simulate import InitialState, SimulationResult, Simulator, simulate
    from .workflows.fitting import FitResult, fit
    from .workflows.model import FittedModel, load_log, load_model
    from .workflows.reproduce import default_dataset_root


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module 'roastlab' has no attribute {name!r}")
    module, _, attr = _LAZY[name].partition(":")
    value = getattr(importlib.import_module(f".{module}", __name__), attr or name)
    globals()[name] = value  # once loaded, an ordinary attribute
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))


class _Package(types.ModuleType):
    """The package: ``roastlab.fit`` is the function (:func:`roastlab.workflows.fitting.fit`), though
    a subpackage has the same name. Python sets a subpackage as its parent's attribute when it first
    loads it; with the names loaded on first use that could come first, so it is refused here for
    the names above and the function stays what ``roastlab.fit`` means."""

    def __setattr__(self, name, value):
        if name in _LAZY and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


__all__ = [
    "INPUT_NAMES",
    "PARAM_NAMES",
    "REGISTRY",
    "STATE_NAMES",
    "THETA_BOUNDS",
    "THETA_PAPER",
    "THETA_START",
    "Batch",
    "FitResult",
    "FittedModel",
    "InitialState",
    "InputError",
    "ParameterError",
    "Plant",
    "RoastlabError",
    "SimulationResult",
    "Simulator",
    "Theta",
    "default_dataset_root",
    "fit",
    "load_log",
    "load_model",
    "load_plant",
    "pack_params",
    "preset_names",
    "read_batch_csv",
    "read_dataset",
    "rhs",
    "simulate",
]
