"""The identified coefficients theta = (hgm, hbm, Pbm): values, bounds, start (Table 1).

hgm and hbm are in kW/(m^2 K) (Table 1 prints W/(m^2 K); MODEL.md explains the slip) and
Pbm is a fraction of the bean surface touching the metal (Table 1 prints %).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

from .errors import InputError, ParameterError

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


def load_theta_json(path: str | Path) -> tuple[Theta, dict]:
    """Read THETA.json: ``{"hgm": ..., "hbm": ..., "Pbm": ...}`` plus any extra keys.

    Returns the Theta and the whole parsed mapping (extra keys kept for callers).
    """
    from .io import read_input_text

    path = Path(path)
    text = read_input_text(path)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"not valid JSON ({exc.msg} at line {exc.lineno}, column {exc.colno})", path) from None
    if not isinstance(data, dict):
        raise InputError(f"expected a JSON object with keys {', '.join(THETA_NAMES)}, got {type(data).__name__}", path)
    missing = [k for k in THETA_NAMES if k not in data]
    if missing:
        raise InputError(f"missing key(s) {', '.join(missing)}", path)
    for k in THETA_NAMES:
        v = data[k]
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InputError(f"must be a number, got {json.dumps(v)}", path, f"key {k}")
    try:
        theta = Theta(float(data["hgm"]), float(data["hbm"]), float(data["Pbm"]))
    except ParameterError as exc:
        raise ParameterError(exc.problem, path) from None
    return theta, data
