"""Prediction bands: how far a measured probe curve may lie from the model's, and how often it does.

A band of level L (default :data:`BAND_LEVEL`) around a prediction combines two independent
sources of error, each a standard deviation at every instant t:

* **the parameters**: the fit's covariance C (its correlation times its standard errors,
  :mod:`roastlab.fit.uncertainty`; parameters a bound holds have none and stay at their value)
  propagated to first order, sigma_p(t)^2 = g(t)' C g(t) with g = dTa/dz the exact derivatives of
  the simulated probe reading from the compiled forward-sensitivity integrator over the population
  (:func:`roastlab.sim.population.output_sensitivities`): the delta method, in the same
  linearisation that gave C (lmfit's ``eval_uncertainty`` does the same with difference quotients).
  Until 2026-11-25 the band drew 200 value sets from N(z*, C) (positive parameters as logarithms)
  and simulated each: where the data pin a combination of parameters that each have a standard
  error larger than their value, the draws leave the fit's linear ridge and the band measured the
  draws, not the data: on the Skywalker, sigma_p 17-22 degC against 0.3-0.4 degC to first order;
  on the Bullet the two agree (0.23-0.29 against 0.18-0.26 degC);
* **roast to roast**: what no parameter explains (the roaster's state on the day, the beans).
  At fitting, the root mean square over the fit-set logs of the model's probe error at each time
  since CHARGE, sigma_r(t), is stored in the model file (``fit.spread``, on a
  :data:`SPREAD_GRID_S` grid; held at its last value past the longest log; a log that ends sooner
  counts with its error at DROP, so that every log enters the spread at every time). Each log's error is
  the one it would have had if it had been left out of the fit (cross-validated: the fit redone
  without it from the full fit's optimum, :func:`roastlab.fit.uncertainty.held_out_residuals`;
  until 2026-11-27 one linearised step, which on three fitted logs could run to a band 329 degC
  wide), because a new roast is not in the fit; the fit set's own errors are smaller by what the
  parameters learnt from each log.

The band is prediction +- sqrt((z sigma_p)^2 + (z_n sigma_r)^2), z the standard normal quantile
of (1 + L)/2 and z_n = t_{(1+L)/2, n} the prediction-interval factor of a new roast when
sigma_r was estimated from n logs (Student's t with n degrees of freedom: the band is centred on
the model, so no mean error is estimated and sigma_r^2 = sum e^2 / n keeps all n). :func:`band_coverage` says how often measured samples fall inside it (calibration:
about L of them should) and how wide it is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

#: The default level of a prediction band (a 90 % band).
BAND_LEVEL = 0.9
#: Time grid of the stored roast-to-roast spread [s].
SPREAD_GRID_S = 30.0


def roast_spread(time_s, errors_C, held_out: bool = True, batch_kg=None, units=None) -> dict | None:
    """``{"time_s": grid, "rms_C": ..., "logs": n, "held_out": bool, "batch_kg": [lo, hi]}``: RMS over logs of each log's
    probe error at each grid time (each log interpolated onto the grid; past its DROP a log counts with
    its error at DROP). Until 2026-12-01 a time counted only the logs that reached it, so the last minutes
    rested on the one or two longest roasts: on the Skywalker's split by name the spread fell from 4.7 °C
    at 9:30 to 0.4 °C at 12:00, and the held-out logs' probe lay inside the 90 % band for 55 % of their
    last two minutes (77 % since; over whole roasts 90 % then, 94 % since). A roast that had gone on would
    most likely have kept the error it had at DROP: the model's drift is smooth in time. The errors
    should be each log's as predicted had it been left out of the fit
    (``held_out``, :func:`roastlab.fit.uncertainty.held_out_residuals`): a fit follows its own logs
    more closely than it predicts a new one, so the fit set's own errors understate the spread a new
    roast meets. ``batch_kg``: the logs' green weights [kg]; their range is kept, because the spread
    is that of roasts of those sizes (:func:`sizes_outside`). ``units``: the roasters the logs name
    (RoasTime's serial number; empty where a log does not say); those named are kept, because the
    spread is that of those drums' roasts (:func:`units_outside`). None for fewer than two logs: one
    roast says nothing about the spread between roasts."""
    if len(time_s) < 2:
        return None
    end = max(float(t[-1]) for t in time_s)
    grid = np.arange(0.0, end + SPREAD_GRID_S, SPREAD_GRID_S)
    sq, count = np.zeros(grid.size), 0  # every log counts at every grid time
    for t, e in zip(time_s, errors_C):
        t, e = np.asarray(t, float), np.asarray(e, float)
        ok = np.isfinite(e)
        if ok.sum() < 2:
            continue
        # past its DROP a log counts with its error at DROP (np.interp holds the last value)
        sq += np.interp(grid, t[ok], e[ok]) ** 2
        count += 1
    if count < 2:
        return None
    rms = np.sqrt(sq / count)
    out = {
        "time_s": grid.tolist(),
        "rms_C": [round(float(v), 4) for v in rms],
        "logs": int(len(time_s)),
        "held_out": bool(held_out),
    }
    if batch_kg is not None and len(batch_kg):
        out["batch_kg"] = [float(min(batch_kg)), float(max(batch_kg))]
    if units and any(units):
        out["units"] = sorted({str(u) for u in units if u})
    return out


def stored_spread(model) -> dict | None:
    """The roast-to-roast spread ``model``'s file stores (``fit.spread``, :func:`roast_spread`), or None
    (fitted on one log, or by an older roastlab)."""
    return (model.doc.get("fit") or {}).get("spread") or None


def _note(*parts) -> str | None:
    """One sentence from the (why, what the band does not hold) parts that apply:
    ``why and why: the band holds neither ... nor ..., so expect fewer measured samples inside it``."""
    parts = [p for p in parts if p]
    if not parts:
        return None
    whys, missing = [p[0] for p in parts], [p[1] for p in parts]
    holds = (
        f"does not hold {missing[0]}"
        if len(missing) == 1
        else f"holds neither {', '.join(missing[:-1])} nor {missing[-1]}"
    )
    return f"{' and '.join(whys)}: the band {holds}, so expect fewer measured samples inside it"


def sizes_outside(model, batch_kg) -> str | None:
    """A note for the roaster when a green weight in ``batch_kg`` [kg] is not one of the sizes the
    model's roast-to-roast spread was measured at (``fit.spread.batch_kg``, grouped into sizes as
    ``roastlab compare-models`` groups them), else None. A weight of None or 0 (a batch without its
    own) is the model plant's batch mass, as a prediction takes it.

    The spread says how far roasts of the fitted sizes stray from the model; it holds nothing about
    the error of predicting another batch size, which is larger (docs/real-roaster.md measures the
    band's coverage at the fitted sizes and at others). Older model files without the range give None."""
    return _note(_sizes_outside(model, batch_kg))


def _sizes_outside(model, batch_kg) -> tuple[str, str] | None:
    """:func:`sizes_outside`'s (why, what the band does not hold), or None."""
    from .metrics import GROUP_STEP_SHARE, size_key

    spread = stored_spread(model) or {}
    rng = spread.get("batch_kg")
    if not rng:
        return None
    lo, hi = rng
    plant_kg = model.plant.Mb_kg if getattr(model, "plant", None) is not None else None
    batch_kg = [m or plant_kg for m in batch_kg]
    # one size as roastlab compare-models groups them (workflows.compare.size_groups): weights that
    # round to the same multiple of a tenth of the fitted weight (490 and 500 g together)
    step = GROUP_STEP_SHARE * 0.5 * (lo + hi)
    first, last = size_key(lo, step), size_key(hi, step)
    odd = sorted({round(float(m), 4) for m in batch_kg if m and not first <= size_key(m, step) <= last})
    if not odd:
        return None
    fitted = f"{lo:g} kg" if lo == hi else f"{lo:g}-{hi:g} kg"
    return (
        f"{', '.join(f'{m:g} kg' for m in odd)} {'lies' if len(odd) == 1 else 'lie'} outside the batch sizes the "
        f"band's spread between roasts was measured at ({fitted})",
        "the error of a batch-size change",
    )


def units_outside(model, units) -> str | None:
    """A note for the roaster when a roaster unit in ``units`` (a log's serial number, empty where the
    log names none) is not one the model's roast-to-roast spread was measured on
    (``fit.spread.units``), else None. The spread holds how one drum's roasts stray; a second
    drum of the same make adds its own difference (docs/real-roaster.md: on the shared Bullet logs
    the band held 86 % of the fit's unit's other-size samples, far fewer on other units'). Model
    files without units (the logs named none, or an older roastlab) give None."""
    return _note(_units_outside(model, units))


def _units_outside(model, units) -> tuple[str, str] | None:
    """:func:`units_outside`'s (why, what the band does not hold), or None."""
    fitted = (stored_spread(model) or {}).get("units")
    odd = sorted({str(u) for u in units if u} - set(fitted or ()))
    if not fitted or not odd:
        return None
    return (
        f"{'unit' if len(odd) == 1 else 'units'} {', '.join(odd)} {'is' if len(odd) == 1 else 'are'} not the "
        f"roaster the band's spread between roasts was measured on ({', '.join(fitted)})",
        "the difference between two drums of one make",
    )


def _no_spread(model) -> tuple[str, str] | None:
    """(why, what the band does not hold) when ``model`` stores no roast-to-roast spread (fitted on
    one log: :func:`roast_spread`), so its band is the parameters' alone; else None."""
    if stored_spread(model) is not None:
        return None
    return "the model was fitted on one log, which says nothing about how roasts differ", "the spread between roasts"


def band_note(model, batches, batch_kg=None) -> str | None:
    """Why a band of ``model`` may hold fewer samples of ``batches`` than its level: no spread
    between roasts in the model (:func:`_no_spread`), their sizes (:func:`sizes_outside`;
    ``batch_kg`` replaces each batch's weight, as a what-if does) and their roasters
    (:func:`units_outside`), in one sentence; None when none applies."""
    masses = [batch_kg or b.Mb_kg for b in batches]
    return _note(_no_spread(model), _sizes_outside(model, masses), _units_outside(model, [b.unit for b in batches]))


def why_no_band(model) -> str | None:
    """None when ``model`` can carry a band (its file has the fit's parameter correlation or a
    roast-to-roast spread); else the reason, in words for the roaster."""
    fit = model.doc.get("fit") or {}
    if (fit.get("correlation") or {}).get("names") or stored_spread(model):
        return None
    return "this model file has no parameter covariance or roast-to-roast spread: no band"


def require_band(model, source=None) -> None:
    """:class:`~roastlab.errors.ParameterError` (naming ``source``, default the model file) when
    ``model`` cannot carry a band (:func:`why_no_band`)."""
    why = why_no_band(model)
    if why is not None:
        raise ParameterError(why, source or model.source)


def check_level(level) -> float:
    """A band level in (0, 1), or :class:`~roastlab.errors.ParameterError`."""
    if isinstance(level, bool) or not (isinstance(level, (int, float)) and 0.0 < level < 1.0):
        raise ParameterError(f"band level must be in (0, 1), e.g. 0.9, got {level!r}")
    return float(level)


def _z(level: float) -> float:
    from scipy.stats import norm

    return float(norm.ppf(0.5 + check_level(level) / 2.0))


def _new_roast_quantile(level: float, n_logs: int) -> float:
    """Half-width factor of a band for a new roast from the spread of ``n_logs`` fitted ones.

    The band is centred on the model's prediction, and sigma_r is the root mean square of n logs'
    errors about zero (:func:`roast_spread`), not about their mean. For a new error e and n errors
    e_i from N(0, s^2), n sigma_r^2 / s^2 is chi-squared with n degrees of freedom, independent of
    e, so e / sigma_r follows Student's t with n degrees of freedom: the factor is t_{(1+L)/2, n}.
    (The textbook t_{n-1} sqrt(1 + 1/n) is for a band centred on the sample mean, which spends one
    degree of freedom on the mean and adds its error; this band does neither.) It tends to the
    normal quantile as n grows; tests/test_bands.py checks its coverage by simulation."""
    from scipy.stats import t

    n = max(int(n_logs), 1)
    return float(t.ppf(0.5 + level / 2.0, n))


def parameter_covariance(model) -> tuple[list[str], np.ndarray]:
    """(names, C): the fitted parameters (and initial states) that have a standard error, and their
    covariance C = R * se se' from the model file's correlation R (``fit.correlation``); a missing
    correlation entry counts as 0. Empty when the file has none."""
    corr = (model.doc.get("fit") or {}).get("correlation") or {}
    entries = {**model.parameters, **model.initial}
    keep, ses = [], []
    for n in corr.get("names", []):
        e = entries.get(n) or {}
        se = e.get("stderr")
        if e.get("value") is None or not isinstance(se, (int, float)) or not np.isfinite(se) or se <= 0:
            continue
        keep.append(n)
        ses.append(float(se))
    if not keep:
        return [], np.zeros((0, 0))
    index = [corr["names"].index(n) for n in keep]
    R = np.array([[corr["matrix"][i][j] if corr["matrix"][i][j] is not None else 0.0 for j in index] for i in index])
    np.fill_diagonal(R, 1.0)
    se = np.array(ses)
    return keep, R * np.outer(se, se)


@dataclass
class Band:
    """One batch's band: prediction and bounds of the probe reading [degC] at its sample times [s]."""

    name: str
    time_s: np.ndarray
    predicted_C: np.ndarray
    lower_C: np.ndarray
    upper_C: np.ndarray
    sigma_parameters_C: np.ndarray
    sigma_roasts_C: np.ndarray
    level: float

    @property
    def width_C(self) -> np.ndarray:
        return self.upper_C - self.lower_C

    @property
    def median_width_C(self) -> float:
        """The band's median width over the roast [degC]: how wide it is, in one number."""
        return float(np.median(self.width_C))


def band_summary(band: Band, note: str | None = None) -> dict:
    """A band in a result's JSON: its level, median width and BT at DROP between its bounds [degC],
    and ``note`` (:func:`band_note`) where there is one."""
    return {
        "level": band.level,
        "median_width_C": round(band.median_width_C, 2),
        "DROP_lower_C": round(float(band.lower_C[-1]), 2),
        "DROP_upper_C": round(float(band.upper_C[-1]), 2),
        **({"note": note} if note else {}),
    }


def band_words(band: Band, what: str, units: str = "C") -> str:
    """A band in one line: its level, what it is the band of (``what``: "the changed probe BT"), its
    median width and BT at DROP between its bounds, in ``units`` ("C" or "F")."""
    from ..metrics.profile import display_temp, display_temp_delta, temp_symbol

    u = temp_symbol(units)
    return (
        f"{band.level * 100:g} % prediction band of {what} (parameter covariance and roast-to-roast spread): "
        f"median width {display_temp_delta(band.median_width_C, units):.1f} {u}; BT at DROP "
        f"{display_temp(band.lower_C[-1], units):.1f} to {display_temp(band.upper_C[-1], units):.1f} {u}"
    )


def prediction_bands(model, batches, level: float = BAND_LEVEL, plant=None, **changes) -> list[Band]:
    """The level-``level`` band of the probe prediction for each batch (module docstring); ``plant``
    and ``changes`` as :meth:`roastlab.workflows.model.FittedModel.apply` (a what-if's band)."""
    from ..sim.population import output_sensitivities

    z = _z(level)
    applied = model.apply(list(batches), plant, **changes)
    center = model.simulate(applied)
    names, C = parameter_covariance(model)
    sigma_p = None
    if names:
        entries = {**model.parameters, **model.initial}
        base_names = list(applied.names)
        values = applied.values[0]  # (nb, k0): the one value set, per batch
        extra = [n for n in names if n not in base_names]
        if extra:
            held = np.array([float(entries[n]["value"]) for n in extra])
            values = np.concatenate([values, np.broadcast_to(held, (values.shape[0], len(extra)))], axis=1)
        all_names = base_names + extra
        _, g = output_sensitivities(applied.packed, all_names, values, [(all_names.index(n), -1) for n in names])["Ta"]
        sigma_p = np.sqrt(np.clip(np.einsum("btk,kl,btl->bt", g, C, g), 0.0, None))  # (nb, nmax), NaN-padded
    spread = stored_spread(model)
    z_roasts = _new_roast_quantile(level, spread["logs"]) if spread else 0.0
    out = []
    for i, r in enumerate(center):
        t = r.time_s
        sp = np.zeros(t.size) if sigma_p is None else np.nan_to_num(sigma_p[i, : t.size])
        sr = np.interp(t, spread["time_s"], spread["rms_C"]) if spread else np.zeros(t.size)
        half = np.sqrt((z * sp) ** 2 + (z_roasts * sr) ** 2)
        out.append(Band(r.name, t, r.Ta_C, r.Ta_C - half, r.Ta_C + half, sp, sr, level))
    return out


def share_inside(rows: list[dict]) -> float:
    """The share of all measured samples inside the band over the rows of :func:`band_coverage`
    (each batch weighted by its samples)."""
    n = sum(r["n"] for r in rows)
    return sum(r["inside"] * r["n"] for r in rows if r["n"]) / n if n else float("nan")


def inside_by_size(rows: list[dict]) -> list[dict]:
    """The rows of :func:`band_coverage` by batch size (:func:`roastlab.evaluate.metrics.size_labels`,
    lightest first): ``[{"size", "logs", "n", "inside"}]``, the share of that size's samples inside
    the band; empty unless every row has a green weight and they make more than one size.

    >>> rows = [{"Mb_kg": 0.5, "n": 100, "inside": 0.9}, {"Mb_kg": 0.49, "n": 100, "inside": 1.0},
    ...         {"Mb_kg": 0.2, "n": 50, "inside": 0.2}]
    >>> [(g["size"], g["logs"], round(g["inside"], 2)) for g in inside_by_size(rows)]
    [('0.2 kg', 1, 0.2), ('0.49-0.5 kg', 2, 0.95)]
    """
    from .metrics import size_groups

    return [{"size": label, "logs": len(at), "n": sum(rows[i]["n"] for i in at), "inside": share_inside([rows[i] for i in at])}
            for label, at in size_groups([r.get("Mb_kg") for r in rows])]  # fmt: skip


def band_report(model, batches, level: float = BAND_LEVEL) -> tuple[dict, list[Band]]:
    """How the level-``level`` band of ``model`` holds the measured probe of ``batches``, and the
    bands: ``({"level", "inside_all" (share of all samples inside), "median_width_C" (median over the
    batches), "batches" (:func:`band_coverage` rows), "by_size" (:func:`inside_by_size`), "note"
    (:func:`band_note` or None), "spread" (whether the band holds a roast-to-roast spread)}, [Band, ...])``."""
    batches = list(batches)
    bands = prediction_bands(model, batches, level)
    rows = coverage(batches, bands)
    widths = [r["median_width_C"] for r in rows]
    doc = {
        "level": level,
        "inside_all": share_inside(rows),
        "median_width_C": float(np.median(widths)) if widths else float("nan"),
        "batches": rows,
        "by_size": inside_by_size(rows),
        "note": band_note(model, batches),
        "spread": stored_spread(model) is not None,
    }
    return doc, bands


def held_out_band(model, batches) -> tuple[dict | None, list[Band] | None]:
    """How well the model's 90 % prediction band holds logs it was not fitted on, and the bands, one
    per batch, to draw (:func:`band_report` at :data:`BAND_LEVEL`); (None, None) when the model file
    can carry no band (:func:`why_no_band`)."""
    if why_no_band(model) is not None:
        return None, None
    return band_report(model, batches, BAND_LEVEL)


def band_coverage(model, batches, level: float = BAND_LEVEL) -> list[dict]:
    """Per batch: ``{"name", "n", "inside" (share of measured probe samples inside the band),
    "median_width_C", "Mb_kg"}``."""
    batches = list(batches)
    return coverage(batches, prediction_bands(model, batches, level))


def coverage(batches, bands: list[Band]) -> list[dict]:
    """The rows of :func:`band_coverage` for bands already computed (one per batch, in order)."""
    rows = []
    for b, band in zip(batches, bands):
        m = np.asarray(b.Ta_C, float)[: band.time_s.size]
        ok = np.isfinite(m)
        inside = (m[ok] >= band.lower_C[ok]) & (m[ok] <= band.upper_C[ok])
        rows.append(
            {
                "name": b.name,
                "Mb_kg": b.Mb_kg,
                "n": int(ok.sum()),
                "inside": float(inside.mean()) if ok.any() else float("nan"),
                "median_width_C": band.median_width_C,
            }
        )
    return rows
