"""Drift and outliers in each machine's history of identified coefficients.

**Drift: a self-starting two-sided CUSUM** (Hawkins 1987, "Self-starting cusum charts for
location and scale", The Statistician 36, 299-316; Page 1954 for the CUSUM). A machine's
values of one coefficient, in order of ``started_at`` and outliers left out, are taken as
x_i = log(value) when all are positive (coefficients scatter by a factor, and drift by a
factor: a 10 % drop is the same shift whatever the level; the per-batch spread of a weakly
pinned coefficient is skewed on the linear scale), and standardised against the mean and standard deviation of the values *before* them since
the last change (no reference period to pick, no known sigma):

    t_i = (x_i - mean_{i-1}) / (sd_{i-1} sqrt(1 + 1/n)),   z_i = Phi^-1(F_{n-1}(t_i))

(F the Student-t CDF; for n > 30 z = t), clipped to +-``CLIP_Z`` so that one wild batch
cannot raise an alarm alone. Two CUSUMs S+_i = max(0, S+ + z - k), S-_i = max(0, S- - z - k)
raise an alarm ``up``/``down`` when one exceeds h. The change is dated at the batch after
the last time that CUSUM was zero; the statistics then restart from there.

Thresholds: k = 0.5 (tuned to a shift of one standard deviation), h = 12. Siegmund's
approximation puts the in-control average run length of one side at ~1e6 batches, so a
machine with 20,000 batches and three coefficients expects ~0.1 false alarms; a shift of
2 standard deviations is flagged ~8 batches after it starts. How fast a 10 % change shows
therefore depends on how well one batch pins the coefficient: on the synthetic fleet hbm
has ~5 % batch-to-batch spread (a 10 % change is 2 sd), hgm ~30 % (a 10 % change is 0.3
sd and needs of order a hundred batches). ``fleet report`` lists each coefficient's spread.

**Outliers** (left out of the drift statistics and listed): a failed fit (no finite SSR),
FIT below ``OUTLIER_FIT`` %, or a mean squared residual over ``OUTLIER_RATIO`` times the
machine's median (a probe fault or a log that is not a roast; a fit that merely misses by
2-3x its machine's typical residual is kept).
"""

from __future__ import annotations

import math

import numpy as np

from .store import filled

CUSUM_K = 0.5
CUSUM_H = 12.0
CLIP_Z = 3.0
#: Values needed before a CUSUM starts (after the start of the history or a change).
WARMUP = 10
OUTLIER_FIT = 50.0
OUTLIER_RATIO = 10.0


def robust_stats(values) -> dict | None:
    """Median and robust spread of the finite values: the median absolute deviation scaled to a normal
    distribution's standard deviation (SciPy's ``median_abs_deviation(scale="normal")``, 1.4826 x MAD)."""
    from scipy.stats import median_abs_deviation

    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    if not len(x):
        return None
    return {"median": float(np.median(x)), "spread": float(median_abs_deviation(x, scale="normal"))}


def _to_normal(t: float, dof: int) -> float:
    if dof > 30:
        return t
    from scipy.stats import norm
    from scipy.stats import t as student

    return float(norm.ppf(student.cdf(t, dof)))


def cusum_alarms(x: np.ndarray, k: float = CUSUM_K, h: float = CUSUM_H, warmup: int = WARMUP) -> list[dict]:
    """Self-starting two-sided CUSUM alarms of the series ``x`` (see the module docstring).

    Returns ``[{"index", "change_index", "direction"}]``: the index where the alarm is raised
    and the estimated first index of the change.

    A step of +30 % at index 40 is raised 5 samples later and dated back to where it began:

    >>> x = np.r_[np.full(40, 1.0), np.full(40, 1.3)] + 0.05 * np.sin(np.arange(80) * 1.7)
    >>> [(a["index"], a["change_index"], a["direction"]) for a in cusum_alarms(x)]
    [(45, 40, 'up')]
    """
    x = np.asarray(x, dtype=float)
    alarms = []
    start = 0
    while start < len(x):
        n, mean, m2 = 0, 0.0, 0.0
        sp = sm = 0.0
        zero_p = zero_m = start
        restart = None
        for i in range(start, len(x)):
            v = x[i]
            if n >= warmup:
                sd = math.sqrt(m2 / (n - 1))
                if sd > 0:
                    z = _to_normal((v - mean) / (sd * math.sqrt(1.0 + 1.0 / n)), n - 1)
                    z = min(max(z, -CLIP_Z), CLIP_Z)
                    sp = max(0.0, sp + z - k)
                    sm = max(0.0, sm - z - k)
                    if sp == 0.0:
                        zero_p = i + 1
                    if sm == 0.0:
                        zero_m = i + 1
                    if sp > h or sm > h:
                        up = sp > h
                        change = zero_p if up else zero_m
                        alarms.append({"index": i, "change_index": change, "direction": "up" if up else "down"})
                        restart = change
                        break
            n += 1
            d = v - mean
            mean += d / n
            m2 += d * (v - mean)
        if restart is None:
            break
        start = max(restart, start + 1)
    return alarms


def outlier_reasons(SSR: np.ndarray, FIT: np.ndarray, n: np.ndarray) -> list[str | None]:
    """Why each batch is an outlier (None if it is not); see the module docstring."""
    SSR = np.asarray(SSR, dtype=float)
    FIT = np.asarray(FIT, dtype=float)
    ok = np.isfinite(SSR) & np.isfinite(FIT)
    msr = np.where(ok, SSR / np.maximum(n, 1), np.nan)
    med = np.nanmedian(msr) if ok.any() else 0.0
    out: list[str | None] = []
    for j in range(len(SSR)):
        if not ok[j]:
            out.append("fit failed")
        elif FIT[j] < OUTLIER_FIT:
            out.append(f"poor fit (FIT {FIT[j]:.1f} % < {OUTLIER_FIT:g} %)")
        elif med > 0 and msr[j] > OUTLIER_RATIO * med:
            out.append(f"mean squared residual {msr[j] / med:.0f}x the machine's median (> {OUTLIER_RATIO:g}x)")
        else:
            out.append(None)
    return out


def _frame(con, sql: str, params: list):
    """A query's result as a DataFrame (timestamps as UTC), built from NumPy columns."""
    import pandas as pd

    cols = con.execute(sql, params).fetchnumpy()
    frame = pd.DataFrame({k: filled(v) for k, v in cols.items()})
    for c in frame.columns:
        if pd.api.types.is_datetime64_any_dtype(frame[c]):
            frame[c] = pd.to_datetime(frame[c], utc=True)
    return frame


def machine_history(con, machine_id: int, spec_id: str):
    """(batches DataFrame in started_at order, values DataFrame batch x parameter) of one machine."""
    frame = _frame(
        con,
        "SELECT b.batch_id, b.started_at, b.source, b.name, f.SSR, f.FIT, f.MAE, f.n_samples "
        "FROM batches b JOIN fits f USING (batch_id) WHERE b.machine_id = ? AND f.spec_id = ? "
        "ORDER BY b.started_at, b.batch_id",
        [machine_id, spec_id],
    )
    vals = _frame(
        con,
        "SELECT v.batch_id, v.parameter, v.value, v.stderr FROM fit_values v JOIN batches b USING (batch_id) "
        "WHERE b.machine_id = ? AND v.spec_id = ?",
        [machine_id, spec_id],
    )
    return frame, vals


def analyse(frame, vals, params: list[str]) -> dict:
    """Outliers, alarms and periods of one machine's history (frame in time order)."""
    reasons = outlier_reasons(frame["SSR"].to_numpy(), frame["FIT"].to_numpy(), frame["n_samples"].to_numpy())
    good = np.array([r is None for r in reasons])
    wide = vals.pivot(index="batch_id", columns="parameter", values="value").reindex(frame["batch_id"])
    alarms = []
    changes = set()
    for p in params:
        x = wide[p].to_numpy(dtype=float)
        keep = np.flatnonzero(good & np.isfinite(x))
        series = x[keep]
        if len(series) and np.all(series > 0):
            series = np.log(series)
        for a in cusum_alarms(series):
            i, c = int(keep[a["index"]]), int(keep[a["change_index"]]) if a["change_index"] < len(keep) else None
            alarms.append(
                {
                    "parameter": p,
                    "batch_index": i,
                    "started_at": frame["started_at"].iloc[i].isoformat(),
                    "direction": a["direction"],
                    "change_index": c,
                    "change_started_at": None if c is None else frame["started_at"].iloc[c].isoformat(),
                    "source": frame["source"].iloc[i],
                }
            )
            if c is not None:
                changes.add(c)
    alarms.sort(key=lambda a: (a["batch_index"], a["parameter"]))
    outliers = [
        {
            "batch_index": j,
            "started_at": frame["started_at"].iloc[j].isoformat(),
            "source": frame["source"].iloc[j],
            "reason": r,
        }
        for j, r in enumerate(reasons)
        if r is not None
    ]
    bounds = [0, *sorted(changes), len(frame)]
    periods = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b <= a:
            continue
        sel = good[a:b]
        part = wide.iloc[a:b][sel]
        stats = {p: st for p in params if (st := robust_stats(part[p].to_numpy(dtype=float)))}
        periods.append({"first_index": a, "last_index": b - 1, "n_batches": int(sel.sum()), "values": stats})
    return {"reasons": reasons, "good": good, "wide": wide, "alarms": alarms, "outliers": outliers, "periods": periods}


def refresh_models(con, spec_of_machine: dict) -> None:
    """Rewrite the ``models`` table for each machine's spec: one model per period (one transaction)."""
    con.execute("BEGIN TRANSACTION")
    try:
        for mid, sid in spec_of_machine.items():
            con.execute("DELETE FROM models WHERE machine_id = ? AND spec_id = ?", [mid, sid])
            frame, vals = machine_history(con, mid, sid)
            if frame.empty:
                continue
            params = sorted(vals["parameter"].unique())
            res = analyse(frame, vals, params)
            rows = []
            for k, per in enumerate(res["periods"]):
                a, b = per["first_index"], per["last_index"]
                for p, st in per["values"].items():
                    rows.append(
                        (
                            mid,
                            sid,
                            k,
                            int(frame["batch_id"].iloc[a]),
                            int(frame["batch_id"].iloc[b]),
                            frame["started_at"].iloc[a],
                            frame["started_at"].iloc[b],
                            per["n_batches"],
                            p,
                            st["median"],
                            st["spread"],
                        )
                    )
            if rows:
                con.executemany("INSERT INTO models VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)", rows)
        con.execute("COMMIT")
    except BaseException:
        con.execute("ROLLBACK")
        raise
