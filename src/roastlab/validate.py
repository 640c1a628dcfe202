"""Simulate batches with given parameters and score them (Table 2 metrics, section 6.2)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .metrics import METRIC_NAMES, absolute_error_moments, average_metrics, batch_metrics
from .population import FREE_NAMES, pack_batches, simulate_population
from .theta import THETA_NAMES


@dataclass
class ValidationResult:
    """Per-batch predictions and metrics of one dataset."""

    names: list[str]
    time_s: list[np.ndarray]
    measured: list[np.ndarray]
    predicted: list[np.ndarray]
    states: list[np.ndarray]
    rows: list[dict]
    plant: str

    @property
    def average(self) -> dict:
        return average_metrics(self.rows)

    @property
    def errors(self) -> list[np.ndarray]:
        return [m - p for m, p in zip(self.measured, self.predicted)]

    @property
    def error_moments(self) -> dict:
        return absolute_error_moments(self.errors)

    def to_json_dict(self) -> dict:
        return {
            "plant": self.plant,
            "batches": [{"name": name, **row} for name, row in zip(self.names, self.rows)],
            "average": self.average,
            "absolute_error": self.error_moments,
        }

    def table(self, title: str | None = None) -> str:
        """A readable text table of the metrics (columns sized to their contents)."""
        w = max([len("average")] + [len(n) for n in self.names]) + 2
        head = f"{'batch':<{w}}" + "".join(f"{k:>11}" for k in METRIC_NAMES)
        lines = ([title] if title else []) + [head, "-" * len(head)]
        for name, row in zip(self.names, self.rows):
            lines.append(f"{name:<{w}}" + "".join(_fmt(k, row[k]) for k in METRIC_NAMES))
        lines.append("-" * len(head))
        lines.append(f"{'average':<{w}}" + "".join(_fmt(k, self.average[k]) for k in METRIC_NAMES))
        em = self.error_moments
        lines.append(
            f"|e| over {em['samples']} samples: mean {em['mean_abs_error']:.3f} °C, variance {em['var_abs_error']:.3f} °C²"
        )
        return "\n".join(lines)


def _fmt(key, value) -> str:
    if key == "n":
        return f"{int(value):>11d}"
    if key == "SSR":
        return f"{value:>11.1f}"
    return f"{value:>11.3f}" if key != "rho" else f"{value:>11.4f}"


def applicable_values(theta_json: dict) -> dict[str, float]:
    """Scalar identified values in a THETA.json that the model can take (theta and freed constants)."""
    out = {}
    for key, value in theta_json.items():
        if (
            (key in THETA_NAMES or key in FREE_NAMES)
            and isinstance(value, (int, float))
            and not isinstance(value, bool)
        ):
            out[key] = float(value)
    return out


def validate(
    batches, plants, theta, initial=None, moisture="schwartzberg", hold="linear", extra_values: dict | None = None
) -> ValidationResult:
    """Simulate every batch with ``theta`` (plus any ``extra_values`` by name) and score it."""
    packed = pack_batches(batches, plants, theta, initial=initial, moisture=moisture, hold=hold)
    extra = {k: v for k, v in (extra_values or {}).items() if k not in THETA_NAMES}
    names = list(extra)
    values = np.array([[[extra[k] for k in names]] * packed.n_batches]) if names else None
    out = simulate_population(packed, names, values)[0]
    rows, meas, pred, times, states = [], [], [], [], []
    for i, b in enumerate(batches):
        n = b.n
        yhat = out[i, :n, 4]
        rows.append(batch_metrics(b.Ta_C, yhat))
        meas.append(np.asarray(b.Ta_C))
        pred.append(yhat.copy())
        times.append(np.asarray(b.time_s))
        states.append(out[i, :n].copy())
    plant_names = plants if isinstance(plants, str) else getattr(plants, "name", str(plants))
    return ValidationResult([b.name for b in batches], times, meas, pred, states, rows, str(plant_names))
