"""Batch files: the canonical input CSV, validation, and dataset folders.

A batch CSV has a header row and columns ``time_s, Gg_kg_s, Tgi_C`` and optionally ``Ta_C``
(the measured probe reading); other columns are ignored. Time must increase strictly, every
value must be a finite number, Gg > 0 and temperatures within -50..1000 degC. Each problem is
reported as an :class:`~roastlab.errors.InputError` naming the file, line and column.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
from array import array
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, ParameterError
from ..metrics.profile import clock_s
from ..model.limits import check_array, check_value
from .files import as_path, atomic_write_text, read_input_text, read_toml

REQUIRED_COLUMNS = ("time_s", "Gg_kg_s", "Tgi_C")
#: Optional columns: the probe reading, the actuator settings (the actuator extension) and a
#: second bean reading compared with the model's Tb (e.g. an infrared bean-surface channel) and
#: the roaster's ET as logged (shown beside the model's, never an input).
OPTIONAL_COLUMNS = ("Ta_C", "heater", "fan", "Tb2_C", "ET_C")
#: Columns whose empty cells mean "not measured here" (read as NaN, written empty).
SPARSE_COLUMNS = ("Tb2_C", "ET_C")


@dataclass
class Batch:
    """One roast: sampled inputs and (optionally) the measured probe temperature.

    Attributes
    ----------
    name : str
    time_s : (n,) array, strictly increasing [s]
    Gg_kg_s : (n,) array, inlet gas mass flow [kg/s]
    Tgi_C : (n,) array, inlet gas temperature [degC]
    Ta_C : (n,) array or None, measured bean-probe temperature [degC]
    source : path it was read from, if any
    initial : per-batch initial-state overrides (e.g. ``{"Tm0_C": 105.0}``)
    Mb_kg : green batch mass [kg] if it differs from the plant's (read from a
        ``# Mb_kg = ...`` comment line of a batch CSV, or from an Artisan log's weight)
    heater, fan : (n,) arrays or None, logged settings (the actuator extension), held between
        changes; units as the map declares (percent, levels or kW)
    Tb2_C : (n,) array or None, a second bean reading compared with the model's Tb (e.g. an
        infrared bean-surface channel); NaN where not measured
    ET_C : (n,) array or None, the roaster's ET as logged [degC] (Artisan's ``temp1``; what it
        measures depends on the machine: the drum, the air in it or the exhaust); shown beside
        the model's temperatures, never an input; NaN where not measured
    events : {event name: time after CHARGE [s]} from the log (e.g. ``FCs``, ``DROP``)
    temp_unit : "C" or "F", the unit the log recorded its temperatures in (Artisan's mode, a map's
        ``[Ta] unit``); every temperature here is in degC whatever it says, and it is what a roaster's
        tables and figures show by default
    """

    name: str
    time_s: np.ndarray
    Gg_kg_s: np.ndarray
    Tgi_C: np.ndarray
    Ta_C: np.ndarray | None = None
    source: str | None = None
    initial: dict = field(default_factory=dict)
    Mb_kg: float | None = None
    notes: list = field(default_factory=list)  # import warnings worth telling the user
    heater: np.ndarray | None = None
    fan: np.ndarray | None = None
    Tb2_C: np.ndarray | None = None
    events: dict = field(default_factory=dict)
    ET_C: np.ndarray | None = None
    unit: str = ""  # which roaster of its make recorded it (RoasTime serial number), empty if unknown
    started_epoch_s: float | None = None  # when its recording started (a copy keeps it: first_of_each_roast)
    temp_unit: str = "C"  # the unit the log was recorded in ("C" or "F"); the values are degC

    @property
    def n(self) -> int:
        return len(self.time_s)

    def validate(self) -> Batch:
        """Check the physical sanity of the arrays; raise InputError naming the source."""
        src = self.source or self.name
        cols = {"time_s": self.time_s, "Gg_kg_s": self.Gg_kg_s, "Tgi_C": self.Tgi_C}
        for name in ("Ta_C", "heater", "fan"):
            if getattr(self, name) is not None:
                cols[name] = getattr(self, name)
        for name in SPARSE_COLUMNS:
            arr = getattr(self, name)
            if arr is not None and len(arr) != len(self.time_s):
                raise InputError(f"column {name} has {len(arr)} values, time has {len(self.time_s)}", src)
        n = len(self.time_s)
        if n < 2:
            raise InputError(f"needs at least 2 samples, got {n}", src)
        for name, arr in cols.items():
            if len(arr) != n:
                raise InputError(f"column {name} has {len(arr)} values, time has {n}", src)
            bad = np.flatnonzero(~np.isfinite(arr))
            if bad.size:
                raise InputError(
                    f"non-finite value {arr[bad[0]]} (NaN or inf)", src, f"row {bad[0] + 1}, column {name}"
                )
        dt = np.diff(self.time_s)
        bad = np.flatnonzero(dt <= 0)
        if bad.size:
            i = bad[0] + 1
            kind = "duplicated" if dt[bad[0]] == 0 else "decreasing"
            raise InputError(
                f"time not strictly increasing ({kind}: {self.time_s[i - 1]:g} then {self.time_s[i]:g} s)",
                src,
                f"row {i + 1}, column time_s",
            )
        for name in ("time_s", "Gg_kg_s", "Tgi_C", "Ta_C", "heater", "fan"):
            if name in cols:
                check_array(name, cols[name], src, None)
        for name in SPARSE_COLUMNS:  # temperatures; NaN = not measured there
            arr = getattr(self, name)
            if arr is not None:
                check_array("Ta_C", arr[np.isfinite(arr)], src, f"column {name}")
        check_array("dt_s", dt, src)
        if self.Mb_kg is not None:
            check_value("Mb_kg", self.Mb_kg, src)
        return self


def logs_temp_unit(batches) -> str:
    """The unit a set of logs was recorded in (each one's ``temp_unit``: a :class:`Batch`, or
    :class:`roastlab.workflows.survey.LogInfo`): "F" where every one of them was recorded in degF, else
    "C" (a folder of logs in both units reads in degC)."""
    units = {b.temp_unit for b in batches}
    return "F" if units == {"F"} else "C"


def recording_second(started_epoch_s) -> int | None:
    """The second a recording started, the key by which two logs are one roast (None: unknown)."""
    return round(started_epoch_s) if started_epoch_s else None


def first_of_each_roast(items, started_epoch_s, name) -> tuple[list, dict[str, str]]:
    """``items`` without their copies, and each copy left out with why (``{name: why}``).

    A roast saved twice (renamed with its batch number, annotated after the roast) keeps the second
    its recording started (Artisan's ``roastepoch``, RoasTime's ``dateTime``): of the items whose
    ``started_epoch_s(item)`` agree to the second, the first in the order given is kept. Read as two
    roasts, one copy would be fitted and the other held out, scoring a model on a roast it was
    fitted to. An item with no start (a plain CSV) is a roast of its own.
    """
    kept, copies, seen = [], {}, {}
    for item in items:
        key = recording_second(started_epoch_s(item))
        if key is not None and key in seen:
            copies[name(item)] = f"{name(item)} is a copy of {seen[key]} (recorded from the same second: one roast)"
            continue
        if key is not None:
            seen[key] = name(item)
        kept.append(item)
    return kept, copies


def read_text(path: Path) -> str:
    """A batch CSV's text, read through the input guard."""
    return read_input_text(path, "CSV text")


def parse_number(cell: str, path, line: int, column: str) -> float:
    text = cell.strip()
    if text == "":
        raise InputError("empty cell", path, f"line {line}, column {column}")
    try:
        value = float(text)
    except ValueError:
        clock = ' (a time written as a clock: a map\'s [time] unit "m:ss" reads it)' if ":" in text else ""
        raise InputError(f"not a number: {text[:40]!r}{clock}", path, f"line {line}, column {column}") from None
    if not math.isfinite(value):
        raise InputError(f"non-finite value {text!r} (NaN or inf)", path, f"line {line}, column {column}")
    return value


#: A cell that is a number or a clock time written with a decimal comma ("131,7", "07:37,5"), as
#: spreadsheets in much of Europe export it (with ";" or a tab between the cells).
_DECIMAL_COMMA = re.compile(r"^\s*-?(?:\d+:)*\d+,\d+\s*$")


def as_comma_separated(text: str) -> str:
    """A raw log's CSV text with its cells separated by commas and decimal points: a file whose
    header row holds more ``;`` or tabs than commas (a European spreadsheet's export: ``Zeit;BT;ET``,
    ``131,7``) is rewritten so (its decimal commas become points); any other text is returned as it
    is. Comment lines (``#``) stay as they are."""
    head = next((ln for ln in io.StringIO(text) if ln.strip() and not ln.lstrip().startswith("#")), "")
    sep = max((";", "\t"), key=head.count)
    if head.count(sep) <= head.count(","):
        return text
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    try:
        for line in io.StringIO(text):
            if line.lstrip().startswith("#") or not line.strip():
                out.write(line if line.endswith("\n") else line + "\n")
                continue
            for row in csv.reader([line], delimiter=sep):
                writer.writerow([c.replace(",", ".") if _DECIMAL_COMMA.match(c) else c for c in row])
    except csv.Error:  # not a table (a NUL byte, a broken quote): the strict reader says where
        return text
    return out.getvalue()


def csv_log_text(path) -> str:
    """A raw CSV log's text through the input guard, comma-separated (:func:`as_comma_separated`):
    what ``roastlab init`` and a map's import both read."""
    return as_comma_separated(read_input_text(path, "a CSV log"))


#: What a ``sparse`` column's cell says when no reading was taken: empty, or NaN as NumPy and
#: spreadsheets write it.
MISSING_CELLS = ("", "nan")


def parse_clock(cell: str, path, line: int, column: str) -> float:
    """A time cell written m:ss, h:mm:ss or in seconds -> [s]; one-line error naming the cell."""
    if not cell.strip():
        raise InputError("empty cell", path, f"line {line}, column {column}")
    try:
        return clock_s(cell)
    except ValueError as exc:
        raise InputError(str(exc), path, f"line {line}, column {column}") from None


def read_table(
    path: str | Path,
    required: tuple[str, ...],
    optional: tuple[str, ...] = (),
    text: str | None = None,
    sparse: tuple[str, ...] = SPARSE_COLUMNS,
    clock: tuple[str, ...] = (),
) -> dict[str, np.ndarray]:
    """Read named numeric columns from a CSV with a header row, strictly.

    Lines starting with ``#`` are comments. Returns ``{column: array}`` for the required
    columns and those optional ones present. An empty cell is an error except in the ``sparse``
    columns, where it is NaN (a reading not taken: a batch CSV's second bean reading and ET; every
    column of a raw log read through a map, whose incomplete samples the import drops; "nan" reads
    so too, :data:`MISSING_CELLS`). The
    ``clock`` columns are times written m:ss or h:mm:ss, read as seconds
    (:func:`roastlab.metrics.profile.clock_s`).
    """
    path = as_path(path, "path")
    text = read_text(path) if text is None else text  # callers that already read it pass it
    # Streamed: the C csv reader walks the text once and each value goes into a compact
    # array of doubles, so memory is a small multiple of the file size whatever its shape.
    at = [0]  # number of the line the reader is on; comment lines never reach the csv reader

    def data_lines():
        for n, line in enumerate(io.StringIO(text), start=1):
            if not line.lstrip().startswith("#"):
                at[0] = n
                yield line

    reader = csv.reader(data_lines())
    header = None
    wanted: list[str] = []
    index: dict[str, int] = {}
    values: dict[str, array] = {}
    rows = 0
    try:
        for row in reader:
            line_no = at[0]
            if not row or not "".join(row).strip():
                continue
            if header is None:
                header, header_line = [h.strip() for h in row], line_no
                wanted, index = _columns(header, required, optional, path, header_line)
                values = {c: array("d") for c in wanted}
                continue
            rows += 1
            for c in wanted:
                j = index[c]
                if j >= len(row):
                    raise InputError(
                        f"row has {len(row)} cells, column {c} missing (truncated file?)", path, f"line {line_no}"
                    )
                if c in sparse and row[j].strip().lower() in MISSING_CELLS:
                    values[c].append(math.nan)  # a reading not taken at this sample
                elif c in clock:
                    values[c].append(parse_clock(row[j], path, line_no, c))
                else:
                    values[c].append(parse_number(row[j], path, line_no, c))
    except csv.Error as exc:
        raise InputError(f"unreadable row ({exc})", path, f"line {at[0]}") from None
    if header is None:
        raise InputError("empty file (no header row)", path)
    if rows == 0:
        raise InputError("header only, no data rows", path)
    return {c: np.frombuffer(v, dtype=np.float64).copy() for c, v in values.items()}


def _columns(header, required, optional, path, header_line) -> tuple[list[str], dict[str, int]]:
    """The wanted columns of a header and their positions; duplicated or missing ones refused."""
    seen = set()
    for h in header:
        if h in seen and h in required + optional:
            raise InputError(f"duplicated column {h!r}", path, f"line {header_line}")
        seen.add(h)
    missing = [c for c in required if c not in header]
    if missing:
        raise InputError(
            f"missing column(s) {', '.join(missing)} (header has: {', '.join(header)})", path, f"line {header_line}"
        )
    wanted = list(dict.fromkeys(c for c in required + optional if c in header))
    return wanted, {c: header.index(c) for c in wanted}


def _refuse_raw_log(text: str, path) -> None:
    """A roast log given where a batch CSV is expected gets one line saying what to do."""
    head = text.lstrip()[:4096]
    if head.startswith("{"):
        kind = (
            "an Artisan .alog" if "timex" in head else ("an Aillio RoasTime" if "beanTemperature" in head else "a JSON")
        )
        raise InputError(
            f"{kind} roast log, not a batch CSV: convert it with 'roastlab import LOG --map MAP.toml' "
            "or read it with a column map (--map MAP.toml; in a fleet manifest, its map column)",
            path,
        )
    if head.split("\n", 1)[0].lstrip("\ufeff").startswith("Date:") or "Unit:" in head.split("\n", 1)[0]:
        raise InputError(
            "an Artisan CSV export, not a batch CSV: convert it with 'roastlab import LOG --map MAP.toml' "
            "or read it with a column map (--map MAP.toml; in a fleet manifest, its map column)",
            path,
        )


def read_batch_csv(path: str | Path, name: str | None = None, require_Ta: bool = False) -> Batch:
    """Read and validate the canonical batch CSV at ``path`` (``time_s, Gg_kg_s, Tgi_C[, Ta_C]``).

    ``name`` names the batch (default: the file stem); ``require_Ta`` refuses a file without Ta_C.
    """
    path = as_path(path, "path")
    required = REQUIRED_COLUMNS + (("Ta_C",) if require_Ta else ())
    text = read_text(path)  # once: the table and the '# Mb_kg' metadata come from the same text
    _refuse_raw_log(text, path)
    cols = read_table(path, required, OPTIONAL_COLUMNS, text=text)
    meta = read_comment_metadata(path, text=text)
    batch = Batch(
        name=name or path.stem,
        time_s=cols["time_s"],
        Gg_kg_s=cols["Gg_kg_s"],
        Tgi_C=cols["Tgi_C"],
        Ta_C=cols.get("Ta_C"),
        source=str(path),
        Mb_kg=meta.get("Mb_kg"),
        heater=cols.get("heater"),
        fan=cols.get("fan"),
        Tb2_C=cols.get("Tb2_C"),
        ET_C=cols.get("ET_C"),
        initial={k: v for k, v in meta.items() if k in INITIAL_METADATA},
    )
    return batch.validate()


#: Metadata a batch CSV may carry in ``# key = value`` comment lines (ranges: the quantity table).
COMMENT_METADATA = ("Mb_kg", "Tm0_C", "Tb0_C", "X0", "Ta0_C")
#: Of those, the initial states a log set through its map's ``[initial]`` (kept in ``Batch.initial``).
INITIAL_METADATA = ("Tm0_C", "Tb0_C", "X0", "Ta0_C")


def read_comment_metadata(path: str | Path, text: str | None = None) -> dict[str, float]:
    """Parse ``# Mb_kg = 0.2``-style metadata lines at the top of a batch CSV."""
    path = Path(path)
    out = {}
    text = read_text(path) if text is None else text
    for line_no, line in enumerate(text.splitlines(), start=1):
        if not line.startswith("#"):
            if line.strip():
                break
            continue
        key, sep, value = line[1:].partition("=")
        key = key.strip()
        if sep and key in COMMENT_METADATA:
            v = parse_number(value, path, line_no, key)
            try:
                out[key] = check_value(key, v)
            except ParameterError as exc:
                raise InputError(exc.problem, path, f"line {line_no}") from None
    return out


def write_batch_csv_text(batch: Batch, comment: str | None = None, decimals: int = 4) -> str:
    """A canonical batch CSV as text (optional ``#`` comment lines first).

    Comment lines start with ``##``, which the metadata reader never obeys, and are made
    printable: text from a log's file name or fields (a newline, a ``Mb_kg = ...``) cannot
    become a line a reader acts on.
    """
    out = io.StringIO()
    for line in (comment or "").splitlines():
        out.write("## " + "".join(c if c.isprintable() else "?" for c in line) + "\n")
    if batch.Mb_kg:
        out.write(f"# Mb_kg = {batch.Mb_kg:.6g}\n")
    for key in INITIAL_METADATA:
        if key in batch.initial:
            out.write(f"# {key} = {float(batch.initial[key]):.10g}\n")
    cols = ["time_s", "Gg_kg_s", "Tgi_C"] + [c for c in OPTIONAL_COLUMNS if getattr(batch, c) is not None]
    out.write(",".join(cols) + "\n")
    arrays = [getattr(batch, c) for c in cols]
    for row in zip(*arrays):
        out.write(",".join(f"{v:.{decimals}f}" if v == v else "" for v in row) + "\n")
    return out.getvalue()


def write_batch_csv(path: str | Path, batch: Batch, comment: str | None = None, decimals: int = 4) -> None:
    """Write a canonical batch CSV atomically (see :func:`write_batch_csv_text`)."""
    atomic_write_text(path, write_batch_csv_text(batch, comment, decimals))


@dataclass
class Dataset:
    """A folder of batch CSVs with a ``dataset.toml`` naming the plant and the batches."""

    name: str
    plant: str
    batches: list[Batch]
    folder: str
    synthetic: bool = False
    description: str = ""


def read_dataset(folder: str | Path) -> Dataset:
    """Read a dataset folder: ``dataset.toml`` with ``plant``, ``[[batch]]`` ``file``/``name``."""
    folder = as_path(folder, "folder")
    meta_path = folder / "dataset.toml"
    if not meta_path.is_file():
        raise InputError("not a dataset folder (no dataset.toml)", folder)
    meta = read_toml(meta_path)
    plant = meta.get("plant")
    if not isinstance(plant, str):
        raise InputError("missing or non-string key 'plant'", meta_path)
    entries = meta.get("batch")
    if not isinstance(entries, list) or not entries:
        raise InputError("no [[batch]] entries", meta_path)
    batches = []
    for k, entry in enumerate(entries):
        if not isinstance(entry, dict) or not isinstance(entry.get("file"), str):
            raise InputError(f"[[batch]] entry {k + 1} needs a string 'file'", meta_path)
        rel = entry["file"]
        if os.path.isabs(rel) or ".." in Path(rel).parts:
            raise InputError(f"[[batch]] entry {k + 1}: file must be inside the dataset folder", meta_path)
        b = read_batch_csv(folder / rel, name=str(entry.get("name", Path(rel).stem)))
        batches.append(b)
    plant_ref = plant
    if plant.endswith(".toml"):
        plant_ref = str(folder / plant)
    return Dataset(
        name=str(meta.get("name", folder.name)),
        plant=plant_ref,
        batches=batches,
        folder=str(folder),
        synthetic=bool(meta.get("synthetic", False)),
        description=str(meta.get("description", "")),
    )


def expand_batch_args(paths: list[str | Path], require_Ta: bool = True) -> tuple[list[Batch], str | None]:
    """Turn CLI arguments (batch CSVs and/or dataset folders) into batches.

    Returns the batches and the plant named by a dataset folder (or None).
    """
    batches: list[Batch] = []
    plant = None
    for p in paths:
        p = Path(p)
        if p.is_dir():
            ds = read_dataset(p)
            plant = plant or ds.plant
            batches.extend(ds.batches)
        else:
            batches.append(read_batch_csv(p, require_Ta=require_Ta))
    if require_Ta:
        for b in batches:
            if b.Ta_C is None:
                raise InputError("no measured Ta_C column: needed to identify or validate", b.source or b.name)
    return batches, plant
