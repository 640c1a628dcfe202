"""Fit specifications: which quantities an identification may move, within which bounds.

A fit spec is a TOML file::

    [free]                      # name = [lower, upper, start]  or a table with per_batch
    hgm = [0.001, 2.0, 0.05]
    hbm = [0.001, 2.0, 0.05]
    Pbm = [0.05, 0.95, 0.5]
    Gg_kg_s = [0.001, 0.2, 0.02]               # needs a map with [Gg] identify = true
    Tm0_C = { lower = 60, upper = 260, start = 160, per_batch = true }

    [fixed]                     # held values (theta components not free default to theta*)
    Kt = 0.02

    [initial]                   # initial-state defaults for every batch
    Tb0_C = 22.0
    X0 = 0.11

    [bed]                       # optional: the bed laws (roastlab.model.bed; default the paper's)
    contact = "wall"
    probe = "tumbling"

    [weights]                   # optional: outputs fitted together (default Ta = 1 alone)
    Ta = 1.0                    # the bean probe, model Ta (eq. 16)
    Tb2 = 0.25                  # a second bean reading (map [Tb2]), model Tb (eq. 15a)
    ET = 0.1                    # the logged ET (drum air), model outlet gas Tgo (eq. 15e)
                                # or "residual": the probe's residual variance over ET's

Names: the theta coefficients ``hgm, hbm, Pbm``, process constants ``A, cm, cw, Ha_R, Het,
k1, k2, Kt, lam``, the metal mass ``Mm``, the gas flow ``Gg_kg_s``, and initial states
``Tb0_C, Tm0_C, X0, He0_kJ_kg, Ta0_C``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError, ParameterError
from ..model.bed import PAPER_BED, BedLaws
from ..model.limits import check_value
from ..model.parameters import (
    DEFAULT_WEIGHTS,
    FREE_NAMES,
    OUTPUTS,
    RESIDUAL_REFERENCE_WHY,
    RESIDUAL_WEIGHT,
    STATE0,
    THETA_NAMES,
    THETA_PAPER,
    FreeParameter,
    by_residuals,
)
from .files import finite_number, read_toml

ALLOWED = FREE_NAMES
INITIAL_NAMES = tuple(STATE0)


@dataclass
class FitSpec:
    free: list[FreeParameter]
    fixed: dict[str, float]
    initial: dict[str, float] = field(default_factory=dict)
    source: str = ""
    weights: dict[str, float] = field(default_factory=dict)
    bed: BedLaws = PAPER_BED


def _checked(name: str, value: float, path, where) -> float:
    """A fixed or initial value inside its plausible range (the quantity table)."""
    try:
        return check_value(name, value)
    except ParameterError as exc:
        raise ParameterError(exc.problem, path, where) from None


def load_fit_spec(path: str | Path) -> FitSpec:
    """Read and check the fit spec at ``path`` (see the module docstring for the format)."""
    path = Path(path)
    data = read_toml(path)
    unknown = sorted(set(data) - {"free", "fixed", "initial", "weights", "bed", "description", "notes"})
    if unknown:
        raise InputError(f"unknown table(s) {', '.join(unknown)} (allowed: free, fixed, initial, weights, bed)", path)
    if not isinstance(data.get("bed", {}), dict):
        raise InputError("[bed] must be a table of option = law", path, "bed")
    try:
        bed = BedLaws.parse(data.get("bed") or None)
    except ParameterError as exc:
        raise InputError(exc.problem, path, "bed") from None
    free = []
    for name, spec in (data.get("free") or {}).items():
        where = f"free.{name}"
        if name not in ALLOWED:
            raise InputError(f"unknown parameter (allowed: {', '.join(ALLOWED)})", path, where)
        per_batch = False
        if isinstance(spec, list):
            if len(spec) != 3:
                raise InputError("expected [lower, upper, start]", path, where)
            lo, hi, start = (finite_number(v, path, where) for v in spec)
        elif isinstance(spec, dict):
            missing = [k for k in ("lower", "upper") if k not in spec]
            if missing:
                raise InputError(f"missing {', '.join(missing)}", path, where)
            lo, hi = finite_number(spec["lower"], path, where), finite_number(spec["upper"], path, where)
            start = finite_number(spec.get("start", 0.5 * (lo + hi)), path, where)
            per_batch = spec.get("per_batch", False)
            if not isinstance(per_batch, bool):
                raise InputError("per_batch must be true or false", path, where)
        else:
            raise InputError("expected [lower, upper, start] or a table", path, where)
        if name == "Pbm" and not (0 < lo and hi < 1):
            raise InputError(f"Pbm bounds must lie inside (0, 1), got {lo:g}:{hi:g}", path, where)
        try:
            free.append(FreeParameter(name, lo, hi, start, per_batch))
        except ParameterError as exc:
            raise InputError(str(exc), path, where) from None
    if not free:
        raise InputError("no [free] parameters: nothing to identify", path)
    fixed = {}
    for name, v in (data.get("fixed") or {}).items():
        if name not in ALLOWED:
            raise InputError(f"unknown parameter (allowed: {', '.join(ALLOWED)})", path, f"fixed.{name}")
        fixed[name] = _checked(name, finite_number(v, path, f"fixed.{name}"), path, f"fixed.{name}")
    names_free = {f.name for f in free}
    both = names_free & set(fixed)
    if both:
        raise InputError(f"{', '.join(sorted(both))} both free and fixed", path)
    for name in THETA_NAMES:  # theta components not free are held at the paper's theta*
        if name not in names_free and name not in fixed:
            fixed[name] = THETA_PAPER.as_dict()[name]
    initial = {}
    for name, v in (data.get("initial") or {}).items():
        if name not in INITIAL_NAMES:
            raise InputError(f"unknown initial state (allowed: {', '.join(INITIAL_NAMES)})", path, f"initial.{name}")
        initial[name] = _checked(name, finite_number(v, path, f"initial.{name}"), path, f"initial.{name}")
    weights = {}
    table = data.get("weights") or {}
    if not isinstance(table, dict):
        raise InputError("[weights] must be a table of output = weight", path, "weights")
    for name, v in table.items():
        if name not in OUTPUTS:
            raise InputError(f"unknown output (allowed: {', '.join(OUTPUTS)})", path, f"weights.{name}")
        if by_residuals(name, v):  # set from a first fit's residuals (fit.identify.residual_weights)
            weights[name] = v
            continue
        if isinstance(v, str):
            why = (
                RESIDUAL_REFERENCE_WHY
                if v == RESIDUAL_WEIGHT
                else f'must be a number or "{RESIDUAL_WEIGHT}" (set from a first fit\'s residuals), got {v[:40]!r}'
            )
            raise InputError(why, path, f"weights.{name}")
        w = finite_number(v, path, f"weights.{name}")
        if w < 0:
            raise InputError(f"must be >= 0, got {w:g}", path, f"weights.{name}")
        weights[name] = w
    if weights and not any(w == RESIDUAL_WEIGHT or w > 0 for w in {**DEFAULT_WEIGHTS, **weights}.values()):
        raise InputError("every output weight is 0: nothing to fit", path, "weights")
    return FitSpec(free, fixed, initial, str(path), weights, bed)
