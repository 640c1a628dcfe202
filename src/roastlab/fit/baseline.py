"""A first-order baseline for real roasters: dBT/dt = (Tgi + k_h heater + k_f fan + offset - BT) / tau.

What a user gets without the physics: the bean probe chases one driving temperature with one
time constant ``tau`` [s] and a constant ``offset`` [degC]. The driving temperature is the
batch's Tgi column (ET on a map that reads ET as Tgi) plus, when the batches carry heater or
fan settings (the actuator maps), a fitted gain per setting [degC per unit]: the same inputs
the physical model is fed. Fitted by least squares on the same batches as the model, so the
comparison shows what the physics buys. The input is held linearly between samples and each
interval is solved exactly.
"""

from __future__ import annotations

import math

import numpy as np

from ..evaluate.metrics import batch_metrics
from ..sim.cache import compiled

BOUNDS = {"tau_s": (1.0, 5000.0), "offset_C": (-200.0, 200.0)}


@compiled
def first_order_response(t, u, y0, tau, offset):
    """Exact response of tau y' = u(t) + offset - y with u linear between samples."""
    n = t.shape[0]
    y = np.empty(n)
    y[0] = y0
    for k in range(n - 1):
        dt = t[k + 1] - t[k]
        s = (u[k + 1] - u[k]) / dt
        a = math.exp(-dt / tau)
        # particular solution of a ramp input: u + offset - tau s
        v0 = u[k] + offset - tau * s
        v1 = u[k + 1] + offset - tau * s
        y[k + 1] = v1 + (y[k] - v0) * a
    return y


#: The settings a baseline may take a gain on, and the name of that gain in its file.
SETTING_GAINS = {"heater": "heater_gain_C", "fan": "fan_gain_C"}


def _drive(b, gains: dict) -> np.ndarray:
    """The baseline's driving temperature [degC] for batch ``b``: Tgi plus the settings' gains."""
    u = np.asarray(b.Tgi_C, dtype=float).copy()
    for setting, key in SETTING_GAINS.items():
        series = getattr(b, setting, None)
        if key in gains and series is not None:
            u += gains[key] * series
    return u


def fit_first_order(batches) -> dict:
    """Fit tau, offset (and a gain per logged setting) jointly on batches with Tgi and Ta."""
    # imported where called: SciPy's optimize and stats cost every command ~1 s (tests/test_layout.py)
    from scipy.optimize import least_squares

    settings = [k for s, k in SETTING_GAINS.items() if any(getattr(b, s, None) is not None for b in batches)]

    def predictions(z):
        gains = dict(zip(settings, z[2:]))
        return [first_order_response(b.time_s, _drive(b, gains), float(b.Ta_C[0]), z[0], z[1]) for b in batches]

    def residuals(z):
        return np.concatenate([y - b.Ta_C for y, b in zip(predictions(z), batches)])

    lo = [BOUNDS["tau_s"][0], BOUNDS["offset_C"][0]] + [-1e3] * len(settings)
    hi = [BOUNDS["tau_s"][1], BOUNDS["offset_C"][1]] + [1e3] * len(settings)
    # start: the heater alone (else the offset) carries the probe ~200 degC above its inputs;
    # a few time constants, the best local solution kept
    heaters = [np.mean(b.heater) for b in batches if b.heater is not None]  # none where only a fan is logged
    heater_mean = float(np.mean(heaters)) if heaters else 0.0
    g0 = [200.0 / heater_mean if k == "heater_gain_C" and heater_mean > 0 else 0.0 for k in settings]
    res = None
    for tau0 in (120.0, 400.0, 1200.0):
        r = least_squares(residuals, [tau0, 0.0] + g0, bounds=(lo, hi), x_scale=[100.0, 10.0] + [1.0] * len(settings))
        if res is None or r.cost < res.cost:
            res = r
    return {
        "baseline": "first-order",
        "tau_s": float(res.x[0]),
        "offset_C": float(res.x[1]),
        **{k: float(v) for k, v in zip(settings, res.x[2:])},
        "SSR": float(res.fun @ res.fun),
        "batches": [b.name for b in batches],
    }


def describe(params: dict, units: str = "C") -> str:
    """One line: the baseline's fitted values, its offset and gains (temperature differences) in ``units``
    ("C" or "F")."""
    from ..metrics.profile import display_temp_delta

    u = "degF" if units == "F" else "degC"  # the ASCII spelling this line has always had
    gains = "".join(
        f", {k.removesuffix('_gain_C')} gain {display_temp_delta(params[k], units):+.3g} {u}/unit"
        for k in SETTING_GAINS.values()
        if k in params
    )
    return f"tau {params['tau_s']:.1f} s, offset {display_temp_delta(params['offset_C'], units):+.2f} {u}{gains}"


def validate_first_order(batches, params: dict):
    """Simulate the baseline on each batch: (predictions, metric rows)."""
    preds, rows = [], []
    for b in batches:
        y = first_order_response(b.time_s, _drive(b, params), float(b.Ta_C[0]), params["tau_s"], params["offset_C"])
        preds.append(y)
        rows.append(batch_metrics(b.Ta_C, y))
    return preds, rows


def validation_of_first_order(batches, params: dict, plant: str = ""):
    """The baseline on each batch as a :class:`~roastlab.evaluate.validate.ValidationResult`."""
    from ..evaluate.validate import ValidationResult

    preds, rows = validate_first_order(batches, params)
    names = [b.name for b in batches]
    return ValidationResult(names, [b.time_s for b in batches], [b.Ta_C for b in batches], preds, [], rows, plant)


def baseline_document(params: dict, result) -> dict:
    """The baseline's validation as JSON: its values, per-batch metrics and their average."""
    from ..evaluate.metrics import average_metrics

    return {
        "baseline": "first-order",
        "tau_s": params["tau_s"],
        "offset_C": params["offset_C"],
        **{k: params[k] for k in SETTING_GAINS.values() if k in params},
        "batches": [{"name": n, **r} for n, r in zip(result.names, result.rows)],
        "average": average_metrics(result.rows),
    }


def load_baseline(path) -> dict:
    """A first-order baseline file (from ``identify --baseline first-order``), checked."""
    import math

    from ..errors import InputError
    from ..io.files import read_input_text
    from ..io.modelfile import parse_json_document

    data = parse_json_document(read_input_text(path, "JSON"), path)
    if not isinstance(data, dict):
        raise InputError("expected a JSON object", path)
    if data.get("baseline") != "first-order":
        raise InputError("not a first-order baseline file (from 'identify --baseline first-order')", path)
    optional = [k for k in SETTING_GAINS.values() if k in data]
    for key in ("tau_s", "offset_C", *optional):
        v = data.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise InputError("missing or not a finite number", path, f"key {key}")
    if not data["tau_s"] > 0:
        raise InputError("tau_s must be > 0", path, "key tau_s")
    return data
