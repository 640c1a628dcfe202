"""Roast-profile figures defined once: rate of rise, crossing times and the area under the curve.

Every figure, table, score and optimiser of roastlab reads a curve through these functions: the
figures' RoR axis, the closed-loop score, the rate-of-rise term of the program optimiser (transfer
and MPC) and the what-if, transfer and control milestone times. So the MPC optimises the same
rate of rise it is scored on.

**Rate of rise** (RoR) [degC/min], Artisan's convention of a trailing window: at each sample, 60
times the slope of the least-squares line through the samples of the last :data:`ROR_SPAN_S`
seconds (that sample included). Artisan's own default "delta span" is 15 s on a 1-3 s sampling;
roastlab uses 30 s because its control and transfer grids are 5 s, where a 15-s window holds
three samples and a sensor's noise of 0.5 degC would swing the RoR by +-3 degC/min. A
least-squares slope, not the difference of the window's ends, so that every sample in the window
counts and one noisy reading moves the RoR by a fraction of its error. The RoR is a linear map
of the curve (:func:`ror_operator`), which is what lets the optimiser put it in its residuals with
an exact Jacobian. The first samples, whose window holds fewer than two points, have no RoR (NaN).

**Area under the curve** (AUC) [degC min], Artisan's measure of the heat a roast gave its beans:
the area between BT and a base temperature where BT is above it, from the turning point to DROP
(:func:`area_under_curve_C_min`). The base is BT at the turning point, Artisan's "from event"
base with its TP start, as 12 of the 16 Skywalker logs record it; Artisan can also take a set base
(the other four: 100 degC), which gives larger numbers. A table that compares curves takes one
base for them all (the measured curve's, :func:`milestone_levels`), so its AUCs differ only by the
curves.

**Crossing time** [s]: the first time the rising curve reaches a temperature after its turning
point, linearly interpolated between samples (:func:`crossing_time_s`); for a curve that stops
short, :func:`crossing_or_projected_s` extends it at the RoR of its last two minutes.

>>> import numpy as np
>>> t = np.arange(0.0, 121.0, 5.0)
>>> ror = rate_of_rise_C_per_min(t, 100.0 + 0.2 * t)  # 0.2 degC/s = 12 degC/min
>>> bool(np.isnan(ror[0])), round(float(ror[-1]), 6)
(True, 12.0)
>>> crossing_time_s(t, 100.0 + 0.2 * t, 110.0)
50.0
"""

from __future__ import annotations

import functools

import numpy as np
from scipy import sparse

from ..model.constants import FIRST_CRACK_BEAN_C

#: Window of the rate-of-rise estimate [s] (see the module docstring for why 30 s).
ROR_SPAN_S = 30.0
#: Window over which a curve that stops short is extended at its rate of rise [s].
PROJECTION_WINDOW_S = 120.0
#: Shortest recording after CHARGE that can be a roast [s]: the fastest roasts, industrial hot-air
#: ones, take about 90 s, shop drum roasters eight minutes or more; a log that ends within a minute
#: of CHARGE is an aborted recording, or one whose CHARGE mark is not where the beans went in.
SHORTEST_ROAST_S = 60.0
#: Bean temperature of DRY END (yellowing) when the log marks none [degC]: Artisan's default
#: phase boundary between drying and Maillard.
DRY_END_C = 150.0
#: Bean-probe temperature of first crack when the log marks none [degC] (Artisan's default FCs
#: phase boundary; the log's own FCs mark is used where there is one).
FIRST_CRACK_C = 196.0


def mmss(seconds: float | None) -> str:
    """A time in the roaster's m:ss ("-" when None or not finite).

    >>> mmss(457.4), mmss(-5), mmss(None)
    ('7:37', '-0:05', '-')
    """
    if seconds is None or not np.isfinite(seconds):
        return "-"
    s = int(round(abs(float(seconds))))
    return f"{'-' if seconds < 0 else ''}{s // 60}:{s % 60:02d}"


def clock_s(text: str) -> float:
    """A time written as the roaster's clock, m:ss or h:mm:ss (``"7:37"``, ``"07:37.5"``,
    ``"1:02:05"``, ``"-0:05"``), or as plain seconds (``"457.4"``) -> [s]: the inverse of
    :func:`mmss`. :class:`ValueError` for anything else.

    >>> clock_s("7:37"), clock_s("-0:05"), clock_s("1:02:05"), clock_s("240")
    (457.0, -5.0, 3725.0, 240.0)
    """
    text = text.strip()
    sign = -1.0 if text.startswith("-") else 1.0
    parts = text.lstrip("+-").split(":")
    if len(parts) > 3 or any(not p.strip() for p in parts) or (len(parts) > 1 and "-" in text[1:]):
        raise ValueError(f"not a time (m:ss or seconds): {text[:40]!r}")
    try:
        whole = [float(p) for p in parts]
    except ValueError:
        raise ValueError(f"not a time (m:ss or seconds): {text[:40]!r}") from None
    if not all(np.isfinite(whole)) or (
        len(whole) > 1 and (any(not 0 <= v < 60 for v in whole[1:]) or any(v != int(v) for v in whole[:-1]))
    ):
        raise ValueError(f"not a time (m:ss or seconds): {text[:40]!r}")
    seconds = 0.0
    for v in whole:
        seconds = 60.0 * seconds + v
    return sign * seconds


def ror_operator(time_s, span_s: float = ROR_SPAN_S) -> tuple[sparse.csr_matrix, np.ndarray]:
    """(D, valid) of :func:`_ror_operator`, remembered per time grid (a what-if, a page update
    or an optimiser asks for the same grid again and again)."""
    t = np.ascontiguousarray(time_s, dtype=float)
    return _ror_operator_cached(t.tobytes(), float(span_s))


@functools.lru_cache(maxsize=64)
def _ror_operator_cached(t_bytes: bytes, span_s: float):
    D, valid = _ror_operator(np.frombuffer(t_bytes, dtype=float), span_s)
    valid.setflags(write=False)
    return D, valid


def _ror_operator(time_s, span_s: float = ROR_SPAN_S) -> tuple[sparse.csr_matrix, np.ndarray]:
    """(D, valid): the rate of rise as a linear map, ``RoR = D @ temp_C`` [degC/min] where ``valid``.

    Row i holds the least-squares slope weights 60 (t_k - mean t) / sum (t - mean t)^2 over the
    samples k with t_i - span_s <= t_k <= t_i; ``valid[i]`` is False where that window has fewer
    than two samples (the row is empty). ``time_s`` must increase.
    """
    t = np.asarray(time_s, dtype=float)
    n = t.size
    start = np.searchsorted(t, t - span_s, side="left")
    rows, cols, vals = [], [], []
    valid = np.zeros(n, dtype=bool)
    for i in range(n):
        j = int(start[i])
        if i - j < 1:
            continue
        tt = t[j : i + 1]
        d = tt - tt.mean()
        w = 60.0 * d / float(d @ d)
        rows.append(np.full(w.size, i))
        cols.append(np.arange(j, i + 1))
        vals.append(w)
        valid[i] = True
    if not rows:
        return sparse.csr_matrix((n, n)), valid
    D = sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    return D, valid


def rate_of_rise_C_per_min(time_s, temp_C, span_s: float = ROR_SPAN_S) -> np.ndarray:
    """Rate of rise [degC/min] of ``temp_C`` [degC] sampled at ``time_s`` [s] (module docstring);
    NaN where the window holds fewer than two samples."""
    D, valid = ror_operator(time_s, span_s)
    out = D @ np.asarray(temp_C, dtype=float)
    out[~valid] = np.nan
    return out


def crossing_time_s(t, y, level: float) -> float | None:
    """First time [s] the rising curve ``y`` [degC] reaches ``level`` [degC] after its turning
    point (the minimum of its first half), linearly interpolated; None if it never does."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    start = int(np.argmin(y[: max(2, len(y) // 2)]))  # after the probe's turning point
    above = np.flatnonzero(y[start:] >= level)
    if not above.size:
        return None
    i = start + int(above[0])
    if i == 0 or y[i] == y[i - 1]:
        return float(t[i])
    return float(t[i - 1] + (level - y[i - 1]) * (t[i] - t[i - 1]) / (y[i] - y[i - 1]))


def crossing_or_projected_s(t, y, level: float, window_s: float = PROJECTION_WINDOW_S) -> float | None:
    """:func:`crossing_time_s`, or when ``y`` never gets there, the time it would at the rate of
    rise of its last ``window_s`` seconds (what a person reads off a curve that stops short);
    None when it is not rising."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    hit = crossing_time_s(t, y, level)
    if hit is not None:
        return hit
    ror_C_s = rate_of_rise_C_per_min(t, y, window_s)[-1] / 60.0  # the one RoR, over the longer window
    if not ror_C_s > 1e-6 or y[-1] >= level:
        return None
    return float(t[-1] + (level - y[-1]) / ror_C_s)


def turning_point(t, y) -> tuple[float | None, float | None]:
    """(time [s], temperature [degC]) of the turning point: the minimum of the curve's first
    half, after the charge drop (None, None for an empty or all-missing curve)."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    half = y[: max(2, len(y) // 2)]
    if not np.any(np.isfinite(half)):
        return None, None
    i = int(np.nanargmin(half))
    return float(t[i]), float(y[i])


def area_under_curve_C_min(t, y, from_s: float | None, base_C: float | None) -> float | None:
    """Artisan's area under the curve [degC min]: the integral of max(y - ``base_C``, 0) [degC] over
    time from ``from_s`` [s] (the turning point) to the curve's end (DROP), in minutes; trapezoids
    between samples, the curve interpolated at ``from_s``. None without a start, a base or two
    samples after the start.

    >>> t = np.arange(0.0, 601.0, 1.0)
    >>> round(area_under_curve_C_min(t, 100.0 + 0.1 * t, 0.0, 100.0), 3)  # a 60 degC x 10 min triangle
    300.0
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(y)
    t, y = t[ok], y[ok]
    if from_s is None or base_C is None or t.size < 2 or not t[0] <= from_s < t[-1]:
        return None
    after = t > from_s
    tt = np.concatenate(([from_s], t[after]))
    yy = np.concatenate(([np.interp(from_s, t, y)], y[after]))
    above = np.maximum(yy - base_C, 0.0)
    return float(np.sum(0.5 * (above[1:] + above[:-1]) * np.diff(tt)) / 60.0)


def auc_base_C(t, y) -> float | None:
    """The base [degC] of the area under the curve for a table that compares curves against ``y`` (the
    measured BT, a transfer's target): ``y`` at its turning point, to 0.1 degC (the module docstring);
    None for a curve with fewer than two readings."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(y)
    tp_C = turning_point(t[ok], y[ok])[1] if ok.sum() >= 2 else None
    return None if tp_C is None else round(tp_C, 1)


def milestone_levels(t, y, events: dict | None = None) -> dict[str, float]:
    """The temperatures [degC] that mark DRY END and first crack on this curve: the curve's own
    reading at the log's DRY / FCs marks where it has them, else :data:`DRY_END_C` and
    :data:`FIRST_CRACK_C`. Other curves (predictions, a changed roast) are then judged by when
    they reach the same temperatures (:func:`milestones`). ``AUC``: the base of the area under
    the curve (:func:`auc_base_C`), which the other curves' areas then take too (absent for a
    curve without one)."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(y)
    levels = {"DRY": DRY_END_C, "FCs": FIRST_CRACK_C}
    for name in levels:
        at = (events or {}).get(name)
        if at is not None and ok.sum() >= 2 and t[ok][0] <= at <= t[ok][-1]:
            levels[name] = round(float(np.interp(at, t[ok], y[ok])), 1)
    if (base := auc_base_C(t, y)) is not None:
        levels["AUC"] = base
    return levels


def milestones(t, y, levels: dict[str, float]) -> dict[str, float | None]:
    """A roaster's milestones of one curve [s, degC, %]: ``TP_s``, ``TP_C`` (turning point),
    ``DRY_s`` and ``FCs_s`` (when the curve reaches ``levels["DRY"]`` / ``levels["FCs"]``,
    :func:`crossing_time_s`), ``DROP_s`` and ``DROP_C`` (the curve's end), ``development_s``
    (DROP - FCs), ``DTR_pct`` (development time ratio, 100 development / DROP) and ``AUC_C_min``
    (the area under the curve from its turning point to DROP above ``levels["AUC"]``,
    :func:`area_under_curve_C_min`). Missing where the curve never gets there (None).

    >>> t = np.arange(0.0, 601.0, 5.0)
    >>> y = 100.0 + 0.2 * np.abs(t - 60.0) - 0.1 * 60  # a V: turning point at 1:00
    >>> m = milestones(t, y, {"DRY": 150.0, "FCs": 190.0})
    >>> m["TP_s"], round(m["FCs_s"]), m["development_s"], round(m["DTR_pct"], 1)
    (60.0, 540, 60.0, 10.0)
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(y)
    tt, yy = t[ok], y[ok]
    tp_s, tp_c = turning_point(tt, yy)
    dry = crossing_time_s(tt, yy, levels["DRY"]) if tt.size >= 2 else None
    fcs = crossing_time_s(tt, yy, levels["FCs"]) if tt.size >= 2 else None
    drop_s = float(t[-1]) if t.size else None
    drop_c = float(y[-1]) if y.size and np.isfinite(y[-1]) else None
    dev = None if fcs is None or drop_s is None else drop_s - fcs
    dtr = None if dev is None or not drop_s else 100.0 * dev / drop_s
    return {
        "TP_s": tp_s,
        "TP_C": tp_c,
        "DRY_s": dry,
        "FCs_s": fcs,
        "DROP_s": drop_s,
        "DROP_C": drop_c,
        "development_s": dev,
        "DTR_pct": dtr,
        "AUC_C_min": area_under_curve_C_min(tt, yy, tp_s, levels.get("AUC")),
    }


#: A roast's three phases as Artisan shades them, each (name, milestone it starts at, milestone
#: it ends at): drying from CHARGE to DRY END, Maillard (browning) to first crack, development
#: from first crack to DROP.
PHASES = (("drying", "CHARGE", "DRY_s"), ("Maillard", "DRY_s", "FCs_s"), ("development", "FCs_s", "DROP_s"))


def phases(ms: dict) -> list[dict]:
    """The phases (:data:`PHASES`) of one curve from its :func:`milestones`:
    ``[{"name", "from_s", "to_s"}, ...]``, a phase left out when a milestone it needs is missing.

    >>> [p["name"] for p in phases({"DRY_s": 240.0, "FCs_s": None, "DROP_s": 600.0})]
    ['drying']
    """
    at = {**ms, "CHARGE": 0.0}
    return [
        {"name": name, "from_s": float(at[a]), "to_s": float(at[b])}
        for name, a, b in PHASES
        if at.get(a) is not None and at.get(b) is not None and at[b] > at[a]
    ]


def display_temp(temp_C: float, units: str = "C") -> float:
    """A temperature [degC] in the display unit ("C" or "F")."""
    return temp_C * 9.0 / 5.0 + 32.0 if units == "F" else temp_C


#: The units temperatures are shown in (a table, a figure, a report); every value inside stays degC.
DISPLAY_UNITS = ("C", "F")


def display_units(units: str) -> str:
    """``units`` if it is one of :data:`DISPLAY_UNITS`, else ParameterError."""
    if units not in DISPLAY_UNITS:
        from ..errors import ParameterError

        raise ParameterError(f"units must be 'C' or 'F', got {units!r}")
    return units


def temp_symbol(units: str = "C") -> str:
    """The display unit ("C" or "F") as written after a number: "°C" or "°F"."""
    return "°F" if units == "F" else "°C"


def display_temp_delta(delta_C: float, units: str = "C") -> float:
    """A temperature difference [K] in the display unit ("C" or "F")."""
    return delta_C * 9.0 / 5.0 if units == "F" else delta_C


def delta_text(delta_C: float, units: str = "C", digits: int = 1) -> str:
    """A temperature difference [K] written in the display unit with its symbol: ``"7.20 °F"``.

    >>> delta_text(4.0, "F", 2)
    '7.20 °F'
    """
    return f"{display_temp_delta(delta_C, units):.{digits}f} {temp_symbol(units)}"


def celsius_of(temp, units: str = "C"):
    """A temperature in the display unit ("C" or "F") in degC: :func:`display_temp`'s inverse."""
    return (temp - 32.0) * 5.0 / 9.0 if units == "F" else temp


def celsius_delta_of(delta, units: str = "C"):
    """A temperature difference in the display unit in K: :func:`display_temp_delta`'s inverse."""
    return delta * 5.0 / 9.0 if units == "F" else delta


#: Share of the roast after the turning point during which the drum metal may run colder than
#: the beans before a fit is called physically implausible [-] (on a machine whose inlet air is
#: colder than the beans, see :func:`implausible_states`).
METAL_BELOW_BEANS_SHARE = 0.5

#: How far a model's beans may read from :data:`roastlab.model.constants.FIRST_CRACK_BEAN_C` at a
#: log's first-crack mark before its states are called implausible [degC] (:func:`implausible_states`):
#: seven standard deviations of the crack temperature (3.4 degC); the Bullet example's beans on its
#: own nine fit logs read within -4 to +6 degC of the infrared reading there.
FIRST_CRACK_TOLERANCE_C = 25.0


#: ET is compared with BT from this long after CHARGE [s], past the charge dip, when the probe
#: still carries the preheat's heat (:func:`et_minus_bt_C`).
ET_CHECK_FROM_S = 60.0


def et_minus_bt_C(time_s, et_C, bt_C, drop_s: float | None = None) -> float | None:
    """Median of ET - BT [degC] from :data:`ET_CHECK_FROM_S` after CHARGE to DROP (``drop_s``,
    default the log's end), over samples where both read (Artisan's -1 and NaN are skipped); None
    with fewer than two such samples.

    A roaster's ET that reads the drum's air, the air that heats the beans, runs above BT through
    the roast; a channel that reads below BT through it measures something else (a thermocouple
    moved out of the drum, into the exhaust after room air has mixed in, or off the drum). A map's
    ``[ET] above_BT = true`` drops such a log's ET (mapping.import_log) rather than fit a model
    temperature to it; the Skywalker's three oldest logs are such a case (docs/real-roaster.md).
    """
    t = np.asarray(time_s, float)
    et, bt = np.asarray(et_C, float), np.asarray(bt_C, float)
    end = t[-1] if drop_s is None else drop_s
    ok = (
        (t >= ET_CHECK_FROM_S)
        & (t <= end)
        & np.isfinite(et)
        & np.isfinite(bt)
        & (et > -1.0 + 1e-9)
        & (bt > -1.0 + 1e-9)
    )
    if ok.sum() < 2:
        return None
    return float(np.median(et[ok] - bt[ok]))


#: Share of the spread of a machine's ET - BT over its logs that one split into a lower and a
#: higher group must explain (Otsu's between-group variance over the total) before
#: :func:`et_not_drum_air` reads the two groups as two sensor positions. The Skywalker's first ten
#: logs by name, three with the sensor elsewhere, split at 0.91. Logs of one position seldom reach
#: 0.85: on seeded draws of 4-30 logs from a normal, a Student-t (3 degrees of freedom) or a
#: skewed spread (2000 machines each), the split adds 0-7 points to the share of machines with a
#: log flagged by the median rule alone (at most 1 point from 16 logs up), while it finds every
#: moved log on 82-98 % of machines with 2 of 6 to 8 of 20 logs 30-40 °C below BT and the others
#: 0-30 °C above, where the median rule finds them on 1-75 % (the more logs moved, the fewer;
#: tests/test_importers.py measures a smaller draw).
TWO_SENSORS_SHARE = 0.85


def _far_below_C(values) -> float:
    """Below what a log's ET - BT lies far below ``values`` (of other logs) [degC]: 0, or the
    values' median minus three robust standard deviations (the median absolute deviation scaled
    to a normal's standard deviation) where that is lower."""
    # imported where called: SciPy's optimize and stats cost every command ~1 s (tests/test_layout.py)
    from scipy.stats import median_abs_deviation

    return min(0.0, float(np.median(values)) - 3.0 * float(median_abs_deviation(values, scale="normal")))


def et_not_drum_air(differences_C) -> list[bool]:
    """For each log's ET - BT (:func:`et_minus_bt_C`, None where unknown) of one machine: True where
    ET reads below BT and far below the machine's other logs. A sensor that moved between roasts
    shows so (the Skywalker's three oldest logs, 31-38 °C below BT against a median of 17 °C
    above); the noise of one sensor does not, nor does an ET that runs a little below BT on every
    log. ``roastlab init`` then writes ``[ET] above_BT = true``.

    Far below is below 0 and below the others' median minus three robust standard deviations,
    where the others are either all the logs, or, where the logs split into two groups that
    explain :data:`TWO_SENSORS_SHARE` of their spread, the larger, higher group (the lower one, a
    minority, is then measured against it). The second reading holds when a third or more of the
    logs have the sensor elsewhere: their readings then widen the median absolute deviation of
    all the logs until none lies three of it below the median (the Skywalker's first ten logs, three
    of them 31-38 °C below BT, the others 2-28 °C above: a cut at -45 °C over all ten, at -18 °C over
    the higher seven)."""
    d = np.array([np.nan if v is None else v for v in differences_C], dtype=float)
    ok = np.isfinite(d)
    flagged = np.zeros(len(d), dtype=bool)
    if ok.sum() < 3:
        return flagged.tolist()
    known = d[ok]
    flagged[ok] = known < _far_below_C(known)
    s = np.sort(known)
    n = len(s)
    if n >= 4 and np.ptp(s) > 0:  # three logs split any way explain nearly all their spread
        k = np.arange(1, n)  # the lower group's size
        cum = np.cumsum(s)[:-1]
        between = k * (n - k) / n**2 * ((s.sum() - cum) / (n - k) - cum / k) ** 2
        lower = int(k[np.argmax(between)])
        if 2 * lower < n and between.max() >= TWO_SENSORS_SHARE * np.var(s):
            flagged[ok] |= (known < s[lower]) & (known < _far_below_C(s[lower:]))
    return [bool(f) for f in flagged]


def et_below_bt_on_every_log(differences_C) -> bool:
    """For each log's ET - BT (:func:`et_minus_bt_C`, None where unknown or no live ET) of one
    machine: True where every log's ET reads below BT through the roast. Then no log's ET is the
    drum's air (:func:`et_not_drum_air` finds the odd logs against the others; here there are no
    others): ET and BT swapped in the device setup, or a probe outside the drum. ``roastlab init``
    then does not use ET."""
    return bool(differences_C) and all(d is not None and d < 0.0 for d in differences_C)


#: The first part of a roast in which an ET that reads the beans shows it [s after CHARGE].
BEANS_IN_VIEW_S = 60.0
#: ET's lowest reading in :data:`BEANS_IN_VIEW_S`, as a share of the way from the room to the
#: probe's lowest then, below which ET reads the beans (:func:`et_reads_beans`).
BEANS_SHARE = 0.2


def et_reads_beans(time_s, et_C, bt_C, room_C: float) -> bool | None:
    """True where a log's ET reads the beans, not the drum's air: an infrared bean sensor logged
    as ET (Artisan's "Aillio Bullet R1 IBTS" device logs the Bullet's IR bean reading as ET). Such
    a sensor reads the green beans the moment they land, at about the room's temperature, while the
    probe in the bed cools only to its turning point and the air leaving the bed stays warmer. The
    test: ET's lowest reading in the first :data:`BEANS_IN_VIEW_S` after CHARGE lies less than
    :data:`BEANS_SHARE` of the way from the room (``room_C``) to the probe's lowest then. On the
    shared logs: the Bullet's IR reading (RoasTime's ``drumTemperature``) falls to 25 °C on all 28,
    0.06 of the way or less to the probe's 74-108 °C; the Skywalker's ET, the drum's air, to
    91-159 °C, 0.83 of the way or more to its probe's 99-136 °C. The steepest fall of an air reading
    we know is roastlab's own model of a 3 kg batch charged into a 5 kg gas drum, whose outlet gas
    falls 0.4 of the way (tests/test_roaster_setup.py's synthetic gas drum). A bean reading then
    climbs with the roast: an ET that never rises above the probe's lowest (a channel left
    unconnected, reading 0) reads nothing and is not taken for the beans. None
    when either reading is missing in that window, or the probe's lowest is not above the room."""
    t = np.asarray(time_s, dtype=float)
    et, bt = np.asarray(et_C, dtype=float), np.asarray(bt_C, dtype=float)
    w = (t >= 0.0) & (t <= BEANS_IN_VIEW_S)
    ok_et, ok_bt = w & np.isfinite(et) & (et > -1.0 + 1e-9), w & np.isfinite(bt) & (bt > -1.0 + 1e-9)
    if not ok_et.any() or not ok_bt.any():
        return None
    bt_low = float(bt[ok_bt].min())
    if bt_low <= room_C:
        return None  # the probe itself at the room's temperature: nothing to tell them apart by
    later = (t > BEANS_IN_VIEW_S) & np.isfinite(et)
    if not later.any() or float(et[later].max()) <= bt_low:
        return False  # no reading that climbs with the roast
    return bool(float(et[ok_et].min()) - room_C < BEANS_SHARE * (bt_low - room_C))


def implausible_states(result, units: str = "C") -> list[str]:
    """What a simulation's states say that the machine cannot do (empty when nothing), its temperatures
    in ``units`` ("C" or "F").

    On a machine whose logged inlet air is colder than the beans (room air drawn into an
    electric or induction drum: ``Tgi_C`` below ``Tb_C`` for most of the roast), the heat reaches
    the beans through the drum, so the drum metal must be hotter than the beans; metal colder
    than the beans for more than :data:`METAL_BELOW_BEANS_SHARE` of the roast after the turning
    point means the fit found another path for the heat than the machine has. (In the paper's
    gas roaster the hot inlet gas heats the beans directly and a heavy drum may lag behind
    them: no warning there.) And where the log marks first crack (``result.meta["events"]["FCs"]``),
    the beans must be near the temperature coffee cracks at
    (:data:`~roastlab.model.constants.FIRST_CRACK_BEAN_C`, within :data:`FIRST_CRACK_TOLERANCE_C`):
    a probe curve alone can be fitted as well with beans 60 degC colder and the probe in hot air.
    ``result`` has ``time_s``, ``Ta_C``, ``Tb_C``, ``Tm_C``, ``Tgi_C`` (and ``meta``).
    """
    return _metal_below_beans(result, units) + _beans_at_first_crack(result, units)


def implausible_summary(results, units: str = "C") -> str | None:
    """:func:`implausible_states` of simulated batches (each with a ``name``) in one sentence: the
    first batch's, and how many more are alike; None where every batch's states are possible. The
    sentence a fit that failed is marked with (:attr:`roastlab.workflows.model.FittedModel.failed`)."""
    odd = [f"{r.name}: {w}" for r in results for w in implausible_states(r, units)]
    if not odd:
        return None
    return odd[0] if len(odd) == 1 else f"{odd[0]} (and {len(odd) - 1} more batch(es) alike)"


def first_crack_s(time_s, events: dict) -> float | None:
    """The log's first-crack mark (``events["FCs"]``, seconds after CHARGE) where it lies within the
    samples ``time_s`` [s], else None: the one rule of whether a log marks first crack (``roastlab
    init``, a map's ``[Tb2] first_crack``, the check of the beans there)."""
    fc_s = (events or {}).get("FCs")
    t = np.asarray(time_s, dtype=float)
    return None if fc_s is None or not t[0] <= fc_s <= t[-1] else float(fc_s)


def beans_at_first_crack(result) -> tuple[float, float] | None:
    """(the log's first-crack mark [s after CHARGE], the model's bean temperature then [degC]) of a
    simulated log (``result.meta["events"]``, ``result.Tb_C``), or None where the log marks no first
    crack within its samples (:func:`first_crack_s`)."""
    fc_s = first_crack_s(result.time_s, (getattr(result, "meta", None) or {}).get("events"))
    return None if fc_s is None else (fc_s, float(np.interp(fc_s, result.time_s, result.Tb_C)))


#: What a roaster whose logs record no heater setting does about it (this check's advice and `init`'s note).
LOG_THE_HEATER = "log the heater's setting (Artisan's event sliders or an extra device)"


def _beans_at_first_crack(result, units: str = "C") -> list[str]:
    """The beans far from :data:`~roastlab.model.constants.FIRST_CRACK_BEAN_C` at the log's FCs mark
    (:func:`beans_at_first_crack`), by more than :data:`FIRST_CRACK_TOLERANCE_C`, with what to do: read
    the mark as a bean reading where the fit did not (:func:`_mark_fitted`); where it did and still
    missed it, the logs lack what heats the beans (no heater setting: ``result.heater`` None) or the
    mark's weight is too low."""
    mark = beans_at_first_crack(result)
    if mark is None:
        return []
    fc_s, tb = mark
    if abs(tb - FIRST_CRACK_BEAN_C) <= FIRST_CRACK_TOLERANCE_C:
        return []
    u = temp_symbol(units)
    where = (
        f"beans at {display_temp(tb, units):.0f} {u} at the log's first crack ({mmss(fc_s)}), where coffee cracks "
        f"at about {display_temp(FIRST_CRACK_BEAN_C, units):.0f} {u}: "
    )
    if not _mark_fitted(result, fc_s):
        return [
            where + "the fit has placed the beans' temperature wrong, the probe alone cannot tell the beans "
            "from the air around it; read the mark as a bean reading ([Tb2] first_crack = true in the map, "
            "weighed in the fit spec's [weights] as Tb2)"
        ]
    if getattr(result, "heater", None) is None:
        return [
            where + "the fit had a bean reading there and could not reach it: the logs record no heater setting, "
            "so nothing the model is given heats the drum as the roaster's heater does (it has only a logged "
            f"air temperature to go by); {LOG_THE_HEATER} and set the roaster up again with roastlab init"
        ]
    return [
        where + "the fit had a bean reading there and did not follow it: raise its weight (Tb2 under the fit "
        "spec's [weights])"
    ]


def _mark_fitted(result, fc_s: float) -> bool:
    """Whether the simulated log carried a bean reading at its first-crack mark ``fc_s`` [s] (the mark
    read as one, a map's ``[Tb2] first_crack``, or a bean sensor's sample): the fit then saw it."""
    tb2 = getattr(result, "Tb2_measured_C", None)
    if tb2 is None:
        return False
    t = np.asarray(result.time_s, dtype=float)
    return bool(np.isfinite(np.asarray(tb2, dtype=float)[int(np.argmin(np.abs(t - fc_s)))]))


def _metal_below_beans(result, units: str = "C") -> list[str]:
    """The drum metal below the beans for most of the roast where the inlet air cannot heat them."""
    t = np.asarray(result.time_s, dtype=float)
    tp_s, _ = turning_point(t, result.Ta_C)
    after = t >= (tp_s or 0.0)
    if after.sum() < 2:
        return []
    tb = np.asarray(result.Tb_C)[after]
    if not np.mean(np.asarray(result.Tgi_C)[after] < tb) > METAL_BELOW_BEANS_SHARE:
        return []  # the inlet gas can heat the beans: metal below them is possible
    below = np.asarray(result.Tm_C)[after] < tb
    if below.mean() > METAL_BELOW_BEANS_SHARE:
        tm, tb = (
            display_temp(np.asarray(result.Tm_C)[after], units),
            display_temp(np.asarray(result.Tb_C)[after], units),
        )
        u = temp_symbol(units)
        return [
            f"drum metal colder than the beans for {100 * below.mean():.0f} % of the roast after the turning point "
            f"(metal {tm.min():.0f}-{tm.max():.0f} {u}, beans {tb.min():.0f}-{tb.max():.0f} {u}): physically "
            "implausible for a drum roaster, the fit found another path for the heat; let the fit tell the heater's "
            "paths apart: weight the logged ET ([weights] ET = 1 in the fit spec, or --weight ET=1), or, where no ET "
            "is logged, let the heater heat the drum alone (remove Tgi_gain_C from [free])"
        ]
    return []
