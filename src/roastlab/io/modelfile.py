"""The fitted-model file, ``roastlab-model/1``: the one module that reads and writes it.

A model file is JSON::

    {
     "format": "roastlab-model/1",
     "plant": {"name": ..., "Mb_kg": ..., "Dch_m": ..., ..., "process": {A: ..., ...}},
     "parameters": {NAME: {"value": v, "unit": u, "how": "fitted" | "fixed" | "default",
                           "stderr": se or null, "bounds": [lo, hi] or null}},
     "initial": {STATE0: {"how": "fixed" | "fitted" | "fitted per batch" | "from log",
                          "value": v or null, "per_batch": {batch: v}, "stderr": ...}},
     "moisture": "schwartzberg", "hold": "linear",
     "map": {the column map as TOML-shaped data} or null,
     "fit": {"SSR": ..., "n_residuals": ..., "method": ..., "seed": ..., "correlation": ..., "warnings": [...],
             "batches": [the fitted batches' names], "started_epoch_s": [when each one's recording started, or null],
             "outputs": {"Ta" | "Tb2" | "ET": {"weight": w, "n": n, "SSR": unweighted}},
             "weights_from_residuals": {"outputs", "rule", "first_pass": {output: {"rms_C"}}} (a spec's "residual"),
             "spread": {"time_s", "rms_C", "logs", "held_out", "batch_kg"} (the bands' roast-to-roast part),
             "failed": why, when the fitted states are ones the machine cannot have},
     "metrics": {"batches": [...], "average": {...}},
     "provenance": {"roastlab": version, "created": ISO 8601, "inputs": [{"role", "path", "sha256"}]}
    }

``parameters`` always holds hgm, hbm and Pbm and every other quantity of the registry
(:data:`roastlab.model.parameters.REGISTRY`) that the fit moved or held. THETA.json files of
roastlab 0.1 (``{"hgm": ..., "hbm": ..., "Pbm": ..., ...}``) still load.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from ..errors import InputError, ParameterError
from ..model.bed import BedLaws
from ..model.limits import check_value
from ..model.parameters import REGISTRY, STATE0, THETA_NAMES, Theta
from ..model.plant import GEOMETRY_KEYS, Plant, plant_from_mapping
from .files import finite_number, read_input_text

FORMAT = "roastlab-model/1"
INITIAL_HOW = ("fixed", "fitted", "fitted per batch", "from log")
PARAMETER_HOW = ("fitted", "fixed", "default")
#: Deepest JSON nesting a model file may have (a real one has 5 levels).
MAX_DEPTH = 32


def _depth_ok(text: str) -> bool:
    depth = deepest = 0
    in_str = esc = False
    for ch in text:
        if in_str:
            if esc:
                esc = False
            elif ch == "\\":
                esc = True
            elif ch == '"':
                in_str = False
        elif ch == '"':
            in_str = True
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
            if deepest > MAX_DEPTH:
                return False
        elif ch in "]}":
            depth -= 1
    return True


def parse_json_document(text: str, path) -> object:
    """JSON with bounded nesting and no NaN/Infinity literals; one InputError on any failure."""
    if not _depth_ok(text):
        raise InputError(f"JSON nested deeper than {MAX_DEPTH} levels", path)

    def no_constant(name):
        raise InputError(f"non-finite number {name} (JSON has no NaN or Infinity)", path)

    try:
        return json.loads(text, parse_constant=no_constant)
    except json.JSONDecodeError as exc:
        raise InputError(f"not valid JSON ({exc.msg} at line {exc.lineno}, column {exc.colno})", path) from None
    except (RecursionError, ValueError, OverflowError):
        raise InputError("JSON with numbers out of range", path) from None


def read_model_document(path: str | Path) -> dict:
    """Read a model file (or a legacy THETA.json) into a checked ``roastlab-model/1`` mapping."""
    path = Path(path)
    data = parse_json_document(read_input_text(path, "a JSON model file"), path)
    if not isinstance(data, dict):
        raise InputError(f"expected a JSON object, got {type(data).__name__}", path)
    if data.get("baseline") == "first-order":
        raise InputError("a first-order baseline file, not a model: use it with --baseline first-order", path)
    if data.get("mode") == "per-batch":
        raise InputError("a per-batch (fleet) result, not a model: refit without --per-batch to get a model", path)
    fmt = data.get("format")
    if fmt is None:
        data = _from_legacy(data, path)
    elif fmt != FORMAT:
        raise InputError(f"unknown model format {str(fmt)[:40]!r} (this roastlab reads {FORMAT})", path)
    return check_document(data, path)


def _from_legacy(data: dict, path) -> dict:
    """A roastlab 0.1 THETA.json -> the ``roastlab-model/1`` layout."""
    missing = [k for k in THETA_NAMES if k not in data]
    if missing:
        raise InputError(f"missing key(s) {', '.join(missing)} (not a model or THETA.json file)", path)
    fixed = data.get("fixed") if isinstance(data.get("fixed"), list) else []
    stderr = data.get("stderr") if isinstance(data.get("stderr"), dict) else {}
    bounds = data.get("bounds") if isinstance(data.get("bounds"), dict) else {}
    names = data.get("batches") if isinstance(data.get("batches"), list) else []
    params, initial = {}, {}
    for name, value in data.items():
        if name not in REGISTRY:
            continue
        how = "fixed" if name in fixed else ("fitted" if name in stderr or name in bounds else "fixed")
        if name in STATE0:
            if isinstance(value, list):
                if len(value) != len(names):
                    raise InputError(f"{len(value)} per-batch values for {len(names)} batches", path, f"key {name}")
                initial[name] = {"how": "fitted per batch", "per_batch": dict(zip(map(str, names), value))}
            else:
                initial[name] = {"how": how, "value": value}
        else:
            params[name] = {"value": value, "how": how, "stderr": stderr.get(name), "bounds": bounds.get(name)}
    saved = data.get("initial") if isinstance(data.get("initial"), dict) else {}
    for name, value in saved.items():
        if name in STATE0 and name not in initial:
            initial[name] = {"how": "fixed", "value": value}
    plant = data.get("plant")
    return {
        "format": FORMAT,
        "plant": plant if isinstance(plant, (str, dict)) else None,
        "parameters": params,
        "initial": initial,
        "moisture": data.get("moisture", "schwartzberg"),
        "hold": data.get("hold", "linear"),
        "map": None,
        "fit": {k: data[k] for k in ("SSR", "n_residuals", "method", "seed", "warnings") if k in data},
        "metrics": None,
        "provenance": {"legacy": "THETA.json of roastlab 0.1", "map_path": data.get("map"), "spec": data.get("spec")},
    }


def check_document(doc: dict, path) -> dict:
    """Check every value of a model mapping; returns it with numbers as floats."""
    params = doc.get("parameters")
    if not isinstance(params, dict):
        raise InputError("missing or non-object 'parameters'", path)
    for name in THETA_NAMES:
        if name not in params:
            raise InputError(f"parameters has no {name}", path)
    for name, entry in params.items():
        where = f"parameters.{name}"
        if name not in REGISTRY or name in STATE0:
            raise InputError(
                f"unknown parameter (allowed: {', '.join(k for k in REGISTRY if k not in STATE0)})", path, where
            )
        if not isinstance(entry, dict):
            raise InputError("must be an object with a value", path, where)
        entry["value"] = finite_number(entry.get("value"), path, where)
        if entry.get("how", "fitted") not in PARAMETER_HOW:
            raise InputError(f"how must be one of {', '.join(PARAMETER_HOW)}", path, where)
        check_value(name, entry["value"], f"{path}: {where}")  # the quantity table's plausible range
    try:
        Theta(*(params[k]["value"] for k in THETA_NAMES))
    except ParameterError as exc:
        raise ParameterError(exc.problem, path, "parameters") from None
    initial = doc.get("initial") or {}
    if not isinstance(initial, dict):
        raise InputError("'initial' must be an object", path)
    for name, entry in initial.items():
        where = f"initial.{name}"
        if name not in STATE0 or not isinstance(entry, dict):
            raise InputError(f"unknown initial state (allowed: {', '.join(STATE0)})", path, where)
        if entry.get("how") not in INITIAL_HOW:
            raise InputError(f"how must be one of {', '.join(INITIAL_HOW)}", path, where)
        if entry.get("value") is not None:
            entry["value"] = finite_number(entry["value"], path, where)
        per = entry.get("per_batch")
        if entry["how"] == "fitted per batch":
            if not isinstance(per, dict) or not per:
                raise InputError("'fitted per batch' needs per_batch values", path, where)
            entry["per_batch"] = {str(k): finite_number(v, path, f"{where}.{k}") for k, v in per.items()}
        elif entry["how"] != "from log" and entry.get("value") is None:
            raise InputError("needs a value", path, where)
    for key, allowed in (("moisture", ("schwartzberg", "printed")), ("hold", ("linear", "zoh"))):
        if doc.get(key, allowed[0]) not in allowed:
            raise InputError(f"must be one of {', '.join(allowed)}", path, key)
    if doc.get("bed") is not None:
        try:
            doc["bed"] = BedLaws.parse(doc["bed"]).as_dict()
        except ParameterError as exc:
            raise InputError(exc.problem, path, "bed") from None
    plant = doc.get("plant")
    if isinstance(plant, dict):
        data = {k: v for k, v in plant.items() if k in GEOMETRY_KEYS or k in ("name", "process")}
        doc["plant"] = plant_from_mapping(data, f"{path} (plant)", str(plant.get("name", "plant")))
    elif plant is not None and not isinstance(plant, str):
        raise InputError("plant must be an object (or a name in old files)", path)
    if doc.get("map") is not None and not isinstance(doc["map"], dict):
        raise InputError("map must be an object or null", path)
    return doc


def plant_mapping(plant: Plant) -> dict:
    """A plant as the mapping the model file stores (geometry and every process constant)."""
    return {"name": plant.name, **plant.geometry(), "process": plant.process.as_dict()}


def jsonable(value):
    """NaN and inf become null: a model file is strict JSON."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, Plant):
        return plant_mapping(value)
    return value


def model_document_text(doc: dict) -> str:
    """The model mapping as the text of a ``roastlab-model/1`` file."""
    return json.dumps(jsonable({"format": FORMAT, **doc}), indent=1, allow_nan=False) + "\n"
