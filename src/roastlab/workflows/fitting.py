"""Fit a model to batches: identification (eqs. 18-19) -> a :class:`FittedModel` and its report.

>>> import roastlab
>>> ds = roastlab.read_dataset(roastlab.default_dataset_root() / "dataset-I")   # SYNTHETIC data
>>> result = roastlab.fit(ds.batches, plant="120kg", seed=0)
>>> result.model                                                                # doctest: +ELLIPSIS
<FittedModel 120kg: hgm=0.04..., hbm=0.02..., Pbm=0.5>
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from ..errors import InputError, ParameterError
from ..evaluate.bands import roast_spread
from ..evaluate.validate import ValidationResult
from ..fit.identify import (
    NO_ET_READING,
    NO_SECOND_READING,
    IdentificationResult,
    build_free_parameters,
    identify,
    residual_weights,
)
from ..io.batch import Batch, first_of_each_roast
from ..io.fitspec import FitSpec, load_fit_spec
from ..io.importers.mapping import ET_NOT_DRUM_AIR, ColumnMap
from ..io.plants import load_plant
from ..metrics.profile import implausible_summary
from ..model.bed import PAPER_BED, BedLaws
from ..model.parameters import N_STARTS, REGISTRY, RESIDUAL_WEIGHT, STATE0, THETA_NAMES, THETA_START
from ..report.result import Result
from ..sim.population import pack_batches
from ..sim.simulate import InitialState
from .model import PAPER_INITIAL, PLACEHOLDER_GG_KG_S, FittedModel, load_log, provenance

#: How a fit whose states the machine cannot have is marked, before the sentence that says which
#: (:func:`~roastlab.metrics.profile.implausible_summary`; :attr:`FittedModel.failed`).
FAILED_STATES = "non-physical states: "


@dataclasses.dataclass
class FitResult(Result):
    """What :func:`fit` returns: the model, the identification behind it, its fit-set validation."""

    model: FittedModel
    identification: IdentificationResult
    validation: ValidationResult

    @property
    def stderr(self) -> dict:
        return self.identification.stderr

    @property
    def correlation(self) -> dict:
        return self.identification.correlation

    @property
    def warnings(self) -> list[str]:
        return self.identification.warnings

    @property
    def failed(self) -> str | None:
        """Why the fit failed (states the machine cannot have, :attr:`FittedModel.failed`), or None."""
        return self.model.failed

    def failed_in(self, units: str = "C") -> str | None:
        """:attr:`failed` with its temperatures in ``units`` ("C" or "F"), said again from the fit set's
        states (the model file keeps it in degC)."""
        if self.failed is None or units == "C":
            return self.failed
        summary = implausible_summary(self.validation.results, units)
        return f"{FAILED_STATES}{summary}" if summary else self.failed

    def warnings_in(self, units: str = "C") -> list[str]:
        """:attr:`warnings` with the one about the states (:func:`implausible_summary`) in ``units``."""
        said = None if units == "C" else implausible_summary(self.validation.results)
        if said is None:
            return self.warnings
        there = implausible_summary(self.validation.results, units)
        return [there if w == said else w for w in self.warnings]

    def report(self) -> str:
        """Text report in the spirit of lmfit's ``fit_report``: values, errors, fit figures, warnings."""
        ident = self.identification
        head = (
            f"fit on {len(self.validation.names)} batch(es), {ident.n_residuals} samples "
            f"[{ident.method}, seed {ident.seed}]: {ident.nfev} simulations in {ident.wall_s:.2f} s"
        )
        corr = ident.correlation
        lines = [head, self.model.report(), "correlations (|r| > 0.5):"]
        if self.failed:
            lines.insert(1, f"FIT FAILED: {self.failed}")
        names = corr["names"]
        for a in range(len(names)):
            for b in range(a + 1, len(names)):
                c = corr["matrix"][a][b]
                if c is not None and abs(c) > 0.5:
                    lines.append(f"  {names[a]}, {names[b]}: {c:+.3f}")
        return "\n".join(lines)

    def to_frame(self):
        """The model's values as a DataFrame (name, value, std. error, unit, how)."""
        import pandas as pd

        return pd.DataFrame(self.model.table(), columns=["name", "value", "stderr", "unit", "how"]).set_index("name")

    def summary(self) -> str:
        """The text report (:meth:`report`)."""
        return self.report()

    def to_json_dict(self) -> dict:
        """The identification (values, standard errors, covariance, AIC/BIC) and the fit-set validation."""
        return {"identification": self.identification.to_json_dict(), "validation": self.validation.to_json_dict()}

    def _figure(self, path, outputs, title=None):
        """Fit-set figure (measured vs predicted BT, residuals)."""
        return self.validation.plot(path, outputs=outputs, title=title or "fit set: measured vs predicted BT")

    def _draw(self, ax) -> None:
        self.validation.plot(ax=ax)

    def __repr__(self) -> str:
        a = self.validation.average
        return f"<FitResult {self.model!r}, fit-set FIT {a['FIT']:.2f} %, MAE {a['MAE']:.3f} °C>"


def _started_at(f, values: dict):
    """Free parameter ``f`` started at its value in ``values`` (inside its bounds); a per-batch one as it was."""
    v = values.get(f.name)
    if f.per_batch or not isinstance(v, (int, float)) or not math.isfinite(v):
        return f
    return dataclasses.replace(f, start=min(max(float(v), f.lower), f.upper))


def _spec_parts(spec, fix, bounds, estimate_tm0):
    if spec is None:
        free, fixed = build_free_parameters(fix, bounds, estimate_tm0=estimate_tm0)
        return free, fixed, {}, None, {}, None
    spec = spec if isinstance(spec, FitSpec) else load_fit_spec(spec)
    if fix or bounds or estimate_tm0:
        raise InputError("a fit spec sets free and fixed parameters itself; drop fix/bounds/estimate_tm0", spec.source)
    return spec.free, dict(spec.fixed), dict(spec.initial), spec.source, dict(spec.weights), spec.bed


def _as_batch(item, column_map) -> Batch:
    """A log path read into a Batch (with ``column_map`` where given); anything else refused."""
    if not isinstance(item, (str, Path)):
        raise ParameterError(f"batches must be Batch objects or log paths, got {type(item).__name__} {item!r}")
    return load_log(item, column_map)


#: The second outputs a fit can weigh beside the probe, and the :class:`~roastlab.io.batch.Batch`
#: column each is read from.
SECOND_OUTPUTS = {"Tb2": "Tb2_C", "ET": "ET_C"}


def weighs(weights: dict, name: str) -> bool:
    """Whether ``weights`` (an output's name to its weight) fit output ``name``: a positive number, or
    :data:`~roastlab.model.parameters.RESIDUAL_WEIGHT` (a weight that is no number is refused by
    identify's ``check_weights``)."""
    w = weights.get(name, 0)
    return w == RESIDUAL_WEIGHT or (isinstance(w, (int, float)) and w > 0)


def records(batches, name: str) -> bool:
    """Whether any of ``batches`` records the second output ``name`` (:data:`SECOND_OUTPUTS`): a
    finite sample of its column."""
    column = SECOND_OUTPUTS[name]
    return any(getattr(b, column) is not None and np.isfinite(getattr(b, column)).any() for b in batches)


def et_dropped(batches) -> int:
    """How many of ``batches`` had their ET left out by the map because it reads below BT through the
    roast (the map's ``[ET] above_BT``, :data:`~roastlab.io.importers.mapping.ET_NOT_DRUM_AIR`)."""
    return sum(any(ET_NOT_DRUM_AIR in n for n in b.notes) for b in batches)


def fit(
    batches: list[Batch],
    plant,
    spec=None,
    *,
    fix: dict | None = None,
    bounds: dict | None = None,
    estimate_tm0: bool = False,
    initial: dict | None = None,
    moisture: str = "schwartzberg",
    hold: str = "linear",
    method: str = "global",
    seed: int = 0,
    starts: int = N_STARTS,
    column_map: ColumnMap | None = None,
    progress=None,
    weights: dict | None = None,
    bed=None,
) -> FitResult:
    """Identify a model on batches with measured Ta and return a :class:`FitResult`.

    Parameters
    ----------
    batches : list of Batch (from :func:`roastlab.load_log` or :func:`roastlab.read_dataset`) or of
        log paths (read with ``column_map``, or as batch CSVs without one)
    plant : Plant, preset name or PLANT.toml path
    spec : FitSpec or FIT.toml path: free parameters with bounds, fixed values, initial states
    fix, bounds, estimate_tm0 : without a spec: hold values (``{"hgm": 0.01}``), change bounds
        (``{"hbm": (0.01, 0.5)}``), fit each batch's initial metal temperature
    initial : initial-state defaults by name (``Tb0_C``, ``Tm0_C``, ``X0`` ...); default section 5.1
    moisture, hold : model variants (``"schwartzberg"``/``"printed"``, ``"linear"``/``"zoh"``)
    method, seed, starts : search (``"global"`` or ``"de"``), its seed, local polishes
    column_map : the map the logs were read with; kept in the model so it reads new logs alike
    progress : callable ``progress(done, total, text)`` or None
    weights : {output: weight}: ``Ta`` (the bean probe, default 1), ``Tb2`` (a second bean
        reading compared with Tb, default 0) and ``ET`` (the logged ET compared with the outlet gas
        Tgo, default 0), or ``"residual"`` for an output other than Ta: set from a first fit's residuals
        (:func:`roastlab.fit.identify.residual_weights`), the second fit searching as the first,
        from the first's optimum and from ``starts`` - 1 trial points; overrides the spec's ``[weights]``
    bed : bed laws (:class:`roastlab.model.bed.BedLaws`, its text or mapping); overrides the spec's
        ``[bed]``; default the paper's bed
    """
    if isinstance(batches, (str, Path, Batch)):
        batches = [batches]
    try:
        batches = list(batches)
    except TypeError:
        raise ParameterError(
            f"batches must be a list of Batch objects or log paths, got {type(batches).__name__}"
        ) from None
    if not batches:
        raise InputError("no batches to fit")
    batches = [b if isinstance(b, Batch) else _as_batch(b, column_map) for b in batches]
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ParameterError(f"seed must be a non-negative integer, got {seed!r}")
    if isinstance(starts, bool) or not isinstance(starts, (int, np.integer)) or starts < 1:
        raise ParameterError(f"starts must be a positive integer, got {starts!r}")
    for b in batches:
        if b.Ta_C is None:
            raise InputError("no measured Ta_C column: needed to identify", b.source or b.name)
    plant_file = str(plant) if isinstance(plant, (str, Path)) and str(plant).lower().endswith(".toml") else None
    plant = load_plant(plant)
    free, fixed, spec_initial, spec_source, spec_weights, spec_bed = _spec_parts(spec, fix, bounds, estimate_tm0)
    laws = BedLaws.parse(bed if bed is not None else spec_bed)
    given = dict(weights or {})
    weights = {**spec_weights, **given}
    from_residuals = [k for k, w in weights.items() if w == RESIDUAL_WEIGHT]  # set below, from a first fit
    if weighs(weights, "Tb2") and not records(batches, "Tb2"):
        raise InputError(NO_SECOND_READING, "command line" if "Tb2" in given else spec_source)
    if weighs(weights, "ET") and not records(batches, "ET"):
        dropped = et_dropped(batches)
        message = NO_ET_READING
        if dropped:  # the map's [ET] above_BT dropped it on every log given (io.importers.mapping)
            message = (
                f"the ET output has a weight, but the map dropped ET on all {dropped} log(s) given (it reads below BT "
                "through the roast there): add logs whose ET is the drum's air, or set ET = 0 under [weights] in the fit spec "
                "(identify: --weight ET=0)"
            )
        raise InputError(message, "command line" if "ET" in given else spec_source)
    names_moved = {f.name for f in free} | set(fixed)
    if "Gg_kg_s" not in names_moved and all(np.all(b.Gg_kg_s == PLACEHOLDER_GG_KG_S) for b in batches):
        raise InputError(
            "every batch's gas flow is the 1 kg/s placeholder of a map with [Gg] identify = true, and nothing "
            "fits it: free Gg_kg_s in a fit spec (--spec FIT.toml), e.g. Gg_kg_s = [0.0005, 0.05, 0.005]",
            batches[0].source or batches[0].name,
        )
    init = {**PAPER_INITIAL, **(initial or {}), **spec_initial}
    packed = pack_batches(batches, plant, THETA_START, InitialState(**init), moisture, hold, bed=laws)
    first = None
    if from_residuals:  # a first fit with those outputs at weight 1 sets their weights; the second starts from it
        at_one = {**weights, **dict.fromkeys(from_residuals, 1.0)}
        first = identify(
            packed,
            free,
            fixed,
            method=method,
            seed=seed,
            n_starts=starts,
            progress=progress,
            weights=at_one,
            held_out=False,  # only its outputs' residuals are used: no refit without each log
        )
        weights = {**weights, **residual_weights(first.outputs, from_residuals)}
        free = [_started_at(f, first.values) for f in free]
    # the second fit searches as the first did, its first start the first fit's optimum: a polish from
    # there alone stopped short of the optimum on a flat ridge (SSR 4e-4 to 5e-3 above it in 11 of the
    # Skywalker's 17 leave-one-log-out fits; docs/real-roaster.md, "Skywalker: the second fit searches")
    ident = identify(packed, free, fixed, method=method, seed=seed, n_starts=starts, progress=progress, weights=weights)
    if first is not None:  # the work of both fits, as the search's figures say it
        ident.nfev, ident.wall_s = ident.nfev + first.nfev, ident.wall_s + first.wall_s
    doc = _document(ident, free, fixed, init, plant, moisture, hold, column_map)
    if first is not None:
        doc["fit"]["weights_from_residuals"] = {
            "outputs": from_residuals,
            "rule": "the probe's residual variance over the output's, from a first fit with it at weight 1",
            "first_pass": {
                k: {"rms_C": round(math.sqrt(o["SSR"] / o["n"]), 4)} for k, o in first.outputs.items() if o["n"]
            },
        }
    # when each fitted roast's recording started: validate finds a copy of one by it (FittedModel.fitted_roasts)
    doc["fit"]["started_epoch_s"] = [b.started_epoch_s for b in batches]
    if laws != PAPER_BED:
        doc["bed"] = laws.as_dict()
    model = FittedModel(doc)
    validation = model.validate(batches)
    _, copies = first_of_each_roast(batches, lambda b: b.started_epoch_s, lambda b: b.name)
    if copies:  # said, not dropped: a fit is what it is given
        ident.warnings.append(f"one roast given twice, so it weighs twice in the fit: {'; '.join(copies.values())}")
        doc["fit"]["warnings"] = ident.warnings
    # a fit whose states a drum roaster cannot have has failed, however small its SSR (metrics.profile);
    # the model file is still written, marked, so it can be looked at
    summary = implausible_summary(validation.results)
    if summary:
        ident.warnings.append(summary)
        doc["fit"]["warnings"] = ident.warnings
        doc["fit"]["failed"] = f"{FAILED_STATES}{summary}"
    # the roast-to-roast part of the prediction bands (evaluate.bands): each log's probe error by time
    # (each log's error as predicted by the fit redone without it, fit.uncertainty.held_out_residuals; the fit set's own
    # errors when the probe was not fitted)
    held = ident.held_out_Ta
    masses = [b.Mb_kg or plant.Mb_kg for b in batches]  # the green weights the spread was measured at
    units = [b.unit for b in batches]  # and the roasters (serial numbers) it was measured on
    if held is not None:
        errors = [held[b, : packed.N[b]] for b in range(packed.n_batches)]
        times = [packed.T[b, : packed.N[b]] for b in range(packed.n_batches)]
        doc["fit"]["spread"] = roast_spread(times, errors, batch_kg=masses, units=units)
    else:
        errors = [
            np.asarray(p, float) - np.asarray(m, float) for m, p in zip(validation.measured, validation.predicted)
        ]
        doc["fit"]["spread"] = roast_spread(validation.time_s, errors, held_out=False, batch_kg=masses, units=units)
    doc["metrics"] = {
        "batches": [{"name": n, **r} for n, r in zip(validation.names, validation.rows)],
        "average": validation.average,
    }
    doc["provenance"] = provenance(
        {
            "batch": [b.source for b in batches],
            "map": [column_map.source] if column_map is not None else [],
            "spec": [spec_source],
            "plant": [plant_file],
        }
    )
    return FitResult(model, ident, validation)


def _document(ident, free, fixed, init, plant, moisture, hold, column_map) -> dict:
    params, initial = {}, {}
    by_name = {f.name: f for f in free}
    values = {**ident.fixed, **ident.values}
    for name in list(THETA_NAMES) + [k for k in values if k not in THETA_NAMES]:
        if name in STATE0:
            continue
        unit = REGISTRY[name].unit
        if name in by_name:
            params[name] = {
                "value": values[name],
                "unit": unit,
                "how": "fitted",
                "stderr": ident.stderr.get(name),
                "bounds": ident.bounds.get(name),
            }
        else:
            params[name] = {"value": float(fixed.get(name, values.get(name))), "unit": unit, "how": "fixed"}
    from_log = dict(column_map.initial) if column_map is not None else {}
    for name in STATE0:
        if name in from_log and name not in by_name:
            initial[name] = {"how": "from log", "field": from_log[name]}  # the map reads it from each log
        elif name in by_name and by_name[name].per_batch:
            labels = [f"{name}[{b}]" for b in ident.batches]
            initial[name] = {
                "how": "fitted per batch",
                "per_batch": dict(zip(ident.batches, values[name])),
                "stderr": {b: ident.stderr.get(lab) for b, lab in zip(ident.batches, labels)},
                "bounds": [by_name[name].lower, by_name[name].upper],
            }
        elif name in by_name:
            initial[name] = {
                "how": "fitted",
                "value": values[name],
                "stderr": ident.stderr.get(name),
                "bounds": ident.bounds.get(name),
            }
        elif name in fixed:
            initial[name] = {"how": "fixed", "value": float(fixed[name])}
        elif name in init:
            initial[name] = {"how": "fixed", "value": float(init[name])}
        else:
            initial[name] = {"how": "from log"}
    return {
        "plant": plant,
        "parameters": params,
        "initial": initial,
        "moisture": moisture,
        "hold": hold,
        "map": None if column_map is None else column_map.to_mapping(),
        "fit": {
            "SSR": ident.SSR,
            "n_residuals": ident.n_residuals,
            "evaluations": ident.nfev,
            "wall_s": round(ident.wall_s, 3),
            "method": ident.method,
            "seed": ident.seed,
            "batches": ident.batches,
            "correlation": ident.correlation,
            "warnings": ident.warnings,
            "outputs": ident.outputs,
        },
    }


def fit_per_batch(
    batches: list[Batch],
    plant,
    *,
    fix: dict | None = None,
    bounds: dict | None = None,
    initial: dict | None = None,
    moisture: str = "schwartzberg",
    hold: str = "linear",
    seed: int = 0,
    progress=None,
):
    """A separate theta = (hgm, hbm, Pbm) for every batch (the compiled per-batch fitter,
    :func:`roastlab.fit.batchfit.identify_each`), from the paper's initial state with ``initial``
    changes; returns its :class:`~roastlab.fit.batchfit.FleetResult`.

    ``fix`` and ``bounds`` name theta components only; ``moisture``, ``hold``, ``seed`` and
    ``progress`` as in :func:`fit`.
    """
    from ..fit.batchfit import identify_each

    unknown = sorted((set(fix or {}) | set(bounds or {})) - set(THETA_NAMES))
    if unknown:
        raise InputError(f"a per-batch fit frees hgm, hbm, Pbm only, not {', '.join(unknown)}")
    init = InitialState(**{**PAPER_INITIAL, **(initial or {})})
    packed = pack_batches(batches, plant, THETA_START, init, moisture, hold)
    return identify_each(packed, bounds=bounds, fix=fix, seed=seed, progress=progress)
