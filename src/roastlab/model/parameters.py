"""Every quantity an identification may move, in one registry; theta = (hgm, hbm, Pbm).

:data:`REGISTRY` is the part of the one quantity table (:mod:`roastlab.model.quantities`) an
identification may free: unit, default, default fit bounds, kind, slot (where it enters the
model: the parameter vector or the initial state) and whether it carries over to another
plant (geometry-independent) or belongs to the plant it was fitted on.

hgm and hbm are in kW/(m^2 K) (Table 1 prints W/(m^2 K); MODEL.md explains the slip) and
Pbm is a fraction of the bean surface touching the metal (Table 1 prints %).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ParameterError
from . import layout
from .quantities import QUANTITIES, Quantity, table

THETA_NAMES = ("hgm", "hbm", "Pbm")
#: Table 1 bounds (from the quantity table).
THETA_BOUNDS = {k: QUANTITIES[k].bounds for k in THETA_NAMES}
THETA_UNITS = {k: QUANTITIES[k].unit for k in THETA_NAMES}


@dataclass(frozen=True)
class Theta:
    """Identified heat-transfer coefficients.

    Attributes
    ----------
    hgm : float
        Gas-to-metal heat-transfer coefficient [kW/(m^2 K)] (eq. 6).
    hbm : float
        Metal-to-bean heat-transfer coefficient [kW/(m^2 K)] (eq. 11).
    Pbm : float
        Fraction of bean area touching the metal [-], in (0, 1) (section 3.1).
    """

    hgm: float
    hbm: float
    Pbm: float

    def __post_init__(self) -> None:
        for name in THETA_NAMES:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ParameterError(f"{name} must be a finite number, got {v!r}")
        if self.hgm < 0 or self.hbm < 0:
            raise ParameterError(f"hgm and hbm must be >= 0 kW/(m2 K), got hgm={self.hgm}, hbm={self.hbm}")
        if not 0.0 < self.Pbm < 1.0:
            raise ParameterError(f"Pbm must be in (0, 1), got {self.Pbm}")

    def as_tuple(self) -> tuple[float, float, float]:
        return (self.hgm, self.hbm, self.Pbm)

    def as_dict(self) -> dict[str, float]:
        return {"hgm": self.hgm, "hbm": self.hbm, "Pbm": self.Pbm}


#: The paper's optimum theta* (Table 1): the quantity table's defaults.
THETA_PAPER = Theta(*(QUANTITIES[k].default for k in THETA_NAMES))
#: The paper's start theta0 (section 5.2).
THETA_START = Theta(0.01, 0.01, 0.5)


def as_theta(value) -> Theta:
    """Coerce a Theta, a (hgm, hbm, Pbm) sequence or a mapping with those keys."""
    if isinstance(value, Theta):
        return value
    if isinstance(value, dict):
        missing = [k for k in THETA_NAMES if k not in value]
        if missing:
            raise ParameterError(f"theta needs {', '.join(THETA_NAMES)}; missing {', '.join(missing)}")
        return Theta(*(value[k] for k in THETA_NAMES))
    try:
        values = [float(v) for v in value]
    except (TypeError, ValueError):
        raise ParameterError(f"theta must be three numbers (hgm, hbm, Pbm), got {str(value)[:60]!r}") from None
    if len(values) != len(THETA_NAMES):
        raise ParameterError(f"theta must be three numbers (hgm, hbm, Pbm), got {len(values)}")
    return Theta(*values)


#: Initial-state names and their index in the state vector (:data:`roastlab.model.layout.STATE0`).
STATE0 = layout.STATE0

#: Order in which the registry lists the identifiable quantities (messages, model files).
_REGISTRY_KINDS = ("theta", "process", "plant", "input", "extension", "initial")


def _build_registry() -> dict[str, Quantity]:
    rows = [q for q in table() if q.identifiable]
    rows.sort(key=lambda q: _REGISTRY_KINDS.index(q.kind))  # stable: table order within a kind
    return {q.name: q for q in rows}


#: Every identifiable quantity by name: the rows of the quantity table
#: (:mod:`roastlab.model.quantities`) that have fit bounds and a slot.
REGISTRY: dict[str, Quantity] = _build_registry()


def set_values(p, values: dict) -> None:
    """Write ``{registry name: value}`` into a parameter vector ``p`` in place (parameter
    entries only; initial states are set through :class:`roastlab.sim.InitialState`)."""
    from .limits import check_value

    P = layout.P
    for name, v in values.items():
        q = REGISTRY.get(name)
        if q is None or q.slot not in P:
            raise ParameterError(
                f"{name!r} is not a model parameter (allowed: {', '.join(n for n in REGISTRY if REGISTRY[n].slot in P)})"
            )
        p[P[q.slot]] = check_value(name, v)


#: Names usable as free or fixed parameters of a fit, in registry order.
FREE_NAMES = tuple(REGISTRY)


@dataclass
class FreeParameter:
    """One quantity a fit may move: name, bounds, start and whether it is per batch."""

    name: str
    lower: float
    upper: float
    start: float
    per_batch: bool = False

    def __post_init__(self) -> None:
        if self.name not in REGISTRY:
            raise ParameterError(f"unknown parameter {self.name!r} (allowed: {', '.join(FREE_NAMES)})")
        if not (math.isfinite(self.lower) and math.isfinite(self.upper)):
            raise ParameterError(f"bounds of {self.name} must be finite: {self.lower:g}:{self.upper:g}")
        if not self.lower < self.upper:
            raise ParameterError(f"bounds of {self.name} inverted or empty: {self.lower:g}:{self.upper:g}")
        from .limits import check_value

        check_value(self.name, self.lower, "lower bound")
        check_value(self.name, self.upper, "upper bound")
        if not self.lower <= self.start <= self.upper:
            self.start = min(max(self.start, self.lower), self.upper)


#: Outputs an identification can fit, each with the measured channel it is compared with.
#: ``Ta``: the model's probe reading Ta (eq. 16) against the log's bean probe; ``Tb2``: the
#: model's bean temperature Tb (eq. 15a) against a second bean reading of the log (e.g. an
#: infrared bean-surface sensor, the map's ``[Tb2]``); ``ET``: the model's outlet gas temperature
#: Tgo (eq. 15e) against the log's ET. Why Tgo: an ET probe sits in the drum's air space, which
#: eq. 15e treats as well mixed, so the air there is the gas that has passed the beans and the
#: metal, at Tgo; the inlet temperature is an input, not a prediction, and the metal is not air.
#: Weights multiply each output's squared residuals in the objective; the default fits Ta alone,
#: as the paper does (eq. 19).
OUTPUTS = ("Ta", "Tb2", "ET")
#: The model quantity each output is compared with: probe Ta, bean Tb, outlet gas Tgo.
MODEL_OF_OUTPUT = {"Ta": "Ta", "Tb2": "Tb", "ET": "Tgo"}
DEFAULT_WEIGHTS = {"Ta": 1.0, "Tb2": 0.0, "ET": 0.0}
#: A weight given as this word is set from the residuals (:func:`roastlab.fit.identify.residual_weights`):
#: the probe's residual variance over the output's, both from a first fit with the output at weight 1.
RESIDUAL_WEIGHT = "residual"
#: Weight of a log's first-crack mark read as the beans' temperature (a column map's ``[Tb2]
#: first_crack``: one sample per log at :data:`roastlab.model.constants.FIRST_CRACK_BEAN_C`) against
#: the probe's samples at weight 1. The mark is one sample against a hundred of the probe's, whose
#: errors run together for minutes (lag-1 autocorrelation 0.95-0.995 at 5 s: 40-400 samples to one
#: independent error), so at weight 1 the probe's curve outvotes it: fitted on the Skywalker's logs the
#: beans read 174-176 degC at the mark at weight 1, 187-199 at 10 and 196-203 at 50, where coffee cracks
#: at about 200 (spread 3.4 degC), the held-out probe FIT within 1.3 points throughout
#: (docs/real-roaster.md, "Skywalker: the beans at first crack").
FIRST_CRACK_WEIGHT = 30.0
#: The output weights from the residuals are relative to, the bean probe: its own weight is a number.
RESIDUAL_REFERENCE = "Ta"
#: Why the reference output cannot be weighed by the residuals (the fit spec's and --weight's error).
RESIDUAL_REFERENCE_WHY = "the probe is what weights from the residuals are relative to: give it a number"


def by_residuals(output: str, weight) -> bool:
    """Whether ``weight`` asks for ``output``'s weight from the residuals (:data:`RESIDUAL_WEIGHT`),
    which any output but :data:`RESIDUAL_REFERENCE` may.

    >>> by_residuals("ET", "residual"), by_residuals("Ta", "residual"), by_residuals("ET", 0.2)
    (True, False, False)
    """
    return weight == RESIDUAL_WEIGHT and output != RESIDUAL_REFERENCE


#: Starts a global search chooses for a local polish by default (:func:`roastlab.fit.identify.identify`:
#: the paper's theta0 and the best distinct trial points; one inside a found basin is skipped).
N_STARTS = 6
