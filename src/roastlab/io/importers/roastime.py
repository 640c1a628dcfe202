"""Aillio RoasTime roast logs (the Bullet's own JSON format), parsed as data only.

Fields used (see ``../shared/data/real/README.md`` for what each holds on a Bullet R1):

* ``sampleRate`` [samples/s]; ``roastStartIndex`` / ``roastEndIndex`` bound the roast
  (charge to drop, end exclusive);
* equal-length series ``beanTemperature`` (the lagging bean probe), ``drumTemperature``
  (after charge an infrared bean-surface-like reading; before charge the drum; RoastWorld's export
  names it ``ibtsTemperature``, read under RoasTime's name), and ``exitTemperature``,
  ``beanDerivative``, ``ibtsDerivative`` when present; ``sampleRate`` where RoastWorld's export
  records none: from ``totalRoastTime`` over the samples;
* ``actions.actionTimeList``: the operator's changes ``{ctrlType, index, value}``, ctrlType
  0 = heater power P (levels 1-9), 1 = fan F (0-12), 2 = drum speed D (0-9); each holds until
  the next change of its type (before the first change: the first value); RoastWorld's export
  lists them as ``actions: [{type, second, setting}]``, type ``Power``, ``Blower``, ``Drum``;
* ``weightGreen`` / ``weightRoasted`` [g] as strings or numbers ("0" = not weighed);
* events ``indexYellowingStart``, ``indexFirstCrackStart``, ``indexFirstCrackEnd``,
  ``indexSecondCrackStart``, ``indexSecondCrackEnd`` (0 = not marked);
* scalar fields ``preheatTemperature``, ``drumChargeTemperature``, ``beanChargeTemperature``,
  ``beanDropTemperature``, ``drumDropTemperature`` [degC], kept in ``fields`` so a map can set
  an initial state from them (the drum temperature at charge: :data:`DRUM_AT_CHARGE`);
* ``ambientTemp`` / ``ambient``: the room temperature the owner typed, kept as written in
  ``ArtisanLog.room`` (a bare number's unit is the column map's ``[Tgi] room_unit``);
* ``serialNumber``: the roaster unit, kept as ``ArtisanLog.unit`` (a RoasTime library can hold
  roasts downloaded from other owners' Bullets; the shared logs come from six units).

The result is the same :class:`~roastlab.io.importers.artisan.ArtisanLog` the Artisan readers
give, with time 0 at charge, so the column map treats every log format alike.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...errors import InputError
from ..files import read_input_text
from ..modelfile import parse_json_document
from .artisan import ArtisanLog, epoch_or_none, number_list, room_from_text

#: RoasTime's control types in ``actions.actionTimeList`` and the channel each becomes.
CONTROL_TYPES = {0: "heater", 1: "fan", 2: "drum"}
#: The same controls by name, as RoastWorld's roast export lists its ``actions`` (``{type, second,
#: setting}``: ``"Power"`` the heater's P, ``"Blower"`` the fan's F, ``"Drum"`` the drum's D).
CONTROL_NAMES = {"power": "heater", "blower": "fan", "fan": "fan", "drum": "drum"}
#: Temperature series read when present, under the file's own names.
SERIES = ("beanTemperature", "drumTemperature", "exitTemperature")
#: The infrared sensor's curve (IBTS) as RoastWorld's export names it; read as ``drumTemperature``,
#: the name RoasTime's own files give the same curve, so one column map serves both.
IR_SERIES = "ibtsTemperature"
EVENTS = {
    "indexYellowingStart": "DRY",
    "indexFirstCrackStart": "FCs",
    "indexFirstCrackEnd": "FCe",
    "indexSecondCrackStart": "SCs",
    "indexSecondCrackEnd": "SCe",
}
FIELDS = (
    "preheatTemperature",
    "drumChargeTemperature",
    "beanChargeTemperature",
    "beanDropTemperature",
    "drumDropTemperature",
)
#: The field that gives the drum metal's temperature at charge (a map's ``[initial] Tm0_C``): the
#: preheat the roaster held the drum at. ``drumChargeTemperature`` is the IR reading stamped at
#: the log's first sample, and a log can start after the beans began to fall: in
#: ``bullet_2020-11-05_1536_500g`` the probe falls from the first sample and the IR reads 195, 183,
#: 171 °C over the first 2 s against a preheat of 245 °C. Where the log starts before the charge
#: the two agree within 3 °C on 26 of the 28 shared logs. docs/real-roaster.md measures the
#: Bullet example with each. A log without a preheat (none recorded, or 0: RoasTime's "not set",
#: as for every field of :data:`FIELDS`) falls back on the IR reading at charge, the map's list
#: tried in order.
DRUM_AT_CHARGE = ("preheatTemperature", "drumChargeTemperature")
#: Where RoasTime keeps the room temperature the owner typed (text, e.g. ``"72"`` or ``"64 F"``):
#: ``ambientTemp`` in older files, ``ambient`` in later ones.
ROOM_KEYS = ("ambientTemp", "ambient")
#: Largest sample rate accepted [1/s] (RoasTime records 2).
MAX_SAMPLE_RATE = 100.0


def _number(data: dict, key: str, path, lo: float, hi: float, required: bool = True):
    v = data.get(key)
    if v is None or v == "":
        if required:
            raise InputError("missing key", path, f"key {key}")
        return None
    if isinstance(v, str):  # RoasTime writes some numbers as strings
        try:
            v = float(v)
        except ValueError:
            raise InputError(f"not a number: {v[:20]!r}", path, f"key {key}") from None
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise InputError(f"expected a number, got {type(v).__name__}", path, f"key {key}")
    try:
        x = float(v)
    except OverflowError:
        raise InputError("number out of range", path, f"key {key}") from None
    if not (math.isfinite(x) and lo <= x <= hi):
        raise InputError(f"{x:g} outside {lo:g}..{hi:g}", path, f"key {key}")
    return x


def _series(data: dict, key: str, path) -> np.ndarray | None:
    return number_list(data[key], path, key) if key in data else None


def _actions(data: dict, n: int, rate: float, path) -> dict[str, np.ndarray]:
    """Step series of each control type over the n samples (held until the next change): RoasTime's
    ``actions.actionTimeList`` (``{ctrlType, index, value}``), or RoastWorld's ``actions`` list
    (``{type, second, setting}``, a second at ``rate`` samples per second)."""
    actions = data.get("actions", {})
    by_name = isinstance(actions, list)
    if not isinstance(actions, dict) and not by_name:
        raise InputError("expected an object or a list", path, "key actions")
    items = actions if by_name else actions.get("actionTimeList", [])
    if not isinstance(items, list):
        raise InputError("expected a list", path, "key actions.actionTimeList")
    keys = ("type", "second", "setting") if by_name else ("ctrlType", "index", "value")
    changes: dict[str, list[tuple[int, float]]] = {name: [] for name in CONTROL_TYPES.values()}
    for k, item in enumerate(items):
        where = f"actions[{k}]" if by_name else f"actions.actionTimeList[{k}]"
        if not isinstance(item, dict):
            raise InputError("expected an object", path, where)
        ctrl, index, value = (item.get(key) for key in keys)
        for label, v in zip(keys[by_name:], (ctrl, index, value)[by_name:]):  # RoastWorld's type is a name
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InputError(f"{label} must be a finite number, got {str(v)[:20]!r}", path, where)
        control = CONTROL_NAMES.get(str(ctrl).strip().lower()) if by_name else CONTROL_TYPES.get(ctrl)
        if control is None:
            continue  # a control this reader does not model
        at = index * rate if by_name else index  # the sample the change is at (a second's overflows to inf)
        if not 0 <= at < 10 * max(n, 1) or not -1e3 <= value <= 1e3:
            raise InputError(f"{keys[1]} {index} or {keys[2]} {value} out of range", path, where)
        changes[control].append((round(at) if by_name else int(at), float(value)))
    out = {}
    for name, steps in changes.items():
        if not steps:
            continue
        steps.sort(key=lambda s: s[0])  # stable: the later of two changes at one index wins
        series = np.full(n, steps[0][1])
        for index, value in steps:
            series[min(index, n) :] = value
        out[name] = series
    return out


def _rate_from_length(data: dict, intervals: int, path) -> tuple[float, str]:
    """The sample rate of a log that records none [1/s], from ``totalRoastTime`` [s] over the
    roast's ``intervals`` between samples: a whole number of samples per second where the two agree
    within 5 % (RoasTime records 2), else their ratio; with a note saying so."""
    total = _number(data, "totalRoastTime", path, 1.0, 1e5, required=False)
    if total is None:
        raise InputError("missing key, and no totalRoastTime to tell the sample rate from", path, "key sampleRate")
    ratio = intervals / total
    whole = round(ratio)
    rate = float(whole) if whole >= 1 and abs(ratio - whole) <= 0.05 * ratio else ratio
    return rate, f"no sampleRate: {rate:g} samples/s from totalRoastTime ({total:g} s over {intervals + 1} samples)"


def read_roastime(path: str | Path, keep_after_drop: bool = False) -> ArtisanLog:
    """Parse an Aillio RoasTime JSON log into an :class:`ArtisanLog` (see module docstring)."""
    path = Path(path)
    data = parse_json_document(read_input_text(path, "a RoasTime log"), path)
    if not isinstance(data, dict):
        raise InputError("expected a JSON object (an Aillio RoasTime log)", path)
    bt = _series(data, "beanTemperature", path)
    if bt is None:
        raise InputError("missing key (not an Aillio RoasTime log?)", path, "key beanTemperature")
    n = len(bt)
    if n < 2:
        raise InputError(f"needs at least 2 samples, beanTemperature has {n}", path, "key beanTemperature")
    start = int(_number(data, "roastStartIndex", path, 0, n - 1, required=False) or 0)
    end_raw = _number(data, "roastEndIndex", path, 0, 10 * n, required=False)
    end = n if not end_raw else int(min(end_raw, n))
    if end - start < 2:
        raise InputError(f"roastStartIndex {start} and roastEndIndex {end} leave fewer than 2 samples", path)
    notes = []
    rate = _number(data, "sampleRate", path, 1e-3, MAX_SAMPLE_RATE, required=False)
    if rate is None:  # RoastWorld's export records none: the roast's length over its samples
        rate, note = _rate_from_length(data, end - 1 - start, path)
        notes.append(note)
    channels = {"beanTemperature": bt}
    for key in SERIES[1:]:
        name = IR_SERIES if key == "drumTemperature" and key not in data and IR_SERIES in data else key
        s = _series(data, name, path)
        if s is not None:
            if len(s) != n:
                raise InputError(
                    f"has {len(s)} values but beanTemperature has {n} (truncated file?)", path, f"key {name}"
                )
            channels[key] = s
    channels.update(_actions(data, n, rate, path))
    stop = n if keep_after_drop else end
    time_s = (np.arange(n, dtype=float) - start) / rate
    sl = slice(start, stop)
    channels = {k: v[sl].copy() for k, v in channels.items()}
    channels["BT"] = channels["beanTemperature"]  # the curve a roaster reads, under Artisan's name
    events = {"CHARGE": 0.0, "DROP": (end - 1 - start) / rate}
    for key, name in EVENTS.items():
        idx = _number(data, key, path, 0, 10 * n, required=False)
        if idx and start < idx < n:
            events[name] = (idx - start) / rate
    weight = _number(data, "weightGreen", path, 0, 1e7, required=False)
    roasted = _number(data, "weightRoasted", path, 0, 1e7, required=False)
    log = ArtisanLog(
        str(path),
        time_s[sl],
        channels,
        set(SERIES) | {"BT"},
        "C",
        start,
        end - 1,
        events,
        weight_in_kg=weight / 1000.0 if weight else None,
        weight_out_kg=roasted / 1000.0 if roasted else None,
        title=str(data.get("roastName", ""))[:200],
        machine="Aillio Bullet",
        started_epoch_s=epoch_or_none(
            data.get("dateTime") / 1000.0 if isinstance(data.get("dateTime"), (int, float)) else None
        ),
    )
    log.notes.extend(notes)
    # 0 is "not recorded" (no drum or bean is at 0 degC during a roast; Artisan writes 0 alike)
    log.fields = {k: v for k in FIELDS if (v := _number(data, k, path, -100, 1000, required=False)) not in (None, 0.0)}
    # the room temperature the owner typed (older RoasTime: ambientTemp, later: ambient), as written;
    # a bare 0 is RoastWorld's "not typed", as for the fields above
    log.room = room_from_text(next((data[k] for k in ROOM_KEYS if data.get(k) not in (None, "", 0)), None))
    serial = data.get("serialNumber")
    if isinstance(serial, (int, str)) and not isinstance(serial, bool) and str(serial).strip():
        log.unit = str(serial).strip()[:40]
    return log
