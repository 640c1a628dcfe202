"""Every quantity an identification may move, in one registry; theta = (hgm, hbm, Pbm).

:data:`REGISTRY` lists each identifiable quantity once: unit, default, default fit bounds,
what it is (a theta coefficient, a process constant, a plant value, an input factor or an
initial state), where it enters the model (a slot of the parameter vector or of the initial
state), whether it is fitted per batch by default, and whether it carries over to another
plant (geometry-independent) or belongs to the plant it was fitted on.

hgm and hbm are in kW/(m^2 K) (Table 1 prints W/(m^2 K); MODEL.md explains the slip) and
Pbm is a fraction of the bean surface touching the metal (Table 1 prints %).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ParameterError

THETA_NAMES = ("hgm", "hbm", "Pbm")
#: Table 1 bounds.
THETA_BOUNDS = {"hgm": (0.01, 0.35), "hbm": (0.01, 0.35), "Pbm": (0.5, 0.8)}
THETA_UNITS = {"hgm": "kW/(m2 K)", "hbm": "kW/(m2 K)", "Pbm": "-"}


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


#: The paper's optimum theta* (Table 1).
THETA_PAPER = Theta(0.0100, 0.0254, 0.5793)
#: The paper's start theta0 (section 5.2).
THETA_START = Theta(0.01, 0.01, 0.5)


def as_theta(value) -> Theta:
    """Coerce a Theta, a (hgm, hbm, Pbm) sequence or a mapping with those keys."""
    if isinstance(value, Theta):
        return value
    if isinstance(value, dict):
        return Theta(*(value[k] for k in THETA_NAMES))
    hgm, hbm, Pbm = value
    return Theta(float(hgm), float(hbm), float(Pbm))


@dataclass(frozen=True)
class Quantity:
    """One identifiable quantity of the model.

    Attributes
    ----------
    name : str
        Name in fit specs, model files and ``--fix``/``--bounds`` options.
    unit : str
    kind : str
        ``"theta"`` (Table 1), ``"process"`` (Table 5 left), ``"plant"`` (a plant value),
        ``"input"`` (a factor on a logged input), ``"actuator"`` (the actuator and shell-loss
        extensions, not in the paper) or ``"initial"`` (an initial state).
    bounds : (float, float)
        Default fit bounds.
    carries_over : bool
        True if geometry-independent, so it applies on another plant (the paper's 120 ->
        360 kg validation); False for values that belong to the fitted plant or batch.
    slot : str
        Name of the parameter-vector entry (:data:`roastlab.model.rhs.PARAM_NAMES`) or of the
        initial state (:data:`STATE0`) it sets.
    doc : str
    """

    name: str
    unit: str
    kind: str
    bounds: tuple[float, float]
    carries_over: bool
    slot: str
    doc: str


#: Initial-state names and their index in the state vector [Tb, Tm, X, He, Ta].
STATE0 = {"Tb0_C": 0, "Tm0_C": 1, "X0": 2, "He0_kJ_kg": 3, "Ta0_C": 4}


def _build_registry() -> dict[str, Quantity]:
    from .constants import ProcessConstants

    q: list[Quantity] = [
        Quantity("hgm", "kW/(m2 K)", "theta", THETA_BOUNDS["hgm"], True, "hgm", "gas-to-metal coefficient, eq. 6"),
        Quantity("hbm", "kW/(m2 K)", "theta", THETA_BOUNDS["hbm"], True, "hbm", "metal-to-bean coefficient, eq. 11"),
        Quantity("Pbm", "-", "theta", THETA_BOUNDS["Pbm"], True, "Pbm", "bean area touching the metal, section 3.1"),
    ]
    units = {"A": "kJ/(kg s)", "cm": "kJ/(kg K)", "cw": "kJ/(kg K)", "Ha_R": "K", "Het": "kJ/kg", "k1": "m2/s"}
    units.update({"k2": "K", "Kt": "1/s", "lam": "kJ/kg"})
    defaults = ProcessConstants()
    for name, unit in units.items():
        v = getattr(defaults, name)
        # a constant freed without bounds may move a factor of 5 either way from Table 5's value
        q.append(Quantity(name, unit, "process", (v / 5.0, v * 5.0), True, name, f"process constant {name}, Table 5"))
    q += [
        Quantity("Mm", "kg", "plant", (1e-3, 1e5), False, "Mm", "drum metal mass in thermal contact, eq. 12"),
        Quantity(
            "Gg_kg_s",
            "kg/s",
            "input",
            (1e-4, 10.0),
            False,
            "Gg_scale",
            "constant gas flow of a log that does not record it (factor on a 1 kg/s placeholder)",
        ),
        # actuator extension (a map with [heater] / [fan]; not in the paper)
        Quantity(
            "Qe_gain_kW",
            "kW/unit",
            "actuator",
            (0.0, 10.0),
            False,
            "Qe_gain",
            "heat into the drum metal per unit of heater setting (eq. 12's Qe)",
        ),
        Quantity(
            "Qe_offset_kW",
            "kW",
            "actuator",
            (-5.0, 5.0),
            False,
            "Qe_offset",
            "heat into the drum metal at heater setting 0 (eq. 12's Qe)",
        ),
        Quantity(
            "Tgi_gain_C",
            "degC/unit",
            "actuator",
            (0.0, 100.0),
            False,
            "Tgi_gain",
            "rise of the inlet gas temperature per unit of heater setting",
        ),
        Quantity(
            "tau_heater_s", "s", "actuator", (1.0, 600.0), False, "tau_heater", "first-order lag of the heater's effect"
        ),
        Quantity(
            "Gg_fan_kg_s",
            "kg/s/unit",
            "actuator",
            (0.0, 1.0),
            False,
            "Gg_fan",
            "gas flow per unit of fan setting (affine with Gg_kg_s)",
        ),
        # drum-shell heat loss (not in the paper, whose shell is adiabatic)
        Quantity(
            "U_shell_kW_m2K",
            "kW/(m2 K)",
            "actuator",
            (0.0, 0.1),
            False,
            "U_shell",
            "heat loss of the drum's outer surface to the room per m2 and K (eq. 12 extension)",
        ),
        Quantity("T_room_C", "degC", "actuator", (0.0, 40.0), False, "T_room", "room temperature for the shell loss"),
        # probe immersion (not in the paper, whose probe is always immersed)
        Quantity(
            "h_probe_m",
            "m",
            "actuator",
            (0.0, 0.5),
            False,
            "h_probe",
            "bean-bed depth that covers the bean probe; shallower beds leave part of it in the gas (eq. 17 extension)",
        ),
        Quantity("Tb0_C", "degC", "initial", (0.0, 60.0), True, "Tb0_C", "bean temperature at CHARGE"),
        Quantity("Tm0_C", "degC", "initial", (20.0, 300.0), False, "Tm0_C", "drum metal temperature at CHARGE"),
        Quantity("X0", "kg/kg", "initial", (0.02, 0.2), True, "X0", "green moisture, dry basis"),
        Quantity("He0_kJ_kg", "kJ/kg", "initial", (0.0, 232.0), True, "He0_kJ_kg", "exothermic heat at CHARGE"),
        Quantity("Ta0_C", "degC", "initial", (0.0, 300.0), False, "Ta0_C", "probe reading at CHARGE"),
    ]
    return {x.name: x for x in q}


#: Every identifiable quantity by name (see :class:`Quantity`).
REGISTRY: dict[str, Quantity] = _build_registry()


def set_values(p, values: dict) -> None:
    """Write ``{registry name: value}`` into a parameter vector ``p`` in place (parameter
    entries only; initial states are set through :class:`roastlab.sim.InitialState`)."""
    from .limits import LIMITS, check_value
    from .rhs import P

    for name, v in values.items():
        q = REGISTRY.get(name)
        if q is None or q.slot not in P:
            raise ParameterError(
                f"{name!r} is not a model parameter (allowed: {', '.join(n for n in REGISTRY if REGISTRY[n].slot in P)})"
            )
        p[P[q.slot]] = check_value(name, v) if name in LIMITS else float(v)


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
        from .limits import LIMITS, check_value

        if self.name in LIMITS:
            check_value(self.name, self.lower)
            check_value(self.name, self.upper)
        elif REGISTRY[self.name].kind not in ("theta", "actuator") and not self.lower > 0:
            raise ParameterError(f"{self.name} must stay > 0 {REGISTRY[self.name].unit}: lower bound {self.lower:g}")
        if not self.lower <= self.start <= self.upper:
            self.start = min(max(self.start, self.lower), self.upper)


#: Outputs an identification can fit, each with the measured channel it is compared with.
#: ``Ta``: the model's probe reading Ta (eq. 16) against the log's bean probe; ``Tb2``: the
#: model's bean temperature Tb (eq. 15a) against a second bean reading of the log (e.g. an
#: infrared bean-surface sensor, the map's ``[Tb2]``). Weights multiply each output's squared
#: residuals in the objective; the default fits Ta alone, as the paper does (eq. 19).
OUTPUTS = ("Ta", "Tb2")
DEFAULT_WEIGHTS = {"Ta": 1.0, "Tb2": 0.0}
