"""A first-order baseline for real roasters: dBT/dt = (ET + offset - BT) / tau.

What a user gets without the physics: the bean probe chases the environment temperature with
one time constant ``tau`` [s] and a constant ``offset`` [degC]. Fitted by least squares on
the same batches as the model (Tgi column = ET), so the comparison shows what the physical
model buys. ET is held linearly between samples and each interval is solved exactly.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.optimize import least_squares

from ..evaluate.metrics import batch_metrics

BOUNDS = {"tau_s": (1.0, 5000.0), "offset_C": (-200.0, 200.0)}


@njit(cache=True)
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


def fit_first_order(batches) -> dict:
    """Fit (tau, offset) jointly on batches with Tgi (= ET) and Ta (= BT)."""

    def residuals(z):
        tau, off = z
        return np.concatenate(
            [first_order_response(b.time_s, b.Tgi_C, float(b.Ta_C[0]), tau, off) - b.Ta_C for b in batches]
        )

    res = least_squares(
        residuals,
        [120.0, 0.0],
        bounds=([BOUNDS["tau_s"][0], BOUNDS["offset_C"][0]], [BOUNDS["tau_s"][1], BOUNDS["offset_C"][1]]),
        x_scale=[100.0, 10.0],
    )
    return {
        "baseline": "first-order",
        "tau_s": float(res.x[0]),
        "offset_C": float(res.x[1]),
        "SSR": float(res.fun @ res.fun),
        "batches": [b.name for b in batches],
    }


def validate_first_order(batches, params: dict):
    """Simulate the baseline on each batch: (predictions, metric rows)."""
    preds, rows = [], []
    for b in batches:
        y = first_order_response(b.time_s, b.Tgi_C, float(b.Ta_C[0]), params["tau_s"], params["offset_C"])
        preds.append(y)
        rows.append(batch_metrics(b.Ta_C, y))
    return preds, rows
