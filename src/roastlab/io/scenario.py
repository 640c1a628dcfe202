"""Closed-loop scenarios: how the simulated roaster, its probe and its actuator differ from the
controller's model (TOML files, checked against the plausibility table).

A scenario file (every key optional; an empty file is the nominal scenario)::

    name = "heavy batch, cold drum"
    description = "free text"

    [plant]              # the simulated roaster; differs from the controller's model
    mass_factor = 1.2    # batch mass / the reference's batch mass [-]
    mass_known = true    # the controller is told the batch mass (roasters weigh every batch)
    X0 = 0.12            # green moisture [kg/kg dry] (default: the model's)
    Tm0_C = 150.0        # drum metal temperature at CHARGE [degC] (default: the model's) ...
    Tm0_offset_C = -60   # ... or a change of it [degC] (a cold or hot drum on any machine)
    Tb0_C = 25.0         # bean temperature at CHARGE [degC] (or Tb0_offset_C)
    Gg_factor = 0.9      # the gas flow the plant gets over the flow set (gas supply -10 %)
    theta = { hgm = 0.011, hbm = 0.028, Pbm = 0.55 }    # values by registry name ...
    theta_factor = { hgm = 0.8, hbm = 0.8 }             # ... or factors on the model's

    [sensor]             # the bean probe the controller reads
    noise_C = 0.5        # white noise, standard deviation [degC]
    delay_s = 2.0        # transport delay of the reading [s]
    seed = 7             # noise seed (the same seed gives the same run)

    [actuator]           # what the controller moves and how far and fast it may
    decide = "Tgi"       # "Tgi" (inlet gas temperature, the paper's input) or "heater"; left out:
                         # the model's own control (the heater on a machine whose inlet is room air)
    Tgi_min_C = 150.0    # level limits [degC] ...
    Tgi_max_C = 550.0
    Tgi_rate_C_per_min = 120.0     # ... and rate limit [degC/min]
    heater_min = 0.0     # with decide = "heater": the heater setting's limits (map units;
                         # default: the machine's, from the model's map [heater])
    heater_max = 9.0
    heater_rate_per_min = 20.0
    Gg_kg_s = 0.4        # fixed gas flow [kg/s] (default: the reference's)
    sample_s = 5.0       # control interval [s]

Every number is checked against :data:`roastlab.model.limits.LIMITS`; an unknown key, an
inverted limit or an implausible value is one :class:`~roastlab.errors.InputError` naming the
file and the key.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError, ParameterError
from ..model.actuators import TGI_LIMITS
from ..model.limits import check_value
from ..model.parameters import REGISTRY, STATE0
from .files import finite_number, read_toml
from .fitspec import _checked

#: Keys of each table (and of the top level).
KEYS = {
    "": {"name", "description", "plant", "sensor", "actuator"},
    "plant": {
        "mass_factor",
        "mass_known",
        "X0",
        "Tm0_C",
        "Tm0_offset_C",
        "Tb0_C",
        "Tb0_offset_C",
        "Gg_factor",
        "theta",
        "theta_factor",
    },
    "sensor": {"noise_C", "delay_s", "seed"},
    "actuator": {
        "decide",
        "Tgi_min_C",
        "Tgi_max_C",
        "Tgi_rate_C_per_min",
        "heater_min",
        "heater_max",
        "heater_rate_per_min",
        "Gg_kg_s",
        "sample_s",
    },
}
#: Values a scenario may set on the plant (registry parameters, not initial states).
PLANT_VALUES = tuple(k for k in REGISTRY if k not in STATE0)
#: Default actuator limits for the inlet gas temperature: (min, max [degC], rate [degC/min]).
TGI_DEFAULTS = TGI_LIMITS


@dataclass(frozen=True)
class PlantChange:
    """How the simulated roaster differs from the controller's model (see the module docstring)."""

    mass_factor: float = 1.0
    mass_known: bool = True
    X0: float | None = None
    Tm0_C: float | None = None
    Tm0_offset_C: float = 0.0
    Tb0_C: float | None = None
    Tb0_offset_C: float = 0.0
    Gg_factor: float = 1.0
    theta: dict = field(default_factory=dict)
    theta_factor: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Sensor:
    """The probe the controller reads: white noise [degC], a transport delay [s], a seed."""

    noise_C: float = 0.0
    delay_s: float = 0.0
    seed: int = 0


@dataclass(frozen=True)
class Actuator:
    """The decided input (``"Tgi"`` or ``"heater"``; None: the model's own control, see
    :meth:`roastlab.fit.program.ProgramLimits.for_model`), its level and rate limits (per
    minute; None: the machine's, as the model's map declares them, or :data:`TGI_DEFAULTS`),
    the fixed gas flow [kg/s] (None: the reference's) and the control interval [s]."""

    decide: str | None = None
    low: float | None = None
    high: float | None = None
    rate_per_min: float | None = None
    Gg_kg_s: float | None = None
    sample_s: float = 5.0


@dataclass(frozen=True)
class Scenario:
    """One closed-loop scenario: a name, the plant's changes, the sensor and the actuator."""

    name: str = "nominal"
    description: str = ""
    plant: PlantChange = field(default_factory=PlantChange)
    sensor: Sensor = field(default_factory=Sensor)
    actuator: Actuator = field(default_factory=Actuator)
    source: str = ""


def _text(v, path, where: str, limit: int = 200) -> str:
    if not isinstance(v, str):
        raise InputError(f"must be a string, got {str(v)[:40]!r}", path, where)
    return "".join(c if c.isprintable() else " " for c in v[:limit])


def _table(data: dict, key: str, path) -> dict:
    t = data.get(key, {})
    if not isinstance(t, dict):
        raise InputError("must be a table", path, key)
    unknown = sorted(set(t) - KEYS[key])
    if unknown:
        raise InputError(f"unknown key(s) {', '.join(unknown)} (allowed: {', '.join(sorted(KEYS[key]))})", path, key)
    return t


def _value(table: dict, key: str, path, where: str, limit_name: str | None = None):
    """The number at ``table[key]`` checked against the plausibility table (None when absent)."""
    if key not in table:
        return None
    x = finite_number(table[key], path, f"{where}.{key}")
    try:
        return check_value(limit_name or key, x)
    except ParameterError as exc:
        raise InputError(exc.problem, path, f"{where}.{key}") from None


def _values(table: dict, key: str, path, factor: bool) -> dict[str, float]:
    t = table.get(key, {})
    if not isinstance(t, dict):
        raise InputError("must be a table such as { hgm = 0.02 }", path, f"plant.{key}")
    out = {}
    for name, v in t.items():
        where = f"plant.{key}.{name}"
        if name not in PLANT_VALUES:
            raise InputError(f"unknown value (allowed: {', '.join(PLANT_VALUES)})", path, where)
        x = finite_number(v, path, where)
        if factor:
            try:
                out[name] = check_value("theta_factor", x)
            except ParameterError as exc:
                raise InputError(exc.problem, path, where) from None
        else:
            out[name] = _checked(name, x, path, where)
    return out


def _plant(data: dict, path) -> PlantChange:
    t = _table(data, "plant", path)
    for a, b in (("Tm0_C", "Tm0_offset_C"), ("Tb0_C", "Tb0_offset_C")):
        if a in t and b in t:
            raise InputError(f"give {a} or {b}, not both", path, "plant")
    known = t.get("mass_known", True)
    if not isinstance(known, bool):
        raise InputError("must be true or false", path, "plant.mass_known")
    theta, factors = _values(t, "theta", path, False), _values(t, "theta_factor", path, True)
    both = sorted(set(theta) & set(factors))
    if both:
        raise InputError(f"{', '.join(both)} in both theta and theta_factor", path, "plant")
    return PlantChange(
        mass_factor=_value(t, "mass_factor", path, "plant") or 1.0,
        mass_known=known,
        X0=_value(t, "X0", path, "plant"),
        Tm0_C=_value(t, "Tm0_C", path, "plant"),
        Tm0_offset_C=_value(t, "Tm0_offset_C", path, "plant") or 0.0,
        Tb0_C=_value(t, "Tb0_C", path, "plant"),
        Tb0_offset_C=_value(t, "Tb0_offset_C", path, "plant") or 0.0,
        Gg_factor=_value(t, "Gg_factor", path, "plant") or 1.0,
        theta=theta,
        theta_factor=factors,
    )


def _sensor(data: dict, path) -> Sensor:
    t = _table(data, "sensor", path)
    seed = t.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise InputError(f"must be an integer from 0 to 2**63 - 1, got {str(seed)[:40]!r}", path, "sensor.seed")
    return Sensor(
        noise_C=_value(t, "noise_C", path, "sensor") or 0.0,
        delay_s=_value(t, "delay_s", path, "sensor") or 0.0,
        seed=seed,
    )


def _actuator(data: dict, path) -> Actuator:
    t = _table(data, "actuator", path)
    implied = (
        "heater" if any(k.startswith("heater_") for k in t) else "Tgi" if any(k.startswith("Tgi_") for k in t) else None
    )
    decide = _text(t["decide"], path, "actuator.decide") if "decide" in t else implied
    if decide not in ("Tgi", "heater", None):
        raise InputError(f"must be 'Tgi' or 'heater', got {decide!r}", path, "actuator.decide")
    if decide is not None:
        other = "heater" if decide == "Tgi" else "Tgi"
        stray = sorted(k for k in t if k.startswith(other + "_"))
        if stray:
            raise InputError(f"{', '.join(stray)} given but decide = {decide!r}", path, "actuator")
    low = high = rate = None
    if decide == "Tgi":
        low = _value(t, "Tgi_min_C", path, "actuator", "Tgi_C")
        high = _value(t, "Tgi_max_C", path, "actuator", "Tgi_C")
        rate = _value(t, "Tgi_rate_C_per_min", path, "actuator", "rate_per_min")
        low = TGI_DEFAULTS[0] if low is None else low
        high = TGI_DEFAULTS[1] if high is None else high
        rate = TGI_DEFAULTS[2] if rate is None else rate
        names = ("Tgi_min_C", "Tgi_max_C")
    elif decide == "heater":  # what is not given comes from the machine (the model's map)
        low = _value(t, "heater_min", path, "actuator", "heater")
        high = _value(t, "heater_max", path, "actuator", "heater")
        rate = _value(t, "heater_rate_per_min", path, "actuator", "rate_per_min")
        names = ("heater_min", "heater_max")
    if low is not None and high is not None and not low < high:
        raise InputError(f"limits inverted or empty: {names[0]} {low:g} >= {names[1]} {high:g}", path, "actuator")
    sample = _value(t, "sample_s", path, "actuator")
    return Actuator(
        decide=decide,
        low=low,
        high=high,
        rate_per_min=rate,
        Gg_kg_s=_value(t, "Gg_kg_s", path, "actuator"),
        sample_s=5.0 if sample is None else sample,
    )


def scenario_from_mapping(data: dict, path: str | Path = "scenario") -> Scenario:
    """A :class:`Scenario` from parsed TOML (see the module docstring for the keys)."""
    if not isinstance(data, dict):
        raise InputError("expected a TOML table", path)
    unknown = sorted(set(data) - KEYS[""])
    if unknown:
        raise InputError(f"unknown key(s) {', '.join(unknown)} (allowed: {', '.join(sorted(KEYS['']))})", path)
    name = _text(data.get("name", Path(str(path)).stem), path, "name", 80)
    return Scenario(
        name=name.strip() or "unnamed",
        description=_text(data.get("description", ""), path, "description", 400),
        plant=_plant(data, path),
        sensor=_sensor(data, path),
        actuator=_actuator(data, path),
        source=str(path),
    )


def load_scenario(path: str | Path) -> Scenario:
    """Read and check the scenario TOML at ``path`` (bounded read, see :mod:`roastlab.io.files`)."""
    return scenario_from_mapping(read_toml(path), path)
