"""The fleet store: machines, batches, their series and per-batch fits in one DuckDB file.

DuckDB is an embedded database: the store is one file (``FLEET.duckdb``), no server runs.
Schema (``SCHEMA_VERSION`` 1; every table is created by :func:`open_store`):

``machines``
    ``machine_id`` INTEGER key, ``name`` (unique), ``plant`` (a preset name or the plant
    file's path as the manifest gave it), ``plant_toml`` (the plant file's text, NULL for a
    preset: the store does not depend on the file staying where it was), ``plant_sha256``.
``batches``
    ``batch_id`` BIGINT key, ``machine_id``, ``source`` (the log's path), ``sha256`` (of its
    bytes, unique: ingesting the same file again is a no-op), ``started_at`` (TIMESTAMPTZ),
    ``name``, ``green_kg`` (the log's green mass, NULL if it has none), ``n_samples``,
    ``map`` and ``map_sha256`` (the column map it was read with, NULL for a batch CSV),
    ``initial_json`` (initial states the log set, e.g. ``{"Tm0_C": 181}``), ``events_json``,
    ``notes`` (importer warnings), ``ingested_at``.
``series``
    one row per sample: ``batch_id``, ``i`` (sample index), ``time_s``, ``Gg_kg_s``, ``Tgi_C``,
    ``Ta_C``, ``heater``, ``fan``, ``Tb2_C`` (NULL where the log has no such channel). The
    canonical batch of :class:`roastlab.io.batch.Batch`, after the importer's map.
``fit_specs``
    ``spec_id`` (SHA-256 of the spec's canonical JSON), ``spec_json``, ``created_at``.
``fits``
    one row per (batch, spec): ``SSR`` [degC^2], ``FIT`` [%], ``MAE`` [degC], ``n_samples``,
    ``simulations``, ``roastlab_version``, ``fitted_at``.
``fit_values``
    one row per (batch, spec, parameter): ``value`` and ``stderr`` (NULL on a bound).
``models``
    the machine models: per (machine, spec, period) and parameter, the median and the
    robust spread (1.4826 MAD) of the good batches' values, with the period's first and last
    batch; periods end at the drift alarms (:mod:`.drift`). Refreshed by every ``fleet fit``.

An ingest commits chunk by chunk (:data:`INGEST_CHUNK` batches per transaction, so memory stays
flat in the fleet's size): one that fails part-way keeps the chunks it committed, and running it
again adds the rest (files already stored are skipped by their SHA-256). A fit commits each
chunk of fits as it returns; the machine models are rewritten in one transaction.
"""

from __future__ import annotations

import contextlib
import csv
import datetime
import functools
import hashlib
import io
import json
import re
import time
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io.files import read_input_bytes, read_input_text
from ..io.plants import load_plant
from ..model.plant import plant_from_mapping, preset_names

SCHEMA_VERSION = 1
MANIFEST_COLUMNS = ("path", "machine", "plant", "started_at")
SERIES_COLUMNS = ("time_s", "Gg_kg_s", "Tgi_C", "Ta_C", "heater", "fan", "Tb2_C")
#: DuckDB's memory limit for the store's connection (its buffer pool fills up to it as a store
#: grows, so it bounds how the process grows with the fleet; a chunk of batches needs far less).
DUCKDB_MEMORY = "64MB"
#: Batches written to DuckDB per append (bounded memory, whatever the manifest's length).
INGEST_CHUNK = 2000

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key VARCHAR PRIMARY KEY, value VARCHAR);
CREATE TABLE IF NOT EXISTS machines (
    machine_id INTEGER PRIMARY KEY, name VARCHAR UNIQUE NOT NULL, plant VARCHAR NOT NULL,
    plant_toml VARCHAR, plant_sha256 VARCHAR);
CREATE TABLE IF NOT EXISTS batches (
    batch_id BIGINT PRIMARY KEY, machine_id INTEGER NOT NULL, source VARCHAR NOT NULL,
    sha256 VARCHAR UNIQUE NOT NULL, started_at TIMESTAMPTZ NOT NULL, name VARCHAR,
    green_kg DOUBLE, n_samples INTEGER NOT NULL, map VARCHAR, map_sha256 VARCHAR,
    initial_json VARCHAR, events_json VARCHAR, notes VARCHAR, ingested_at TIMESTAMPTZ);
CREATE TABLE IF NOT EXISTS series (
    batch_id BIGINT NOT NULL, i INTEGER NOT NULL, time_s DOUBLE NOT NULL, Gg_kg_s DOUBLE NOT NULL,
    Tgi_C DOUBLE NOT NULL, Ta_C DOUBLE, heater DOUBLE, fan DOUBLE, Tb2_C DOUBLE);
CREATE TABLE IF NOT EXISTS fit_specs (spec_id VARCHAR PRIMARY KEY, spec_json VARCHAR, created_at TIMESTAMPTZ);
CREATE TABLE IF NOT EXISTS fits (
    batch_id BIGINT NOT NULL, spec_id VARCHAR NOT NULL, SSR DOUBLE, FIT DOUBLE, MAE DOUBLE,
    n_samples INTEGER, simulations BIGINT, roastlab_version VARCHAR, fitted_at TIMESTAMPTZ,
    PRIMARY KEY (batch_id, spec_id));
CREATE TABLE IF NOT EXISTS fit_values (
    batch_id BIGINT NOT NULL, spec_id VARCHAR NOT NULL, parameter VARCHAR NOT NULL, value DOUBLE,
    stderr DOUBLE, PRIMARY KEY (batch_id, spec_id, parameter));
CREATE TABLE IF NOT EXISTS models (
    machine_id INTEGER NOT NULL, spec_id VARCHAR NOT NULL, period INTEGER NOT NULL,
    first_batch_id BIGINT, last_batch_id BIGINT, from_started_at TIMESTAMPTZ, to_started_at TIMESTAMPTZ,
    n_batches INTEGER, parameter VARCHAR NOT NULL, median DOUBLE, spread DOUBLE);
"""


def _duckdb():
    try:
        import duckdb
    except ImportError:  # an optional extra
        raise InputError("the fleet store needs DuckDB: pip install 'roastlab[fleet]'") from None
    return duckdb


#: How often a store locked by another process is tried again while waiting [s].
LOCK_POLL_S = 0.25


def _connect(db: Path, read_only: bool, wait_s: float):
    """A DuckDB connection to ``db``; a lock held by another process is waited for up to
    ``wait_s`` seconds and then named as such (not as a damaged file)."""
    duckdb = _duckdb()
    deadline = time.monotonic() + wait_s
    while True:
        try:
            return duckdb.connect(str(db), read_only=read_only)
        except duckdb.Error as exc:
            text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            if "lock" not in text.lower():
                raise InputError(f"cannot open as a DuckDB fleet store ({text})", db) from None
            if time.monotonic() < deadline:
                time.sleep(LOCK_POLL_S)
                continue
            pid = re.search(r"PID (\d+)", text)
            who = f" (PID {pid.group(1)})" if pid else ""
            waited = f"still after {wait_s:g} s" if wait_s > 0 else "try again when it has finished, or wait for it"
            raise InputError(
                f"in use by another process{who}: {waited} (ingest and fit take --wait SECONDS)", db
            ) from None


@functools.cache
def _schema_columns() -> dict[str, list[str]]:
    """Each table of :data:`_SCHEMA` and its columns, read from DuckDB itself (one source)."""
    con = _duckdb().connect(":memory:")
    try:
        con.execute(_SCHEMA)
        rows = con.execute(
            "SELECT table_name, column_name FROM information_schema.columns ORDER BY table_name, ordinal_position"
        ).fetchall()
    finally:
        con.close()
    out: dict[str, list[str]] = {}
    for table, column in rows:
        out.setdefault(table, []).append(column)
    return out


def _check_store(con, db: Path) -> bool:
    """Whether the database behind ``con`` (opened read-only) is empty; raise unless it is empty
    or a roastlab fleet store of :data:`SCHEMA_VERSION` with every table and column in place."""
    kinds = dict(
        con.execute(
            "SELECT table_name, table_type FROM information_schema.tables WHERE table_catalog = current_database()"
        ).fetchall()
    )
    if not kinds:
        return True
    if "meta" not in kinds:
        shown = ", ".join(sorted(kinds)[:6]) + (", ..." if len(kinds) > 6 else "")
        raise InputError(f"a DuckDB database but not a roastlab fleet store (its tables: {shown}); left untouched", db)
    rows = con.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchall()
    version = rows[0][0] if rows else None
    if version != str(SCHEMA_VERSION):
        newer = str(version).isdigit() and int(version) > SCHEMA_VERSION
        why = "written by a newer roastlab" if newer else f"schema version {version!r}"
        raise InputError(f"fleet store of {why}; this roastlab reads version {SCHEMA_VERSION}; left untouched", db)
    for table, columns in _schema_columns().items():
        if table not in kinds:
            raise InputError(f"damaged fleet store: no table {table!r}", db)
        if kinds[table] != "BASE TABLE":
            raise InputError(f"damaged fleet store: {table!r} is a {kinds[table].lower()}, not a table", db)
        have = {
            r[0]
            for r in con.execute(
                "SELECT column_name FROM information_schema.columns WHERE table_catalog = current_database() "
                "AND table_name = ?",
                [table],
            ).fetchall()
        }
        missing = [c for c in columns if c not in have]
        if missing:
            raise InputError(f"damaged fleet store: table {table!r} lacks column(s) {', '.join(missing)}", db)
    return False


@contextlib.contextmanager
def store_errors(db):
    """Turn any DuckDB error while working on the store into one line naming it."""
    duckdb = _duckdb()
    try:
        yield
    except duckdb.Error as exc:
        text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputError(f"fleet store unreadable or damaged ({text})", db) from None


def open_store(db: str | Path, read_only: bool = False, wait_s: float = 0.0):
    """Open (creating if needed) the fleet store at ``db``; returns a DuckDB connection.

    An existing file is first opened read-only and checked (:func:`_check_store`): a foreign
    database, another schema version or a damaged store is refused before anything is written.
    A lock held by another process is waited for up to ``wait_s`` seconds.
    """
    db = Path(db)
    if read_only and not db.exists():
        raise InputError("no such fleet store (create it with 'roastlab fleet ingest')", db)
    if db.exists() and not db.is_file():
        raise InputError("not a file", db)
    empty = True
    if db.exists():
        con = _connect(db, True, wait_s)
        try:
            with store_errors(db):
                empty = _check_store(con, db)
        finally:
            if not read_only or empty:
                con.close()
        if read_only and empty:
            raise InputError("an empty database, not a fleet store (create it with 'roastlab fleet ingest')", db)
    if not read_only:
        con = _connect(db, False, wait_s)
    with store_errors(db):
        con.execute("SET TimeZone = 'UTC'")
        # DuckDB's buffer manager takes up to 80 % of RAM by default; a store of years of batches
        # streams through far less (it spills to a temporary folder beside the file if it must)
        con.execute(f"SET memory_limit = '{DUCKDB_MEMORY}'")
        if not read_only and empty:
            con.execute(_SCHEMA)
            con.execute("INSERT OR IGNORE INTO meta VALUES ('schema_version', ?)", [str(SCHEMA_VERSION)])
    return con


@dataclass
class IngestReport:
    """What an ingest did: batches added, files already in the store, rejected manifest rows."""

    added: int = 0
    already: int = 0
    machines_added: list[str] = field(default_factory=list)
    rejected: list[str] = field(default_factory=list)
    wall_s: float = 0.0

    def summary(self) -> str:
        s = f"{self.added} batch(es) ingested, {self.already} already in the store"
        if self.machines_added:
            s += f"; new machine(s): {', '.join(self.machines_added)}"
        if self.rejected:
            s += f"; {len(self.rejected)} row(s) rejected"
        return s + f" ({self.wall_s:.1f} s)"


def _parse_started_at(text: str) -> datetime.datetime:
    """ISO 8601 date-time; without a zone it is read as UTC."""
    try:
        ts = datetime.datetime.fromisoformat(text.strip())
    except ValueError:
        raise ValueError(f"started_at {text!r} is not an ISO 8601 date-time (e.g. 2024-03-01T08:30:00+01:00)") from None
    if ts.tzinfo is None:
        ts = ts.replace(tzinfo=datetime.UTC)
    return ts


def iter_manifest(path: str | Path) -> tuple[Iterator[tuple[int, dict]], list[str], int]:
    """The rows of a manifest CSV, one at a time, as (line number, {column: text}), with its
    header and its number of data lines (for progress). A missing column is an InputError at
    once; an unreadable row raises one when it is reached."""
    text = read_input_text(path, "manifest")
    reader = csv.DictReader(io.StringIO(text))
    try:
        header = [h.strip() for h in (reader.fieldnames or [])]
    except csv.Error as exc:
        raise InputError(f"not a readable CSV header ({exc})", path, "line 1") from None
    missing = [c for c in MANIFEST_COLUMNS if c not in header]
    if missing:
        raise InputError(
            f"missing column(s) {', '.join(missing)} (a manifest has {','.join(MANIFEST_COLUMNS)}[,map])",
            path,
            "line 1",
        )
    reader.fieldnames = header

    def rows():
        try:
            for rec in reader:
                yield reader.line_num, {k: (v or "").strip() for k, v in rec.items() if k is not None}
        except csv.Error as exc:  # e.g. a field over the csv module's 128 KiB limit
            raise InputError(f"unreadable CSV ({exc})", path, f"line {reader.line_num}") from None

    lines = text.count("\n") + (0 if text.endswith("\n") else 1)
    return rows(), header, max(0, lines - 1)


def read_manifest(path: str | Path) -> tuple[list[tuple[int, dict]], list[str]]:
    """Rows of a manifest CSV as (line number, {column: text}); a missing column is an InputError."""
    rows, header, _ = iter_manifest(path)
    return list(rows), header


class _Machines:
    """Machines known to the store or added by this ingest, with their plants checked once."""

    def __init__(self, con, base: Path):
        self.con = con
        self.base = base
        self.known = {
            name: (mid, plant, sha)
            for mid, name, plant, sha in con.execute(
                "SELECT machine_id, name, plant, plant_sha256 FROM machines"
            ).fetchall()
        }
        self.next_id = 1 + max([v[0] for v in self.known.values()], default=0)
        self.new: list[tuple] = []
        self._plants: dict[str, tuple] = {}
        self._plant_objects: dict = {}

    def _plant(self, spec: str) -> tuple[str, str | None, str | None]:
        """(plant as stored, its TOML text or None for a preset, its SHA-256)."""
        if spec in self._plants:
            return self._plants[spec]
        if spec in preset_names():
            out = (spec, None, None)
        else:
            path = Path(spec) if Path(spec).is_absolute() else self.base / spec
            if not path.exists():
                raise ValueError(f"unknown plant {spec!r}: neither a preset ({', '.join(preset_names())}) nor a file")
            text = read_input_text(path, "plant file")
            load_plant(path)  # checks the geometry; raises InputError naming the file
            out = (str(path), text, hashlib.sha256(text.encode()).hexdigest())
        self._plants[spec] = out
        return out

    def plant(self, spec: str):
        """The :class:`~roastlab.model.plant.Plant` of a manifest's plant column (ValueError if unknown),
        read once per column value."""
        if spec not in self._plant_objects:
            stored, text, _sha = self._plant(spec)
            self._plant_objects[spec] = plant_of(spec, stored, text)
        return self._plant_objects[spec]

    def check(self, name: str, plant_spec: str) -> None:
        """ValueError if the plant is unknown or differs from the one the machine already has."""
        plant, _text, sha = self._plant(plant_spec)
        if name in self.known:
            _mid, known_plant, known_sha = self.known[name]
            if (sha or plant) != (known_sha or known_plant):
                raise ValueError(f"machine {name!r} already has plant {known_plant}, not {plant}")

    def resolve(self, name: str, plant_spec: str) -> int:
        """The machine's id, adding it (with its plant) if the store does not know it yet."""
        self.check(name, plant_spec)
        if name in self.known:
            return self.known[name][0]
        plant, text, sha = self._plant(plant_spec)
        mid = self.next_id
        self.next_id += 1
        self.known[name] = (mid, plant, sha)
        self.new.append((mid, name, plant, text, sha))
        return mid


def ingest(db: str | Path, manifest: str | Path, progress=None, wait_s: float = 0.0) -> IngestReport:
    """Ingest the logs a manifest lists into the store at ``db``, committed chunk by chunk
    (:data:`INGEST_CHUNK` batches per transaction, so memory stays flat in the manifest's length).

    The manifest is a CSV with columns ``path,machine,plant,started_at[,map]``: ``path`` and
    ``map`` relative to the manifest's folder, ``plant`` a preset or a PLANT.toml, ``started_at``
    ISO 8601 (UTC if it names no zone). A row that cannot be ingested (missing file, unknown
    plant, bad date, unreadable log) is rejected with one line naming its line number; the
    others still ingest. A file already in the store (same SHA-256) is skipped, so an ingest that
    fails part-way (disk full, interrupted) keeps the chunks it committed, and running it again
    adds the rest: the store ends as one uninterrupted ingest leaves it. A store locked by
    another process is waited for up to ``wait_s`` seconds.
    """
    from ..io.batch import read_batch_csv
    from ..io.importers import import_log, load_map

    t0 = time.perf_counter()
    manifest = Path(manifest)
    rows, _, n_rows = iter_manifest(manifest)
    base = manifest.parent
    report = IngestReport()
    with store_errors(db):
        con = open_store(db, wait_s=wait_s)
        try:
            con.execute("BEGIN TRANSACTION")
            machines = _Machines(con, base)
            # the digests as 32 raw bytes, not 64 hex characters: this set grows with the store
            seen = {bytes.fromhex(r[0]) for r in con.execute("SELECT sha256 FROM batches").fetchall()}
            next_batch = 1 + (con.execute("SELECT max(batch_id) FROM batches").fetchall()[0][0] or 0)
            maps: dict[str, tuple] = {}
            pending_b: list[tuple] = []
            pending_s: list[tuple] = []
            now = datetime.datetime.now(datetime.UTC)
            for k, (line, row) in enumerate(rows):
                where = f"line {line}"
                try:
                    for col in MANIFEST_COLUMNS:
                        if not row.get(col):
                            raise ValueError(f"empty {col}")
                    started = _parse_started_at(row["started_at"])
                    machines.check(row["machine"], row["plant"])
                    path = Path(row["path"]) if Path(row["path"]).is_absolute() else base / row["path"]
                    if not path.exists():
                        raise ValueError(f"file not found: {row['path']}")
                    raw = read_input_bytes(path)
                    digest = hashlib.sha256(raw).digest()
                    sha = digest.hex()
                    if digest in seen:
                        report.already += 1
                        continue
                    map_name = row.get("map") or ""
                    if map_name:
                        if map_name not in maps:
                            mpath = Path(map_name) if Path(map_name).is_absolute() else base / map_name
                            mtext = read_input_text(mpath, "map")
                            maps[map_name] = (load_map(mpath), str(mpath), hashlib.sha256(mtext.encode()).hexdigest())
                        cmap, map_path, map_sha = maps[map_name]
                        batch = import_log(path, cmap)
                    elif path.suffix.lower() == ".csv":
                        batch, map_path, map_sha = read_batch_csv(path), None, None
                    else:
                        batch, map_path, map_sha = import_log(path, None), None, None
                    try:  # a batch its plant cannot take is refused here, as a model's apply refuses it
                        if batch.Mb_kg:
                            machines.plant(row["plant"]).check_batch_mass(batch.Mb_kg)
                    except InputError as exc:
                        raise InputError(exc.problem, path) from None
                    mid = machines.resolve(row["machine"], row["plant"])
                except (InputError, ValueError, OSError) as exc:
                    report.rejected.append(f"{manifest}: {where}: {exc}")
                    continue
                seen.add(digest)
                bid = next_batch
                next_batch += 1
                pending_b.append(
                    (
                        bid,
                        mid,
                        str(path),
                        sha,
                        started,
                        batch.name,
                        batch.Mb_kg,
                        batch.n,
                        map_path,
                        map_sha,
                        json.dumps(batch.initial),
                        json.dumps(batch.events),
                        "\n".join(batch.notes) or None,
                        now,
                    )
                )
                pending_s.append((bid, batch))
                report.added += 1
                if len(pending_s) >= INGEST_CHUNK:
                    _flush(con, machines, pending_b, pending_s)
                    # one transaction per chunk: DuckDB holds a transaction's appends in memory
                    # until it commits (measured: one transaction for the whole manifest grew the
                    # process by ~15 kB per batch, 1.8 GB at 100,000 batches)
                    con.execute("COMMIT")
                    con.execute("BEGIN TRANSACTION")
                if progress is not None and (k + 1) % 500 == 0:
                    progress(k + 1, n_rows, "rows read")
            _flush(con, machines, pending_b, pending_s)
            con.execute("COMMIT")
        except BaseException:
            try:
                con.execute("ROLLBACK")
            finally:
                con.close()
            raise
        con.close()
    report.machines_added = [m[1] for m in machines.new]
    report.wall_s = time.perf_counter() - t0
    if progress is not None:
        progress(n_rows, n_rows, "rows read")
    return report


def _flush(con, machines: _Machines, pending_b: list, pending_s: list) -> None:
    """Append the buffered machines, batches and series (inside the caller's transaction)."""
    import pandas as pd

    if machines.new:
        written = {r[0] for r in con.execute("SELECT machine_id FROM machines").fetchall()}
        rows = [m for m in machines.new if m[0] not in written]
        if rows:
            con.executemany("INSERT INTO machines VALUES (?, ?, ?, ?, ?)", rows)
    if not pending_b:
        return
    bf = pd.DataFrame(
        pending_b,
        columns=[
            "batch_id",
            "machine_id",
            "source",
            "sha256",
            "started_at",
            "name",
            "green_kg",
            "n_samples",
            "map",
            "map_sha256",
            "initial_json",
            "events_json",
            "notes",
            "ingested_at",
        ],
    )
    con.register("_bf", bf)
    con.execute("INSERT INTO batches SELECT * FROM _bf")
    con.unregister("_bf")
    n = sum(b.n for _, b in pending_s)
    cols = {"batch_id": np.empty(n, dtype=np.int64), "i": np.empty(n, dtype=np.int32)}
    for c in SERIES_COLUMNS:
        cols[c] = np.full(n, np.nan)
    a = 0
    for bid, b in pending_s:
        sl = slice(a, a + b.n)
        cols["batch_id"][sl] = bid
        cols["i"][sl] = np.arange(b.n)
        for c in SERIES_COLUMNS:
            v = getattr(b, c)
            if v is not None:
                cols[c][sl] = v
        a += b.n
    sf = pd.DataFrame(cols)
    con.register("_sf", sf)
    # NaN (no such channel, or a sparse Tb2 gap) is stored as NULL
    con.execute(
        "INSERT INTO series SELECT batch_id, i, time_s, Gg_kg_s, Tgi_C, "
        + ", ".join(f"CASE WHEN isnan({c}) THEN NULL ELSE {c} END" for c in SERIES_COLUMNS[3:])
        + " FROM _sf"
    )
    con.unregister("_sf")
    pending_b.clear()
    pending_s.clear()


def filled(column) -> np.ndarray:
    """A DuckDB ``fetchnumpy`` column with NULLs (a masked array) as NaN; other columns as they are."""
    return np.ma.filled(column.astype(float), np.nan) if np.ma.isMaskedArray(column) else column


def plant_of(name: str, plant: str, plant_toml: str | None):
    """The Plant of a stored machine: its preset, or the plant text kept in the store."""
    if plant_toml is None:
        return load_plant(plant)
    return plant_from_mapping(tomllib.loads(plant_toml), plant, Path(plant).stem)
