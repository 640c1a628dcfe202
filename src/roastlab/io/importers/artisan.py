"""Artisan roast logs: ``.alog`` (Python-literal or JSON dict) and the Artisan CSV export.

Fields used: ``timex`` [s], ``temp1`` = ET, ``temp2`` = BT, ``mode`` ('C' or 'F'), ``-1`` =
missing sample, ``timeindex`` = sample indices of [CHARGE, DRY, FCs, FCe, SCs, SCe, DROP, COOL]
(0 = not set, except CHARGE whose 0 is a real index only when set explicitly; -1 = unset in
newer files), ``weight`` = [green, roasted, unit], extra devices (``extratimex``,
``extratemp1/2``, ``extraname1/2``, ``extraNoneTempHint1/2`` marking non-temperature channels),
and special events (``specialevents`` sample indices, ``specialeventstype`` indices into
``etypes``, ``specialeventsvalue`` in Artisan's internal encoding).

The file is parsed as data only and in bounded memory: JSON when it is JSON; otherwise the
Python literal Artisan writes (``repr`` of a dict) is translated token by token to JSON
(:func:`python_literal_to_json`) and parsed by the JSON parser, so parsing costs a small
multiple of the file's size (``ast.literal_eval`` builds a syntax tree of ~1 kB per number,
about 18 GB for a 16 MB file). A file holding code (a call, a name) is refused, never run.
"""

from __future__ import annotations

import ast
import io
import json
import math
import re
import warnings
from array import array
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import InputError
from ...metrics.profile import clock_s, mmss, turning_point
from ..files import read_input_text

#: The channel whose reading at CHARGE is the drum's temperature then, for an Artisan log (a map's
#: ``[initial] Tm0_C``; what ``roastlab init`` writes): BT, the probe that has soaked in the preheated
#: empty drum, and the charge temperature roasters quote. Over the minute before the charge it moves
#: by a median 1.1 °C on the Skywalker's 16 logs (more than 2.5 °C on one), while ET moves by a median
#: 11 °C and up to 24 °C as the drum is opened and charged, so ET's reading stamped at CHARGE depends
#: on the second the button was pressed. Leave-one-log-out on the Skywalker's 16 logs: FIT 79.3 % with BT, 76.5 %
#: with ET (the paper's probe; 83.8 % and 77.3 % with the bed laws of
#: :data:`roastlab.model.bed.CROSS_VALIDATED`; docs/real-roaster.md). ET stands in where a log has no BT
#: reading at CHARGE (a map's ``[initial]`` sources are tried in order).
DRUM_AT_CHARGE = ("BT", "ET")
#: The field (``ArtisanLog.fields``) with ET's reading before CHARGE: the median over the
#: :data:`BT_FALL_WINDOW_S` before the CHARGE sample, where the log recorded the preheated drum. Where
#: ET is an infrared bean sensor (:func:`roastlab.metrics.profile.et_reads_beans`), it then looks at
#: the empty drum, as RoasTime's ``preheatTemperature`` does, while at CHARGE it already reads the
#: beans; ``roastlab init`` takes it as the drum's temperature at charge for such logs.
ET_BEFORE_CHARGE = "ET before CHARGE"
EVENT_NAMES = ("CHARGE", "DRY", "FCs", "FCe", "SCs", "SCe", "DROP", "COOL")
#: A log with no CHARGE or DROP marked: they are where the bean probe bends into a fall of BT_FALL_C
#: or more within BT_FALL_WINDOW_S, at the charge (cold beans on the probe) and at the discharge (the
#: probe left in the emptied drum). On the Skywalker's 16 logs BT falls 14-36 degC in the 30 s after
#: each marked CHARGE and 11-34 degC after each DROP (one log's probe failed before its DROP), and at
#: most 0.2 degC within any 30 s between the turning point and the last 30 s before DROP. Found so
#: with the marks ignored: CHARGE within 3 s of the marked one on all 16, DROP 1.5-7.5 s after it on
#: the 15 whose probe held (tests/test_real_roaster.py).
BT_FALL_C = 10.0
BT_FALL_WINDOW_S = 30.0
#: A fall is the charge only if BT then climbs this much above its turning point (a roast follows):
#: the Skywalker's 16 logs climb 65-100 degC from the turning point to DROP; after the discharge's
#: fall BT does not climb again.
ROAST_RISE_C = 40.0
WEIGHT_UNITS = {"g": 1e-3, "kg": 1.0, "lb": 0.45359237, "oz": 0.028349523125}


def f_to_c(values):
    """Temperatures [degF] as a float array [degC] (:func:`roastlab.metrics.profile.celsius_of`)."""
    from ...metrics.profile import celsius_of

    return celsius_of(np.asarray(values, dtype=float), "F")


#: Artisan's default special-event types, in its order (a log's ``specialeventstype`` indexes them).
DEFAULT_ETYPES = ("Air", "Drum", "Damper", "Burner", "--")


def events_external_to_internal(x: float) -> float:
    """The inverse of :func:`events_internal_to_external`: an external value in [-100, 100] as
    Artisan stores it, 1 + x/10 (and -(1 + |x|/10) below 0).

    >>> events_external_to_internal(70.0), events_internal_to_external(events_external_to_internal(70.0))
    (8.0, 70.0)
    """
    return round(1.0 + x / 10.0, 4) if x >= 0 else -round(1.0 + abs(x) / 10.0, 4)


def events_internal_to_external(v: float) -> float:
    """Artisan's event-value encoding: internal v in [-11, 11] -> external in [-100, 100].

    Artisan stores slider/button event values as v = 1 + external/10 (so 0 % is 1.0 and
    100 % is 11.0); values with |v| <= 1 mean 0.
    """
    if v is None or -1.0 <= v <= 1.0:
        return 0.0
    if v < -1.0:
        return -(round(abs(v) * 10) - 10)
    return float(round(v * 10) - 10)


@dataclass(frozen=True)
class RoomReading:
    """The room temperature a log records, as written: Artisan's ``ambientTemp`` (in the profile's
    mode), RoasTime's ``ambientTemp`` / ``ambient`` (text the owner typed: ``"72"``, ``"64 F"``).

    ``unit`` is ``"C"`` or ``"F"`` where the log says which, None for a bare number (the column
    map's ``[Tgi] room_unit`` decides); ``value`` is NaN where the text is not a temperature.
    """

    value: float
    unit: str | None
    text: str


_ROOM_TEXT = re.compile(r"\s*([-+]?\d+(?:[.,]\d+)?)\s*(?:°|deg(?:rees?)?)?\s*([CF])?\s*\Z", re.I)


def room_from_text(value) -> RoomReading | None:
    """A :class:`RoomReading` from a log's room-temperature entry; None where there is none.

    >>> room_from_text("64 F")
    RoomReading(value=64.0, unit='F', text='64 F')
    >>> room_from_text("72").unit is None, room_from_text("") is None, room_from_text(None) is None
    (True, True, True)
    >>> import math; math.isnan(room_from_text("warm").value)
    True
    """
    if value is None or isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        v = _float_or_nan(value)
        return RoomReading(v, None, f"{v:g}" if math.isfinite(v) else str(value)[:40])
    text = str(value).strip()[:40]
    if not text:
        return None
    m = _ROOM_TEXT.match(text)
    if m is None:
        return RoomReading(math.nan, None, text)
    unit = m.group(2).upper() if m.group(2) else None
    return RoomReading(float(m.group(1).replace(",", ".")), unit, text)


@dataclass
class ArtisanLog:
    """A parsed Artisan profile, in degC, time aligned so that CHARGE is t = 0.

    channels : name -> array over ``time_s`` (``BT``, ``ET``, extra device names, and one step
    signal per special-event type, e.g. ``Burner``, ``Air``, in Artisan's external units).
    """

    path: str
    time_s: np.ndarray
    channels: dict[str, np.ndarray]
    temperature_channels: set
    mode: str
    charge_index: int
    drop_index: int | None
    events: dict[str, float] = field(default_factory=dict)  # event name -> time after CHARGE [s]
    weight_in_kg: float | None = None
    weight_out_kg: float | None = None
    title: str = ""
    fields: dict = field(default_factory=dict)  # scalar fields of the log (e.g. RoasTime's drum charge temperature)
    machine: str = ""  # the roaster as the log names it (Artisan's roastertype; "Aillio Bullet" for RoasTime)
    started_epoch_s: float | None = None  # when the roast started (Artisan roastepoch, RoasTime dateTime)
    unit: str = ""  # which roaster of that make (RoasTime serialNumber); empty when the log does not say
    room: RoomReading | None = None  # the room temperature the log records, as written; None if it does not
    notes: list[str] = field(default_factory=list)  # what the reader inferred (an unmarked CHARGE or DROP)
    capacity_kg: float | None = None  # the roaster's batch capacity the log states (Artisan's roastersize)


def bt_falls_from(time_s: np.ndarray, bt: np.ndarray, start: int) -> int | None:
    """The first sample from ``start`` on from which BT falls by :data:`BT_FALL_C` or more within
    :data:`BT_FALL_WINDOW_S` (the beans' arrival at CHARGE, their departure at DROP), or None."""
    from scipy.ndimage import minimum_filter1d

    if len(bt) - start < 2:
        return None
    # the window in samples at the log's median sampling interval (Artisan and RoasTime sample evenly);
    # a forward running minimum, so a long log costs one pass, not one slice per sample
    width = max(2, int(round(BT_FALL_WINDOW_S / float(np.median(np.diff(time_s))))) + 1)
    x = np.where(np.isfinite(bt), bt, np.inf)[start:]
    ahead = minimum_filter1d(x, size=width, origin=-(width // 2), mode="nearest")
    hits = np.flatnonzero(np.isfinite(x) & (x - ahead >= BT_FALL_C))
    return start + int(hits[0]) if hits.size else None


def _running_median3(x: np.ndarray) -> np.ndarray:
    """Each sample replaced by the median of it and its two neighbours (one glitch cannot look like
    a fall); the ends by the median of the three nearest."""
    if len(x) < 3:
        return x.copy()
    with warnings.catch_warnings():  # three missing samples in a row stay missing (NaN), said by no warning
        warnings.simplefilter("ignore", RuntimeWarning)
        y = np.nanmedian(np.stack([x[:-2], x[1:-1], x[2:]]), axis=0)
    return np.concatenate([y[:1], y, y[-1:]])


def _bend_of_fall(time_s: np.ndarray, bt: np.ndarray, start: int) -> int | None:
    """Where BT bends into the first fall of :func:`bt_falls_from` after ``start`` (:func:`_fall`)."""
    fall = _fall(time_s, bt, start)
    return None if fall is None else fall[0]


def _fall(time_s: np.ndarray, bt: np.ndarray, start: int) -> tuple[int, int] | None:
    """``(knee, end)`` of the first fall of :func:`bt_falls_from` after ``start``, or None: ``end`` is
    where BT has fallen :data:`BT_FALL_C`; ``knee``, over the span from :data:`BT_FALL_WINDOW_S`
    before the fall begins to ``end``, the sample furthest above the chord joining the span's ends
    (a slow drift before the fall, or a rise, is not the event; the knee where the fall steepens is)."""
    k0 = bt_falls_from(time_s, bt, start)
    if k0 is None:
        return None
    k1 = k0 + int(np.flatnonzero(bt[k0:] <= bt[k0] - BT_FALL_C)[0])
    a = max(start, int(np.searchsorted(time_s, time_s[k0] - BT_FALL_WINDOW_S)))
    t, b = time_s[a : k1 + 1], bt[a : k1 + 1]
    chord = b[0] + (b[-1] - b[0]) * (t - t[0]) / (t[-1] - t[0])
    return a + int(np.nanargmax(b - chord)), k1


def et_before_charge(time_s, et, charge: int) -> dict:
    """``{ET_BEFORE_CHARGE: reading}`` from ET's samples in the :data:`BT_FALL_WINDOW_S` before
    sample ``charge`` (their median; Artisan's -1 and NaN skipped), or ``{}`` when the log holds
    none there (recording began at the charge)."""
    t, v = np.asarray(time_s, dtype=float), np.asarray(et, dtype=float)
    w = (t < t[charge]) & (t >= t[charge] - BT_FALL_WINDOW_S) & np.isfinite(v) & (v != -1.0)
    return {ET_BEFORE_CHARGE: float(np.median(v[w]))} if w.any() else {}


def marks_or_bt(time_s, bt, charge: int | None, drop: int | None, keep_after_drop: bool = False):
    """A log's CHARGE and DROP sample indices, each as marked or, where unmarked (None), found in BT
    (:func:`charge_from_bt`, :func:`drop_from_bt`); returns ``(charge, drop or None, notes)``, a note
    for each mark found so. No CHARGE in BT: the first sample; no DROP: the log's end."""
    notes = []
    if charge is None:
        charge = charge_from_bt(time_s, bt, drop)
        notes.append(
            f"no CHARGE marked: taken at {time_s[charge] - time_s[0]:.0f} s into the recording, where BT bends "
            f"into a fall of {BT_FALL_C:g} degC or more within {BT_FALL_WINDOW_S:g} s"
            if charge is not None
            else "no CHARGE marked and BT shows no charge: the log is read from its first sample (a recording "
            "begun after the beans went in holds no drum temperature at charge; mark CHARGE or record from the preheat)"
        )
        charge = charge or 0
    if drop is None and not keep_after_drop:
        drop = drop_from_bt(time_s, bt, charge)
        if drop is not None:
            notes.append(
                f"no DROP marked: taken at {mmss(time_s[drop] - time_s[charge])} after CHARGE, where BT bends "
                f"into a fall of {BT_FALL_C:g} degC or more within {BT_FALL_WINDOW_S:g} s after its peak"
            )
    return charge, drop, notes


def charge_from_bt(time_s: np.ndarray, bt: np.ndarray, before: int | None = None) -> int | None:
    """An unmarked CHARGE: where BT bends into its first fall (:func:`_bend_of_fall`) that a roast
    follows (:func:`_roast_follows`: a recording begun after the charge shows the discharge's fall,
    not the charge's), before sample ``before`` (a marked DROP) if given; or None."""
    b = _running_median3(bt)
    end = len(b) if before is None else max(0, min(int(before), len(b)))
    t, b = time_s[:end], b[:end]
    start = 0
    while (fall := _fall(t, b, start)) is not None:
        knee, end_of_fall = fall
        if _roast_follows(t[knee:], b[knee:]):
            return knee
        start = end_of_fall + 1  # past this fall
    return None


def _roast_follows(time_s: np.ndarray, bt: np.ndarray) -> bool:
    """Whether BT climbs :data:`ROAST_RISE_C` or more above its turning point
    (:func:`roastlab.metrics.profile.turning_point`) after a fall: a charge, not a discharge."""
    tp_s, tp_C = turning_point(time_s, bt)
    if tp_s is None:
        return False
    after = bt[int(np.searchsorted(time_s, tp_s)) :]
    return bool(np.any(np.isfinite(after)) and np.nanmax(after) - tp_C >= ROAST_RISE_C)


def drop_from_bt(time_s: np.ndarray, bt: np.ndarray, charge: int) -> int | None:
    """An unmarked DROP: where BT bends into its first fall after its peak past the turning point
    (:func:`roastlab.metrics.profile.turning_point` of the curve from CHARGE); None when BT never
    falls so (the log is then read to its end)."""
    b = _running_median3(bt)
    tp_s, _ = turning_point(time_s[charge:], b[charge:])
    if tp_s is None:
        return None
    tp = int(np.searchsorted(time_s, tp_s))
    peak = tp + int(np.nanargmax(b[tp:]))
    return _bend_of_fall(time_s, b, peak)


# Tokens of a Python literal that JSON spells differently. Strings come first so that words,
# brackets and colons inside a string are consumed with it; what is left between matches
# (numbers, [ ] { } , :, white space) is the same in both languages, and anything else
# (a name, a call, a bytes literal) stays and makes the JSON parser refuse the text.
_PY_TOKENS = re.compile(
    r"""(?P<s>[uU]?'(?:[^'\\\n]|\\.)*'|[uU]?"(?:[^"\\\n]|\\.)*")"""
    r"|(?P<w>\b(?:True|False|None)\b)"
    r"|(?P<k>-?\d+(?:\.\d*)?(?=\s*:))"
    r"|(?P<o>\()|(?P<c>\))",
    re.S,
)
_PY_WORDS = {"True": "true", "False": "false", "None": "null"}


def _py_token_to_json(m: re.Match) -> str:
    kind = m.lastgroup
    tok = m.group()
    if kind == "s":
        body = tok[2:-1] if tok[0] in "uU" else tok[1:-1]
        if "\\" in body:
            return json.dumps(ast.literal_eval(tok))  # one string literal: bounded, data only
        return json.dumps(body)
    if kind == "w":
        return _PY_WORDS[tok]
    if kind == "k":
        return json.dumps(tok)  # a number used as a dict key: JSON keys are strings
    return "[" if kind == "o" else "]"


def python_literal_to_json(text: str) -> str:
    """Translate the Python literal of an Artisan profile into JSON text.

    Single- and double-quoted strings (with escapes), ``True``/``False``/``None`` and
    tuples are rewritten; numbers and punctuation are shared by both languages. The result
    is parsed by ``json.loads``, which refuses anything that is not data. Work and memory are
    linear in the text's length.
    """
    return _PY_TOKENS.sub(_py_token_to_json, text)


def _parse_text(path: Path, text: str) -> dict:
    stripped = text.strip()
    if not stripped:
        raise InputError("empty file", path)
    if stripped[0] != "{":
        raise InputError("not an Artisan profile (expected a dict starting with '{')", path)
    try:
        data = json.loads(stripped)
    except json.JSONDecodeError:
        try:
            data = json.loads(python_literal_to_json(stripped))
        except json.JSONDecodeError as exc:
            if exc.pos >= len(exc.doc) - 1:
                raise InputError("truncated Artisan profile (ends before its closing brace)", path) from None
            raise InputError(
                f"not a data-only Artisan profile (unexpected text at line {exc.lineno}, column {exc.colno}); "
                "code is never run",
                path,
            ) from None
        except SyntaxError:  # a malformed escape inside one string
            raise InputError("malformed string in the Artisan profile", path) from None
        except RecursionError:
            raise InputError("Artisan profile nested too deeply to parse", path) from None
        except ValueError as exc:  # e.g. an integer longer than Python's digit limit
            raise InputError(f"number out of range in the Artisan profile ({str(exc)[:60]})", path) from None
    except RecursionError:
        raise InputError("Artisan profile nested too deeply to parse", path) from None
    except ValueError as exc:  # e.g. an integer longer than Python's digit limit
        raise InputError(f"number out of range in the Artisan profile ({str(exc)[:60]})", path) from None
    if not isinstance(data, dict):
        raise InputError(f"expected a dict at the top level, got {type(data).__name__}", path)
    return data


def _as_list(value) -> list:
    """A field that should be a list, or [] when the file has anything else there."""
    return value if isinstance(value, list) else []


def number_list(value, path: Path, key: str) -> np.ndarray:
    """A parsed list of numbers as a float array; else one InputError naming file and key.

    Shared by the log readers (Artisan, RoasTime): booleans and strings are refused, integers
    beyond float range are "out of range", never an OverflowError. A null (JSON's ``null``, Python's
    ``None``, as a converter writes a reading not taken) is NaN: a missing sample, as Artisan's -1.
    """
    if not isinstance(value, (list, tuple)):
        raise InputError(f"expected a list of numbers, got {type(value).__name__}", path, f"key {key}")
    out = np.empty(len(value))
    for i, v in enumerate(value):
        if v is None:
            out[i] = np.nan
            continue
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InputError(f"expected numbers, found {type(v).__name__} at position {i}", path, f"key {key}")
        try:
            out[i] = v
        except OverflowError:
            raise InputError(f"number out of range at position {i}", path, f"key {key}") from None
    return out


def _numeric_list(data: dict, key: str, path: Path, required: bool = True):
    if key not in data:
        if required:
            raise InputError("missing key", path, f"key {key}")
        return None
    return number_list(data[key], path, key)


def _weight(value, factor: float, path: Path) -> float | None:
    """A logged weight in kg to a tenth of a gram (finer than a roaster's scale reads; a weight in
    pounds then prints as the grams it was), or None when absent (Artisan writes 0 for 'not weighed')."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        return None
    try:
        kg = float(value) * factor
    except OverflowError:
        raise InputError("weight out of range", path, "key weight") from None
    return round(kg, 4) if math.isfinite(kg) else None


#: An extra device's name as Artisan shows it: ``{0}``-``{3}`` stand for the event types' names
#: (``etypes``), as Artisan's own machine setups name their heater and fan readouts (the Aillio R1's
#: ``{3}`` and ``{0}`` read "Heater" and "Fan").
EXTRA_NAME_FIELD = re.compile(r"\{([0-3])\}")
#: What a readout is called when its name is an event type's and the log has that type's events too:
#: the events are the setting the roaster made (the map's default), the readout what the machine reports.
READOUT_SUFFIX = " readout"


def extra_name(name: str, etypes: list, with_events: set[str]) -> str:
    """``name`` of an extra device with Artisan's ``{n}`` fields filled from ``etypes`` (no
    :meth:`str.format` on a file's text), and :data:`READOUT_SUFFIX` added when an event type of
    that name has events in the log (else the events would be written over the readout)."""
    filled = EXTRA_NAME_FIELD.sub(
        lambda m: str(etypes[int(m.group(1))]) if int(m.group(1)) < len(etypes) else m.group(0), name
    )
    return filled + READOUT_SUFFIX if filled in with_events else filled


def _special_events(data: dict, etypes: list, n: int, path) -> list[tuple[int, str, float]]:
    """The log's special events as ``(sample index, event type's name, value in external units)``,
    checked (malformed ones refused); events of an unknown type, of type ``--`` or outside the
    log's samples are skipped."""
    idx, types, vals = (data.get(k, []) for k in ("specialevents", "specialeventstype", "specialeventsvalue"))
    if not (isinstance(idx, list) and isinstance(types, list) and isinstance(vals, list)):
        raise InputError("special events must be lists", path, "key specialevents")
    if not (len(idx) == len(types) == len(vals)):
        raise InputError(
            f"specialevents/type/value lengths differ ({len(idx)}, {len(types)}, {len(vals)})",
            path,
            "key specialevents",
        )
    out = []
    for i, ty, v in zip(idx, types, vals):
        if not all(isinstance(q, (int, float)) and not isinstance(q, bool) for q in (i, ty, v)):
            raise InputError("special events must be numbers", path, "key specialevents")
        if not all(abs(q) <= 1e9 for q in (i, ty, v)):  # also False for NaN; exact for huge ints
            raise InputError("special event index, type or value out of range", path, "key specialevents")
        ty, i = int(ty), int(i)
        if not 0 <= ty < len(etypes) or not 0 <= i < n or str(etypes[ty]) == "--":
            continue
        out.append((i, str(etypes[ty]), events_internal_to_external(float(v))))
    return out


def time_follows(timex: np.ndarray) -> np.ndarray:
    """Which samples' times are finite and later than every finite time before them (a boolean mask)."""
    finite = np.isfinite(timex)
    before = np.maximum.accumulate(np.where(finite, timex, -np.inf))
    return finite & (timex > np.concatenate(([-np.inf], before[:-1])))


def read_alog(path: str | Path, keep_after_drop: bool = False, align_charge: bool = True) -> ArtisanLog:
    """Parse an Artisan ``.alog`` file into an :class:`ArtisanLog` (see module docstring)."""
    path = Path(path)
    data = _parse_text(path, read_input_text(path, "an Artisan profile"))
    timex = _numeric_list(data, "timex", path)
    et = _numeric_list(data, "temp1", path)
    bt = _numeric_list(data, "temp2", path)
    n = len(timex)
    if n < 2:
        raise InputError(f"needs at least 2 samples, timex has {n}", path, "key timex")
    for key, arr in (("temp1", et), ("temp2", bt)):
        if len(arr) != n:
            raise InputError(f"has {len(arr)} values but timex has {n} (truncated file?)", path, f"key {key}")
    mode = data.get("mode", "C")
    if mode not in ("C", "F"):
        raise InputError(f"mode must be 'C' or 'F', got {mode!r}", path, "key mode")
    # a sample whose time does not follow every one before it (a repeated or backward stamp, a
    # missing one) is dropped, and the marks and events that index the samples are moved with them
    kept = np.flatnonzero(time_follows(timex))
    if len(kept) < 2:
        raise InputError("time not strictly increasing: fewer than 2 samples follow one another", path, "key timex")
    dropped_times = n - len(kept)

    def moved(k: int) -> int:
        """Sample ``k`` of the file as a kept sample: itself, or the next kept one."""
        return int(np.searchsorted(kept, k)) if 0 <= k < n else k

    channels = {"ET": et.copy(), "BT": bt.copy()}
    temps = {"ET", "BT"}
    etypes = _as_list(data.get("etypes")) or list(DEFAULT_ETYPES)
    events = _special_events(data, etypes, n, path)
    with_events = {name for _, name, _ in events}
    # extra devices: each has a time base and two channels with names
    extratimex = _as_list(data.get("extratimex"))
    if extratimex:
        for d, tx in enumerate(extratimex):
            for k in (1, 2):
                names = _as_list(data.get(f"extraname{k}"))
                values = _as_list(data.get(f"extratemp{k}"))
                hints = _as_list(data.get(f"extraNoneTempHint{k}"))
                if d >= len(names) or d >= len(values):
                    continue
                name = names[d]
                if not isinstance(name, str) or not name:
                    continue
                name = extra_name(name, etypes, with_events)
                if name in channels:
                    continue
                arr = _numeric_list({"v": values[d]}, "v", path)
                txa = _numeric_list({"v": tx}, "v", path)
                if len(arr) != len(txa) or len(arr) == 0:
                    continue
                arr = np.where(arr == -1, np.nan, arr)
                channels[name] = np.interp(timex, txa, arr, left=np.nan, right=np.nan) if len(txa) != n else arr
                is_temp = not (d < len(hints) and bool(hints[d]))
                if is_temp:
                    temps.add(name)
    # -1 marks a missing sample
    for name in list(channels):
        arr = channels[name]
        channels[name] = np.where(arr == -1, np.nan, arr)
    if mode == "F":
        for name in temps:
            channels[name] = f_to_c(channels[name])

    # special events -> step signals in external units, one per event type
    for i, name, value in events:
        channels.setdefault(name, np.full(n, np.nan))[i:] = value

    # CHARGE alignment and DROP cut
    ti = data.get("timeindex", [0] * 8)
    if not isinstance(ti, list) or not all(isinstance(q, int) and not isinstance(q, bool) for q in ti):
        raise InputError("timeindex must be a list of integers", path, "key timeindex")
    ti = (ti + [0] * 8)[:8]
    if dropped_times:  # the marks first, while n is still the file's count
        ti = [moved(k) if k > 0 or (k == 0 and i == 0) else k for i, k in enumerate(ti)]
        timex, n = timex[kept], len(kept)
        channels = {name: arr[kept] for name, arr in channels.items()}
    if 0 <= ti[0] < n and 0 < ti[6] < n and ti[6] <= ti[0]:
        raise InputError(
            f"DROP (sample {ti[6]}, {timex[ti[6]]:.0f} s) is marked at or before CHARGE (sample {ti[0]}, "
            f"{timex[ti[0]]:.0f} s): mark them again in Artisan",
            path,
            "key timeindex",
        )
    charge, drop, notes = marks_or_bt(
        timex,
        channels["BT"],
        ti[0] if 0 <= ti[0] < n else None,  # CHARGE unmarked: Artisan's -1
        ti[6] if 0 < ti[6] < n else None,  # DROP unmarked: 0
        keep_after_drop,
    )
    # a mark past the last sample does not belong to these samples (a template, a file cut short)
    beyond = [f"{name} (sample {k})" for name, k in zip(EVENT_NAMES, ti) if k >= n]
    if beyond:
        notes.insert(0, f"{', '.join(beyond)} marked past the log's last sample ({n - 1}): read as unmarked")
    if dropped_times:
        notes.insert(0, f"dropped {dropped_times} sample(s) whose time does not follow the one before (timex)")
    ti[0], ti[6] = charge, drop or 0
    events = {}
    for name, k in zip(EVENT_NAMES, ti):
        if (k > 0 or name == "CHARGE") and k < n:
            events[name] = float(timex[k] - timex[charge])
    pre_charge = et_before_charge(timex, channels["ET"], charge)  # before the slice below drops those samples
    t0 = timex[charge] if align_charge else 0.0
    end = n if (keep_after_drop or drop is None) else drop + 1
    start = charge if align_charge else 0
    time_s = timex[start:end] - t0
    for name in channels:
        channels[name] = channels[name][start:end]
    weight_in = weight_out = None
    w = data.get("weight")
    if isinstance(w, list) and len(w) >= 3 and isinstance(w[2], str):
        factor = WEIGHT_UNITS.get(w[2].lower())
        if factor is not None:
            weight_in, weight_out = (_weight(v, factor, path) for v in w[:2])
    return ArtisanLog(
        str(path),
        time_s,
        channels,
        temps,
        mode,
        charge,
        drop,
        events,
        weight_in,
        weight_out,
        str(data.get("title", "")),
        fields=pre_charge,
        machine=str(data.get("roastertype", "") or "")[:100],
        started_epoch_s=epoch_or_none(data.get("roastepoch")),
        room=_alog_room(data.get("ambientTemp"), mode),
        notes=notes,
        capacity_kg=stated_capacity_kg(data.get("roastersize")),
    )


#: Artisan's ``roastersize`` (Roast Properties, the machine's "Capacity") is in kg, 0 when not set; Artisan
#: keeps it within 0-999.
ROASTERSIZE_MAX_KG = 999.0


def stated_capacity_kg(value) -> float | None:
    """The batch capacity [kg] a log states (Artisan's ``roastersize``), or None when it is not set
    (0), not a number or out of Artisan's range."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if 0.0 < value <= ROASTERSIZE_MAX_KG else None


def _alog_room(value, mode: str) -> RoomReading | None:
    """Artisan's ``ambientTemp``, in the profile's mode; Artisan writes 0 where none was entered."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    v = _float_or_nan(value)
    return RoomReading(v, mode, f"{v:g} {mode}") if math.isfinite(v) and v != 0 else None


def _float_or_nan(value: int | float) -> float:
    """A parsed number as a float; NaN for one beyond float range (a JSON integer can be)."""
    try:
        return float(value)
    except OverflowError:
        return math.nan


def epoch_or_none(value) -> float | None:
    """A plausible Unix time [s] (1990-2100), else None: a log's start, for ordering logs."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    v = float(value)
    return v if 6.3e8 < v < 4.1e9 else None


#: The marks of an Artisan CSV export's first line kept as the log's events (the export's name ->
#: :data:`EVENT_NAMES`' name); CHARGE and DROP are read apart, the turning point is computed, not kept.
CSV_EVENTS = {"DRYe": "DRY", "FCs": "FCs", "FCe": "FCe", "SCs": "SCs", "SCe": "SCe"}


def csv_started_epoch_s(meta: dict) -> float | None:
    """When an Artisan CSV export's roast was recorded, from its first line's ``Date`` (dd.MM.yyyy, the
    export's own format) and ``Time`` (hh:mm) [s since 1970, the clock as written, to the minute], for
    ordering logs; None where either is missing or not so written.

    >>> csv_started_epoch_s({"Date": "27.09.2025", "Time": "12:36"})
    1758976560.0
    >>> csv_started_epoch_s({"Date": "2025-09-27"}) is None
    True
    """
    import datetime

    try:
        when = datetime.datetime.strptime(f"{meta.get('Date', '')} {meta.get('Time', '')}", "%d.%m.%Y %H:%M")
    except ValueError:
        return None
    return epoch_or_none(when.replace(tzinfo=datetime.UTC).timestamp())


def named_as_temperature(name: str) -> bool:
    """Whether a channel's name says it is a temperature ("Inlet temp", "Exhaust °C"): a CSV does not
    mark its temperature columns, as an Artisan log's ``extraNoneTempHint`` does.

    >>> [named_as_temperature(n) for n in ("Inlet Temp", "Abluft °C", "Burner", "Fan")]
    [True, True, False, False]
    """
    return "temp" in name.lower() or "°" in name


def _mmss(text: str) -> float:
    """An Artisan CSV time cell (m:ss) [s]; NaN when empty (:func:`roastlab.metrics.profile.clock_s`)."""
    return clock_s(text) if text.strip() else float("nan")


def _meta_clock_s(meta: dict, key: str, path) -> float | None:
    """An Artisan CSV export's first-line mark ``key`` (DROP, FCs, ...) as a clock time on the Time1
    axis [s], as CHARGE's; None where the line leaves it empty."""
    if not meta.get(key):
        return None
    try:
        return _mmss(meta[key])
    except ValueError:
        raise InputError(f"{key} time {meta[key][:20]!r} is not mm:ss", path, "line 1") from None


def _merge_repeated_times(time_s: np.ndarray, columns):
    """Rows that share a time stamp merged into one, each column the mean of its readings there
    (NaN where none): Artisan's CSV export writes whole seconds, so a log sampled faster than once a
    second, or with jitter, repeats times. Returns ``(times, columns, how many times repeat)``;
    times that go backwards are left as they are, and the import drops the rows whose time does not
    follow the ones before (:func:`time_follows`)."""
    if time_s.size < 2 or not np.any(np.diff(time_s) == 0) or np.any(np.diff(time_s) < 0):
        return time_s, columns, 0
    times, inverse, counts = np.unique(time_s, return_inverse=True, return_counts=True)

    def mean(x):
        ok = np.isfinite(x)
        n = np.bincount(inverse, weights=ok.astype(float), minlength=times.size)
        total = np.bincount(inverse, weights=np.where(ok, x, 0.0), minlength=times.size)
        return np.divide(total, n, out=np.full(times.size, np.nan), where=n > 0)

    return times, tuple(mean(c) for c in columns), int(np.sum(counts > 1))


def read_artisan_csv(path: str | Path, keep_after_drop: bool = False) -> ArtisanLog:
    """Parse Artisan's CSV export: a first line with ``Unit:C``/``Unit:F`` and the event clock
    times (CHARGE, DRYe, FCs, FCe, SCs, SCe, DROP, COOL on the Time1 axis; kept as the events of
    :data:`CSV_EVENTS`), a header ``Time1, Time2, ET, BT, Event`` (tab- or comma-separated) and
    then two columns per extra device (its two channels' names, Artisan's ``{n}`` fields filled from
    its default event types, :data:`DEFAULT_ETYPES`: the export does not carry the log's own), rows
    with mm:ss times (Time2 counts from CHARGE, empty before it), -1 or empty for a missing sample.

    The export does not say which extra channels are temperatures (the log's ``extraNoneTempHint``):
    a channel is one where its name says so (:func:`named_as_temperature`), and only those are
    converted from degF; the others (a burner, a fan) are read as written."""
    path = Path(path)
    from ..batch import read_text

    text = read_text(path)
    # Streamed line by line into compact arrays: memory stays a small multiple of the file.
    lines = ((n, ln) for n, ln in enumerate(io.StringIO(text), start=1) if ln.strip())
    first = [next(lines, None), next(lines, None)]
    if first[1] is None:
        raise InputError("too short for an Artisan CSV export (meta line, header, data)", path)
    meta_line, header_line = first[0][1].rstrip("\r\n"), first[1][1].rstrip("\r\n")
    sep = "\t" if "\t" in header_line else ","
    meta = {}
    for item in meta_line.split(sep):
        k, _, v = item.partition(":")
        meta[k.strip()] = v.strip()
    mode = meta.get("Unit", "C")
    if mode not in ("C", "F"):
        raise InputError(f"Unit must be C or F, got {mode!r}", path, "line 1")
    header = [h.strip() for h in header_line.split(sep)]
    for col in ("Time1", "ET", "BT"):
        if col not in header:
            raise InputError(f"missing column {col} (header has: {', '.join(header)})", path, "line 2")
    idx = {c: header.index(c) for c in header}
    start = header.index("Event") + 1 if "Event" in header else len(header)
    extras = {}  # channel name -> column index: the extra devices' columns after Event
    for k in range(start, len(header)):
        name = extra_name(header[k], list(DEFAULT_ETYPES), set())
        if name and name not in ("Time1", "Time2", "ET", "BT", "Event") and name not in extras:
            extras[name] = k
    t1, t2, et, bt = array("d"), array("d"), array("d"), array("d")
    extra_values = {name: array("d") for name in extras}
    readings = [(idx["ET"], "ET", et), (idx["BT"], "BT", bt), *((k, n, extra_values[n]) for n, k in extras.items())]
    for line_no, ln in lines:
        cells = ln.rstrip("\r\n").split(sep)
        if len(cells) < len(header) - 1:
            raise InputError(
                f"row has {len(cells)} cells, header {len(header)} (truncated file?)", path, f"line {line_no}"
            )
        try:
            t1.append(_mmss(cells[idx["Time1"]]))
            t2.append(_mmss(cells[idx["Time2"]]) if "Time2" in idx and idx["Time2"] < len(cells) else float("nan"))
        except ValueError as exc:
            raise InputError(f"not a mm:ss time: {str(exc)[:20]!r}", path, f"line {line_no}, column Time1") from None
        for k, col, dest in readings:  # -1 or an empty cell: a sample not taken
            cell = cells[k].strip() if k < len(cells) else ""
            try:
                v = float(cell) if cell else float("nan")
            except ValueError:
                raise InputError(f"not a number: {cell[:20]!r}", path, f"line {line_no}, column {col}") from None
            dest.append(float("nan") if v == -1 else v)
    if not t1:
        raise InputError("too short for an Artisan CSV export (meta line, header, data)", path)
    t1, t2 = np.array(t1), np.array(t2)
    et, bt = np.array(et), np.array(bt)
    extra = {name: np.array(v) for name, v in extra_values.items()}
    temps = {"ET", "BT", *(name for name in extra if named_as_temperature(name))}
    if mode == "F":
        et, bt = f_to_c(et), f_to_c(bt)
        extra = {name: f_to_c(v) if name in temps else v for name, v in extra.items()}
    t1, (t2, et, bt, *merged), repeats = _merge_repeated_times(t1, (t2, et, bt, *extra.values()))
    extra = dict(zip(extra, merged))
    charged = np.flatnonzero(np.isfinite(t2))
    drop = None
    if (drop_at := _meta_clock_s(meta, "DROP", path)) is not None:
        drop = int(np.argmin(np.abs(t1 - drop_at)))
    if drop is not None and charged.size and drop <= charged[0]:  # as read_alog refuses such marks
        raise InputError(
            f"DROP ({meta['DROP'][:20]}) is marked at or before CHARGE ({mmss(t1[charged[0]])} on the Time1 axis): "
            "mark them again in Artisan",
            path,
            "line 1",
        )
    charge, drop, notes = marks_or_bt(t1, bt, int(charged[0]) if charged.size else None, drop, keep_after_drop)
    if repeats:
        notes.insert(0, f"{repeats} time stamp(s) repeat (the export writes whole seconds): their rows averaged")
    time_s = t1 - t1[charge]
    end = len(time_s) if (keep_after_drop or drop is None) else drop + 1
    sl = slice(charge, end)
    events = {"CHARGE": 0.0}
    for key, name in CSV_EVENTS.items():
        if (at := _meta_clock_s(meta, key, path)) is not None and 0.0 < at - t1[charge] <= time_s[end - 1]:
            events[name] = float(at - t1[charge])
    if drop is not None:
        events["DROP"] = float(time_s[drop])
    return ArtisanLog(
        str(path),
        time_s[sl],
        {"ET": et[sl], "BT": bt[sl], **{name: v[sl] for name, v in extra.items()}},
        temps,
        mode,
        charge,
        drop,
        events,
        fields=et_before_charge(t1, et, charge),
        started_epoch_s=csv_started_epoch_s(meta),
        notes=notes,
    )
