"""Physical plausibility: every value a user gives is checked against its quantity's range.

The ranges live in the one quantity table, :mod:`roastlab.model.quantities`. The CLI, the file
readers and the Python API check values with :func:`check_value` and :func:`check_array`, and the
message names the quantity, its unit and the range. The ranges are wide (any real roaster
fits well inside) but exclude values that break the model or give absurd answers: a gas flow
of 1e17 kg/s saturates every heat transfer and still prints a plausible-looking curve.
"""

from __future__ import annotations

import math

from ..errors import ParameterError
from .quantities import QUANTITIES

#: name -> (lowest, highest, unit, meaning); bounds inclusive. A view of the quantity table
#: (:data:`roastlab.model.quantities.QUANTITIES`), aliases included, kept for the readers that
#: index it by name.
LIMITS: dict[str, tuple[float, float, str, str]] = {
    name: (*q.plausible, q.unit, q.meaning) for name, q in QUANTITIES.items()
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
    except OverflowError:
        v = math.copysign(math.inf, value)  # an integer beyond float range: reported as out of range below
    except (TypeError, ValueError):
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
