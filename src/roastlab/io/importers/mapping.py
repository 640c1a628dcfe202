"""Column maps: which channel of a log is time, Ta (BT), Tgi and Gg, and in which units.

A map is a TOML file::

    format = "auto"            # auto | alog | artisan-csv | csv | parquet
    keep_after_drop = false    # Artisan logs: keep samples after DROP
    resample_s = 0             # > 0: resample onto a uniform grid of this step [s]

    [time]                     # generic tables only; Artisan time is aligned to CHARGE
    column = "time"
    unit = "s"                 # s | min | ms | m:ss (a clock: 07:37, 1:02:05)

    [Ta]                       # the measured bean probe
    column = "BT"
    unit = "C"                 # C | F | K

    [Tgi]                      # inlet gas temperature: a column, or an Artisan ET / extra channel
    column = "ET"
    unit = "C"
    offset_C = 0.0

    [Tgi]                      # or a constant, e.g. room air drawn into an induction drum
    constant_C = 22.0          # where a log records no room temperature
    room = true                # the room temperature the log records (Artisan ambientTemp,
    room_unit = "F"            # RoasTime ambient); a bare number's unit (default C)

    [Gg]                       # exactly one of: column, constant_kg_s, identify, [Gg.pitot]
    column = "flow"
    unit = "kg/h"              # kg/s | kg/h | g/s | m3/h (with density_kg_m3)
    density_kg_m3 = 1.2
    # constant_kg_s = 0.02
    # identify = true          # Gg unknown: write 1 kg/s and free Gg_kg_s in the fit spec
    # [Gg.pitot]               # eq. 16
    # dp_column = "dp_Pa"; T_column = "T_pitot_C"; section_m2 = 0.03; rho0_kg_m3 = 1.275

    # --- the actuator extension (optional; the paper's model uses none of these) ---
    batch_kg = 0.5             # green weight of a log that records none, nor in its file name [kg]
    [heater]                   # a logged heater/burner setting, held between changes
    column = "Burner"          # Artisan event type, RoasTime "heater" (P1-P9), or a CSV column;
                               # ["Burner", "Power"]: logs that name it differently, the first a log has
    unit = "percent"           # percent | level | tens (levels shown x10) | kW | W | rpm | a gas
                               # pressure (kPa, hPa, mbar, Pa, psi, inWC, mmWC) | reading (no unit named)
    [fan]                      # a logged fan/air setting
    column = "Air"             # Artisan event type, RoasTime "fan" (F0-F12), or a CSV column
    unit = "percent"
    [Tb2]                      # a second bean reading compared with the model's Tb
    column = "drumTemperature" # e.g. the Bullet's infrared channel
    # first_crack = true       # ... or, with no bean channel: the log's FCs mark read as the beans
                               # at FIRST_CRACK_BEAN_C (one sample per log that marks first crack)
    [ET]                       # the roaster's ET, drawn beside the model (default: an Artisan
    column = "ET"              # log's ET channel); never an input
    above_BT = true            # drop it on a log where it reads below BT through the roast
    [initial]                  # initial states from the log: a scalar field or a channel at CHARGE
                               # (a CSV or Parquet log: one of the map's temperature columns, first row),
    Tm0_C = "preheatTemperature"  # or a list tried in order: ["ET", "BT"]
    Tb0_C = "Tgi"              # "Tgi": the inlet gas at CHARGE (with room = true, the room's)

The fit spec decides what the settings drive: free ``Qe_gain_kW`` (heater -> heat into the
drum metal), ``Tgi_gain_C`` (heater -> inlet gas), ``tau_heater_s`` (its lag) and
``Gg_fan_kg_s`` (fan -> flow, affine with ``Gg_kg_s``).

Artisan channel names are ``BT``, ``ET``, the extra devices' names and the special-event
types (``Burner``, ``Air``, ...); RoasTime's are ``beanTemperature`` (also ``BT``),
``drumTemperature``, ``exitTemperature``, ``heater``, ``fan``, ``drum``. Every error names the
map or log file and the key.
"""

from __future__ import annotations

import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import InputError, ParameterError
from ...metrics.profile import (
    ET_CHECK_FROM_S,
    delta_text,
    display_temp,
    display_temp_delta,
    et_minus_bt_C,
    first_crack_s,
    temp_symbol,
)
from ...model.actuators import UNIT_DEFAULTS, Actuator
from ...model.constants import FIRST_CRACK_BEAN_C
from ...model.limits import check_value
from ...model.pitot import gas_flow_pitot_kg_s
from ...model.quantities import default
from ..batch import REQUIRED_COLUMNS, Batch, csv_log_text, read_table
from ..files import as_path, finite_number, read_input_bytes, read_toml
from .artisan import ArtisanLog, f_to_c, read_alog, read_artisan_csv, time_follows
from .roastime import DRUM_AT_CHARGE, read_roastime

FORMATS = ("auto", "alog", "artisan-csv", "roastime", "csv", "parquet")
#: Units a logged setting may be given in, and the plausible range of each (the actuator table's).
SETTING_UNITS = {unit: (lo, hi) for unit, (lo, hi, _, _) in UNIT_DEFAULTS.items()}
#: Initial states a map may take from the log.
INITIAL_FROM_LOG = ("Tm0_C", "Tb0_C", "X0")
#: A time column's units [s per unit]; "m:ss" is a clock (``7:37``, ``1:02:05``) read as seconds.
TIME_UNITS = {"s": 1.0, "min": 60.0, "ms": 1e-3, "m:ss": 1.0}
TEMP_UNITS = ("C", "F", "K")
FLOW_UNITS = {"kg/s": 1.0, "kg/h": 1.0 / 3600.0, "g/s": 1e-3, "m3/h": None}
DROP_BT_LIMIT_C = 300.0
#: A second, infrared bean reading counts from this long after CHARGE [s]: while the beans fall in
#: it still reads the hot drum (``bullet_2020-11-05_1536_500g``: 195, 183, 171 degC over the first
#: 2 s, then the beans).
SECOND_BEAN_START_S = 10.0


def probe_fault(bt_C: np.ndarray) -> int | None:
    """The last sample before the bean probe's first step larger than :data:`MAX_JUMP_C` between
    two samples (a sensor fault), or None when it makes none. Spikes (:func:`probe_spikes`) are
    dropped first: this is a step that does not come back."""
    jumps = np.flatnonzero(np.abs(np.diff(bt_C)) > MAX_JUMP_C)
    return int(jumps[0]) if jumps.size else None


def probe_spikes(time_s: np.ndarray, bt_C: np.ndarray) -> np.ndarray:
    """Which samples are the bean probe's spikes: after a step larger than :data:`MAX_JUMP_C` between
    two samples, the samples until the probe reads within half the step of the reading before it
    again, where that happens within :data:`SPIKE_MAX_S` (a thermocouple's pick-up of a motor or a
    loose contact; Artisan's own spike filter drops them as it records). A step that does not come
    back so soon is a fault (:func:`probe_fault`), not a spike. A boolean mask over the samples."""
    spikes = np.zeros(len(bt_C), dtype=bool)
    start = 0
    while (jumps := np.flatnonzero(np.abs(np.diff(bt_C[start:])) > MAX_JUMP_C)).size:
        k = start + int(jumps[0])  # the last sample before the step
        after = slice(k + 1, None)
        step = abs(bt_C[k + 1] - bt_C[k])
        back = np.flatnonzero((time_s[after] - time_s[k] <= SPIKE_MAX_S) & (np.abs(bt_C[after] - bt_C[k]) < 0.5 * step))
        if not back.size:
            break
        start = k + 1 + int(back[0])
        spikes[k + 1 : start] = True
    return spikes


def probe_faults(time_s: np.ndarray, bt_C: np.ndarray) -> tuple[np.ndarray, int | None]:
    """The bean probe's spikes (:func:`probe_spikes`, a mask) and, in its readings without them, the
    last sample before a fault (:func:`probe_fault`): the import and ``roastlab init`` read a probe so."""
    spikes = probe_spikes(time_s, bt_C)
    return spikes, probe_fault(bt_C[~spikes])


def hot_drop(bt_at_drop_C: float) -> str | None:
    """Why a bean temperature at DROP above :data:`DROP_BT_LIMIT_C` is not a roast in degC (a log in
    degF declared as degC), else None."""
    if not bt_at_drop_C > DROP_BT_LIMIT_C:
        return None
    return f"bean temperature {bt_at_drop_C:.0f} degC at DROP is above {DROP_BT_LIMIT_C:.0f}: °F data declared as °C?"


#: Smallest resampling step [s] and most samples a log may have after resampling.
MIN_RESAMPLE_S = 0.1
MAX_SAMPLES = 1_000_000
#: A bean probe cannot move this much between two samples: a larger step is a sensor fault.
MAX_JUMP_C = 40.0
#: A step of the bean probe undone within this long is a spike, dropped, not a fault that ends the log [s].
SPIKE_MAX_S = 10.0


@dataclass
class ColumnMap:
    """A parsed column map (see module docstring)."""

    source: str
    format: str = "auto"
    keep_after_drop: bool = False
    resample_s: float = 0.0
    time: dict = field(default_factory=lambda: {"column": "time_s", "unit": "s"})
    Ta: dict = field(default_factory=lambda: {"column": "Ta_C", "unit": "C"})
    Tgi: dict = field(default_factory=lambda: {"column": "Tgi_C", "unit": "C"})
    Gg: dict = field(default_factory=lambda: {"column": "Gg_kg_s", "unit": "kg/s"})
    heater: dict | None = None
    fan: dict | None = None
    Tb2: dict | None = None
    ET: dict | None = None
    initial: dict = field(default_factory=dict)
    batch_kg: float | None = None

    def to_mapping(self) -> dict:
        """The map as the TOML-shaped mapping :func:`map_from_mapping` reads (for model files)."""

        def clean(d: dict) -> dict:
            return {k: (clean(v) if isinstance(v, dict) else v) for k, v in d.items() if v is not None}

        return clean(
            {
                "format": self.format,
                "keep_after_drop": self.keep_after_drop,
                "resample_s": self.resample_s,
                "time": self.time,
                "Ta": self.Ta,
                "Tgi": self.Tgi,
                "Gg": self.Gg,
                "heater": self.heater,
                "fan": self.fan,
                "Tb2": self.Tb2,
                "ET": self.ET,
                "initial": self.initial or None,
                "batch_kg": self.batch_kg,
            }
        )

    @property
    def uses_actuators(self) -> bool:
        """True if the map reads heater or fan settings (the actuator extension)."""
        return self.heater is not None or self.fan is not None

    def actuator(self, name: str) -> Actuator | None:
        """The ``heater`` or ``fan`` control this map declares (levels, step, rate), or None."""
        spec = getattr(self, name)
        return None if spec is None else Actuator.from_spec(name, spec)

    def setting_units(self) -> dict[str, str]:
        """The unit of each logged setting this map reads ({"heater": "level", ...})."""
        return {k: getattr(self, k)["unit"] for k in ("heater", "fan") if getattr(self, k)}

    @property
    def inlet_is_constant(self) -> bool:
        """True if the inlet gas is a constant (room air drawn into an induction or electric drum)."""
        return "constant_C" in self.Tgi

    @property
    def et_is_bean_reading(self) -> bool:
        """True if the map reads the log's ET as its second bean reading (``[Tb2] column = "ET"``: an
        infrared bean sensor logged as ET, as ``roastlab init`` maps it), so ET is no drum air."""
        return (self.Tb2 or {}).get("column") == "ET"

    @property
    def first_crack_as_beans(self) -> bool:
        """True if the map reads each log's first-crack mark as its one bean reading (``[Tb2]
        first_crack = true``: the model's Tb at the FCs mark against
        :data:`~roastlab.model.constants.FIRST_CRACK_BEAN_C`), for logs with no bean channel."""
        return bool((self.Tb2 or {}).get("first_crack"))

    @property
    def identifies_flow(self) -> bool:
        """True if the map writes a 1 kg/s placeholder flow for the fit to scale (``[Gg] identify``)."""
        return bool(self.Gg.get("identify"))


#: The import note of a log whose ET a map's ``[ET] above_BT`` dropped (a fit that weighs ET looks for it).
ET_NOT_DRUM_AIR = "not the drum's air on this log"

#: Keys each map table may hold; anything else is a typo worth reporting.
TABLE_KEYS = {
    "time": {"column", "unit"},
    "Ta": {"column", "unit", "offset_C"},
    "Tgi": {"column", "unit", "offset_C", "constant_C", "room", "room_unit"},
    "heater": {"column", "unit", "min", "max", "step", "rate_per_min"},
    "fan": {"column", "unit", "min", "max", "step", "rate_per_min"},
    "Tb2": {"column", "unit", "offset_C", "start_s", "first_crack"},
    "ET": {"column", "unit", "offset_C", "above_BT"},
    "initial": set(INITIAL_FROM_LOG),
    "Gg": {"column", "unit", "density_kg_m3", "constant_kg_s", "identify", "pitot"},
    "pitot": {"dp_column", "T_column", "section_m2", "rho0_kg_m3", "T_unit"},
}


def _table(data: dict, key: str, src) -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise InputError(f"[{key}] must be a table", src, f"key {key}")
    unknown = sorted(set(value) - TABLE_KEYS.get(key, set(value)))
    if unknown:
        allowed = ", ".join(sorted(TABLE_KEYS[key]))
        raise InputError(f"unknown key(s) {', '.join(unknown)} (allowed: {allowed})", src, f"[{key}]")
    return value


def _names(table: dict, key: str, src, where: str) -> str | list[str]:
    """One field or channel name, or a list of them tried in order (an ``[initial]`` entry; a
    ``[heater]`` or ``[fan]`` column whose name differs between a roaster's logs)."""
    v = table.get(key)
    if isinstance(v, list):
        if not v or not all(isinstance(x, str) and x for x in v) or len(set(v)) < len(v):
            raise InputError(f"must be a name or a list of names, each once, got {v!r}", src, f"{where}.{key}")
        return list(v)
    return _check_str(table, key, src, where)


def names_of(column: str | list[str]) -> list[str]:
    """A map entry's names, tried in order: ``"Burner"`` or ``["Burner", "Power"]``."""
    return [column] if isinstance(column, str) else list(column)


def _check_str(table: dict, key: str, src, where: str, required: bool = True, choices=None):
    v = table.get(key)
    if v is None:
        if required:
            raise InputError("missing key", src, f"{where}.{key}")
        return None
    if not isinstance(v, str) or not v:
        raise InputError(f"must be a non-empty string, got {v!r}", src, f"{where}.{key}")
    if choices is not None and v not in choices:
        raise InputError(f"must be one of {', '.join(choices)}, got {v!r}", src, f"{where}.{key}")
    return v


def _check_num(table: dict, key: str, src, where: str, positive=False, default=None):
    v = table.get(key, default)
    if v is None:
        return None
    x = finite_number(v, src, f"{where}.{key}")
    if positive and not x > 0:
        raise InputError(f"must be > 0, got {v!r}", src, f"{where}.{key}")
    return x


def load_map(path: str | Path) -> ColumnMap:
    """Read and check a column-map TOML file."""
    return map_from_mapping(read_toml(path), path)


def map_from_mapping(data: dict, path: str | Path) -> ColumnMap:
    """Check a parsed map (a TOML file, or the copy a model file keeps) and build a ColumnMap."""
    if not isinstance(data, dict):
        raise InputError("a column map must be a table", path)
    known = {"format", "keep_after_drop", "resample_s", "time", "Ta", "Tgi", "Gg", "name", "description", "notes"}
    known |= {"heater", "fan", "Tb2", "ET", "initial", "batch_kg"}
    unknown = sorted(set(data) - known)
    if unknown:
        raise InputError(f"unknown key(s) {', '.join(unknown)} (allowed: {', '.join(sorted(known))})", path)
    m = ColumnMap(source=str(path))
    m.format = _check_str(data, "format", path, "map", required=False, choices=FORMATS) or "auto"
    kad = data.get("keep_after_drop", False)
    if not isinstance(kad, bool):
        raise InputError(f"must be true or false, got {kad!r}", path, "keep_after_drop")
    m.keep_after_drop = kad
    m.resample_s = _check_num(data, "resample_s", path, "map", default=0.0) or 0.0
    if m.resample_s != 0 and not MIN_RESAMPLE_S <= m.resample_s <= 600:
        raise InputError(f"must be 0 (off) or {MIN_RESAMPLE_S:g}..600 s, got {m.resample_s:g}", path, "resample_s")
    if "time" in data:
        t = _table(data, "time", path)
        m.time = {
            "column": _check_str(t, "column", path, "time", required=False) or "time_s",
            "unit": _check_str(t, "unit", path, "time", required=False, choices=tuple(TIME_UNITS)) or "s",
        }
    for key in ("Ta", "Tgi", "Tb2", "ET"):
        if key in data:
            t = _table(data, key, path)
            if key == "Tgi" and "constant_C" in t:
                if "column" in t:
                    raise InputError("give column or constant_C, not both", path, "Tgi")
                m.Tgi = {"constant_C": check_value("Tgi_C", _check_num(t, "constant_C", path, key), str(path))}
                room = t.get("room", False)
                if not isinstance(room, bool):
                    raise InputError(f"must be true or false, got {room!r}", path, "Tgi.room")
                if room:
                    m.Tgi["room"] = True
                    m.Tgi["room_unit"] = (
                        _check_str(t, "room_unit", path, key, required=False, choices=("C", "F")) or "C"
                    )
                elif "room_unit" in t:
                    raise InputError("room_unit needs room = true", path, "Tgi")
                continue
            if key == "Tb2" and "first_crack" in t:
                if t["first_crack"] is not True:
                    raise InputError(
                        f"must be true (or leave it out), got {t['first_crack']!r}", path, "Tb2.first_crack"
                    )
                if set(t) != {"first_crack"}:
                    raise InputError(
                        "first_crack reads the log's FCs mark as the beans' temperature: give it alone, not with "
                        f"{', '.join(sorted(set(t) - {'first_crack'}))}",
                        path,
                        "Tb2",
                    )
                m.Tb2 = {"first_crack": True}
                continue
            if "room" in t or "room_unit" in t:
                raise InputError(
                    "room = true needs constant_C (the inlet air where a log records no room)", path, "Tgi"
                )
            m_t = {
                "column": _check_str(t, "column", path, key),
                "unit": _check_str(t, "unit", path, key, required=False, choices=TEMP_UNITS) or "C",
                "offset_C": _check_num(t, "offset_C", path, key, default=0.0),
            }
            setattr(m, key, m_t)
    if m.ET is not None and "above_BT" in data["ET"]:
        flag = data["ET"]["above_BT"]
        if not isinstance(flag, bool):
            raise InputError(f"must be true or false, got {flag!r}", path, "ET.above_BT")
        m.ET["above_BT"] = flag
    if m.Tb2 is not None and not m.first_crack_as_beans:
        start = _check_num(data["Tb2"], "start_s", path, "Tb2", default=0.0)
        if not 0 <= start <= 3600:
            raise InputError(f"must be 0..3600 s, got {start:g}", path, "Tb2.start_s")
        m.Tb2["start_s"] = start
    for key in ("heater", "fan"):
        if key in data:
            t = _table(data, key, path)
            spec = {
                "column": _names(t, "column", path, key),
                "unit": _check_str(t, "unit", path, key, required=False, choices=tuple(SETTING_UNITS)) or "percent",
            }
            spec.update(_actuator_levels(t, spec["unit"], path, key))
            setattr(m, key, spec)
    if "initial" in data:
        t = _table(data, "initial", path)
        m.initial = {k: _names(t, k, path, "initial") for k in t}
    if "batch_kg" in data:
        m.batch_kg = check_value("batch_kg", _check_num(data, "batch_kg", path, "map"), str(path))
    if "Gg" in data:
        g = _table(data, "Gg", path)
        ways = [k for k in ("column", "constant_kg_s", "identify", "pitot") if k in g]
        if len(ways) != 1:
            raise InputError(
                f"[Gg] needs exactly one of column, constant_kg_s, identify, [Gg.pitot]; got {', '.join(ways) or 'none'}",
                path,
                "Gg",
            )
        way = ways[0]
        if way == "column":
            unit = _check_str(g, "unit", path, "Gg", required=False, choices=tuple(FLOW_UNITS)) or "kg/s"
            dens = _check_num(g, "density_kg_m3", path, "Gg", positive=True)
            if unit == "m3/h" and dens is None:
                raise InputError("unit m3/h needs density_kg_m3", path, "Gg.density_kg_m3")
            m.Gg = {"column": _check_str(g, "column", path, "Gg"), "unit": unit, "density_kg_m3": dens}
        elif way == "constant_kg_s":
            m.Gg = {"constant_kg_s": _check_num(g, "constant_kg_s", path, "Gg", positive=True)}
        elif way == "identify":
            if g["identify"] is not True:
                raise InputError("identify must be true (or leave it out)", path, "Gg.identify")
            m.Gg = {"identify": True}
        else:
            p = _table(g, "pitot", path)
            m.Gg = {
                "pitot": {
                    "dp_column": _check_str(p, "dp_column", path, "Gg.pitot"),
                    "T_column": _check_str(p, "T_column", path, "Gg.pitot"),
                    "section_m2": _check_num(p, "section_m2", path, "Gg.pitot", positive=True)
                    or _missing(path, "Gg.pitot.section_m2"),
                    "rho0_kg_m3": _check_num(p, "rho0_kg_m3", path, "Gg.pitot", positive=True, default=1.275),
                    "T_unit": _check_str(p, "T_unit", path, "Gg.pitot", required=False, choices=TEMP_UNITS) or "C",
                }
            }
    return m


def _actuator_levels(table: dict, unit: str, path, key: str) -> dict:
    """The optional ``min``, ``max``, ``step``, ``rate_per_min`` of a ``[heater]``/``[fan]`` table,
    checked against the unit's plausible range (:data:`SETTING_UNITS`)."""
    lo_u, hi_u = SETTING_UNITS[unit]
    out = {}
    for name in ("min", "max", "step", "rate_per_min"):
        v = _check_num(table, name, path, key)
        if v is not None:
            out[name] = v
    lo, hi = out.get("min", lo_u), out.get("max", hi_u)
    if not lo_u <= lo < hi <= hi_u:
        raise InputError(
            f"min {lo:g} and max {hi:g} must satisfy {lo_u:g} <= min < max <= {hi_u:g} for unit {unit!r}", path, key
        )
    if "step" in out and not 0 < out["step"] <= hi - lo:
        raise InputError(
            f"step must be > 0 and at most max - min ({hi - lo:g}), got {out['step']:g}", path, f"{key}.step"
        )
    if "rate_per_min" in out and not out["rate_per_min"] > 0:
        raise InputError(f"rate_per_min must be > 0, got {out['rate_per_min']:g}", path, f"{key}.rate_per_min")
    return out


def _missing(path, key):
    raise InputError("missing key", path, key)


def to_celsius(values: np.ndarray, unit: str) -> np.ndarray:
    """A column in ``unit`` ("C", "F" or "K") in degC."""
    if unit == "F":
        from ...metrics.profile import celsius_of

        return celsius_of(values, "F")
    if unit == "K":
        return values - 273.15
    return values


#: A green weight written in a log's file name: "..._230g.alog", "kenya 250 g.csv".
_GRAMS = re.compile(r"(?<![0-9])(\d{2,5})\s?g(?![a-z])", re.I)


def grams_in_name(path: Path) -> tuple[float, str] | None:
    """The green batch [kg] a log's file name states, with the text it was read from, or None."""
    m = _GRAMS.search(Path(path).stem)
    return (int(m.group(1)) / 1000.0, m.group(0)) if m else None


#: The suffixes of a text table: a plain CSV log, Artisan's CSV export, or a batch CSV (by content).
CSV_SUFFIXES = (".csv", ".txt", ".tsv")


#: What a log of unknown format is told: the formats read, and the way in for another program's logs
#: (Artisan imports Cropster, IKAWA, Giesen, Loring, RoastPATH and more, and saves them as .alog).
READS = (
    "roastlab reads Artisan (.alog, its CSV export), RoasTime (.json) and CSV logs (a map's format key names one "
    "for another suffix); another program's log (Cropster .xlsx, IKAWA, Loring, ...) opens in Artisan (File > "
    "Import) and saves there as .alog"
)


def detect_format(path: Path, fmt: str = "auto") -> str:
    """The log format of ``path``: ``fmt`` unless "auto", else by suffix and content (a file without a
    suffix, as RoasTime keeps its logs, by its content alone: a JSON object with RoasTime's series, or
    a Python-literal dict with Artisan's ``'timex'``)."""
    if fmt != "auto":
        return fmt
    suffix = path.suffix.lower()
    if suffix == ".alog":
        return "alog"
    if suffix == ".json":
        head = read_input_bytes(path)[:65536]
        if b"beanTemperature" in head or b"actionTimeList" in head:
            return "roastime"
    if suffix in (".parquet", ".pq"):
        return "parquet"
    if suffix in CSV_SUFFIXES:
        first = read_input_bytes(path)[:4096].split(b"\n", 1)[0]  # through the guard: never a FIFO
        return "artisan-csv" if b"Unit:" in first else "csv"
    if suffix == "":  # RoasTime keeps its logs without a suffix; an Artisan log can lose its own
        head = read_input_bytes(path)[:65536]
        if head.lstrip().startswith(b"{"):
            if b'"beanTemperature"' in head or b'"actionTimeList"' in head:
                return "roastime"
            if b"'timex'" in head:
                return "alog"
        raise InputError(f"no suffix, and the content is neither a RoasTime nor an Artisan log: {READS}", path)
    raise InputError(f"cannot tell the log format from suffix {suffix!r}: {READS}", path)


def is_log_by_content(path: Path) -> bool:
    """Whether a file is a roast log by its content alone (:func:`detect_format`): how a file without
    a suffix, as RoasTime keeps its roasts, is told from a LICENSE or a Makefile beside it."""
    try:
        detect_format(path)
    except InputError:
        return False
    return True


#: Most rows a Parquet log may declare; checked from its footer before any column is decoded,
#: so a small file that would decompress to gigabytes is refused first.
MAX_PARQUET_ROWS = 2_000_000
#: Most bytes the columns a map reads may decode to, by the footer's uncompressed page sizes
#: (2 million rows of eight 8-byte columns, with room for page headers).
MAX_PARQUET_DECODED_BYTES = 160 * 1024 * 1024


def _parquet_plain_number(kind) -> bool:
    """Whether an Arrow type decodes to one fixed-width number per row (what a log column is)."""
    import pyarrow.types as pat

    return pat.is_integer(kind) or pat.is_floating(kind) or pat.is_boolean(kind) or pat.is_decimal(kind)


def _read_parquet(path: Path, columns: list[str]) -> dict[str, np.ndarray]:
    """The ``columns`` of a Parquet log as float arrays; refused from the footer alone (before any
    page is decoded) when it declares too many rows, a wanted column is not a plain number
    (lists, structs, strings, dictionaries) or the wanted columns would decode too large."""
    raw = read_input_bytes(path)  # the bytes come through the guard, never from the name
    try:
        import pyarrow.parquet as pq

        pfile = pq.ParquetFile(io.BytesIO(raw))
        meta = pfile.metadata
        if meta.num_rows > MAX_PARQUET_ROWS:
            raise InputError(f"declares {meta.num_rows} rows, over the limit of {MAX_PARQUET_ROWS}", path)
        schema = pfile.schema_arrow
        all_names = list(schema.names)
        twice = sorted({c for c in all_names if all_names.count(c) > 1 and c in columns})
        if twice:
            raise InputError(f"column(s) {', '.join(twice)} appear more than once: which one is meant?", path)
        missing = [c for c in columns if c not in all_names]
        if missing:
            shown = ", ".join(map(str, all_names[:20])) + (", ..." if len(all_names) > 20 else "")
            raise InputError(f"missing column {missing[0]!r} (columns: {shown})", path)
        for c in columns:
            kind = schema.field(c).type
            if not _parquet_plain_number(kind):
                raise InputError(f"holds {str(kind)[:60]} values, not one number per row", path, f"column {c}")
        wanted = set(columns)
        decoded = sum(
            rg.column(j).total_uncompressed_size
            for rg in (meta.row_group(i) for i in range(meta.num_row_groups))
            for j in range(rg.num_columns)
            if rg.column(j).path_in_schema.split(".")[0] in wanted
        )
        if decoded > MAX_PARQUET_DECODED_BYTES:
            raise InputError(
                f"its columns {', '.join(columns)} would decode to {decoded / 2**20:.0f} MiB, over the limit of "
                f"{MAX_PARQUET_DECODED_BYTES / 2**20:.0f} MiB",
                path,
            )
        table = pfile.read(columns=list(dict.fromkeys(columns)))
    except InputError:
        raise
    except ImportError:
        raise InputError("reading Parquet needs pyarrow (pip install 'roastlab[parquet]')", path) from None
    except Exception as exc:  # pyarrow raises many types for a bad file
        raise InputError(f"not a readable Parquet file ({type(exc).__name__})", path) from None
    out = {}
    for c in columns:
        try:
            out[c] = table.column(c).to_numpy(zero_copy_only=False).astype(float)
        except (TypeError, ValueError, ArithmeticError):
            raise InputError("not numeric", path, f"column {c}") from None
    return out


def _resample(time_s: np.ndarray, columns: dict[str, np.ndarray], step: float, path):
    if (time_s[-1] - time_s[0]) / step > MAX_SAMPLES:
        raise InputError(
            f"resampling {time_s[-1] - time_s[0]:.0f} s every {step:g} s gives over {MAX_SAMPLES} samples", path
        )
    grid = np.arange(time_s[0], time_s[-1] + 1e-9, step)
    return grid, {k: np.interp(grid, time_s, v) for k, v in columns.items()}


def _drop_et_not_drum_air(
    time_s, Ta, drop_s, settings: dict, series: dict, notes: list, units: str = "C", inlet=None, path=None
) -> set:
    """Where the map asks (``[ET] above_BT``) and ET reads below BT through the roast, ET is not the
    drum's air on this log (:func:`roastlab.metrics.profile.et_minus_bt_C`): it is removed from
    ``settings`` and ``series`` with a note (its gap in ``units``, the log's "C" or "F"); returns the
    channels so rejected (no initial state is read from them).

    ``inlet``: the channel the model's inlet air was read from on this log (a map with no heater takes
    ET as the inlet), else None. Where that is the rejected ET, nothing the log records drives the
    model as the roaster's heat did: an :class:`InputError` naming ``path`` (a fit leaves such a log
    out), not a prediction driven by a sensor that was elsewhere."""
    spec = settings.get("ET")
    if spec is None or not spec.get("above_BT"):
        return set()
    gap = et_minus_bt_C(time_s, series["ET"], Ta, drop_s)
    if gap is None or gap >= 0:
        return set()
    reads = f"ET reads {delta_text(-gap, units, 0)} below BT through the roast (median from {ET_CHECK_FROM_S:g} s)"
    if inlet is not None and inlet in names_of(spec["column"]):
        raise InputError(
            f"{reads}: {ET_NOT_DRUM_AIR}, and the map drives the model with it as the inlet air ([Tgi] column "
            f"{inlet!r}, no heater logged): nothing else in the log can drive the model",
            path,
        )
    notes.append(f"{reads}: {ET_NOT_DRUM_AIR}, so it is neither fitted nor scored")
    del settings["ET"], series["ET"]
    return {spec["column"]}


#: How far below zero a control's readout may read, as a share of its highest reading, and still be
#: a sensor's offset about its zero rather than a wrong unit (:func:`readout_zero_offset`).
ZERO_OFFSET_SHARE = 0.05


def readout_zero_offset(unit: str, values: np.ndarray) -> bool:
    """True where a control logged by a readout in a continuous unit (W, rpm, a gas pressure: no step
    in :data:`roastlab.model.actuators.UNIT_DEFAULTS`) dips below 0 by no more than
    :data:`ZERO_OFFSET_SHARE` of its highest reading: a pressure gauge or a power meter at rest reads
    a little either side of its zero (-0.02 kPa with the burner off), which is off, not a wrong unit.
    A stepped setting (percent, level) below 0 stays a wrong unit."""
    if UNIT_DEFAULTS[unit][2] is not None or not values.size or values.min() >= 0.0:
        return False
    return bool(values.max() > 0.0 and -values.min() <= ZERO_OFFSET_SHARE * values.max())


def roastime_default_map(log: ArtisanLog) -> ColumnMap:
    """The map the parsed RoasTime ``log`` is read with when none is given: the channels a Bullet logs.

    The bean probe is Ta; the heat comes from the heater's levels into room air drawn through the
    drum (the quantity table's room temperature, ``T_room_C``); the fan's levels move the air; the
    infrared channel is a second bean reading from :data:`SECOND_BEAN_START_S`; the drum at charge
    is the preheat (:data:`~roastlab.io.importers.roastime.DRUM_AT_CHARGE`). Only what the log holds
    is mapped (a log with no fan change, no IR channel or no drum reading at charge is read without
    them). ``roastlab init`` writes the same map with the settings' ranges its logs use.
    """
    has = log.channels.__contains__
    at_charge = [f for f in DRUM_AT_CHARGE if f in log.fields]
    return map_from_mapping(
        {
            "format": "roastime",
            "Ta": {"column": "BT"},
            "Tgi": {"constant_C": default("T_room_C")},
            "Gg": {"identify": True},
            **{k: {"column": k, "unit": "level"} for k in ("heater", "fan") if has(k)},
            **(
                {"Tb2": {"column": "drumTemperature", "start_s": SECOND_BEAN_START_S}} if has("drumTemperature") else {}
            ),
            **({"initial": {"Tm0_C": at_charge}} if at_charge else {}),
        },
        "default RoasTime map",
    )


#: The roasting programs whose own log formats a map reads, by format (how a mismatch is named).
LOG_SOFTWARE = {"alog": "Artisan", "artisan-csv": "Artisan", "roastime": "RoasTime"}
#: Artisan's two files of a roast: its profile (``.alog``) and its CSV export. Their channels carry the same
#: names (BT, ET, the extra devices'), so a column map written for one reads the other (:func:`log_format`).
ARTISAN_FORMATS = tuple(fmt for fmt, program in LOG_SOFTWARE.items() if program == "Artisan")


def log_format(path: Path, map_format: str) -> str:
    """The format ``path`` is read in under a map of ``map_format`` (:func:`detect_format`): the map's,
    but where the map's is one of :data:`ARTISAN_FORMATS` and the file is the other (by its suffix and
    first line), the file's own. A log of another program than the map's (a RoasTime log under a map of
    Artisan logs, or the other way round) is refused in one line naming both, not read as the map's
    format (which failed on a key the other program does not write)."""
    fmt = detect_format(path, map_format)
    if fmt not in LOG_SOFTWARE or not path.is_file():
        return fmt
    try:
        own = detect_format(path, "auto")
    except InputError:  # the content names no program: read as the map says, whose reader says what is wrong
        return fmt
    if own not in LOG_SOFTWARE:  # a plain CSV under an Artisan map: the map's reader says what is wrong
        return fmt
    if LOG_SOFTWARE[own] != LOG_SOFTWARE[fmt]:
        article = "an" if LOG_SOFTWARE[own][0] in "AEIOU" else "a"
        raise InputError(
            f"{article} {LOG_SOFTWARE[own]} log, and the column map reads {LOG_SOFTWARE[fmt]} logs: a log of another "
            "roaster than the map's (or the model's), or give a map for it (--map MAP.toml)",
            path,
        )
    return own  # the same program: the file's own format (an Artisan export under a map of .alog files)


def reads_as_log(path: str | Path, cmap: ColumnMap | None) -> bool:
    """Whether ``path`` is a roast log that the column map ``cmap`` reads, rather than a batch CSV (the
    canonical columns): a file by its suffix (.alog, RoasTime's .json, Parquet); a text table
    (:data:`CSV_SUFFIXES`) where the map reads plain CSV logs and its header is not a batch CSV's
    (:data:`~roastlab.io.batch.REQUIRED_COLUMNS`), or the map is an Artisan map and the file Artisan's
    CSV export (:func:`log_format`)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in (".alog", ".json", ".parquet", ".pq"):
        return True
    if suffix not in CSV_SUFFIXES or cmap is None:
        return False
    if not path.is_file():
        return cmap.format in ("artisan-csv", "csv")  # the reader then says the file is missing
    if cmap.format == "csv":  # a plain CSV log, unless its header is a batch CSV's
        first = read_input_bytes(path)[:4096].split(b"\n", 1)[0].decode("utf-8", "replace")
        return not set(REQUIRED_COLUMNS) <= {c.strip().strip('"') for c in re.split(r"[,;\t]", first)}
    return cmap.format in ARTISAN_FORMATS and detect_format(path, "auto") == "artisan-csv"


def _named_input(k: str, cmap, settings: dict) -> str:
    """An input of the map as a message names it: ``k`` and, where the map names one, its column."""
    spec = settings.get(k) or getattr(cmap, k, None) or {}
    column = spec.get("column") if isinstance(spec, dict) else None
    return f"{k} (column {column})" if isinstance(column, str) else k


def import_log(path: str | Path, cmap: ColumnMap | None, name: str | None = None) -> Batch:
    """Read any supported log with a column map into a validated canonical :class:`Batch`."""
    path = as_path(path, "path")
    default_notes = []
    preread = None  # a log read to choose its default map, read once
    if cmap is None:
        cmap = ColumnMap(source="default map")
        if path.exists() and detect_format(path, "auto") in ("alog", "artisan-csv"):
            # Artisan's own channel names: BT the bean probe, ET the environment (taken as the inlet)
            cmap = ColumnMap(
                source="default Artisan map",
                Ta={"column": "BT", "unit": "C"},
                Tgi={"column": "ET", "unit": "C"},
                Gg={"identify": True},
            )
            default_notes.append(
                "no map: read as Artisan's defaults, BT = bean probe (Ta), ET = inlet (Tgi), gas flow unknown "
                "(a 1 kg/s placeholder); give a column map for anything else (--map, or a fleet manifest's map column)"
            )
        elif path.exists() and detect_format(path, "auto") == "roastime":
            preread = read_roastime(path)
            cmap = roastime_default_map(preread)
            settings = " and ".join(k for k in ("heater", "fan") if getattr(cmap, k))
            read = [
                "BT = bean probe (Ta)",
                f"the {settings} levels over room air at {cmap.Tgi['constant_C']:g} degC (Tgi)"
                if settings
                else f"room air at {cmap.Tgi['constant_C']:g} degC (Tgi) and no heater (the log records none)",
                *(["the IR as a second bean reading"] if cmap.Tb2 else []),
                *([f"the drum at charge from {' else '.join(cmap.initial['Tm0_C'])}"] if cmap.initial else []),
                "gas flow unknown (a 1 kg/s placeholder)",
            ]
            default_notes.append(
                f"no map: read as a Bullet's defaults, {', '.join(read)}; `roastlab init LOGS --out DIR` writes a map "
                "fitted to your logs"
            )
    if not path.exists():
        raise InputError("file not found", path)
    fmt = log_format(path, cmap.format)
    gg = cmap.Gg
    Mb = None
    initial: dict = {}
    events: dict = {}
    unit = ""
    temp_unit = "F" if str(cmap.Ta.get("unit", "C")).upper() == "F" else "C"  # a CSV's: its map's
    started_epoch_s = None  # when the recording started (Artisan roastepoch, RoasTime dateTime)
    bean_channel = None if cmap.first_crack_as_beans else cmap.Tb2  # the mark is read after the log, below
    settings = {k: spec for k, spec in (("heater", cmap.heater), ("fan", cmap.fan), ("Tb2", bean_channel)) if spec}
    et_spec = cmap.ET
    if fmt in ("alog", "artisan-csv", "roastime"):
        if fmt == "alog":
            log = read_alog(path, keep_after_drop=cmap.keep_after_drop)
        elif fmt == "roastime":
            log = preread or read_roastime(path, keep_after_drop=cmap.keep_after_drop)
        else:
            log = read_artisan_csv(path, cmap.keep_after_drop)
        time_s = log.time_s
        available = log.channels
        default_notes.extend(log.notes)

        def missing(spec: dict) -> str | None:
            """Why the log has no channel the map's ``spec`` names, or None where it has one."""
            names = names_of(spec["column"])
            if any(n in available for n in names):
                return None
            return f"no channel {' or '.join(map(repr, names))} in the log (has: {', '.join(sorted(available))})"

        def channel(spec: dict, what: str) -> np.ndarray:
            why = missing(spec)
            if why is not None:
                raise InputError(f"{what}: {why}", path)
            # a control the logs name differently: the first this log has
            col = next(n for n in names_of(spec["column"]) if n in available)
            return np.array(available[col], dtype=float)  # log temperatures already in degC

        Ta = channel(cmap.Ta, "Ta") + (cmap.Ta.get("offset_C") or 0.0)
        Tgi = _constant_or(cmap.Tgi, len(time_s), lambda: channel(cmap.Tgi, "Tgi") + (cmap.Tgi.get("offset_C") or 0.0))
        inlet = None  # the channel the inlet air was read from, if one was
        if "constant_C" not in cmap.Tgi and "column" in cmap.Tgi:
            inlet = next(n for n in names_of(cmap.Tgi["column"]) if n in available)  # channel() found one
        if cmap.Tgi.get("room"):
            room_C, note = room_temperature_C(log.room, cmap.Tgi["room_unit"])
            if room_C is not None:
                Tgi = np.full(len(time_s), room_C)
                inlet = None
            if note:
                default_notes.append(note)
        extra = {}
        if "column" in gg:
            extra["Gg"] = channel(gg, "Gg")
        elif "pitot" in gg:
            extra["dp"] = channel({"column": gg["pitot"]["dp_column"]}, "Gg.pitot.dp_column")
            extra["Tp"] = channel({"column": gg["pitot"]["T_column"]}, "Gg.pitot.T_column")
        # a second reading (the beans' IR, the drum's air) that this log does not record is left out of
        # it with a note, as an ET that is not the drum's air is: the probe alone is fitted and scored
        for k, spec in (("Tb2", settings.get("Tb2")), ("ET", et_spec)):
            why = None if spec is None else missing(spec)
            if why is not None:
                default_notes.append(f"{k}: {why}, so it is neither fitted nor scored")
                settings.pop(k, None)
                if k == "ET":
                    et_spec = None
        series = {k: channel(spec, k) + (spec.get("offset_C") or 0.0) for k, spec in settings.items()}
        # Artisan's ET (temp1): drawn beside the model, never an input; unless the map reads it as the beans
        if (
            et_spec is None
            and cmap.ET is None
            and fmt != "roastime"
            and "ET" in available
            and not cmap.et_is_bean_reading
        ):
            et_spec = {"column": "ET"}
        rejected = set()  # channels that do not read what the map says (no initial state from them)
        if et_spec is not None:
            settings["ET"] = et_spec
            series["ET"] = channel(et_spec, "ET") + (et_spec.get("offset_C") or 0.0)
            rejected = _drop_et_not_drum_air(
                time_s, Ta, log.events.get("DROP"), settings, series, default_notes, log.mode, inlet, path
            )
            et_spec = settings.get("ET")
        Mb = log.weight_in_kg
        unit = log.unit
        temp_unit = log.mode  # Artisan's profile mode (RoasTime: degC)
        started_epoch_s = log.started_epoch_s
        drop_known = log.drop_index is not None
        events = dict(log.events)
        for state, sources in cmap.initial.items():
            for source in [sources] if isinstance(sources, str) else sources:
                if source in rejected:
                    continue
                if source == "Tgi":  # the inlet gas at CHARGE: the room's, read above, or the map's
                    initial[state] = float(Tgi[0])
                    break
                if source in log.fields:
                    initial[state] = float(log.fields[source])
                    break
                if source in available and np.isfinite(available[source][0]):
                    initial[state] = float(available[source][0])  # the channel's reading at CHARGE
                    break
            else:
                have = ", ".join(sorted((set(log.fields) | set(available)) - rejected))
                raise InputError(f"initial.{state}: no field or channel {sources!r} in the log (has: {have})", path)
    else:
        needed = [cmap.time["column"], cmap.Ta["column"]]
        needed += [cmap.Tgi["column"]] if "column" in cmap.Tgi else []
        if "column" in gg:
            needed.append(gg["column"])
        elif "pitot" in gg:
            needed += [gg["pitot"]["dp_column"], gg["pitot"]["T_column"]]
        if et_spec is not None:
            settings["ET"] = et_spec
        for k, spec in settings.items():
            if not isinstance(spec["column"], str):
                raise InputError(
                    f"[{k}] column: a list of names serves Artisan and RoasTime logs, whose controls a roaster may "
                    "rename; a CSV or Parquet map names its one column",
                    cmap.source,
                )
        needed += [spec["column"] for spec in settings.values()]
        needed = list(dict.fromkeys(needed))
        # an empty cell is a sample not taken: NaN here, its row dropped below with a note
        cols = (
            _read_parquet(path, needed)
            if fmt == "parquet"
            else read_table(
                path,
                tuple(needed),
                text=csv_log_text(path),
                sparse=tuple(needed),
                clock=(cmap.time["column"],) if cmap.time["unit"] == "m:ss" else (),
            )
        )
        time_s = cols[cmap.time["column"]] * TIME_UNITS[cmap.time["unit"]]
        Ta = to_celsius(cols[cmap.Ta["column"]], cmap.Ta["unit"]) + (cmap.Ta.get("offset_C") or 0.0)
        Tgi = _constant_or(
            cmap.Tgi,
            len(time_s),
            lambda: to_celsius(cols[cmap.Tgi["column"]], cmap.Tgi["unit"]) + (cmap.Tgi.get("offset_C") or 0.0),
        )
        extra = {}
        if "column" in gg:
            extra["Gg"] = cols[gg["column"]]
        elif "pitot" in gg:
            extra["dp"] = cols[gg["pitot"]["dp_column"]]
            extra["Tp"] = to_celsius(cols[gg["pitot"]["T_column"]], gg["pitot"]["T_unit"])
        series = {}
        for k, spec in settings.items():
            v = cols[spec["column"]]
            series[k] = (
                to_celsius(v, spec.get("unit", "C")) + (spec.get("offset_C") or 0.0) if k in ("Tb2", "ET") else v
            )
        drop_known = True
        inlet = cmap.Tgi["column"] if "constant_C" not in cmap.Tgi and "column" in cmap.Tgi else None
        rejected = _drop_et_not_drum_air(time_s, Ta, None, settings, series, default_notes, temp_unit, inlet, path)
        # the first row is the charge: an initial state from the log is one of the map's temperature
        # columns read there (in its unit), the first of a list that has a reading
        temps = {cmap.Ta["column"]: Ta}
        if "column" in cmap.Tgi:
            temps[cmap.Tgi["column"]] = Tgi
        for k in ("Tb2", "ET"):  # a reading the check above dropped on this log gives no state
            if (getattr(cmap, k) or {}).get("column"):  # (a first-crack mark is no channel)
                temps[getattr(cmap, k)["column"]] = series.get(k, np.full(len(time_s), np.nan))
        for state, sources in cmap.initial.items():
            names = [sources] if isinstance(sources, str) else sources
            unknown = [n for n in names if n not in temps]
            if unknown:
                raise InputError(
                    f"initial.{state}: {', '.join(map(repr, unknown))} is not one of this map's temperature "
                    f"columns ({', '.join(temps)}), which a CSV's initial states are read from",
                    cmap.source,
                )
            found = next((temps[n][0] for n in names if n not in rejected and np.isfinite(temps[n][0])), None)
            if found is None:
                raise InputError(f"initial.{state}: no reading of {', '.join(names)} in the first row", path)
            initial[state] = float(found)
    # the log's own weight, else its file name's, else the map's batch_kg (roastlab init reads them in this order)
    if Mb is None and (named := grams_in_name(path)):  # the log records none; its name does
        Mb = named[0]
        default_notes.append(f"green weight {named[0]:g} kg from the file name's '{named[1]}'")
    if Mb is None and cmap.batch_kg is not None:
        Mb = cmap.batch_kg
    if Mb is None and fmt == "roastime":
        raise InputError(
            "the log has no green weight (weightGreen 0) nor grams in its name (as in roast_500g.json): set batch_kg = "
            "... in the map",
            path,
        )
    for k, spec in settings.items():
        if k in ("heater", "fan"):
            lo, hi = SETTING_UNITS[spec["unit"]]
            v = series[k][np.isfinite(series[k])]
            if v.size and readout_zero_offset(spec["unit"], v):
                default_notes.append(
                    f"{k}: the {spec['column']} readout reads down to {v.min():g} {spec['unit']}, a sensor's offset "
                    "about its zero: read as 0 there"
                )
                series[k] = np.where(series[k] < 0.0, 0.0, series[k])
                v = np.maximum(v, 0.0)
            if v.size and (v.min() < lo or v.max() > hi):
                raise InputError(
                    f"{k} setting {v.min():g}..{v.max():g} outside {lo:g}..{hi:g} for unit {spec['unit']!r} "
                    "(wrong unit in the map?)",
                    path,
                    f"channel {spec['column']}",
                )

    # Gg in kg/s
    if "column" in gg:
        factor = FLOW_UNITS[gg["unit"]]
        Gg = extra["Gg"] * (gg["density_kg_m3"] / 3600.0 if factor is None else factor)
    elif "pitot" in gg:
        if np.any(extra["dp"][np.isfinite(extra["dp"])] < 0):
            raise InputError("negative Pitot pressure difference", path, f"column {gg['pitot']['dp_column']}")
        Gg = gas_flow_pitot_kg_s(extra["dp"], extra["Tp"], gg["pitot"]["section_m2"], gg["pitot"]["rho0_kg_m3"])
    elif "constant_kg_s" in gg:
        Gg = np.full(len(time_s), gg["constant_kg_s"])
    else:  # identify: a 1 kg/s placeholder scaled by the identified Gg_kg_s
        Gg = np.ones(len(time_s))

    # missing samples (Artisan -1, empty cells) are dropped rather than invented; a missing
    # second bean reading (Tb2) only leaves a gap in that reading
    # a row whose time does not follow every one before it (a repeated or backward stamp in a CSV
    # log; an Artisan log's are dropped as it is read) is dropped too, not the log
    ordered = time_follows(time_s)
    stumbled = int((np.isfinite(time_s) & ~ordered).sum())
    ok = ordered & np.isfinite(Ta) & np.isfinite(Tgi) & np.isfinite(Gg)
    for k in ("heater", "fan"):
        if k in series:
            ok &= np.isfinite(series[k])
    if "Tb2" in series:  # the second reading only counts from start_s (e.g. once the beans are in view)
        series["Tb2"] = np.where(time_s >= settings["Tb2"].get("start_s", 0.0), series["Tb2"], np.nan)
    if "ET" in series:  # Artisan writes -1 where a channel read nothing
        series["ET"] = np.where(series["ET"] > -1.0 + 1e-9, series["ET"], np.nan)
    if ok.sum() < 2:  # name the inputs that have (next to) no readings, where that is why
        required = {"Ta": Ta, "Tgi": Tgi, "Gg": Gg, **{k: series[k] for k in ("heater", "fan") if k in series}}
        empty = [_named_input(k, cmap, settings) for k, v in required.items() if np.isfinite(v).sum() < 2]
        why = f": no readings in {', '.join(empty)}" if empty else ": no sample has every input"
        raise InputError(f"fewer than 2 complete samples after dropping missing values{why}", path)

    def select(which):
        """The samples ``which`` (a mask or a slice) of every series."""
        return time_s[which], Ta[which], Tgi[which], Gg[which], {k: v[which] for k, v in series.items()}

    time_s, Ta, Tgi, Gg, series = select(ok)
    notes = list(default_notes)
    if stumbled:
        notes.append(f"dropped {stumbled} sample(s) whose time does not follow the one before")
    if (incomplete := int((~ok).sum()) - stumbled) > 0:  # a missing time is a missing value
        notes.append(f"dropped {incomplete} incomplete sample(s) (missing values)")
    spikes, j = probe_faults(time_s, Ta)
    u = temp_symbol(temp_unit)  # the notes speak the log's own unit

    def jump(k):
        return f"bean temperature jumps {display_temp(Ta[k], temp_unit):.0f} -> {display_temp(Ta[k + 1], temp_unit):.0f} {u} at t = {time_s[k + 1]:.0f} s"

    if spikes.any():
        at = time_s[spikes]
        notes.append(
            f"dropped {spikes.sum()} sample(s) of bean-probe spikes at t = {at[0]:.0f}"
            + (f"-{at[-1]:.0f}" if at[-1] > at[0] else "")
            + f" s (a step over {display_temp_delta(MAX_JUMP_C, temp_unit):g} {u} that came back within {SPIKE_MAX_S:g} s)"
        )
        time_s, Ta, Tgi, Gg, series = select(~spikes)
    if j is not None:
        # a probe fault: keep what came before it rather than fit a physically impossible step
        if j + 1 < max(2, 0.5 * len(Ta)):
            raise InputError(
                f"{jump(j)}, early in the log: sensor fault?",
                path,
            )
        notes.append(f"{jump(j)} (probe fault): log cut there")
        time_s, Ta, Tgi, Gg, series = select(slice(None, j + 1))
    if drop_known and (why := hot_drop(Ta[-1])):
        raise InputError(why, path)
    if cmap.resample_s > 0:
        if np.any(np.diff(time_s) <= 0):
            raise InputError("time not strictly increasing", path)
        grid, cols = _resample(time_s, {"Ta": Ta, "Tgi": Tgi, "Gg": Gg, **series}, cmap.resample_s, path)
        for k in ("heater", "fan"):  # settings are steps: hold the last change, never interpolate
            if k in series:
                cols[k] = series[k][np.searchsorted(time_s, grid, side="right") - 1]
        time_s, Ta, Tgi, Gg = grid, cols["Ta"], cols["Tgi"], cols["Gg"]
        series = {k: cols[k] for k in series}
    batch = Batch(
        name or path.stem,
        np.asarray(time_s, float),
        np.asarray(Gg, float),
        np.asarray(Tgi, float),
        np.asarray(Ta, float),
        source=str(path),
        Mb_kg=Mb,
        heater=series.get("heater"),
        fan=series.get("fan"),
        Tb2_C=series.get("Tb2"),
        ET_C=series.get("ET"),
        events=events,
        unit=unit,
        started_epoch_s=started_epoch_s,
        temp_unit=temp_unit,
    )
    batch.initial.update(initial)
    if cmap.first_crack_as_beans:
        batch.Tb2_C, note = first_crack_reading(batch.time_s, events)
        if note:
            notes.append(note)
    batch.notes = notes
    return batch.validate()


def first_crack_reading(time_s, events: dict) -> tuple[np.ndarray | None, str | None]:
    """The log's first-crack mark as a bean reading: NaN everywhere but the sample nearest the FCs
    mark, which reads :data:`~roastlab.model.constants.FIRST_CRACK_BEAN_C` (a map's ``[Tb2]
    first_crack``), and a note; (None, a note) where the log marks no first crack within its samples.

    >>> tb2, _ = first_crack_reading(np.array([0.0, 5.0, 10.0, 15.0]), {"FCs": 11.0})
    >>> tb2
    array([ nan,  nan, 200.,  nan])
    >>> first_crack_reading(np.array([0.0, 5.0]), {})[1]
    'no first-crack mark (FCs) in the log: no bean reading on it ([Tb2] first_crack)'
    """
    t = np.asarray(time_s, dtype=float)
    fc_s = first_crack_s(t, events)
    if fc_s is None:
        where = (
            "the first-crack mark lies outside the log" if "FCs" in events else "no first-crack mark (FCs) in the log"
        )
        return None, f"{where}: no bean reading on it ([Tb2] first_crack)"
    tb2 = np.full(t.size, np.nan)
    tb2[int(np.argmin(np.abs(t - fc_s)))] = FIRST_CRACK_BEAN_C
    return tb2, None


def room_temperature_C(room, bare_unit: str) -> tuple[float | None, str | None]:
    """The room temperature [degC] a log records (:class:`~.artisan.RoomReading`) and a note.

    A number without a unit is in ``bare_unit`` (the map's ``[Tgi] room_unit``: RoasTime keeps
    what the owner typed, "72" in a °F kitchen). Where the log has none: (None, None), the
    map's constant stands. Where it is not a temperature, or not a room's (outside the
    registry's limits of ``T_room_C``): (None, a note saying so), the constant stands.

    >>> from roastlab.io.importers.artisan import room_from_text
    >>> round(room_temperature_C(room_from_text("72"), "F")[0], 2), room_temperature_C(room_from_text("18 C"), "F")[0]
    (22.22, 18.0)
    >>> room_temperature_C(room_from_text("85"), "C")[1]
    "room temperature '85' in the log is not a room's (85 degC): the map's constant_C used"
    """
    if room is None:
        return None, None
    unit = room.unit or bare_unit
    value_C = float(f_to_c(room.value)) if unit == "F" else room.value
    try:
        return check_value("T_room_C", value_C), None
    except ParameterError:
        shown = "not a number" if not np.isfinite(value_C) else f"{value_C:.0f} degC"
        return None, f"room temperature {room.text!r} in the log is not a room's ({shown}): the map's constant_C used"


def bare_room_unit(rooms) -> str | None:
    """The unit a set of logs' bare room temperatures are in (what ``roastlab init`` writes as
    ``[Tgi] room_unit``; a user who knows better edits it): ``"F"`` where one of them is no room's
    read as degC but is one read as degF (``"72"``), else ``"C"``; None when none is bare.

    >>> from roastlab.io.importers.artisan import room_from_text
    >>> [bare_room_unit([room_from_text(t) for t in ts]) for ts in (("42", "72", "18 C"), ("21",), ("18 C",))]
    ['F', 'C', None]
    """
    bare = [r for r in rooms if r is not None and r.unit is None]
    if not bare:
        return None
    as_F = any(room_temperature_C(r, "C")[0] is None and room_temperature_C(r, "F")[0] is not None for r in bare)
    return "F" if as_F else "C"


def _constant_or(spec: dict, n: int, read) -> np.ndarray:
    """A map entry that is a constant (``constant_C``) as a series of n, else ``read()``."""
    if "constant_C" in spec:
        return np.full(n, float(spec["constant_C"]))
    return read()
