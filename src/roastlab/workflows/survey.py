"""``roastlab init``: read a roaster's logs and write its column map, plant, fit spec and fleet
spec (:func:`init_roaster`), which ``roastlab fit-roaster`` (:mod:`roastlab.workflows.roaster`) then
fits, validates on held-out logs and reports.

What :func:`survey` detects in the logs (and says in the files' comments):

* the format (Artisan ``.alog``/CSV, RoasTime JSON, a plain CSV whose columns are found by name,
  :func:`plain_csv_columns`) and the bean probe (BT);
* which channels are the heater/burner and the fan/air, by name in Artisan's languages (an
  event type or an extra device), with their unit by value range over every log (whole steps up
  to 20: a level; whole tens above 100 up to :data:`TENS_MAX`: levels shown in tens; up to 100:
  percent; above 100 otherwise: a heater's power in W);
* a second bean reading (RoasTime's infrared ``drumTemperature``, or an ET that falls to the
  green beans at CHARGE, :func:`roastlab.metrics.profile.et_reads_beans`: an infrared bean sensor
  as Artisan's Aillio Bullet R1 IBTS device logs it, the drum at CHARGE then ET's reading before it,
  :data:`roastlab.io.importers.artisan.ET_BEFORE_CHARGE`);
* an inlet-air temperature (:data:`INLET_NAMES`): the paper's input Tgi where no heater is logged
  (offered, commented, where one is);
* ET (the drum temperature at CHARGE is BT's reading then,
  :data:`roastlab.io.importers.artisan.DRUM_AT_CHARGE`; RoasTime's preheat for RoasTime logs);
* each log's green batch (Artisan ``weight``, RoasTime ``weightGreen``, a file name's "230g").

The plant (:func:`estimate_plant`) comes from the drum's dimensions when given, else from the
batch capacity (given, from :data:`CATALOGUE` by the log's machine name or model number, or twice the largest
logged batch) by the same rules the shipped examples' hand estimates follow: a drum that holds
the capacity at a 20 % fill, length 1.25 diameters, vanes D/8 high at 0.6 D pitch, metal 3 kg
per kg of capacity. The fit spec (:func:`fit_spec_text`) frees what these logs can determine:
the paper's three coefficients and the probe constant always; the gas flow when none is
logged; the heater's gains and lag when a heater is logged (into the drum metal, and into the
air unless the machine heats the drum itself or no ET is logged to tell the two paths apart); the fan's share of the flow when a fan is
logged; a shell loss when the inlet is room air; the probe's immersion under the bed laws
cross-validation chose (for every roaster), its depth scale held at the drum's diameter, or fitted from
there where the logs span batch sizes and no bean reading runs beside the probe (:func:`fit_spec_text`); the
second reading's weight and the beans' exothermic rate law (:data:`EXOTHERM_LAW`) when the log has
a second bean reading; ET's weight (against the outlet
gas) when ET is logged beside a heater, because a fit on BT alone can heat the beans by a path the machine does
not have, and such a fit fails (:attr:`roastlab.workflows.model.FittedModel.failed`). Bounds come
from the quantity table.
"""

from __future__ import annotations

import io
import json
import math
import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..evaluate.metrics import size_labels
from ..io.batch import first_of_each_roast, logs_temp_unit
from ..io.importers.artisan import DRUM_AT_CHARGE as ARTISAN_DRUM_AT_CHARGE
from ..io.importers.artisan import (
    ET_BEFORE_CHARGE,
    WEIGHT_UNITS,
    RoomReading,
    named_as_temperature,
    read_alog,
    read_artisan_csv,
)
from ..io.importers.mapping import (
    SECOND_BEAN_START_S,
    bare_room_unit,
    detect_format,
    grams_in_name,
    hot_drop,
    is_log_by_content,
    names_of,
    probe_faults,
)
from ..io.importers.roastime import DRUM_AT_CHARGE, read_roastime
from ..metrics.profile import (
    LOG_THE_HEATER,
    SHORTEST_ROAST_S,
    delta_text,
    display_temp,
    display_temp_delta,
    et_below_bt_on_every_log,
    et_minus_bt_C,
    et_not_drum_air,
    et_reads_beans,
    first_crack_s,
    mmss,
    temp_symbol,
)
from ..model.actuators import CONTROL_UNITS, PRESSURE_FAN_EXP, PRESSURE_HEATER_EXP, PRESSURE_UNITS, UNIT_DEFAULTS
from ..model.bed import CROSS_VALIDATED, PROBE_DEPTH_OVER_DIAMETER
from ..model.constants import FIRST_CRACK_BEAN_C, GREEN_BULK_DENSITY_KG_M3
from ..model.parameters import FIRST_CRACK_WEIGHT, RESIDUAL_WEIGHT
from ..model.quantities import default, quantity

#: Names of a heater/burner and a fan/air channel in Artisan's languages (lower case, substrings).
HEATER_NAMES = ("burner", "heater", "power", "heat", "gas", "brûleur", "bruleur", "brenner", "quemador",
                "queimador", "bruciatore", "potencia", "leistung", "puissance", "火力", "火")  # fmt: skip
#: The words of a control's name that say it is logged as a gas pressure (lower case, whole words
#: of the name: "Gas kPa", "Gas (mbar)", 'Gas "WC'), and the unit each names
#: (:data:`roastlab.model.actuators.PRESSURE_UNITS`).
PRESSURE_WORDS = {"kpa": "kPa", "hpa": "hPa", "mbar": "mbar", "pa": "Pa", "psi": "psi", "wc": "inWC",
                  "inwc": "inWC", "inh2o": "inWC", "mmwc": "mmWC", "mmh2o": "mmWC", "mmaq": "mmWC"}  # fmt: skip
assert set(PRESSURE_WORDS.values()) <= set(PRESSURE_UNITS)
#: Every word of a control's name that names its unit: the gas pressures, and a fan's drive
#: frequency ("Fan Hz", "Exhaust (Hz)": a variable-frequency drive's readout, 30-60 Hz, which the
#: values alone would read as a percent).
UNIT_WORDS = {**PRESSURE_WORDS, "hz": "Hz", "percent": "percent", "pct": "percent"}
assert set(UNIT_WORDS.values()) <= set(UNIT_DEFAULTS)
#: Logged controls the model does not use, named so the map can say so.
OTHER_NAMES = {
    "damper": ("damper", "klappe", "registre", "valve"),
    "drum speed": ("drum", "trommel", "tambour", "tambor"),
}
FAN_NAMES = (
    "air",
    "fan",
    "airflow",
    "draft",
    "draught",
    "ventilateur",
    "lüfter",
    "luefter",
    "luft",
    "ventilador",
    "aria",
    "風",
    "风",
)
#: Names of a temperature channel that logs the air entering the drum, the paper's inlet gas Tgi
#: (lower case, substrings): an extra device many shop roasters log beside BT and ET.
INLET_NAMES = ("inlet", "intake", "zuluft", "eintritt", "entrée", "entree", "entrada", "ingresso")


@dataclass(frozen=True)
class Machine:
    """One catalogue entry: a roaster family recognised in Artisan's ``roastertype``.

    ``pattern`` is a regular expression searched in the lower-case machine name. Its first group,
    when it has one, is the model number, which these makers set to the rated batch in
    ``per_unit_kg`` units (Giesen W6: 6 kg; San Franciscan SF25: 25 lb); an entry without a group
    has the fixed ``capacity_kg``. ``heat`` says where the heater's power enters: ``"drum"``
    (induction), ``"air"`` (hot air or a convection burner) or ``"both"``. ``tens``: Artisan's
    machine setups for it show its levels in tens (the Aillio Bullet's: fan F1-F12 as 10-120,
    power P0-P9 as 0-90, the R2's P0-P14 as 0-140), so a setting its Artisan logs move in whole
    tens is those levels, not a percent, even where the logs stay under 100.
    """

    pattern: str
    heat: str
    source: str
    capacity_kg: float | None = None
    per_unit_kg: float = 1.0
    tens: bool = False

    def capacity(self, machine: str) -> float | None:
        """The rated green batch [kg] of ``machine`` if this entry names it, else None."""
        m = re.search(self.pattern, machine.lower())
        if m is None:
            return None
        if self.capacity_kg is not None:
            return self.capacity_kg
        return float(m.group(1)) * self.per_unit_kg


#: Published capacities of common roasters, first match wins (a fixed model before its family's
#: number rule). The model lists are Artisan's machine pages (artisan-scope.org/machines/...);
#: drum dimensions are not published by these makers, so the plant is estimated from the capacity.
CATALOGUE = (
    Machine(r"aillio|bullet", "drum", "Aillio Bullet R1: 1 kg maximum batch, induction-heated drum (aillio.com product page)", 1.0, tens=True),
    Machine(r"hottop", "both", "Hottop KN-8828B-2K+: 250 g maximum batch, electric element (hottopusa.com)", 0.25),
    Machine(r"behmor", "both", "Behmor 1600+: 1 lb maximum batch, quartz elements (behmor.com)", WEIGHT_UNITS["lb"]),
    Machine(r"kaffelogic", "air", "Kaffelogic Nano 7: 120 g maximum batch, hot-air (kaffelogic.com)", 0.12),
    Machine(r"coffeetool\D*r\s?500", "both", "Coffeetool R500: 500 g batch (coffeetool.gr; artisan-scope.org/machines/coffeetool)", 0.5),
    Machine(r"coffeetool\D*r\s?(\d+(?:\.\d+)?)", "both", "Coffeetool R3/R5/R15: the model number is the batch in kg (coffeetool.gr; artisan-scope.org/machines/coffeetool)"),
    Machine(r"giesen\D*w\s?(\d+)", "both", "Giesen W1-W140: the model number is the batch in kg (giesencoffeeroasters.eu; artisan-scope.org/machines/giesen)"),
    Machine(r"loring\D*s\s?(\d+)", "air", "Loring S7/S15/S35/S70: the model number is the batch in kg, convection burner (loring.com; artisan-scope.org/machines/loring)"),
    Machine(r"probat\D*?(\d+)", "both", "Probat(one) 5/12/25: the model number is the batch in kg (probat.com; artisan-scope.org/machines/probat)"),
    Machine(r"\bimf\D*rm\s?(\d+)", "both", "IMF RM5/RM15: the model number is the batch in kg (imf-srl.com; artisan-scope.org/machines/imf)"),
    Machine(r"diedrich\D*ir\s?-?(\d+(?:\.\d+)?)", "both", "Diedrich IR-2.5/IR-5/IR-12: the model number is the batch in kg (diedrichroasters.com; artisan-scope.org/machines/diedrich)"),
    Machine(r"(?:san\s?franciscan\D*|\b)sf\s?-?(\d+)", "both", "San Franciscan SF1-SF75: the model number is the batch in pounds (sanfranroaster.com; artisan-scope.org/machines/sf)", per_unit_kg=WEIGHT_UNITS["lb"]),
)  # fmt: skip
#: Fill fraction at which a drum holds its rated batch [-] (the examples' estimates: 20-25 %).
RATED_FILL = 0.20
#: Drum length over diameter [-], vane height and pitch over diameter, metal per kg of capacity
#: [kg/kg]: the rules of the shipped examples' estimates (Skywalker 0.16 x 0.20 m, 1.5 kg for
#: 0.5 kg; Bullet 0.20 x 0.25 m, 3 kg for 1 kg).
LENGTH_OVER_DIAMETER = 1.25
VANE_HEIGHT_OVER_D = 1 / 8
VANE_PITCH_OVER_D = 0.6
METAL_KG_PER_KG = 3.0
#: Highest gas flow a fit may reach, per kg of batch capacity [kg/s per kg] (never below
#: :data:`GAS_FLOW_MAX_FLOOR_KG_S`): six times the paper's 120 kg plant (0.3-0.4 kg/s, dataset-I's
#: Gg, about 0.003 kg/s per kg), so a machine's flow scales with its size instead of one bound for all.
GAS_FLOW_MAX_KG_S_PER_KG = 0.02
#: The gas-flow bound of the small roasters the examples fit (Skywalker, Bullet) [kg/s].
GAS_FLOW_MAX_FLOOR_KG_S = 0.05
#: Lowest gas flow a fit may reach [kg/s]: half a gram of air per second (about 0.4 L/s), below the
#: flow of any drum with a fan; the Skywalker's fit ends on it (docs/real-roaster.md), the examples'
#: fit specs use the same bound.
GAS_FLOW_MIN_KG_S = 0.0005
#: The beans' exothermic rate law (eq. 14's A and Ha/R), fitted within the quantity table's bounds
#: where the logs carry a second bean reading beside the probe: such a reading pins the law (the
#: Bullet's IR: cross-validated by batch size and by roaster, the fitted law predicts unseen sizes
#: 2.1 points and unseen drums 2.6 points better); the probe alone does not (the Skywalker's logs
#: send A to its bound and predict worse), and the paper's law stays (docs/real-roaster.md, "The
#: beans' exotherm, fitted").
EXOTHERM_LAW = ("A", "Ha_R")
#: Lower bound of the heat-transfer coefficients a small roaster's fit may reach [kW/(m2 K)]: an
#: order below the quantity table's fit bounds (made for the paper's industrial drums), inside
#: its plausible range (the Bullet's gas-metal coefficient ends near it).
SMALL_COEFF_FLOOR = 0.001
#: Where a fit starts the share of the drum's rise over the room that the probe soaked in the empty
#: drum shows (``Tm0_share``, :func:`roastlab.model.rhs.drum_at_charge_C`): between the Bullet's soaked
#: probe, 0.48-0.69 of the way from the room to its preheated drum, and the drum itself (1); the
#: Skywalker's fits end at 0.76-0.87 from here (docs/real-roaster.md, "Skywalker: the drum above its
#: probe at CHARGE").
TM0_SHARE_START = 0.8


@dataclass
class LogInfo:
    """What one log holds (see the module docstring)."""

    path: Path
    format: str
    machine: str
    channels: list[str]
    batch_kg: float | None
    batch_from: str
    heater: str | None = None
    fan: str | None = None
    second_bean: str | None = None
    has_et: bool = False
    heater_max: float = 0.0
    fan_max: float = 0.0
    started_epoch_s: float | None = None
    unused: dict = field(default_factory=dict)  # other logged controls: {"damper": channel, ...}
    unit: str = ""  # the roaster unit the log names (RoasTime serialNumber), else empty
    et_minus_bt_C: float | None = None  # median ET - BT through the roast (metrics.profile.et_minus_bt_C)
    room: RoomReading | None = None  # the room temperature the log records, as written
    columns: dict | None = None  # a plain CSV's own names and units (plain_csv_columns)
    capacity_kg: float | None = None  # the batch capacity the log states (Artisan's roastersize)
    et_reads_beans: bool | None = None  # ET falls to the green beans at CHARGE (metrics.profile.et_reads_beans)
    et_before_charge: bool = False  # the log has ET's reading before CHARGE (artisan.ET_BEFORE_CHARGE)
    seen: dict = field(default_factory=dict)  # the heater's and the fan's distinct logged values (their unit: survey)
    inlet: str | None = None  # a temperature channel named as the inlet air (INLET_NAMES)
    marks_first_crack: bool = False  # the log marks first crack (FCs) within its samples
    temp_unit: str = "C"  # the unit the log was recorded in ("C" or "F": Artisan's mode, a CSV's column names)


@dataclass
class Survey:
    """The logs' common layout, the machine and the batches (:func:`survey`)."""

    logs: list[LogInfo]
    format: str
    machine: str
    heater: str | None
    heater_unit: str | None
    fan: str | None
    fan_unit: str | None
    second_bean: str | None
    has_et: bool
    heater_max: float = 0.0
    fan_max: float = 0.0
    unused: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    et_not_air: list[str] = field(default_factory=list)  # logs whose ET is not the drum's air
    rooms: int = 0  # logs that record the room temperature
    room_unit: str | None = None  # the unit of their bare numbers (mapping.bare_room_unit); None if none is bare
    columns: dict | None = None  # a plain CSV's own names and units (plain_csv_columns)
    batch_kg: float | None = None  # --batch-kg: the green weight of a log that records none (the map's batch_kg)
    unweighed: list[str] = field(default_factory=list)  # logs set aside: no green weight (logs_without_weight)
    et_is_bean: bool = False  # ET is a bean reading (the second one, an infrared sensor), not the drum's air
    in_tens: dict = field(default_factory=dict)  # {"heater": True, ...}: every logged value a whole ten
    inlet: str | None = None  # the inlet-air channel every log records (INLET_NAMES), else None
    et_below_bt: bool = False  # ET reads below BT through every roast: not the drum's air, not used
    fan_at: float | None = None  # the one fan setting of every log, where the fan never moves; else None
    first_crack: bool = False  # no bean reading but the probe, and most logs mark first crack: the map reads
    # the mark as the beans' temperature ([Tb2] first_crack, roastlab.model.constants.FIRST_CRACK_BEAN_C)
    renamed: dict = field(default_factory=dict)  # {"heater": [names, the most used first]} where the logs
    # name a control differently; the heater or fan field above is the first of them
    # {"heater": "kPa"}: a control's unit as the roaster gave it (init --heater-unit), not as detected
    given: dict = field(default_factory=dict)

    @property
    def drum_start_from_probe(self) -> bool:
        """The map reads the drum at CHARGE from the bean probe soaked in the empty drum (BT then), not
        from a reading of the drum itself (RoasTime's preheat, an infrared sensor on the empty drum)."""
        return self.format != "roastime" and not (self.et_is_bean and any(i.et_before_charge for i in self.logs))


#: A heater logged in watts heats the drum by at most its electric power [kW per W].
KW_PER_W = 1e-3


#: The highest setting read as a machine's levels shown in tens (:func:`_unit_of`, the unit "tens"
#: of :data:`roastlab.model.actuators.UNIT_DEFAULTS`): Artisan's sliders for the Aillio Bullet show
#: its fan F1-F12 as 10-120 (its machine setup "Bullet R1 IBTS": fan 10-120, heater 0-90, drum
#: 10-90), and a heater's power in W lies far above it.
TENS_MAX = UNIT_DEFAULTS["tens"][1]


def _in_whole_tens(values: np.ndarray) -> bool:
    """Every finite value a whole multiple of ten (a level shown in tens, or a percent so moved)."""
    v = values[np.isfinite(values)]
    return bool(v.size) and bool(np.all(np.abs(v / 10.0 - np.round(v / 10.0)) < 1e-9))


def named_unit(name: str | None) -> str | None:
    """The unit a control's ``name`` says it is logged in ("Gas kPa" -> "kPa", "Fan Hz" -> "Hz",
    "Gas %" -> "percent"), else None (:data:`UNIT_WORDS`, whole words: "Gas (mbar)", 'Gas "WC', "Gas in. WC", "Gas mmH2O")."""
    if "%" in (name or ""):  # "Gas %", "Fan (%)": a percent, whatever its values
        return "percent"
    words = re.findall(r"[a-z0-9]+", (name or "").lower())
    # "in. WC" / "in H2O": the inches of water column written apart
    joined = [a + b for a, b in zip(words, words[1:]) if a in ("in", "mm") and b in ("wc", "h2o")]
    return next((UNIT_WORDS[w] for w in joined + words if w in UNIT_WORDS), None)


#: A setting read as a percent reaches above this somewhere in the logs: a roaster who never sets the
#: burner or the fan above 10 % of its range does not roast coffee with it, so a readout with decimals
#: that stays below is a reading in a unit its name does not give ("reading": a "Gas" manometer at
#: 0.5-3.5 kPa), read over its logged range rather than as a sliver of 0-100 %.
PERCENT_TOP_ABOVE = 10.0


def _unit_of(values: np.ndarray, name: str | None = None) -> str:
    """A logged setting's unit: the one the channel's ``name`` names (:func:`named_unit`: a gas
    pressure, a drive's frequency); else by its values (every log's, pooled: one unit for the channel):
    whole steps up to 20 a level; decimals never above :data:`PERCENT_TOP_ABOVE` a "reading" in a
    unit nobody named (a burner's manometer at 0.5-3.5 kPa under the name "Gas"); whole tens above
    100 and up to :data:`TENS_MAX` levels shown in tens ("tens"); up to 100 a percent; above 100
    otherwise a power in watts (a heater's power readout; a fan so logged is not used)."""
    if unit := named_unit(name):
        return unit
    v = values[np.isfinite(values)]
    whole = bool(v.size) and bool(np.all(np.abs(v - np.round(v)) < 1e-9))
    if whole and v.max() <= 20:
        return "level"
    if v.size and 0.0 < v.max() <= PERCENT_TOP_ABOVE:
        return "reading"
    if v.size and 100.0 < v.max() <= TENS_MAX and _in_whole_tens(v):
        return "tens"
    return "W" if v.size and v.max() > 100.0 else "percent"


def find_name(names, candidates) -> str | None:
    """The first of ``names`` that is one of ``candidates`` (lower case), else the first that
    contains one: an event type "Fan" before a device's "Fan RPM", "Heater" before "Heater readout"."""
    lows = [name.lower().strip() for name in names]
    for test in (lambda low, c: low == c, lambda low, c: c in low):
        for name, low in zip(names, lows):
            if any(test(low, c) for c in candidates):
                return name
    return None


#: A plain CSV's columns by name: the first word of a header, lower case ("BT (F)" -> "bt").
CSV_TIME_WORDS = ("time", "t", "sec", "secs", "seconds", "elapsed", "zeit", "temps", "tiempo", "tempo")
CSV_BT_WORDS = ("bt", "bean", "beans", "beantemp")
CSV_ET_WORDS = ("et", "env", "environment", "exhaust", "exit")
#: Words that make a column a rate or a difference, not a reading ("BT RoR", "delta BT").
CSV_NOT_A_READING = ("ror", "delta", "rate", "dbt", "det")


def plain_csv_columns(header: list[str]) -> dict:
    """The time, BT and ET columns of a plain CSV log by their names (:data:`CSV_TIME_WORDS` ...),
    with their units: minutes or milliseconds where the time's name says so, else seconds; degF
    where a temperature's name says F (``BT (F)``, ``bean_temp_degF``, ``°F``), else degC."""

    def words(name):
        return re.findall(r"[a-z]+", name.lower().replace("°", " deg"))

    def first(candidates, taken=()):
        for name in header:
            w = words(name)
            if w and w[0] in candidates and name not in taken and not set(w) & set(CSV_NOT_A_READING):
                return name
        return None

    def temp_unit(name):
        return "F" if {"f", "degf", "fahrenheit"} & set(words(name)) else "C"

    time, bt = first(CSV_TIME_WORDS), first(CSV_BT_WORDS)
    et = first(CSV_ET_WORDS, (bt,))
    tw = set(words(time or ""))
    return {
        "time": time,
        "time_unit": "min" if tw & {"min", "mins", "minutes"} else ("ms" if "ms" in tw else "s"),
        "BT": bt,
        "ET": et,
        "temp_unit": temp_unit(bt or ""),
    }


def read_plain_csv(path: Path):
    """A plain CSV log (a header row, numbers below; its first row the charge) read as an
    :class:`~roastlab.io.importers.artisan.ArtisanLog` whose BT and ET are in degC under those
    names, and its columns (:func:`plain_csv_columns`): what :func:`inspect_log` needs."""
    import csv as _csv

    from ..io.batch import csv_log_text, read_table
    from ..io.importers.artisan import ArtisanLog
    from ..io.importers.mapping import TIME_UNITS, to_celsius

    text = csv_log_text(path)
    rows = (row for row in _csv.reader(ln for ln in io.StringIO(text) if not ln.lstrip().startswith("#")) if row)
    header = [h.strip() for h in next(rows, [])]
    cols = plain_csv_columns(header)
    if cols["time"] is None or cols["BT"] is None:
        raise InputError(
            f"a CSV log needs a time column and a bean-temperature column by name (a header like time,BT,ET; "
            f"found: {', '.join(header[:8])})",
            path,
        )
    at = header.index(cols["time"])
    first_time = next((row[at] for row in rows if at < len(row) and row[at].strip()), "")
    if ":" in first_time:  # the time written as a clock (m:ss): its first filled cell says so
        cols["time_unit"] = "m:ss"
    clock = (cols["time"],) if cols["time_unit"] == "m:ss" else ()
    data = read_table(path, (cols["time"], cols["BT"]), text=text, sparse=(cols["time"], cols["BT"]), clock=clock)
    for h in (cols["ET"], *(h for h in header if h and h not in (cols["time"], cols["BT"], cols["ET"]))):
        try:  # a column of words (events, notes) is not a reading the model can use; a gap is a sample not taken
            data.update(read_table(path, (h,), text=text, sparse=(h,)) if h else {})
        except InputError:
            cols["ET"] = None if h == cols["ET"] else cols["ET"]
            cols["not read"] = [*cols.get("not read", []), h]
    others = tuple(h for h in header if h in data and h not in (cols["time"], cols["BT"], cols["ET"]))
    kept = np.isfinite(data[cols["time"]]) & np.isfinite(data[cols["BT"]])  # rows with a time and a BT
    if kept.sum() < 2:
        raise InputError(f"fewer than 2 rows with both {cols['time']!r} and {cols['BT']!r}", path)
    data = {k: v[kept] for k, v in data.items()}
    time_s = data[cols["time"]] * TIME_UNITS[cols["time_unit"]]
    channels = {"BT": to_celsius(data[cols["BT"]], cols["temp_unit"])}
    if cols["ET"]:
        channels["ET"] = to_celsius(data[cols["ET"]], cols["temp_unit"])
    channels.update({h: data[h] for h in others})
    log = ArtisanLog(str(path), time_s - time_s[0], channels, {"BT", "ET"}, cols["temp_unit"], 0, None, {"CHARGE": 0.0})
    return log, cols


def live_reading(values_C) -> bool:
    """Whether a temperature channel reads anything: above the room (the quantity table's
    ``T_room_C``) at some sample. An unconnected thermocouple reads 0 (or Artisan's -1) throughout."""
    return bool(np.nanmax(np.asarray(values_C, dtype=float), initial=-np.inf) > default("T_room_C"))


def inspect_log(path, batch_kg: float | None = None) -> LogInfo:
    """One log's layout (format, channels, heater/fan, second bean reading, batch)."""
    path = Path(path)
    fmt = detect_format(path, "auto")
    columns = None
    if fmt == "alog":
        log = read_alog(path)
    elif fmt == "artisan-csv":
        log = read_artisan_csv(path)
    elif fmt == "roastime":
        log = read_roastime(path)
    elif fmt == "csv":
        log, columns = read_plain_csv(path)
    else:
        raise InputError("not a roast log roastlab can set up from (Artisan .alog/.csv, RoasTime .json, CSV)", path)
    names = list(log.channels)
    if "BT" not in log.channels or not np.isfinite(log.channels["BT"]).any():
        raise InputError("no bean temperature (BT) in this log: roastlab needs the bean probe", path)
    read = np.isfinite(log.channels["BT"])
    bt = log.channels["BT"][read]
    spikes, fault = probe_faults(log.time_s[read], bt)  # the import drops spikes and cuts a probe fault so
    bt = bt[~spikes]
    bt = bt[: fault + 1] if fault is not None else bt
    if log.drop_index is not None and (why := hot_drop(float(bt[-1]))):
        raise InputError(why, path)  # the import refuses it too; say it before the files are written
    if not live_reading(bt):  # a probe that read nothing (0 degC throughout), said in the log's unit
        u = temp_symbol(log.mode)
        raise InputError(
            f"BT never reads above the room ({display_temp(default('T_room_C'), log.mode):g} {u}; highest "
            f"{display_temp(bt.max(), log.mode):.0f} {u}): no roast recorded, an unconnected probe?",
            path,
        )
    if (length := float(log.time_s[-1] - log.time_s[0])) < SHORTEST_ROAST_S:
        raise InputError(
            f"the log ends {mmss(length)} after CHARGE, shorter than any roast ({mmss(SHORTEST_ROAST_S)}): an "
            "aborted recording, or CHARGE marked where the beans did not go in?",
            path,
        )
    others = [n for n in names if n not in ("BT", "ET", "beanTemperature", "drumTemperature", "exitTemperature")]
    temps = [n for n in others if (named_as_temperature(n) if fmt == "csv" else n in log.temperature_channels)]
    inlet = find_name([n for n in temps if np.isfinite(log.channels[n]).any()], INLET_NAMES)
    if fmt == "csv":  # a CSV's other temperatures ("inlet temp", "air temp") are not settings
        others = [n for n in others if n not in temps]
    others = [n for n in others if n != inlet]  # the inlet air is no setting ("Inlet Air" is not the fan)
    heater = "heater" if fmt == "roastime" and "heater" in names else find_name(others, HEATER_NAMES)
    # a channel the log marks as a temperature and that reads above 100 is no fan setting (a speed would be
    # marked otherwise): an exhaust air "Abluft" named like the air ("Luft"), not a fan in rpm
    hot = {n for n in others if n in temps and np.nanmax(log.channels[n], initial=-np.inf) > 100.0}
    fan = (
        "fan"
        if fmt == "roastime" and "fan" in names
        else find_name([n for n in others if n not in (heater, *hot)], FAN_NAMES)
    )
    if fan is None:  # no fan channel: a damper sets the air flow through the drum (one fixed-speed exhaust fan)
        fan = find_name([n for n in others if n not in (heater, *hot)], OTHER_NAMES["damper"])
    if log.weight_in_kg:  # the import's order (mapping.import_log): the log, its file name, the map's batch_kg
        mass, source = log.weight_in_kg, "the log's green weight"
    elif named := grams_in_name(path):
        mass, source = named[0], f"the file name's '{named[1]}'"
    elif batch_kg is not None:
        mass, source = batch_kg, "--batch-kg"
    else:
        mass, source = None, ""
    info = LogInfo(
        path,
        fmt,
        log.machine,
        names,
        mass,
        source,
        heater,
        fan,
        "drumTemperature" if fmt == "roastime" and "drumTemperature" in names else None,
        "ET" in names and live_reading(log.channels["ET"]),
        float(np.nanmax(log.channels[heater])) if heater else 0.0,
        float(np.nanmax(log.channels[fan])) if fan else 0.0,
        log.started_epoch_s,
        {
            what: ch
            for what, names_ in OTHER_NAMES.items()
            if (ch := find_name([n for n in others if n not in (heater, fan)], names_))
        },
        log.unit,
        et_minus_bt_C(log.time_s, log.channels["ET"], log.channels["BT"], log.events.get("DROP"))
        if "ET" in names
        else None,
        log.room,
        columns,
        log.capacity_kg,
    )
    if fmt != "roastime" and info.has_et:  # RoasTime names its IR reading (drumTemperature) itself
        info.et_reads_beans = et_reads_beans(log.time_s, log.channels["ET"], log.channels["BT"], default("T_room_C"))
        info.et_before_charge = ET_BEFORE_CHARGE in log.fields
    info.inlet = inlet
    info.marks_first_crack = first_crack_s(log.time_s, log.events) is not None
    info.temp_unit = log.mode
    for what, channel in (("heater", heater), ("fan", fan)):
        if channel:
            values = log.channels[channel]
            info.seen[what] = np.unique(values[np.isfinite(values)])
    return info


#: The suffixes of the logs a folder given as LOG stands for, in the order one is preferred to
#: another where a folder holds several (Artisan's .alog before the CSV exports beside it, which
#: are the same roasts): Artisan .alog, RoasTime .json, RoasTime's files without a suffix (where
#: their content is a RoasTime or Artisan log: :func:`roastlab.io.importers.mapping.detect_format`),
#: then .csv (Artisan's export or a plain CSV).
FOLDER_LOG_SUFFIXES = (".alog", ".json", "", ".csv")


def log_paths(paths, passed_over: dict[str, str] | None = None) -> list[Path]:
    """The LOG arguments as files. A folder stands for the logs directly inside it, by name, of one
    format: the first of :data:`FOLDER_LOG_SUFFIXES` it holds (its hidden files, subfolders and
    files of other suffixes are not logs). A folder with no log in it is refused, naming it.
    ``passed_over``, where given, gets ``{folder: why}`` for each folder that also holds logs of a
    later suffix, which are not read (the CSV exports beside Artisan's logs, or another roaster's
    logs in the same folder): counted, so a roaster can name them to read them instead."""
    out: list[Path] = []
    for arg in map(Path, paths):
        if not arg.is_dir():
            out.append(arg)
            continue
        found: dict[str, list[Path]] = {}
        for p in sorted(arg.iterdir()):
            suffix = p.suffix.lower()
            if p.name.startswith(".") or not p.is_file() or suffix not in FOLDER_LOG_SUFFIXES:
                continue
            if suffix or is_log_by_content(p):  # without a suffix, a LICENSE or a Makefile is no log
                found.setdefault(suffix, []).append(p)
        if not found:
            raise InputError("no roast logs in this folder (Artisan .alog/.csv, RoasTime .json, CSV)", arg)
        chosen = next(s for s in FOLDER_LOG_SUFFIXES if s in found)
        out += found[chosen]
        others = [f"{len(v)} {k or 'suffix-less'} file(s)" for k, v in found.items() if k != chosen]
        if others and passed_over is not None:
            passed_over[str(arg)] = (
                f"{' and '.join(others)} in {arg}, not read: a folder stands for its logs of one format (its "
                f"{chosen or 'suffix-less'} files); name the others to read them instead"
            )
    return out


def readable_logs(paths, batch_kg: float | None = None) -> tuple[list[LogInfo], dict[str, str]]:
    """Each log inspected (:func:`inspect_log`), and those that cannot be read as a roast, each
    with why (``{name: why}``). A roaster's folder often holds an aborted or empty recording beside
    its roasts: that log is named and left out, not the whole set refused. So is a second copy of
    one roast (renamed, annotated: :func:`roastlab.io.batch.first_of_each_roast`). Where fewer than two logs
    can be read beside one that cannot (fit-roaster needs two: one to fit, one to hold out), the
    first unreadable log's error is raised, one line, as for any bad input."""
    infos, unreadable, first_error = [], {}, None
    for p in map(Path, paths):
        try:
            infos.append(inspect_log(p, batch_kg))
        except InputError as exc:
            first_error = first_error or exc
            where = f"{exc.where}: " if exc.where else ""
            unreadable[p.name] = f"{p.name} cannot be read as a roast ({where}{exc.problem})"
    if first_error is not None and len(infos) < 2:
        raise first_error
    infos, copies = first_of_each_roast(infos, lambda i: i.started_epoch_s, lambda i: i.path.name)
    return infos, {**unreadable, **copies}


def survey(paths, batch_kg: float | None = None, units: dict | None = None) -> Survey:
    """Inspect every log; refuse logs that disagree (formats, channels, machines) or have no
    batch mass, each with one message saying what to pass. A log that cannot be read as a roast
    is left out and named (:func:`readable_logs`). ``units`` (``{"heater": "kPa"}``, the roaster's
    word, :data:`CONTROL_UNITS`) sets a control's unit in place of what its name and values say."""
    passed_over: dict[str, str] = {}
    paths = log_paths(paths, passed_over)
    if not paths:
        raise InputError("give the roast logs of one roaster", "command line")
    infos, unreadable = readable_logs(paths, batch_kg)
    first = infos[0]
    kinds = {i.format for i in infos}
    if len(kinds) > 1:
        odd = next(i for i in infos if i.format != first.format)
        raise InputError(
            f"the logs disagree on formats ({', '.join(sorted(kinds))}): {first.path.name} vs {odd.path.name}. "
            "Set up one roaster (one layout) at a time",
            odd.path,
        )
    # a control the logs name differently (an Artisan event type renamed between roasts) is one
    # control if every name reads in one unit: the map lists its names, the most used first, and each
    # log is read by the first it has. A log without a control's events (the setting never moved while
    # Artisan recorded) does not say what the setting was: the map keeps the channel the other logs
    # name, fit-roaster leaves that log out (logs_without_controls). The names, the most used first
    # (a tie: the first log's first), are those of every readable log, weighed or not
    uses = {what: Counter(getattr(i, what) for i in infos if getattr(i, what)) for what in ("heater", "fan")}
    control_names = {what: [name for name, _ in uses[what].most_common()] for what in uses}
    heater, fan = (control_names[what][0] if control_names[what] else None for what in ("heater", "fan"))
    renamed = {what: n for what, n in control_names.items() if len(n) > 1}
    for what, n in renamed.items():
        by_name = {
            name: _unit_of(np.concatenate(v), name)
            for name in n
            if (v := [i.seen[what] for i in infos if getattr(i, what) == name and what in i.seen])
        }
        one, odd = (next(i for i in infos if getattr(i, what) == name) for name in n[:2])
        if first.columns is not None:  # a plain CSV's map names its one column
            raise InputError(
                f"the CSV logs name the {what} column differently ({', '.join(n)}): {one.path.name} vs "
                f"{odd.path.name}. A CSV map names one column: give the column one name in every log",
                odd.path,
            )
        if len(set(by_name.values())) > 1:
            raise InputError(
                f"the logs disagree on {what} channels ({', '.join(f'{k} in {u}' for k, u in by_name.items())}): "
                f"{one.path.name} vs {odd.path.name}. Set up one roaster (one layout) at a time",
                odd.path,
            )
    layout = ("time", "time_unit", "BT", "temp_unit")  # ET may be unreadable on some logs (has_et says)
    if first.columns is not None and any(
        [i.columns[k] for k in layout] != [first.columns[k] for k in layout] for i in infos
    ):
        odd = next(i for i in infos if [i.columns[k] for k in layout] != [first.columns[k] for k in layout])
        raise InputError(
            f"the CSV logs name their columns differently ({first.path.name} vs {odd.path.name}): one layout at a time",
            odd.path,
        )
    machines = {i.machine for i in infos if i.machine}
    if len(machines) > 1:
        raise InputError(f"the logs name different roasters ({', '.join(sorted(machines))}): one at a time")
    unweighed = logs_without_weight(infos)
    if unweighed and len(infos) - len(unweighed) < 2:
        missing = list(unweighed)
        raise InputError(
            f"no green weight in {len(missing)} log(s) ({', '.join(missing[:3])}{' ...' if len(missing) > 3 else ''}) "
            "and none in the file name: pass --batch-kg"
        )
    infos = [i for i in infos if i.path.name not in unweighed]  # the set-up reads the weighed logs
    pooled = {
        what: np.concatenate(seen)
        for what in ("heater", "fan")
        if (seen := [i.seen[what] for i in infos if what in i.seen])
    }
    heater_unit, fan_unit = (
        _unit_of(pooled[what], name) if what in pooled else None for what, name in (("heater", heater), ("fan", fan))
    )
    in_tens = {what: _in_whole_tens(v) for what, v in pooled.items()}
    if first.format in ("alog", "artisan-csv") and len(machines) == 1 and artisan_shows_tens(next(iter(machines))):
        # Artisan's setup for this machine shows its levels in tens: a percent in whole tens is those levels
        heater_unit, fan_unit = (
            "tens" if unit == "percent" and in_tens.get(what) else unit
            for unit, what in ((heater_unit, "heater"), (fan_unit, "fan"))
        )
    notes = [f"left out: {why}" for why in (*passed_over.values(), *unreadable.values())]
    given = {what: u for what, u in (units or {}).items() if u is not None}
    unit_of, name_of = {"heater": heater_unit, "fan": fan_unit}, {"heater": heater, "fan": fan}
    for what, unit in given.items():
        if unit not in CONTROL_UNITS[what]:
            raise InputError(f"--{what}-unit {unit}: one of {', '.join(CONTROL_UNITS[what])}", "command line")
        if what not in pooled:
            raise InputError(f"--{what}-unit {unit}: the logs have no {what} setting to read in it", "command line")
        if unit != unit_of[what]:
            notes.append(
                f"the {what} ({name_of[what]}) read in {unit}, as given (its name and values read as {unit_of[what]})"
            )
        unit_of[what] = unit
    for what, unit in unit_of.items():
        if unit == "reading" and what not in given:
            notes.append(
                f"the {what} ({name_of[what]}) logs decimals never above {pooled[what].max():g}: no percent a "
                f"roaster roasts with, so it is read as it is, over its logged range; if you know its unit, "
                f"init --{what}-unit UNIT says it ("
                + (
                    "a gas pressure: kPa, mbar, inWC ...)"
                    if what == "heater"
                    else "a drive frequency: Hz; a draft: Pa ...)"
                )
            )
    heater_unit, fan_unit = unit_of["heater"], unit_of["fan"]
    for what, n in renamed.items():
        notes.append(
            f"the logs name the {what} differently ({', '.join(f'{k}: {uses[what][k]} log(s)' for k in n)}): read as "
            f"one {what}, each log by the name it has; if these are two roasters, set them up apart"
        )
    if unweighed:
        names = list(unweighed)
        notes.append(
            f"{len(names)} log(s) record no green weight, nor one in the file name ({', '.join(names[:3])}"
            f"{' ...' if len(names) > 3 else ''}): fit-roaster leaves them out (--batch-kg gives them one)"
        )
    if fan_unit == "W":  # above 100 and not in tens: a fan's speed readout, whose flow rises in proportion
        fan_unit = "rpm"
        notes.append(
            f"the {fan} channel reads above 100 (up to {pooled['fan'].max():g}), neither a percent nor a level: "
            "taken as the fan's speed in rpm, the air flow rising in proportion to it (the fan laws); "
            "set its unit in the map if it is not"
        )
    if fan and find_name([fan], OTHER_NAMES["damper"]):
        notes.append(
            f"no fan channel: the {fan} sets the air flow through the drum, so the map takes it as the fan "
            "(the model's flow rises with it)"
        )
    lacking = {what: list(logs_without_controls(infos, {what: control_names[what]})) for what in ("heater", "fan")}
    for what, logs in lacking.items():
        if logs:
            notes.append(
                f"{len(logs)} log(s) record no {' or '.join(control_names[what])} ({', '.join(logs[:3])}"
                f"{' ...' if len(logs) > 3 else ''}): their {what} setting is unknown, so fit-roaster leaves them out"
            )
    if lacking["heater"] and len(infos) - len(lacking["heater"]) < 2:
        raise InputError(
            f"only one log records the {heater} setting: fit-roaster needs two (one to fit, one to hold out)", "init"
        )
    if first.columns is not None:
        c = first.columns
        notes.append(
            f"CSV: time {c['time']!r} [{c['time_unit']}], BT {c['BT']!r}"
            + (f", ET {c['ET']!r}" if c["ET"] else ", no ET")
            + f" [deg{c['temp_unit']}], by their names; each log's first row is taken as CHARGE"
            + (f"; not read (not numbers): {', '.join(c['not read'])}" if c.get("not read") else "")
        )
    named = [i for i in infos if i.unit]
    serials = Counter(i.unit for i in named)
    if len(serials) > 1:
        notes.append(
            f"the logs come from {len(serials)} units of this roaster (serial number: logs; {unit_counts(named)}): "
            "one fit treats them as one drum, so the differences between units count as its error; "
            f"fit one unit's logs for that unit's model (fit-roaster --unit {serials.most_common(1)[0][0]})"
        )
    inlets = {i.inlet for i in infos}
    inlet = inlets.pop() if len(inlets) == 1 else None  # every log records it, under one name
    if inlet is None and inlets - {None}:
        notes.append(
            f"{sum(i.inlet is not None for i in infos)} of {len(infos)} log(s) record the inlet air "
            f"({', '.join(sorted(inlets - {None}))}): not used, as the others do not"
        )
    told = [i for i in infos if i.et_reads_beans is not None]  # logs whose ET can tell beans from air
    beans = [i.path.name for i in told if i.et_reads_beans]
    et_is_bean = bool(told) and len(beans) == len(told)
    if et_is_bean:
        notes.append(
            f"ET falls to the green beans' temperature at CHARGE on {'every log' if len(told) > 1 else 'the log'}: "
            "it reads the beans (an infrared bean sensor, as Artisan's Aillio Bullet R1 IBTS device logs ET), "
            "not the drum's air, so the map fits it as a second bean reading ([Tb2]) against the model's beans"
        )
    elif beans:
        notes.append(
            f"ET falls to the green beans' temperature at CHARGE on {len(beans)} log(s) ({', '.join(beans[:3])}"
            f"{' ...' if len(beans) > 3 else ''}), unlike the others: a bean sensor there, not the drum's air; "
            "set up those logs apart"
        )
    # weighed against the model's air, an ET that is the drum's air on no log would pull the fit off
    unit = logs_temp_unit(infos)  # the notes' temperatures in the unit the logs were recorded in
    differences = [i.et_minus_bt_C if i.has_et else None for i in infos]
    et_below_bt = not et_is_bean and et_below_bt_on_every_log(differences)
    if et_below_bt:
        notes.append(
            f"ET reads below BT through the roast on every log (by {display_temp_delta(-max(differences), unit):.0f} "
            f"to {delta_text(-min(differences), unit, 0)}): not the drum's air, which "
            "runs above the beans it heats, so the "
            "map does not use it; if ET and BT are swapped in the device setup, swap them back and run init again"
        )
    odd = (
        []
        if et_is_bean or et_below_bt
        else [i.path.name for i, bad in zip(infos, et_not_drum_air([i.et_minus_bt_C for i in infos])) if bad]
    )
    et_drives = not heater and inlet is None  # map_text then takes ET as the inlet air that drives the model
    if odd:
        notes.append(
            f"ET reads below BT through the roast on {len(odd)} log(s) ({', '.join(odd[:3])}{' ...' if len(odd) > 3 else ''}), "
            "unlike the others: not the drum's air there, so the map drops ET on such logs ([ET] above_BT)"
            + (
                "; with no heater logged ET is the inlet air that drives the model, so fit-roaster leaves them out"
                if et_drives
                else ""
            )
        )
    second_bean = first.second_bean or (((first.columns or {}).get("ET") or "ET") if et_is_bean else None)
    marked = sum(i.marks_first_crack for i in infos)
    first_crack = second_bean is None and 2 * marked > len(infos)
    if first_crack:
        notes.append(
            f"no bean reading but the probe; {marked} of {len(infos)} log(s) mark first crack, where the beans are at "
            f"about {display_temp(FIRST_CRACK_BEAN_C, unit):.0f} {temp_symbol(unit)}: the map reads each mark as the beans' temperature then ([Tb2] "
            "first_crack), so the fit cannot put the beans where coffee does not crack"
        )
    has_et = all(i.has_et for i in infos) and not et_is_bean and not et_below_bt
    if et_drives and has_et:
        notes.append(
            "no heater setting in the logs: ET drives the model as the inlet air, but a burner or element also "
            "heats the drum itself, which the air does not show, so the fit is weak or fails (docs/your-roaster.md, "
            f'"No heater in the logs"); {LOG_THE_HEATER} for a model that follows the roaster'
        )
    fan_at = _one_setting(pooled.get("fan")) if fan else None
    if fan_at is not None:
        notes.append(
            f"the {fan} sits at {fan_at:g} in every log: its share of the air flow cannot be told from the base "
            "flow, so the fit does not free it (the model's flow stays one constant)"
        )
    return Survey(
        infos,
        first.format,
        machines.pop() if machines else "",
        heater,
        heater_unit,
        fan,
        fan_unit,
        second_bean,
        has_et,
        max(i.heater_max for i in infos),
        max(i.fan_max for i in infos),
        {k: v for i in infos for k, v in i.unused.items()},
        notes,
        odd,
        sum(i.room is not None for i in infos),
        bare_room_unit(i.room for i in infos),
        first.columns,
        batch_kg,
        list(unweighed),
        et_is_bean,
        in_tens,
        inlet,
        et_below_bt,
        fan_at=fan_at,
        first_crack=first_crack,
        renamed=renamed,
        given=given,
    )


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string (JSON's escapes are TOML's): a channel name from a log may hold a
    quote or a backslash."""
    return json.dumps(text, ensure_ascii=False)


def _one_setting(values) -> float | None:
    """The setting every logged value is (a control that never moved in any log), else None."""
    v = np.unique(np.asarray(values, dtype=float)[np.isfinite(values)]) if values is not None else np.array([])
    return float(v[0]) if v.size == 1 else None


def _catalogued(machine: str) -> tuple[Machine, float] | None:
    """The first :data:`CATALOGUE` entry that names ``machine`` (Artisan's ``roastertype``) with its
    rated batch [kg], or None for a machine the catalogue does not know."""
    return next(((e, cap) for e in CATALOGUE if (cap := e.capacity(machine)) is not None and cap > 0), None)


def catalogue_entry(machine: str) -> tuple[float, str, str] | None:
    """``(rated batch [kg], heat path, source)`` of the catalogue's entry for ``machine``, or None."""
    found = _catalogued(machine)
    return None if found is None else (found[1], found[0].heat, found[0].source)


def artisan_shows_tens(machine: str) -> bool:
    """Whether Artisan's setup for ``machine`` (its ``roastertype``) shows the machine's levels in
    tens (:attr:`Machine.tens` of its catalogue entry)."""
    found = _catalogued(machine)
    return found is not None and found[0].tens


def batch_capacity(s: Survey, capacity_kg=None) -> tuple[float, str]:
    """The roaster's rated green batch [kg] and where it comes from: given, the capacity the logs
    state (Artisan's Roast Properties; the most common when they differ; none below a logged batch),
    the catalogue entry of the logs' machine, or ESTIMATED as twice the largest logged batch."""
    entry = catalogue_entry(s.machine) if s.machine else None
    if capacity_kg is not None:
        return capacity_kg, "--batch-capacity-kg"
    largest = max(i.batch_kg for i in s.logs)
    stated = Counter(i.capacity_kg for i in s.logs if i.capacity_kg and i.capacity_kg >= largest)
    if stated:
        cap, k = stated.most_common(1)[0]
        return cap, f"the capacity {k} of {len(s.logs)} log(s) state (Artisan's Roast Properties)"
    if entry is not None:
        return entry[0], f"the catalogue: {entry[2]}"
    return 2.0 * largest, "ESTIMATED as twice the largest logged batch (pass --batch-capacity-kg)"


#: A roaster's name where neither the roaster nor its logs give one.
DEFAULT_ROASTER_NAME = "my-roaster"


def roaster_name(given: str | None, machine: str | None, folder: str | Path | None = None) -> str:
    """The plant's name: ``given`` (the roaster's choice), else the make the logs record (``machine``),
    else the output ``folder``'s name, else :data:`DEFAULT_ROASTER_NAME`; lower case, runs of anything
    but letters and digits as one "-".

    >>> roaster_name(None, "Aillio Bullet", "out/mybullet"), roaster_name("Probat L12", "Aillio Bullet")
    ('aillio-bullet', 'probat-l12')
    >>> roaster_name(None, None, "roasters/mysky"), roaster_name("", None, "..")
    ('mysky', 'my-roaster')
    """
    for text in (given, machine, Path(folder).name if folder else None):
        name = re.sub(r"[^a-z0-9]+", "-", (text or "").lower()).strip("-")
        if name:
            return name
    return DEFAULT_ROASTER_NAME


def estimate_plant(
    s: Survey, capacity_kg=None, diameter_m=None, length_m=None, name: str | None = None
) -> tuple[dict, list[str]]:
    """The plant's geometry and the comment lines that say where each number comes from; ``name``: the
    plant's (:func:`roaster_name`; default the make the logs record, else :data:`DEFAULT_ROASTER_NAME`)."""
    masses = [i.batch_kg for i in s.logs]
    cap, why = batch_capacity(s, capacity_kg)
    notes = [f"batch capacity {cap:g} kg: {why}"]
    if diameter_m is None:
        volume = cap / (GREEN_BULK_DENSITY_KG_M3 * RATED_FILL)
        diameter_m = (4.0 * volume / (math.pi * LENGTH_OVER_DIAMETER)) ** (1.0 / 3.0)
        notes.append(
            f"drum diameter ESTIMATED: a drum that holds {cap:g} kg at a {RATED_FILL:.0%} fill "
            f"({volume * 1000:.1f} L, length {LENGTH_OVER_DIAMETER:g} diameters); pass --drum-diameter-m"
        )
    if length_m is None:
        length_m = LENGTH_OVER_DIAMETER * diameter_m
        notes.append(f"drum length ESTIMATED as {LENGTH_OVER_DIAMETER:g} diameters; pass --drum-length-m")
    notes.append(
        f"vanes ESTIMATED {VANE_HEIGHT_OVER_D:.3g} D high at {VANE_PITCH_OVER_D:g} D pitch; metal "
        f"{METAL_KG_PER_KG:g} kg per kg of capacity (drum, vanes and front plate in thermal contact)"
    )
    plant = {
        "name": name or roaster_name(None, s.machine),
        "Mb_kg": round(float(np.median(masses)), 4),
        "Dch_m": round(diameter_m, 4),
        "Lch_m": round(length_m, 4),
        "Hflap_m": round(VANE_HEIGHT_OVER_D * diameter_m, 4),
        "Sflap_m": round(VANE_PITCH_OVER_D * diameter_m, 4),
        "Mm_kg": round(METAL_KG_PER_KG * cap, 3),
    }
    return plant, notes


def _setting_span(unit: str, top: float) -> float:
    """The range of a logged setting: 0..100 for percent, 0..the highest logged value otherwise (a
    level, also in tens, a power, a speed, a gas pressure, which may top out under 1 psi; 1 where
    nothing above 0 was logged)."""
    return 100.0 if unit == "percent" else (top if top > 0 else 1.0)


#: A setting's drive as a power of it where the setting is a pressure (rhs.heater_drive, rhs.fan_drive):
#: the exponent and why, per control.
PRESSURE_DRIVES = {
    "heater": (PRESSURE_HEATER_EXP, "a gas burner's heat goes as the square root of its pressure (its gas flow through the jet, an orifice)"),
    "fan": (PRESSURE_FAN_EXP, "the air flow a draft drives through the drum goes as its square root"),
}  # fmt: skip


def _drive_law(what: str, unit: str, top: float, per: str, fixed: list) -> tuple[float, str]:
    """The span over which a setting's gain is bounded and the unit its gain is per: a setting logged
    as a pressure drives as its power (``heater_exp``/``fan_exp`` of :data:`PRESSURE_DRIVES`, the line
    appended to the fit spec's ``fixed`` table), its gain per unit^exp; any other in proportion."""
    exp, why = PRESSURE_DRIVES[what] if unit in PRESSURE_UNITS else (1.0, "")
    if exp != 1.0:
        fixed.append(f"{what}_exp = {exp:g}".ljust(38) + f"# {why}")
        per = f"{per}^{exp:g}"
    return _setting_span(unit, top) ** exp, per


def map_text(s: Survey) -> str:
    """The column map, commented with what was detected."""
    lines = [
        "# Written by roastlab init from "
        + ", ".join(i.path.name for i in s.logs[:3])
        + (" ..." if len(s.logs) > 3 else ""),
        f"# format: {s.format}; roaster: {s.machine or '(not named in the logs)'}",
        f'format = "{s.format}"',
        "resample_s = 5.0      # fits fast and loses nothing at roasting time scales",
        *(
            [f"batch_kg = {s.batch_kg:g}        # --batch-kg: the green weight of a log that records none"]
            if s.batch_kg
            else []
        ),
        "",
    ]
    cols = s.columns  # a plain CSV names its own columns and units; Artisan's are BT and ET in degC
    if cols:
        lines += ["[time]", f'column = "{cols["time"]}"', f'unit = "{cols["time_unit"]}"', ""]
    lines += ["[Ta]", f'column = "{cols["BT"] if cols else "BT"}"         # the bean probe']
    lines += [f'unit = "{cols["temp_unit"]}"', ""] if cols else [""]
    et, et_unit = (cols["ET"], f'\nunit = "{cols["temp_unit"]}"') if cols else ("ET", "")
    room_air = bool(s.heater)
    inlet_unit = f'\nunit = "{cols["temp_unit"]}"' if cols else ""
    if room_air:
        lines += [
            "[Tgi]",
            f"constant_C = {default('T_room_C'):.1f}     # room air drawn into the drum: the heat comes from the heater",
        ]
        if s.inlet:  # an option: the heater is what a program decides
            lines += [
                f"# the logs also record the inlet air ({s.inlet!r}); to take it as the paper's input in place of "
                "the room air and the heater's air path, replace the line above with the one below and remove "
                "Tgi_gain_C from fit.toml's [free]:",
                f'# column = "{s.inlet}"',
            ]
        if s.rooms:  # an option, not the default: on the shared logs it helps one machine and not the other
            lines += [
                f"# {s.rooms} of {len(s.logs)} logs record the room temperature; to take the inlet air from it "
                "(the constant where a log has none), uncomment (docs/real-roaster.md measures both ways):",
                "# room = true",
            ]
            if s.room_unit:
                lines.append(
                    f'# room_unit = "{s.room_unit}"    # the unit of a bare number the owner typed'
                    + (" (some read as degC are no room's)" if s.room_unit == "F" else "")
                )
        lines.append("")
    elif s.inlet:
        lines += [
            "[Tgi]",
            f'column = "{s.inlet}"         # the logged inlet air, the paper\'s input (no heater logged){inlet_unit}',
            "",
        ]
    elif s.has_et:
        lines += ["[Tgi]", f'column = "{et}"         # no heater logged: ET taken as the inlet gas{et_unit}', ""]
    else:
        raise InputError("the logs have neither a heater setting nor ET: nothing drives the model", s.logs[0].path)
    lines += ["[Gg]", "identify = true       # the gas flow is not logged: a constant the fit identifies", ""]
    for name, col, unit, top in (
        ("heater", s.heater, s.heater_unit, s.heater_max),
        ("fan", s.fan, s.fan_unit, s.fan_max),
    ):
        if col:
            why = {
                "level": "by the logged values (whole steps)",
                "tens": "by the logged values (whole tens: the machine's levels as Artisan's setup for it shows them, in tens)",
                "percent": "by the logged values (percent)",
                "W": "by the logged values (above 100: a power in watts)",
                "rpm": "by the logged values (above 100: the fan's speed)",
                "reading": f"by the logged values (decimals, never above {top:g}: no percent a roaster "
                "roasts with; a reading in a unit the name does not give"
                + (
                    ". A gas pressure? init --heater-unit kPa (or its unit) fits the burner's square-root law)"
                    if name == "heater"
                    else ")"
                ),
            }.get(
                unit,
                f"as the name says ({unit}: {'a gas pressure' if unit in PRESSURE_UNITS else 'a drive frequency'})",
            )
            if name in s.given:
                why = f"as given (init --{name}-unit {unit})"
            column = (
                f"column = [{', '.join(map(toml_string, s.renamed[name]))}]      # detected by name; the logs name it "
                "differently: each log is read by the first name it has"
                if name in s.renamed
                else f"column = {toml_string(col)}      # detected by name"
            )
            lines += [
                f"[{name}]",
                column,
                f'unit = "{unit}"       # {why}',
            ]
            if unit != "percent":
                lines += ["min = 0", f"max = {top:g}                # the highest setting the logs use"]
            if unit in ("level", "tens"):
                lines.append(f"step = {UNIT_DEFAULTS[unit][2]:g}")
            elif unit == "percent" and not cols:
                if s.in_tens.get(name):  # levels in tens under a percent's name (the Bullet in Artisan: P0-P9 as 0-90)
                    lines += [f"max = {top:g}                # the highest setting the logs use",
                              "step = 10             # every log moves it in 10 % steps"]  # fmt: skip
                else:
                    lines.append("step = 5              # Artisan's slider in 5 % steps")
            lines.append("")
    for what, ch in s.unused.items():
        lines.insert(2, f"# logged but not used by the model: {what} ({ch!r})")
    if s.et_is_bean:
        lines += [
            "[Tb2]",
            f'column = "{s.second_bean}"   # ET reads the beans: it falls to the green beans at CHARGE (infrared)'
            + et_unit,
            f"start_s = {SECOND_BEAN_START_S:g}",
            "",
        ]
    elif s.second_bean:
        lines += [
            "[Tb2]",
            f'column = "{s.second_bean}"   # a second bean reading (infrared)',
            f"start_s = {SECOND_BEAN_START_S:g}",
            "",
        ]
    elif s.first_crack:
        lines += [
            "[Tb2]",
            f"first_crack = true   # the first-crack mark (FCs) as the beans at {FIRST_CRACK_BEAN_C:g} degC then",
            "",
        ]
    initial = []
    if s.format == "roastime":
        sources = ", ".join(f'"{c}"' for c in DRUM_AT_CHARGE)
        initial.append(
            f"Tm0_C = [{sources}]   # the drum at charge: the preheat it was held at, else the IR reading then"
        )
    elif cols:  # the first row is the charge: BT there, else ET (as for Artisan, ARTISAN_DRUM_AT_CHARGE)
        if s.has_et and (s.heater or s.inlet):  # ET a reading, not the inlet
            lines += ["[ET]", f'column = "{et}"       # the roaster\'s ET, weighed against the outlet gas{et_unit}']
            if s.et_not_air:
                lines.append(
                    f"above_BT = true        # ET reads below BT through the roast on {len(s.et_not_air)} log(s)"
                )
            lines.append("")
        sources = ", ".join(
            f'"{cols[k]}"' for k in ARTISAN_DRUM_AT_CHARGE if cols[k] and not (s.et_is_bean and k == "ET")
        )
        initial.append(
            f"Tm0_C = [{sources}]  # the drum at CHARGE: BT in the first row, the probe soaked in the empty drum"
        )
    elif s.et_is_bean:  # ET read the empty preheated drum before the beans came (as RoasTime's preheat)
        before = [ET_BEFORE_CHARGE] if any(i.et_before_charge for i in s.logs) else []
        sources = ", ".join(f'"{c}"' for c in (*before, "BT"))
        initial.append(
            f"Tm0_C = [{sources}]  # the drum at CHARGE: "
            + ("ET before it, the infrared sensor on the empty preheated drum, else " if before else "")
            + "BT then, the probe soaked in the drum"
        )
    else:
        if s.has_et and s.et_not_air:
            lines += [
                "[ET]",
                'column = "ET"',
                f"above_BT = true        # ET reads below BT through the roast on {len(s.et_not_air)} log(s), unlike "
                "the others: not the drum's air there, dropped on such logs",
                "",
            ]
        sources = ", ".join(f'"{c}"' for c in ARTISAN_DRUM_AT_CHARGE)
        initial.append(
            f"Tm0_C = [{sources}]  # the drum at CHARGE: BT then, the probe soaked in the empty preheated drum "
            "(steadier than ET), else ET"
        )
    if initial:
        lines += ["[initial]", *initial, ""]
    return "\n".join(lines)


def fit_spec_text(s: Survey, capacity_kg: float, diameter_m: float) -> str:
    """The fit spec, freeing what the logs can determine (module docstring), bounds from the table;
    ``diameter_m``: the drum's (the probe's depth scale, :data:`~roastlab.model.bed.PROBE_DEPTH_OVER_DIAMETER`)."""

    def line(name, lo, hi, start, why):
        return f"{name} = [{lo:g}, {hi:g}, {start:g}]".ljust(40) + f"# {why}"

    gg_hi = round(max(GAS_FLOW_MAX_FLOOR_KG_S, GAS_FLOW_MAX_KG_S_PER_KG * capacity_kg), 4)
    rows = [
        "# Written by roastlab init: what these logs can determine (see roastlab.workflows.survey).",
        "[free]",
        line("hgm", SMALL_COEFF_FLOOR, 1.0, 0.02, "gas-metal coefficient [kW/(m2 K)]"),
        line("hbm", SMALL_COEFF_FLOOR, 1.0, 0.02, "metal-bean coefficient [kW/(m2 K)]"),
        line("Pbm", 0.05, 0.95, 0.5, "bean area touching metal [-]"),
        line("Gg_kg_s", GAS_FLOW_MIN_KG_S, gg_hi, gg_hi / 10, "gas flow [kg/s] (not logged)"),
        line("Kt", 0.002, 0.2, 0.02, "bean-probe inverse time constant [1/s]"),
    ]
    if s.second_bean:  # a bean reading beside the probe pins the beans' exotherm (EXOTHERM_LAW)
        rows.append("# a second bean reading pins the beans' exothermic rate law (eq. 14); the paper's is the start")
        for name in EXOTHERM_LAW:
            q = quantity(name)
            rows.append(line(name, *q.bounds, q.default, f"{q.meaning} [{q.unit}]"))
    entry = catalogue_entry(s.machine) if s.machine else None
    # BT alone cannot tell the heater's two paths apart (a fit free to use both can heat the beans
    # through the air with the drum colder than they are, and fails): without ET to tell them
    # apart, the heater heats the drum, the path of a drum roaster and the one the Skywalker's fit
    # with ET chooses (docs/your-roaster.md, "No ET in the logs")
    path = entry[1] if entry else ("both" if s.has_et else "drum")
    if s.heater and path == "drum" and not entry:
        rows.append("# no ET logged to tell the heater's paths apart: the heater heats the drum metal alone")
    fixed = []  # the [fixed] table's lines
    if s.heater:
        per = {"tens": "logged unit, a level is 10", "reading": "logged unit"}.get(s.heater_unit, s.heater_unit)
        span, per = _drive_law("heater", s.heater_unit, s.heater_max, per, fixed)
        qe_hi = round(10.0 * capacity_kg / span, 4)  # ~10 kW per kg of capacity at full setting, generous
        if s.heater_unit == "W":  # a power readout: the drum gets at most all of it
            qe_hi = KW_PER_W
        if path in ("drum", "both"):
            rows.append(
                line("Qe_gain_kW", 0.0, qe_hi, qe_hi / 10, f"heater -> heat into the drum metal [kW per {per}]")
            )
        if path in ("air", "both"):
            rows.append(
                line(
                    "Tgi_gain_C",
                    0.0,
                    round(1000.0 / span, 4),
                    round(200.0 / span, 4),
                    f"heater -> the air it heats [degC per {per}]",
                )
            )
        rows.append(line("tau_heater_s", 1.0, 300.0, 30.0, "lag of the heater's effect [s]"))
        rows.append(line("U_shell_kW_m2K", 0.0, 0.1, 0.01, "drum shell heat loss to the room [kW/(m2 K)]"))
    # the probe soaked in the empty drum reads short of the drum (roastlab.model.rhs.drum_at_charge_C); only
    # where a heater drives the model: with ET as the inlet a free share stands in for the heater the logs
    # lack (six Skywalker logs without their events: on its floor, the drum at 389 degC at CHARGE)
    if s.heater and s.drum_start_from_probe:
        q = quantity("Tm0_share")
        why = "share of the drum's rise over the room BT shows at CHARGE [-]"
        rows.append(line("Tm0_share", *q.bounds, TM0_SHARE_START, why))
    depth_m = (
        f"{PROBE_DEPTH_OVER_DIAMETER * diameter_m:.4g}"  # the probe's depth scale, held (and where freed, started)
    )
    masses = [i.batch_kg for i in s.logs if i.batch_kg]
    spans_sizes = spans_batch_sizes(masses)
    span_g = f"{min(masses) * 1e3:.0f}-{max(masses) * 1e3:.0f} g" if masses else ""
    # Only a change of batch size determines the probe's depth scale. Where no bean reading runs beside the
    # probe, it is also what tells the probe from the beans: held at the diameter, the Skywalker's probe reads
    # mostly air and the fit lumps beans and metal (hbm on its ceiling, the beans at 108 degC 5 s after
    # CHARGE); freed, it predicts as well (each log held out once 83.1 % either way) with hbm inside the
    # paper's range and the beans at 44 degC at 5 s. A bean reading (the Bullet's IR) pins the beans, and
    # there the freed scale predicted worse (80.4 % against 81.2 %): held (docs/real-roaster.md).
    fit_depth = spans_sizes and not s.second_bean
    if fit_depth:
        lo, hi = quantity("h_probe_m").bounds
        rows.append(
            line(
                "h_probe_m",
                lo,
                hi,
                float(depth_m),
                f"bed depth that covers the probe [m], from the drum's diameter: these logs span {span_g} "
                "and no bean reading runs beside the probe",
            )
        )
    if s.fan and s.fan_at is not None:
        # Gg + Gg_fan fan with one fan setting in every log: the two cannot be told apart
        rows.append(
            f"# the fan sits at {s.fan_at:g} in every log: its share of the flow cannot be told from the base "
            "flow Gg_kg_s, so it is not fitted (logs that move the fan can fit Gg_fan_kg_s)"
        )
    elif s.fan and s.fan_unit in ("level", "tens"):
        step = UNIT_DEFAULTS[s.fan_unit][2]  # per unit of the logged value: a level shown in tens is ten of them
        why = (
            "air flow per fan step [kg/s]" if step == 1 else f"air flow per logged fan unit [kg/s] (a step is {step:g})"
        )
        rows.append(line("Gg_fan_kg_s", 0.0, 0.01 / step, 0.001 / step, why))
    elif s.fan:  # every other unit (init reads a fan in W as its speed in rpm, and never in kW)
        # the flow rises with the fan (or damper) the roaster moves through the roast: at full setting it
        # adds at most the largest base flow, a tenth of that to start (rhs.gas_inputs, Gg + Gg_fan fan);
        # a speed in rpm: in proportion to it (the fan laws: volume flow ~ speed), the highest logged as full
        per = {"percent": "%", "reading": "logged unit"}.get(s.fan_unit, s.fan_unit)
        span, per = _drive_law("fan", s.fan_unit, s.fan_max, per, fixed)
        hi, start = (float(f"{x:.3g}") for x in (gg_hi / span, gg_hi / span / 10))
        rows.append(line("Gg_fan_kg_s", 0.0, hi, start, f"air flow per {per} of the fan [kg/s]"))
    rows += ["", "[initial]", f"Tb0_C = {default('T_room_C'):.1f}                          # green beans at room temperature",
             "X0 = 0.11                             # typical green-coffee moisture [kg/kg dry]"]  # fmt: skip
    rows += [  # the probe's immersion in the bed: the laws and depth scale cross-validation chose
        "",
        "# The probe in a tumbling bed, its uncovered part in the bed's air: the laws chosen by",
        "# cross-validation on both real roasters (roastlab.model.bed.CROSS_VALIDATED, docs/real-roaster.md)",
        "[bed]",
        *(f'{k} = "{v}"' for k, v in CROSS_VALIDATED.as_dict().items()),
    ]
    if not fit_depth:
        fixed.append(
            f"h_probe_m = {depth_m}".ljust(38)
            + "# bed depth that covers the probe [m]: the drum's diameter; only other batch sizes determine it",
        )
    if fixed:
        rows += ["", "[fixed]", *fixed]
    if spans_sizes and not fit_depth:
        lo, hi = quantity("h_probe_m").bounds
        rows += [
            f"# these logs span {span_g}, which can determine it: to fit it, move it "
            f"to [free] as h_probe_m = [{lo:g}, {hi:g}, {depth_m}]",
            "# and compare the two with 'roastlab compare-models --group-by log' (with the bean reading beside the probe",
            '# it predicted worse on the Bullet: docs/real-roaster.md, "Skywalker: the probe half in the bed")',
        ]
    weights = []
    if s.second_bean:
        weights.append("Tb2 = 1.0                             # the second bean reading vs the model's Tb")
    elif s.first_crack:
        weights.append(
            f"Tb2 = {FIRST_CRACK_WEIGHT:g}".ljust(38) + "# the first-crack mark vs the model's Tb, against the probe's "
            "samples at 1 (roastlab.model.parameters.FIRST_CRACK_WEIGHT)"
        )
    if s.has_et and (s.heater or s.inlet):
        # ET is then a reading, not the inlet (map_text): fitted against the outlet gas, it tells the
        # heater's paths (into the air, into the drum) apart, which BT alone cannot, and pins the
        # air's heat to the beans where the inlet is logged; weighed by its residuals against the probe's
        # (fit.identify.residual_weights), so the model's coarser reading of the air does not pull the beans
        weights.append(
            f'ET = "{RESIDUAL_WEIGHT}"'.ljust(38) + "# the logged ET vs the model's outlet gas Tgo, weighed "
            "by the probe's residual variance over its own (a first fit at weight 1)"
        )
    if weights:
        rows += ["", "[weights]", "Ta = 1.0", *weights]
    return "\n".join(rows) + "\n"


#: What a fleet fit frees per batch on a roaster ``init`` set up, each the first of its choices that
#: the fit spec frees: the heater's heat into the drum (a weakening heater) or, without a heater, the
#: metal-bean coefficient (a fouling drum), and the probe's time constant (a probe fouling with oils);
#: the Skywalker's fleet spec frees the same two (docs/fleet.md). Everything else comes from the model file.
FLEET_FREE = (("Qe_gain_kW", "hbm"), ("Kt",))


def fleet_spec_text(fit_text: str) -> str:
    """The fleet spec beside ``fit_text`` (a fit spec's text): :data:`FLEET_FREE`'s names with their
    lines of its [free] table as they are (bounds, start and comment), to fit each batch under the
    model ``fit-roaster`` writes from that spec."""
    # the [free] table's lines by the name they set (a comment line's key is never a name)
    lines = {ln.split("=", 1)[0].strip(): ln for ln in fit_text.split("[free]", 1)[1].split("\n[", 1)[0].splitlines()}
    names = [next(n for n in choice if n in lines) for choice in FLEET_FREE if any(n in lines for n in choice)]
    return (
        "\n".join(
            [
                "# Written by roastlab init: what a fleet fit frees per batch (roastlab.workflows.survey.FLEET_FREE),",
                "# under the machine model 'roastlab fit-roaster' writes (model.json in this folder), which holds the rest:",
                "#   roastlab fleet fit --db FLEET.duckdb --spec MACHINE=fleet.toml --model MACHINE=model.json",
                "[free]",
                *(lines[n] for n in names),
            ]
        )
        + "\n"
    )


def plant_text(plant: dict, notes: list[str]) -> str:
    lines = ["# Written by roastlab init. " + "; ".join(notes[:1])] + [f"# {n}" for n in notes[1:]]
    lines.append(f'name = "{plant["name"]}"')
    for k in ("Mb_kg", "Dch_m", "Lch_m", "Hflap_m", "Sflap_m", "Mm_kg"):
        lines.append(f"{k} = {plant[k]:g}")
    return "\n".join(lines) + "\n"


def init_roaster(
    paths, out_dir, *, batch_kg=None, capacity_kg=None, diameter_m=None, length_m=None, units=None, name=None
) -> dict:
    """Survey the logs and write ``out_dir``/map.toml, plant.toml, fit.toml and fleet.toml; returns a summary.
    ``units``: a control's unit as the roaster gives it (:func:`survey`); ``name``: the roaster's, in its
    plant, model and report (:func:`roaster_name`: default the make its logs record, else ``out_dir``'s name)."""
    from ..io.files import Outputs

    s = survey(paths, batch_kg, units)
    paths = log_paths(paths)
    plant, notes = estimate_plant(s, capacity_kg, diameter_m, length_m, roaster_name(name, s.machine, out_dir))
    cap, _ = batch_capacity(s, capacity_kg)
    out = Path(out_dir)
    with Outputs(list(paths)) as o:
        o.folder(out)
        o.write_text(out / "map.toml", map_text(s) + "\n")
        o.write_text(out / "plant.toml", plant_text(plant, notes))
        fit_text = fit_spec_text(s, cap, plant["Dch_m"])
        o.write_text(out / "fit.toml", fit_text)
        o.write_text(out / "fleet.toml", fleet_spec_text(fit_text))
    return {"survey": s, "plant": plant, "notes": notes}


#: How the per-unit lines name the logs that record no roaster unit (an Artisan log among RoasTime's).
UNNAMED_UNIT = "(none named)"


def unit_counts(infos) -> str:
    """The roaster units the logs name and each one's number of logs, the most first: "2779: 22, 2054: 2"
    (RoasTime's serial number, :attr:`LogInfo.unit`; a log that names none counts as :data:`UNNAMED_UNIT`)."""
    return ", ".join(f"{u}: {k}" for u, k in Counter(i.unit or UNNAMED_UNIT for i in infos).most_common())


def logs_without_weight(infos) -> dict[str, str]:
    """The logs whose green weight is unknown (none in the log, its file name or ``--batch-kg``),
    each with why; ``{name: why}``. The model scales with the batch, so a log of unknown batch cannot
    be fitted or scored: ``init`` names them, ``fit-roaster`` leaves them out."""
    return {
        i.path.name: f"{i.path.name} records no green weight, nor one in its file name (its batch is unknown)"
        for i in infos
        if i.batch_kg is None
    }


def logs_without_controls(infos, controls: dict) -> dict[str, str]:
    """The logs that do not record a setting the model is driven with (``controls``: ``{"heater":
    channel, "fan": channel}``, a channel a name or a list of names (:func:`names_of`), None or empty
    for none; a channel with no events: Artisan logs a setting only when it moves), each with why;
    ``{name: why}``. ``init`` names them, ``fit-roaster`` leaves them out."""
    out = {}
    for info in infos:
        for what, channel in controls.items():
            if channel and not set(names_of(channel)) & set(info.channels):
                out[info.path.name] = (
                    f"{info.path.name} records no {' or '.join(names_of(channel))} (its {what} setting is unknown: "
                    "Artisan logs a setting only when it moves)"
                )
                break
    return out


def spans_batch_sizes(masses) -> bool:
    """Whether green batch masses [kg] fall in more than one of ``compare-models``' size groups
    (:func:`roastlab.evaluate.metrics.size_labels`)."""
    masses = [m for m in masses if m]
    return bool(masses) and len(set(size_labels(masses)[0])) > 1
