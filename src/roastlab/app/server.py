"""The roaster's page (``roastlab app``): a local, single-user web page over the library.

Starlette serves one page of our own (``page.html``, ``page.js``) and Plotly's own bundled
``plotly.min.js`` from the installed ``plotly`` wheel (no CDN, nothing copied into this
repository); the page talks JSON to a handful of endpoints, each a thin call into the library:

* ``GET  /api/files``     the logs, models and plants under the data folder
* ``POST /api/open``      a log and a model -> measured and predicted curves, milestones
* ``POST /api/whatif``    changes -> the changed prediction and the milestone table
  (:func:`roastlab.workflows.whatif.whatif`, the same call as ``roastlab whatif``)
* ``POST /api/transfer``  a batch size or plant -> the runnable program, its curve, and the
  program CSV and Artisan background written to ``<data>/downloads/<session>/``
  (:func:`roastlab.workflows.transfer.transfer`, as ``roastlab transfer``)
* ``POST /api/upload``    a log file into ``<data>/uploads/`` (size-limited, read as data)
* ``POST /api/fit``       fit a model on chosen logs in the background (``roastlab init`` +
  ``fit-roaster`` into ``<data>/roasters/<name>/``; ``every_log``: each log also held out once;
  ``by_size``: fitted at one batch size, the others predicted);
  ``GET /api/fit-status`` its progress and report (report.md, and as HTML with its figures in place;
  ``/api/open`` gives the same HTML for a model fit-roaster wrote)
* ``GET  /downloads/...`` what a transfer wrote

Safety: the server binds 127.0.0.1 unless told otherwise; every path a request names is
resolved (symlinks included) and must lie inside the data folder; uploads are size-limited
and go through the same readers and input guard as the command line; nothing is written
outside ``<data>/uploads``, ``<data>/downloads`` and ``<data>/roasters``. Each browser tab sends its own session id,
so two tabs do not share or overwrite state. A bad file or an infeasible request is a JSON
``{"error": ...}`` the page shows; the server keeps running.
"""

from __future__ import annotations

import re
import threading
import time
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from ..errors import InputError, RoastlabError
from ..io.files import Outputs
from ..io.importers.mapping import is_log_by_content
from ..metrics.profile import DISPLAY_UNITS, rate_of_rise_C_per_min

#: Largest upload [bytes]: a 30-minute log sampled every second is ~2 MB.
MAX_UPLOAD_BYTES = 16 * 1024 * 1024
#: Suffixes the page lists as logs.
LOG_SUFFIXES = (".alog", ".json", ".csv")
#: Sessions kept at most (the oldest is dropped).
MAX_SESSIONS = 32
_SESSION = re.compile(r"^[A-Za-z0-9-]{8,64}$")


@dataclass
class Session:
    """One browser tab's state: the log, the model and the last answers."""

    batch: object = None
    model: object = None
    log: str = ""
    model_path: str = ""
    as_run: object = None
    et: str = "Tm"  # what ET is on this machine (workflows.transfer.et_source)
    fit: dict = field(default_factory=dict)  # the background fit's progress and answer
    sid: str = ""
    used: float = field(default_factory=time.monotonic)


class Sessions:
    """Per-tab state, keyed by the id the page sends in ``X-Session`` (a thread-safe dict)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._items: dict[str, Session] = {}

    def get(self, sid: str | None) -> Session:
        if not sid or not _SESSION.match(sid):
            raise InputError("missing or malformed session id (X-Session header)", "request")
        with self._lock:
            s = self._items.get(sid)
            if s is None:
                if len(self._items) >= MAX_SESSIONS:
                    oldest = min(self._items, key=lambda k: self._items[k].used)
                    del self._items[oldest]
                s = self._items[sid] = Session(sid=sid)
            s.used = time.monotonic()
            return s


def inside(data_dir: Path, rel: str) -> Path:
    """The file ``rel`` names inside ``data_dir``, refused when it leaves the folder (``..``, an
    absolute path, a symlink pointing out) or does not exist."""
    if not isinstance(rel, str) or not rel or rel.startswith(("/", "\\")) or "\x00" in rel:
        raise InputError("give a path inside the data folder", str(rel)[:80])
    root = data_dir.resolve()
    path = (root / rel).resolve()
    if path != root and root not in path.parents:
        raise InputError("outside the data folder: refused", rel)
    if not path.is_file():
        raise InputError("no such file in the data folder", rel)
    return path


def list_files(data_dir: Path, limit: int = 2000) -> dict:
    """Logs, models and plants under ``data_dir`` (relative paths; links leaving it skipped); a file
    without a suffix is a log where its content is one (RoasTime's own files)."""
    root = data_dir.resolve()
    logs, models, plants = [], [], []
    for path in sorted(root.rglob("*")):
        if len(logs) + len(models) + len(plants) >= limit:
            break
        if not path.is_file() or any(p.startswith(".") for p in path.relative_to(root).parts):
            continue
        real = path.resolve()
        if real != root and root not in real.parents:
            continue
        rel = path.relative_to(root).as_posix()
        if rel.startswith("downloads/"):
            continue
        suffix = path.suffix.lower()
        if suffix == ".toml":
            head = path.read_bytes()[:4096]
            if b"Dch_m" in head or b"Mb_kg" in head:
                plants.append(rel)
        elif suffix == ".json" and b"roastlab-model" in path.read_bytes()[:4096]:
            models.append(rel)
        elif suffix in LOG_SUFFIXES or (not suffix and is_log_by_content(path)):
            logs.append(rel)
    return {"logs": logs, "models": models, "plants": plants}


def _series(values) -> list | None:
    """A series as JSON numbers (3 decimals), missing values as null."""
    if values is None:
        return None
    a = np.round(np.asarray(values, dtype=float), 3)
    return [None if v != v or v in (np.inf, -np.inf) else v for v in a.tolist()]


def curves(batch, result, et: str = "Tm") -> dict:
    """The page's view of one prediction: times, BT and beans, the model's ET (``et``: "Tm" the
    drum, "Tgi" the inlet gas the model sees, "Tb" the beans where ET is a bean reading, as :func:`roastlab.workflows.transfer.et_source`
    reads the machine's map), the settings and the rate of rise [degC/min] (the one RoR of
    :mod:`roastlab.metrics.profile`); with ``batch`` the measured BT, ET and a second bean
    reading too."""
    from ..report.figures import second_bean_reading
    from ..workflows.transfer import model_et_C

    t = result.time_s
    out = {
        "time_s": _series(t),
        "BT_model": _series(result.Ta_C),
        "beans_model": _series(result.Tb_C),
        "ET_model": _series(model_et_C(result, et)),
        "RoR_model": _series(rate_of_rise_C_per_min(t, result.Ta_C)),
        "heater": _series(result.heater),
        "fan": _series(result.fan),
    }
    if batch is not None and batch.Ta_C is not None:
        out["BT_measured"] = _series(batch.Ta_C)
        out["RoR_measured"] = _series(rate_of_rise_C_per_min(batch.time_s, batch.Ta_C))
    if batch is not None and (reading := second_bean_reading(batch)) is not None:
        out["beans_measured"] = _series(batch.Tb2_C)
        out["beans_measured_label"], out["beans_measured_few"] = reading
        out["beans_measured_label_F"] = second_bean_reading(batch, "F")[0]  # the page in degF
    if batch is not None and batch.ET_C is not None:
        out["ET_measured"] = _series(batch.ET_C)
    return out


#: What the model's ET curve is, per :func:`roastlab.workflows.transfer.et_source`.
ET_NAMES = {"Tm": "drum metal (model Tm)", "Tgi": "inlet gas the model sees (Tgi)", "Tb": "the beans (model Tb)"}


def band(model, batch) -> dict:
    """The as-run prediction band of :func:`roastlab.evaluate.bands.prediction_bands` (level
    :data:`~roastlab.evaluate.bands.BAND_LEVEL`) or, for a model without standard errors or a
    roast-to-roast spread, ``{"why": ...}``."""
    from ..evaluate.bands import BAND_LEVEL, band_note, prediction_bands, why_no_band

    why = why_no_band(model)
    if why is not None:
        return {"why": why}
    return band_dict(prediction_bands(model, [batch], BAND_LEVEL)[0], band_note(model, [batch]))


def whatif_table(w) -> dict:
    """A :class:`~roastlab.workflows.whatif.WhatIf`'s table as ``roastlab whatif --json`` writes it (numbers
    in degC), and its notes, sentences, in each unit the page shows (``warnings_by_unit``): the page
    turns the numbers into its unit itself, and a note reads in the unit of the table beside it."""
    return {**w.to_json_dict(), "warnings_by_unit": {u: w.warnings(u) for u in DISPLAY_UNITS}}


def band_dict(b, note: str | None = None) -> dict:
    """A :class:`~roastlab.evaluate.bands.Band` as the page draws it; ``note``: why it may hold
    fewer samples than its level (:func:`roastlab.evaluate.bands.band_note`)."""
    return {
        "level": b.level,
        "lower": _series(b.lower_C),
        "upper": _series(b.upper_C),
        "median_width_C": round(b.median_width_C, 2),
        **({"note": note} if note else {}),
    }


def _fit_figures(batch, result, fitted: bool = False) -> dict | None:
    """FIT [%] and MAE [degC] of the model as run against the measured BT (the paper's indexes,
    :func:`roastlab.evaluate.metrics.batch_metrics`); ``fitted_on``: the model was fitted on this
    roast (:meth:`roastlab.workflows.model.FittedModel.fitted_roasts`), so they are not a prediction's."""
    from ..evaluate.metrics import batch_metrics

    if batch.Ta_C is None:
        return None
    m = batch_metrics(batch.Ta_C, result.Ta_C)
    return {"FIT_pct": round(m["FIT"], 1), "MAE_C": round(m["MAE"], 2), "fitted_on": fitted}


def report_html(folder: Path) -> str | None:
    """``folder``/report.md (``roastlab fit-roaster``'s report) as HTML for the page, or None where
    there is none: :func:`roastlab.report.markdown.markdown_html`, its figures the PNGs beside it that
    it names (a picture naming anything else, a path out of the folder included, is dropped)."""
    from ..report.markdown import markdown_html

    path = folder / "report.md"
    if not path.is_file():
        return None
    root = folder.resolve()  # a link out of the folder is not read
    pictures = {p.name: p.read_bytes() for p in folder.glob("*.png") if p.resolve().parent == root and p.is_file()}
    return markdown_html(path.read_text(encoding="utf-8"), pictures)


def _report_beside(model_path: Path) -> str | None:
    """The fit report of a model ``fit-roaster`` wrote (``model.json`` with ``report.md`` beside it,
    written with or after it), as HTML (:func:`report_html`); None for any other model file."""
    report = model_path.parent / "report.md"
    if model_path.name != "model.json" or not report.is_file():
        return None
    if report.stat().st_mtime < model_path.stat().st_mtime:
        return None  # the model was written again after the report: the report is not its
    return report_html(model_path.parent)


def _program_sets(body: dict, units: dict) -> list:
    """Steps dragged on the page's program plot: ``[{"setting", "value", "from_s", "until_s"}]``
    -> :class:`~roastlab.workflows.whatif.SettingChange` "set" changes, in the order given."""
    from ..io.files import finite_number
    from ..workflows.whatif import SettingChange

    items = body.get("program") or []
    if not isinstance(items, list) or len(items) > 500:
        raise InputError("program: expected a list of at most 500 steps", "request")
    out = []
    for i, item in enumerate(items):
        if not isinstance(item, dict) or item.get("setting") not in ("heater", "fan"):
            raise InputError("program step: expected {setting: heater|fan, value, from_s, until_s}", f"step {i + 1}")
        where = f"program step {i + 1}"
        value = finite_number(item.get("value"), "request", where)
        start = finite_number(item.get("from_s", 0.0), "request", where)
        end = finite_number(item.get("until_s", 1e9), "request", where)
        out.append(SettingChange(item["setting"], "set", value, max(start, 0.0), units.get(item["setting"], ""), end))
    return out


def _changes(body: dict, session: Session):
    """The what-if's changes from the page's fields (the CLI's parsers, the same units)."""
    from ..io.files import finite_number
    from ..model.limits import check_value
    from ..workflows.whatif import drop_time_s, parse_setting_change

    setting_changes, changes = [], {}
    cmap = session.model.column_map
    units = cmap.setting_units() if cmap else {}
    for name in ("heater", "fan"):
        text = str(body.get(name) or "").strip()
        if text and text not in ("+0", "0", "-0"):
            setting_changes.append(parse_setting_change(name, text, units.get(name, "")))
    setting_changes += _program_sets(body, units)
    for key, name in (("Tm0_C", "Tm0_C"), ("Tb0_C", "Tb0_C"), ("X0", "X0"), ("batch_kg", "batch_kg")):
        if body.get(key) not in (None, ""):
            changes[name] = check_value(name, body[key], key)
    if body.get("tgi") not in (None, "", 0, "0"):
        changes["Tgi_offset_C"] = check_value("Tgi_offset_C", body["tgi"], "tgi")
    # the changed roast's DROP (roastlab whatif --drop-at / --drop-bt): a time, or the BT [degC] to drop at
    if str(body.get("drop_at") or "").strip():
        changes["drop_s"] = drop_time_s(str(body["drop_at"]), float(session.batch.time_s[-1]))
    if body.get("drop_bt") not in (None, ""):
        changes["drop_bt_C"] = finite_number(body["drop_bt"], "request", "drop_bt")
    return setting_changes, changes


def _limits(body: dict, model, plant_to):
    """The transfer's limits: the default for this machine and target
    (:func:`roastlab.workflows.transfer.default_limits`), with the page's lowest and highest level
    of the decided input where given (the CLI's --heater-min/--heater-max, --tgi-min/--tgi-max)."""
    from ..fit.program import ProgramLimits
    from ..workflows.transfer import default_limits

    d = default_limits(model, None, plant_to)
    low, high = (None if body.get(k) in (None, "") else body[k] for k in ("limit_low", "limit_high"))
    if low is None and high is None:
        return d
    return ProgramLimits.for_model(model.column_map, d.decide, low, high)


def create_app(data_dir: str | Path):
    """The Starlette application serving the page over ``data_dir``."""
    from starlette.applications import Starlette
    from starlette.requests import Request
    from starlette.responses import FileResponse, HTMLResponse, JSONResponse, Response
    from starlette.routing import Route

    from ..io.files import end_run

    data = Path(data_dir)
    if not data.is_dir():
        raise InputError("not a folder", data)
    end_run()  # a server is not one run: each write below names its own inputs (roastlab.io.files.end_run)
    sessions = Sessions()
    assets = resources.files("roastlab.app")

    def error(exc: Exception, status: int = 400) -> JSONResponse:
        return JSONResponse({"error": str(exc)}, status_code=status)

    def handler(fn):
        async def wrapped(request: Request):
            try:
                body = await request.json() if request.method == "POST" else {}
                if not isinstance(body, dict):
                    raise InputError("expected a JSON object", "request")
                session = sessions.get(request.headers.get("x-session"))
                return JSONResponse(fn(session, body))
            except RoastlabError as exc:
                return error(exc)
            except ValueError as exc:  # malformed JSON
                return error(InputError(f"bad request ({exc})", "request"))
            except Exception as exc:  # noqa: BLE001 - the page shows it; the server keeps running
                return error(RoastlabError(f"internal error: {type(exc).__name__}: {exc}"), 500)

        return wrapped

    async def page(request: Request):
        return HTMLResponse((assets / "page.html").read_text(encoding="utf-8"))

    async def page_js(request: Request):
        return Response((assets / "page.js").read_text(encoding="utf-8"), media_type="text/javascript")

    async def plotly_js(request: Request):
        import plotly

        path = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"
        return FileResponse(path, media_type="text/javascript")

    def files(session: Session, body: dict) -> dict:
        return list_files(data)

    def open_log(session: Session, body: dict) -> dict:
        from ..metrics.profile import phases
        from ..model.quantities import QUANTITIES
        from ..workflows.model import load_log_for, load_model
        from ..workflows.transfer import default_limits, et_source
        from ..workflows.whatif import whatif

        model_path = inside(data, body.get("model", ""))
        model = load_model(model_path)
        log_path = inside(data, body.get("log", ""))
        batch = load_log_for(log_path, model)
        w = whatif(model, batch)
        session.batch, session.model, session.log = batch, model, body["log"]
        session.model_path, session.as_run = body["model"], w.as_run
        session.et = et_source(model.column_map)
        lim = default_limits(model)
        probe = {r["key"]: r for r in w.rows if r["reading"] == "probe"}
        ms = {k: probe[k]["measured" if batch.Ta_C is not None else "as_run"] for k in ("DRY_s", "FCs_s")}
        ms["DROP_s"] = float(batch.time_s[-1])
        cmap = model.column_map
        actuators = {}
        for name in ("heater", "fan"):
            act = cmap.actuator(name) if cmap is not None and getattr(batch, name) is not None else None
            if act is not None:
                actuators[name] = {"unit": act.unit, "low": act.low, "high": act.high, "step": act.step,
                                   "label": act.describe()}  # fmt: skip
        return {
            "log": batch.name,
            "model": body["model"],  # the model file the curves and figures are from, as chosen
            "batch_kg": batch.Mb_kg,
            "temp_unit": batch.temp_unit,  # the unit the log was recorded in: the page shows it unless told otherwise
            "Tm0_C": round(float(w.as_run.Tm_C[0]), 1),  # the drum at CHARGE the model starts from
            "X0": round(float(w.as_run.X_kg_kg[0]), 4),
            "Tb0_C": round(float(w.as_run.Tb_C[0]), 1),
            # the fields' ranges: the span an identification may give each initial state
            "ranges": {k: QUANTITIES[k].bounds for k in ("Tm0_C", "Tb0_C", "X0")},
            "transfer_limits": {"decide": lim.decide, "unit": lim.unit, "low": lim.low, "high": lim.high},
            "events": batch.events,
            "notes": list(batch.notes),
            "curves": curves(batch, w.as_run, session.et),
            "ET_model_is": ET_NAMES[session.et],
            "phases": phases(ms),
            "band": band(model, batch),
            "metrics": _fit_figures(batch, w.as_run, fitted=batch.name in model.fitted_roasts([batch])),
            "table": whatif_table(w),
            "settings": model.column_map.setting_units() if model.column_map else {},
            "actuators": actuators,
            "report_html": _report_beside(model_path),  # the fit report, where fit-roaster wrote the model
        }

    def need(session: Session):
        if session.batch is None:
            raise InputError("open a log and a model first", "page")

    def whatif_(session: Session, body: dict) -> dict:
        from ..evaluate.bands import BAND_LEVEL, why_no_band
        from ..workflows.whatif import whatif

        need(session)
        t0 = time.perf_counter()
        setting_changes, changes = _changes(body, session)
        with_band = bool(body.get("band")) and why_no_band(session.model) is None
        w = whatif(
            session.model, session.batch, setting_changes, band_level=BAND_LEVEL if with_band else None, **changes
        )
        return {
            "curves": curves(None, w.changed, session.et),
            "table": whatif_table(w),
            "band": band_dict(w.band, w.band_note) if w.band is not None else None,
            "server_ms": round((time.perf_counter() - t0) * 1e3, 2),
        }

    def whatif_background(session: Session, body: dict) -> dict:
        """The what-if's changed roast as an Artisan background (the page's changes, the same call as
        ``roastlab whatif --alog``) and, where the machine has settings, its changed settings as Artisan
        alarms (``--alarms``), written under the tab's downloads folder."""
        from ..workflows.whatif import whatif

        need(session)
        setting_changes, changes = _changes(body, session)
        w = whatif(session.model, session.batch, setting_changes, **changes)
        stem = f"{session.batch.name}-whatif"
        files = {f"{stem}-background.alog": w.alog_text()}
        if w.setting_series():
            files[f"{stem}-settings.alrm"] = w.alarms_text()
        url, *alarms = downloads(session, files)
        return {"download": url, "alarms": alarms[0] if alarms else None, "changes": w.changes}

    def downloads(session: Session, files: dict[str, str]) -> list[str]:
        """Write ``files`` (name -> text) under the tab's downloads folder, atomically and never over
        the open log; their URLs, in order."""
        folder = data / "downloads" / session.sid
        names = [re.sub(r"[^A-Za-z0-9_.-]", "_", name) for name in files]
        with Outputs([data / session.log]) as out:
            out.folder(folder)
            for name, text in zip(names, files.values()):
                out.write_text(folder / name, text)
        rel = folder.relative_to(data).as_posix()
        return [f"/{rel}/{name}" for name in names]

    def transfer_(session: Session, body: dict) -> dict:
        from ..evaluate.bands import BAND_LEVEL, why_no_band
        from ..io.importers import import_log
        from ..model.actuators import TM0_FREE_RANGE_C
        from ..model.limits import check_value
        from ..model.plant import preset_names
        from ..workflows.transfer import aim_at, transfer

        need(session)
        kg = body.get("batch_kg")
        tm0_free = TM0_FREE_RANGE_C if body.get("tm0_free") else None
        plant_to = body.get("plant_to") or None
        if plant_to is not None and not any(plant_to == p for p in preset_names()):
            plant_to = inside(data, plant_to)  # a PLANT.toml in the data folder, never outside it
        reference = session.batch
        if body.get("target"):  # another log's BT from this log's settings and charge state (transfer --target)
            reference = aim_at(reference, import_log(inside(data, body["target"]), None))
        r = transfer(
            session.model,
            reference,
            None,
            plant_to,
            limits=_limits(body, session.model, plant_to),
            batch_kg=None if kg in (None, "") else check_value("batch_kg", kg, "to batch"),
            tm0_free=tm0_free,
            band_level=None if why_no_band(session.model) else BAND_LEVEL,
            units="F" if body.get("units") == "F" else "C",  # the page's unit, for the summary's words
        )
        stem = f"{reference.name}-{r.batch_kg:g}kg"  # the followed curve's name (a --target's)
        files = {f"{stem}-program.csv": r.program_csv_text(), f"{stem}-background.alog": r.alog_text()}
        if r.limits.decide == "heater":  # a heater program runs in Artisan as its alarms (transfer --alarms)
            files[f"{stem}-program.alrm"] = r.alarms_text()
        urls = downloads(session, files)
        pr = r.program
        return {
            "summary": r.summary(),
            "metrics": r.to_json_dict(),
            "time_s": _series(pr.time_s),
            "target": _series(r.target_C),
            "predicted": _series(pr.Ta_pred_C),
            "program": _series(pr.Tgi_C if r.limits.decide == "Tgi" else pr.heater),
            "decide": r.limits.decide,
            "unit": r.limits.unit,
            # the axis of the program: the limits, in the machine's steps where it has them
            "low": r.limits.low,
            "high": r.limits.high,
            "step": r.limits.actuator.step if r.limits.actuator is not None and r.limits.actuator.stepped else None,
            "downloads": urls,
            "band": band_dict(r.band) if r.band is not None else None,
        }

    def fit_start(session: Session, body: dict) -> dict:
        from ..workflows.roaster import fit_roaster
        from ..workflows.sizes import across_sizes_sentence
        from ..workflows.survey import init_roaster, roaster_name

        logs = body.get("logs") or []
        units = body.get("units") if body.get("units") in DISPLAY_UNITS else None  # the page's, else the logs'
        if not isinstance(logs, list) or len(logs) < 2:
            raise InputError("choose at least two logs of one roaster to fit (one to fit, one to hold out)", "fit")
        paths = [inside(data, rel) for rel in logs]
        given = str(body.get("name") or "")[:40] or None  # none typed: the make its logs record names it
        folder = data / "roasters" / roaster_name(given, None)
        if session.fit.get("running"):
            raise InputError("a fit is already running in this tab", "fit")
        session.fit = {"running": True, "done": 0, "total": 1, "text": "reading the logs", "name": folder.name}

        def progress(done, total, text=""):
            session.fit.update(done=done, total=total, text=text)

        def work():
            try:
                init_roaster(paths, folder, batch_kg=body.get("batch_kg") or None, name=given)
                r = fit_roaster(
                    folder,
                    paths,
                    progress=progress,
                    every_log=bool(body.get("every_log")),
                    by_size=bool(body.get("by_size")),
                    units=units,
                )
                session.fit.update(
                    running=False,
                    model=(folder / "model.json").relative_to(data).as_posix(),
                    report=(folder / "report.md").read_text(encoding="utf-8"),
                    report_html=report_html(folder),  # the same as the page shows it, its figures in place
                    held_out=r["held_out"],
                    verdict=r["below_baseline"],
                    every_log=r["every_log"] and {"FIT": r["every_log"]["FIT"]},
                    across_sizes=r["across_sizes"] and across_sizes_sentence(r["across_sizes"]),
                )
            except RoastlabError as exc:
                session.fit.update(running=False, error=str(exc))
            except Exception as exc:  # noqa: BLE001 - reported on the page
                session.fit.update(running=False, error=f"internal error: {type(exc).__name__}: {exc}")

        threading.Thread(target=work, daemon=True).start()
        return {"started": True, "folder": folder.relative_to(data).as_posix()}

    def fit_status(session: Session, body: dict) -> dict:
        return {k: v for k, v in session.fit.items()}

    async def upload(request: Request):
        from ..workflows.model import load_log_for, load_model
        from ..workflows.survey import inspect_log

        try:
            sessions.get(request.headers.get("x-session"))
            name = Path(request.query_params.get("name", "")).name
            if not name or Path(name).suffix.lower() not in LOG_SUFFIXES:
                raise InputError(f"upload a log ({', '.join(LOG_SUFFIXES)})", name or "upload")
            size = int(request.headers.get("content-length") or 0)
            if size > MAX_UPLOAD_BYTES:
                raise InputError(f"{size / 1e6:.1f} MB is over the {MAX_UPLOAD_BYTES // 2**20} MB upload limit", name)
            chunks, total = [], 0
            async for chunk in request.stream():
                total += len(chunk)
                if total > MAX_UPLOAD_BYTES:
                    raise InputError(f"over the {MAX_UPLOAD_BYTES // 2**20} MB upload limit", name)
                chunks.append(chunk)
            folder = data / "uploads"
            target = folder / name
            with Outputs() as out:
                out.folder(folder)
                out.write_bytes(target, b"".join(chunks))
            model_rel = request.query_params.get("model")
            try:  # read it as the model would (with none chosen, as `init` reads a log), so a bad file is refused now
                load_log_for(target, load_model(inside(data, model_rel))) if model_rel else inspect_log(target)
            except RoastlabError:
                target.unlink(missing_ok=True)
                raise
            return JSONResponse({"path": target.relative_to(data).as_posix()})
        except RoastlabError as exc:
            return error(exc)

    async def download(request: Request):
        rel = request.path_params["path"]
        try:
            path = inside(data, "downloads/" + rel)
        except RoastlabError as exc:
            return error(exc, 404)
        return FileResponse(path, filename=path.name)

    routes = [
        Route("/", page),
        Route("/assets/page.js", page_js),
        Route("/assets/plotly.min.js", plotly_js),
        Route("/api/files", handler(files), methods=["GET"]),
        Route("/api/open", handler(open_log), methods=["POST"]),
        Route("/api/whatif", handler(whatif_), methods=["POST"]),
        Route("/api/whatif-background", handler(whatif_background), methods=["POST"]),
        Route("/api/transfer", handler(transfer_), methods=["POST"]),
        Route("/api/upload", upload, methods=["POST"]),
        Route("/api/fit", handler(fit_start), methods=["POST"]),
        Route("/api/fit-status", handler(fit_status), methods=["GET"]),
        Route("/downloads/{path:path}", download),
    ]
    return Starlette(routes=routes)
