"""Physical plausibility: the one table of allowed ranges for every quantity a user can give.

The CLI, the file readers and the Python API check values against :data:`LIMITS`, and the
message names the quantity, its unit and the range. The ranges are wide (any real roaster
fits well inside) but exclude values that break the model or give absurd answers: a gas flow
of 1e17 kg/s saturates every heat transfer and still prints a plausible-looking curve.
"""

from __future__ import annotations

import math

from ..errors import ParameterError

#: name -> (lowest, highest, unit, meaning); bounds inclusive.
LIMITS: dict[str, tuple[float, float, str, str]] = {
    # inputs
    "time_s": (0.0, 86400.0, "s", "time since CHARGE (a day at most)"),
    "Gg_kg_s": (1e-6, 100.0, "kg/s", "inlet gas mass flow"),
    "Tgi_C": (-50.0, 1000.0, "degC", "inlet gas temperature"),
    "Ta_C": (-50.0, 1000.0, "degC", "bean-probe temperature"),
    "dt_s": (1e-6, 3600.0, "s", "time between two samples"),
    # initial states
    "Tb0_C": (-50.0, 400.0, "degC", "bean temperature at CHARGE"),
    "Tm0_C": (-50.0, 700.0, "degC", "drum metal temperature at CHARGE"),
    "X0": (0.0, 1.0, "kg/kg", "green moisture, dry basis"),
    "He0_kJ_kg": (0.0, 1e4, "kJ/kg", "exothermic heat at CHARGE"),
    "Ta0_C": (-50.0, 700.0, "degC", "probe reading at CHARGE"),
    # identified coefficients and constants
    "hgm": (0.0, 100.0, "kW/(m2 K)", "gas-to-metal coefficient"),
    "hbm": (0.0, 100.0, "kW/(m2 K)", "metal-to-bean coefficient"),
    "Pbm": (1e-6, 1.0 - 1e-6, "-", "bean area touching the metal"),
    "Mm": (1e-4, 1e6, "kg", "drum metal mass"),
    "Mb_kg": (1e-4, 1e5, "kg", "green batch mass"),
    "batch_kg": (1e-4, 1e5, "kg", "green batch mass"),
    "Tgi_offset_C": (-500.0, 500.0, "degC", "change of the inlet gas temperature"),
}


def check_value(name: str, value, source: str | None = None) -> float:
    """``value`` as a float if it is a finite number inside ``LIMITS[name]``; else ParameterError.

    >>> check_value("X0", 0.11)
    0.11
    """
    lo, hi, unit, meaning = LIMITS[name]
    if isinstance(value, bool):
        raise ParameterError(f"{name} ({meaning}) must be a number, got {value!r}", source)
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"{name} ({meaning}) must be a number, got {str(value)[:40]!r}", source) from None
    if not math.isfinite(v) or not lo <= v <= hi:
        raise ParameterError(
            f"{name} ({meaning}) = {v:g} {unit} outside the plausible range {lo:g}..{hi:g} {unit}", source
        )
    return v


def check_array(name: str, values, source: str | None = None, where: str | None = None) -> None:
    """Every element finite and inside ``LIMITS[name]``; else ParameterError naming the first bad row."""
    import numpy as np

    lo, hi, unit, meaning = LIMITS[name]
    a = np.asarray(values, dtype=float)
    bad = np.flatnonzero(~np.isfinite(a) | (a < lo) | (a > hi))
    if bad.size:
        i = int(bad[0])
        raise ParameterError(
            f"{name} ({meaning}) = {a[i]:g} {unit} outside the plausible range {lo:g}..{hi:g} {unit}",
            source,
            where or f"row {i + 1}, column {name}",
        )
