"""Performance indexes of a fit (paper Table 2, eq. 18; MODEL.md).

With measured Y, predicted Yhat and e = Y - Yhat over n samples:

* SSR = sum(e^2) (eq. 18) and norm = ||e||_2 = sqrt(SSR). The paper's Tables 3-4 column
  headed SSR matches ``norm``, not sum(e^2); both are reported, clearly named.
* MAE = mean|e|; MPE = 100/n sum(e/Y) (signed, as printed in Table 2);
  MAPE = 100/n sum|e/Y| (the paper's tabulated "MPE" values match MAPE).
* FIT = 100 (1 - ||e|| / ||Y - mean(Y)||); rho = Pearson correlation of Y and Yhat.
"""

from __future__ import annotations

import math

import numpy as np

#: One batch size: green weights that round to the same multiple of this share of a typical
#: (median) weight are one size (a tenth: 490 and 500 g together). Used to group logs by size
#: (roastlab.workflows.compare.size_groups) and to say when a band meets a size its spread was not
#: measured at (roastlab.evaluate.bands.sizes_outside).
GROUP_STEP_SHARE = 0.1


def size_key(mass_kg: float, step_kg: float) -> int:
    """The size a green weight [kg] belongs to, in steps of ``step_kg`` (:data:`GROUP_STEP_SHARE`)."""
    return round(mass_kg / step_kg)


def size_labels(masses_kg, step_kg: float | None = None) -> tuple[list[str], float]:
    """A size-group label per green weight [kg] and the step used: weights that round to the same
    multiple of ``step_kg`` (default :data:`GROUP_STEP_SHARE` of the median weight) are one size,
    labelled by their weights ("0.49-0.5 kg"). ValueError for a step that is not a positive mass.

    >>> size_labels([0.49, 0.5, 0.2, 0.49])[0]
    ['0.49-0.5 kg', '0.49-0.5 kg', '0.2 kg', '0.49-0.5 kg']
    """
    masses = [float(m) for m in masses_kg]
    if step_kg is None:
        step_kg = float(np.median(masses)) * GROUP_STEP_SHARE
    if not (step_kg > 0 and math.isfinite(step_kg)):
        raise ValueError(f"group step must be a positive mass in kg, got {step_kg!r}")
    keys = [size_key(m, step_kg) for m in masses]
    labels = {}
    for key in set(keys):
        members = [m for m, k in zip(masses, keys) if k == key]
        lo, hi = min(members), max(members)
        labels[key] = f"{lo:.3g} kg" if lo == hi else f"{lo:.3g}-{hi:.3g} kg"
    return [labels[k] for k in keys], step_kg


def size_groups(masses_kg) -> list[tuple[str, list[int]]]:
    """The positions of ``masses_kg`` [kg] by batch size (:func:`size_labels`), lightest size first:
    ``[(label, [i, ...]), ...]``; empty unless every mass is a positive weight and they make more than
    one size.

    >>> size_groups([0.5, 0.2, 0.49])
    [('0.2 kg', [1]), ('0.49-0.5 kg', [0, 2])]
    """
    masses = list(masses_kg)
    if not masses or not all(isinstance(m, (int, float)) and not isinstance(m, bool) and m > 0 for m in masses):
        return []
    labels, _ = size_labels(masses)
    if len(set(labels)) < 2:
        return []
    order = sorted(set(labels), key=lambda lab: min(m for m, x in zip(masses, labels) if x == lab))
    return [(lab, [i for i, x in enumerate(labels) if x == lab]) for lab in order]


METRIC_NAMES = ("n", "SSR", "norm", "MAE", "MPE", "MAPE", "FIT", "rho")
#: The power of a temperature difference each index carries (SSR in K², norm and MAE in K); the
#: others have none: FIT and rho are ratios, and MPE and MAPE are percent of the reading in degC, as
#: Table 2 defines them (a percent of a reading depends on the scale's zero, so not restated in degF).
METRIC_TEMP_POWER = {"SSR": 2, "norm": 1, "MAE": 1}


def metrics_in_units(row: dict, units: str = "C") -> dict:
    """A row of :func:`batch_metrics` with its temperature differences in the display unit ("C" or "F";
    :data:`METRIC_TEMP_POWER`).

    >>> metrics_in_units({"n": 3, "SSR": 200.0, "norm": 14.1, "MAE": 5.0, "FIT": 90.0}, "F")["MAE"]
    9.0
    """
    from ..metrics.profile import display_temp_delta

    return {k: display_temp_delta(1.0, units) ** METRIC_TEMP_POWER[k] * v if k in METRIC_TEMP_POWER else v
            for k, v in row.items()}  # fmt: skip


def fit_percent(measured, predicted) -> float:
    """FIT = 100 (1 - ||Y - Yhat|| / ||Y - mean(Y)||) [%] (Table 2); NaN for a flat Y.

    >>> round(fit_percent([100.0, 200.0, 300.0], [110.0, 190.0, 300.0]), 3)
    90.0
    """
    y = np.asarray(measured, dtype=float)
    e = y - np.asarray(predicted, dtype=float)
    spread = float(np.linalg.norm(y - y.mean()))
    return float(100.0 * (1.0 - np.linalg.norm(e) / spread)) if spread > 0 else float("nan")


def batch_metrics(measured, predicted) -> dict[str, float]:
    """All indexes of one batch as a dict keyed by :data:`METRIC_NAMES`.

    >>> m = batch_metrics([100.0, 200.0, 300.0], [110.0, 190.0, 300.0])
    >>> m["SSR"], m["MAE"], round(m["FIT"], 3)
    (200.0, 6.666666666666667, 90.0)
    """
    y = np.asarray(measured, dtype=float)
    yhat = np.asarray(predicted, dtype=float)
    e = y - yhat
    n = len(y)
    ssr = float(e @ e)
    sy, sp = y.std(), yhat.std()
    rho = float(np.corrcoef(y, yhat)[0, 1]) if sy > 0 and sp > 0 else float("nan")
    return {
        "n": n,
        "SSR": ssr,
        "norm": float(np.sqrt(ssr)),
        "MAE": float(np.mean(np.abs(e))),
        "MPE": float(100.0 / n * np.sum(e / y)),
        "MAPE": float(100.0 / n * np.sum(np.abs(e / y))),
        "FIT": fit_percent(y, yhat),
        "rho": rho,
    }


def average_metrics(rows: list[dict]) -> dict[str, float]:
    """Mean of each index over batches (n is summed), as the paper's 'Average' rows."""
    out = {}
    for key in METRIC_NAMES:
        vals = [r[key] for r in rows]
        out[key] = int(sum(vals)) if key == "n" else float(np.mean(vals))
    return out


def absolute_error_moments(errors: list[np.ndarray]) -> dict[str, float]:
    """Mean and (sample) variance of |e| pooled over a dataset's batches (section 6.2)."""
    a = np.abs(np.concatenate([np.asarray(e, dtype=float) for e in errors]))
    return {
        "mean_abs_error": float(a.mean()),
        "var_abs_error": float(a.var(ddof=1)) if a.size > 1 else 0.0,
        "samples": int(a.size),
    }


#: Confidence level of the interval on a difference of means between two sets of logs (FIT, MPE).
GAP_LEVEL = 0.9


def mean_gap(values, reference, level: float = GAP_LEVEL) -> dict[str, float]:
    """Difference of two sets' means (``values`` minus ``reference``), e.g. mean FIT [%] of other
    batch sizes against held-out nominal logs, with its ``level`` confidence interval.

    The logs of a set are taken as independent draws with their own spread (Welch's t: the
    Satterthwaite degrees of freedom, ``scipy.stats.ttest_ind(..., equal_var=False)``), so the
    interval says how far a handful of logs pins the gap: with five logs of one size and eight
    nominal ones, a gap of 8 points can be anything from about 0 to 17. Returns ``{"gap", "low",
    "high", "se", "dof", "n", "n_reference", "level"}``; ``low``/``high`` are NaN when either set
    has fewer than two values or no spread.

    >>> g = mean_gap([70.0, 74.0, 78.0], [84.0, 86.0, 88.0, 86.0])
    >>> round(g["gap"], 2), round(g["low"], 2) < -12 < round(g["high"], 2)
    (-12.0, True)
    """
    from scipy.stats import ttest_ind

    a = np.asarray(values, dtype=float)
    b = np.asarray(reference, dtype=float)
    if not (a.size and b.size):
        raise ValueError("mean_gap needs at least one value in each set")
    gap = float(a.mean() - b.mean())
    out = {"gap": gap, "low": np.nan, "high": np.nan, "se": np.nan, "dof": np.nan}
    out.update(n=int(a.size), n_reference=int(b.size), level=float(level))
    if a.size > 1 and b.size > 1:
        se = float(np.sqrt(a.var(ddof=1) / a.size + b.var(ddof=1) / b.size))
        if se > 0.0:
            test = ttest_ind(a, b, equal_var=False)
            ci = test.confidence_interval(level)
            out.update(low=float(ci.low), high=float(ci.high), se=se, dof=float(test.df))
    return out
