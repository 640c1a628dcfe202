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

from .errors import InputError, ParameterError, RoastlabError  # noqa: E402
from .io.batch import Batch, read_batch_csv, read_dataset  # noqa: E402
from .io.plants import load_plant  # noqa: E402
from .model.parameters import REGISTRY, THETA_BOUNDS, THETA_PAPER, THETA_START, Theta  # noqa: E402
from .model.plant import Plant, preset_names  # noqa: E402
from .model.rhs import INPUT_NAMES, PARAM_NAMES, STATE_NAMES, pack_params  # noqa: E402
from .model.rhs import checked_rhs as rhs  # noqa: E402
from .sim.simulate import InitialState, SimulationResult, Simulator, simulate  # noqa: E402
from .workflows.fitting import FitResult, fit  # noqa: E402
from .workflows.model import FittedModel, load_log, load_model  # noqa: E402
from .workflows.reproduce import default_dataset_root  # noqa: E402

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
