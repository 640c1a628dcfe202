"""A fitted model as one object: what a fit found, applied the same way by every command.

:class:`FittedModel` holds a plant, theta, every other identified or held value (process
constants, a gas flow, the metal mass), how the initial states are set (fixed, fitted, fitted
per batch, or from the log), the column map the fit read its logs with, the metrics on its
fit set and provenance. :meth:`FittedModel.apply` is the only place a model meets batches:
``simulate``, ``validate``, ``predict`` and later commands all go through it, so the same log
and model give the same prediction whichever way they are asked.

>>> import numpy as np, roastlab
>>> m = roastlab.FittedModel.paper("120kg")           # the paper's theta*, section 5.1 start
>>> t = np.arange(0, 901, 30.0)
>>> r = m.predict({"time_s": t, "Gg_kg_s": np.full_like(t, 0.4), "Tgi_C": np.full_like(t, 450.0)}, Ta0_C=30.0)
>>> round(float(r.Tb_C[-1]), 2)
218.31
"""

from __future__ import annotations

import copy
import dataclasses
import datetime
import html
import math
from pathlib import Path

import numpy as np

from ..errors import InputError, ParameterError
from ..evaluate.validate import ValidationResult, score
from ..fit import uncertainty
from ..io.batch import Batch, first_of_each_roast, recording_second
from ..io.files import Outputs, input_digest
from ..io.importers.mapping import ColumnMap, map_from_mapping
from ..io.modelfile import model_document_text, read_model_document
from ..io.plants import load_plant
from ..model.bed import BedLaws
from ..model.limits import check_value
from ..model.parameters import REGISTRY, STATE0, THETA_NAMES, THETA_PAPER, THETA_UNITS, Theta
from ..model.plant import Plant
from ..model.quantities import default
from ..model.rhs import P, drum_start_reading_C
from ..sim.kernels import I_TGO, NS, failure
from ..sim.population import pack_batches, run_arrays, simulate_population
from ..sim.simulate import InitialState, SimulationResult

#: Initial state of the paper's section 5.1 (Ta0 from the log's first reading): the quantity table's defaults.
PAPER_INITIAL = {name: default(name) for name in ("Tb0_C", "Tm0_C", "X0", "He0_kJ_kg")}
#: Gas flow written by a map with ``[Gg] identify = true`` and scaled by a fitted Gg_kg_s [kg/s].
PLACEHOLDER_GG_KG_S = default("Gg_kg_s")


def _version() -> str:
    from .. import __version__

    return __version__


def as_batch(data, name: str = "inputs") -> Batch:
    """A :class:`Batch` from a Batch, or a mapping/DataFrame with ``time_s, Gg_kg_s, Tgi_C[, Ta_C]``."""
    if isinstance(data, Batch):
        return data
    try:
        cols = {k: np.array(data[k], dtype=np.float64) for k in ("time_s", "Gg_kg_s", "Tgi_C")}
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"inputs need time_s, Gg_kg_s and Tgi_C as numeric arrays ({exc})", name) from None
    ta = None
    try:
        if "Ta_C" in data:
            ta = np.array(data["Ta_C"], dtype=np.float64)
    except TypeError:
        pass
    return Batch(name, cols["time_s"], cols["Gg_kg_s"], cols["Tgi_C"], ta).validate()


def _plant_specific_initial(name: str, entry: dict) -> bool:
    """An initial state fitted on the model's own plant (e.g. its drum start temperature)."""
    return not REGISTRY[name].carries_over and entry.get("how", "").startswith("fitted")


@dataclasses.dataclass
class Applied:
    """Batches with a model applied: the packed runs, the named values and what was noted."""

    batches: list[Batch]
    packed: object
    names: list[str]
    values: np.ndarray
    plant: Plant
    notes: list[str]


class FittedModel:
    """A fitted model (see module docstring). Build with :func:`load_model`, :func:`fit` or
    :meth:`paper`; apply with :meth:`predict` / :meth:`validate`; store with :meth:`save`.

    Parameters
    ----------
    doc : dict
        A checked ``roastlab-model/1`` mapping (:func:`roastlab.io.modelfile.read_model_document`).
    """

    def __init__(self, doc: dict):
        self.doc = doc
        plant = doc.get("plant")
        self.plant: Plant | None = plant if isinstance(plant, Plant) else None
        if isinstance(plant, str):  # an old THETA.json names its plant; presets resolve
            try:
                self.plant = load_plant(plant)
            except InputError:
                self.plant = None
        self.parameters: dict = doc["parameters"]
        self.initial: dict = doc.get("initial") or {}
        self.moisture: str = doc.get("moisture", "schwartzberg")
        self.hold: str = doc.get("hold", "linear")
        m = doc.get("map")
        self.column_map: ColumnMap | None = None if m is None else map_from_mapping(copy.deepcopy(m), "model file map")
        self.source: str | None = doc.get("_source")

    @property
    def failed(self) -> str | None:
        """Why this model's fit failed (its states are ones the machine cannot have:
        :func:`roastlab.metrics.profile.implausible_states`), or None for a fit that stands."""
        return (self.doc.get("fit") or {}).get("failed")

    def fitted_roasts(self, batches) -> dict[str, str]:
        """Which of ``batches`` this model was fitted on, or are one roast twice: ``{name: why}``.

        A batch is a fitted roast when its recording started in the same second as one the model
        file lists under ``fit.batches`` (``fit.started_epoch_s``; a renamed or annotated copy keeps
        it, :func:`roastlab.io.batch.first_of_each_roast`), or, where either start is unknown, when
        it has that one's name: its figures are then the fit set's, not held out. Of two given
        batches that are one roast, the later is named too: it counts twice in an average.
        """
        fit = self.doc.get("fit")
        fit = fit if isinstance(fit, dict) else {}
        names, starts = fit.get("batches"), fit.get("started_epoch_s")
        names = [str(n) for n in names] if isinstance(names, list) else []
        starts = [  # a model file is a user's file: a start that is no finite number is unknown
            recording_second(t) if isinstance(t, (int, float)) and math.isfinite(t) else None
            for t in (starts if isinstance(starts, list) else [])
        ]
        starts += [None] * (len(names) - len(starts))  # a model file from before the starts were kept has names alone
        start_of = dict(zip(names, starts))
        fitted = {t: n for n, t in zip(names, starts) if t is not None}
        why = {}
        for b in batches:
            t = recording_second(b.started_epoch_s)
            if b.name in start_of and (None in (t, start_of[b.name]) or start_of[b.name] == t):
                why[b.name] = f"{b.name} is a log the model was fitted on: its figures are the fit set's, not held out"
            elif t is not None and t in fitted:
                why[b.name] = (
                    f"{b.name} is a copy of {fitted[t]}, which the model was fitted on (recorded from the "
                    "same second): its figures are the fit set's, not held out"
                )
        _, copies = first_of_each_roast(list(batches), lambda b: b.started_epoch_s, lambda b: b.name)
        for name, text in copies.items():
            why.setdefault(name, f"{text}, so it counts twice in the average")
        return why

    @property
    def bed(self) -> BedLaws:
        """The bed laws (:mod:`roastlab.model.bed`): the model file's ``bed``, else the paper's."""
        return BedLaws.parse(self.doc.get("bed"))

    @bed.setter
    def bed(self, laws) -> None:
        self.doc["bed"] = BedLaws.parse(laws).as_dict()

    # ------------------------------------------------------------------ construction
    @classmethod
    def paper(cls, plant="120kg", theta=None) -> FittedModel:
        """The paper's model: theta* (Table 1) and the initial state of section 5.1."""
        th = THETA_PAPER if theta is None else (theta if isinstance(theta, Theta) else Theta(*theta))
        return cls(
            {
                "plant": load_plant(plant),
                "parameters": {
                    k: {"value": v, "how": "fixed", "unit": THETA_UNITS[k]} for k, v in th.as_dict().items()
                },
                "initial": {k: {"how": "fixed", "value": v} for k, v in PAPER_INITIAL.items()}
                | {"Ta0_C": {"how": "from log"}},
                "provenance": {"roastlab": _version(), "note": "the paper's theta*; nothing fitted"},
            }
        )

    @property
    def theta(self) -> Theta:
        return Theta(*(self.parameters[k]["value"] for k in THETA_NAMES))

    @property
    def values(self) -> dict[str, float]:
        """Every parameter value the model applies (theta and the rest), by registry name."""
        return {k: e["value"] for k, e in self.parameters.items()}

    def with_values(self, **values) -> FittedModel:
        """A copy with some values changed (registry names, e.g. ``hgm=0.02``, ``Tm0_C=150``)."""
        doc = copy.deepcopy(self.doc)
        for name, v in values.items():
            if name in STATE0:
                doc.setdefault("initial", {})[name] = {"how": "fixed", "value": float(v)}
            elif name in REGISTRY:
                doc["parameters"][name] = {**doc["parameters"].get(name, {}), "value": float(v), "how": "fixed"}
            else:
                raise ParameterError(f"unknown value {name!r} (allowed: {', '.join(REGISTRY)})")
        return FittedModel(doc)

    # ------------------------------------------------------------------ application
    def _target_plant(self, plant) -> tuple[Plant, list[str]]:
        if plant is None:
            if self.plant is None:
                raise InputError("the model file names no plant geometry: give the plant (--plant)", self.source)
            return self.plant, []
        target = load_plant(plant)
        if self.plant is None or target == self.plant:
            return target, []
        kept = [k for k in self.parameters if REGISTRY[k].carries_over]
        dropped = [k for k in self.parameters if not REGISTRY[k].carries_over]
        dropped += [k for k, e in self.initial.items() if _plant_specific_initial(k, e)]
        note = f"model fitted on plant {self.plant.name} applied to {target.name}: carried over {', '.join(kept)}"
        note += f"; dropped plant-specific {', '.join(dropped)} (defaults used)" if dropped else ""
        return target, [note]

    def apply(self, batches, plant=None, **changes) -> Applied:
        """Apply the model to batches: the one place where values meet data.

        ``plant`` (a Plant, preset or PLANT.toml) moves the model to another plant: values
        that carry over (theta, process constants) stay, plant-specific ones (a fitted gas
        flow, metal mass, drum start temperature) are dropped and named in ``notes``.
        ``changes`` override by name: any registry quantity (``hgm``, ``Kt``, ``Tm0_C`` ...),
        ``Tgi_offset_C`` (added to the inlet temperature [degC]), ``Tgi_C`` / ``Gg_kg_s``
        (replace an input by a value or an array), ``batch_kg`` (green batch mass [kg]) and
        ``heater`` / ``fan`` (a number is added to the logged setting, an array replaces it).
        """
        batches = [as_batch(b) for b in (batches if isinstance(batches, (list, tuple)) else [batches])]
        if not batches:
            raise InputError("no batches to apply the model to")
        target, notes = self._target_plant(plant)
        transfer = bool(notes)
        params = {k: e["value"] for k, e in self.parameters.items() if not (transfer and not REGISTRY[k].carries_over)}
        initial = {k: e for k, e in self.initial.items() if not (transfer and _plant_specific_initial(k, e))}
        allowed = set(REGISTRY) | {"Tgi_offset_C", "Tgi_C", "Gg_kg_s", "batch_kg", "heater", "fan"}
        unknown = sorted(set(changes) - allowed)
        if unknown:
            raise ParameterError(f"unknown change(s) {', '.join(unknown)} (allowed: {', '.join(sorted(allowed))})")
        base = dict(PAPER_INITIAL)
        per_batch: dict[str, dict[str, float]] = {}
        for name, e in initial.items():
            if e["how"] == "fitted per batch":
                per_batch[name] = e["per_batch"]
                base[name] = float(np.median(list(e["per_batch"].values())))
            elif e.get("value") is not None:
                base[name] = e["value"]
        ready = []
        for b in batches:
            b = dataclasses.replace(b, initial=dict(b.initial))
            for name, vals in per_batch.items():
                if b.name in vals:
                    b.initial[name] = vals[b.name]
                elif name not in changes and name not in b.initial:  # else the log's own reading (its map)
                    notes.append(
                        f"{b.name}: not in the fit set, {name} = {base[name]:.4g} (median of the fitted batches)"
                    )
            self._check_batch(b, params, target)
            b = self._changed_inputs(b, changes)
            if "batch_kg" in changes:
                target.check_batch_mass(b.Mb_kg)
            ready.append(b)
        for name in REGISTRY:
            if name in changes and name not in STATE0:
                params[name] = check_value(name, changes[name], name)
        for name in STATE0:
            if name in changes:
                value = check_value(name, changes[name], name)  # one number in its plausible range
                if name == "Tm0_C" and params.get("Tm0_share", 1.0) != 1.0:
                    # a drum temperature given here, where the batch holds the reading that implies it
                    # (roastlab.model.rhs.drum_at_charge_C, applied to it in the population's run_arrays)
                    room = params.get("T_room_C", default("T_room_C"))
                    value = float(drum_start_reading_C(value, params["Tm0_share"], room))
                for b in ready:
                    b.initial[name] = value
        theta = Theta(*(params.pop(k) for k in THETA_NAMES))
        fields = {k: base[k] for k in PAPER_INITIAL}
        if "Ta0_C" in base:
            fields["Ta0_C"] = base["Ta0_C"]
        packed = pack_batches(ready, target, theta, InitialState(**fields), self.moisture, self.hold, bed=self.bed)
        names = list(params)
        values = np.array([[[params[k] for k in names]] * len(ready)]) if names else np.zeros((1, len(ready), 0))
        return Applied(ready, packed, names, values, target, notes)

    def _check_batch(self, b: Batch, params: dict, plant: Plant) -> None:
        """A log that cannot be this plant's: the wrong flow, or a batch far from its size."""
        src = b.source or b.name
        placeholder = bool(np.all(b.Gg_kg_s == PLACEHOLDER_GG_KG_S))
        if "Gg_kg_s" in params and not placeholder:
            raise InputError(
                "the model fitted a constant gas flow (its map writes a 1 kg/s placeholder) but this batch has a "
                f"logged Gg (first value {b.Gg_kg_s[0]:g} kg/s): read the log with the model's map",
                src,
            )
        if "Gg_kg_s" not in params and placeholder and self.column_map is not None and self.column_map.identifies_flow:
            raise InputError("the batch's gas flow is a 1 kg/s placeholder and the model has no fitted flow", src)
        if b.Mb_kg and not plant.batch_fits(b.Mb_kg):
            raise InputError(
                f"batch of {b.Mb_kg:g} kg on plant {plant.name} (nominal {plant.Mb_kg:g} kg): wrong plant for this log?",
                src,
            )

    @staticmethod
    def _changed_inputs(b: Batch, changes: dict) -> Batch:
        n = b.n

        def column(name, current):
            v = np.asarray(changes[name], dtype=np.float64)
            if v.ndim == 0:
                return np.full(n, float(v))
            if v.shape != (n,):
                raise ParameterError(f"{name} has {v.size} values, the batch has {n} samples")
            return v.copy()

        Gg = column("Gg_kg_s", b.Gg_kg_s) if "Gg_kg_s" in changes else b.Gg_kg_s
        Tgi = column("Tgi_C", b.Tgi_C) if "Tgi_C" in changes else b.Tgi_C
        if "Tgi_offset_C" in changes:
            Tgi = Tgi + float(changes["Tgi_offset_C"])
        Mb = float(changes["batch_kg"]) if "batch_kg" in changes else b.Mb_kg
        settings = {}
        for name in ("heater", "fan"):  # a number shifts the logged setting; an array replaces it
            if name in changes:
                current = getattr(b, name)
                if current is None:
                    raise ParameterError(f"the batch has no {name} setting to change (its map reads none)")
                v = np.asarray(changes[name], dtype=np.float64)
                settings[name] = current + float(v) if v.ndim == 0 else column(name, current)
        return dataclasses.replace(b, Gg_kg_s=Gg, Tgi_C=Tgi, Mb_kg=Mb, **settings).validate()

    def simulate(self, applied: Applied) -> list[SimulationResult]:
        """Run applied batches in one compiled population call; one result per batch."""
        out = simulate_population(applied.packed, applied.names, applied.values)[0]
        _, _, PP = run_arrays(applied.packed, applied.names, applied.values)
        results = []
        for i, b in enumerate(applied.batches):
            n = b.n
            p = PP[i].copy()
            Gg = b.Gg_kg_s * p[P["Gg_scale"]]  # the flow as applied; the result's params then carry 1
            p[P["Gg_scale"]] = 1.0
            meta = {"notes": list(applied.notes), "plant": applied.plant.name, "events": dict(b.events)}
            res = SimulationResult(
                b.time_s.copy(),
                out[i, :n, :NS].copy(),
                out[i, :n, I_TGO].copy(),
                Gg,
                b.Tgi_C.copy(),
                p,
                heater=None if b.heater is None else b.heater.copy(),
                fan=None if b.fan is None else b.fan.copy(),
            )
            res.name, res.meta = b.name, meta
            res.Ta_measured_C = None if b.Ta_C is None else b.Ta_C.copy()
            res.Tb2_measured_C = None if b.Tb2_C is None else b.Tb2_C.copy()
            res.ET_measured_C = None if b.ET_C is None else b.ET_C.copy()
            why = failure(res.states, b.time_s)
            if why is not None:
                raise InputError(f"{why}: check the inputs, initial state and values", b.source or b.name)
            results.append(res)
        return results

    def predict(self, batch_or_inputs, plant=None, **changes) -> SimulationResult:
        """Predict one batch.

        ``batch_or_inputs`` is a Batch, a log path (read with the model's map) or a mapping of
        arrays ``time_s, Gg_kg_s, Tgi_C[, Ta_C]``; ``plant`` moves the model to another plant
        and ``changes`` are as in :meth:`apply`, e.g. ``predict(batch, Tgi_offset_C=20)``.
        """
        if isinstance(batch_or_inputs, (str, Path)):
            batch_or_inputs = load_log(batch_or_inputs, self.column_map)
        return self.simulate(self.apply([batch_or_inputs], plant, **changes))[0]

    def transfer(self, reference, plant_from=None, plant_to=None, **options):
        """The input program that reproduces ``reference``'s probe curve on ``plant_to``.

        ``reference`` is a Batch or a log path (read with the model's map); ``plant_from`` the
        plant it was roasted on (default: the model's); ``options`` are those of
        :func:`roastlab.workflows.transfer.transfer` (``limits``, ``batch_kg``, ``gg_kg_s``,
        ``interval_s``, ``tm0_free``, ``tolerance_C``, ``initial``). Returns a
        :class:`~roastlab.workflows.transfer.TransferResult`.
        """
        from .transfer import transfer

        if isinstance(reference, (str, Path)):
            reference = load_log(reference, self.column_map)
        return transfer(self, reference, plant_from, plant_to, **options)

    def predict_many(self, batches, plant=None, **changes) -> list[SimulationResult]:
        """Predict several ``batches`` in one compiled call (``plant``, ``changes`` as in :meth:`apply`)."""
        return self.simulate(self.apply(list(batches), plant, **changes))

    def validate(self, batches, plant=None, **changes) -> ValidationResult:
        """Predict ``batches`` with a measured Ta and score them (Table 2 metrics).

        ``plant`` and ``changes`` as in :meth:`apply` (the paper's validation moves a 120 kg
        model to the 360 kg plant with ``plant="360kg"``).
        """
        applied = self.apply(list(batches), plant, **changes)
        for b in applied.batches:
            if b.Ta_C is None:
                raise InputError("no measured Ta_C: needed to validate", b.source or b.name)
        results = self.simulate(applied)
        out = score(results, applied.plant.name)
        out.notes = applied.notes
        return out

    # ------------------------------------------------------------------ files and display
    def to_document(self) -> dict:
        doc = {k: v for k, v in self.doc.items() if not k.startswith("_")}
        doc["plant"] = self.plant
        return doc

    def save(self, path) -> Path:
        """Write the model file (``roastlab-model/1``) to ``path`` atomically."""
        with Outputs() as out:
            out.write_text(path, model_document_text(self.to_document()))
        return Path(path)

    def table(self) -> list[tuple[str, str, str, str, str]]:
        """Rows (name, value, std. error, unit, how) of every value the model applies."""
        rows = []
        for name, e in self.parameters.items():
            se, value = e.get("stderr"), e["value"]
            bounds = e.get("bounds")  # a user's file: used only where it is a pair of finite numbers
            bounded = _is_bounds(bounds)
            if se is None and bounded:
                # a value the fit left on a bound to rounding (1.08e-16 on a floor of 0) reads as that bound
                value = next(
                    (
                        b
                        for b in bounds
                        if math.isclose(value, b, rel_tol=1e-9, abs_tol=1e-9 * abs(bounds[1] - bounds[0]))
                    ),
                    value,
                )
            shown = "" if se is None else f"{se:.2g}"
            if se is not None and bounded and uncertainty.unpinned([se], [bounds[0]], [bounds[1]])[0]:
                shown = "wider than its range"  # the data leave it open (uncertainty.unpinned): no number to read
            rows.append((name, f"{value:.5g}", shown, REGISTRY[name].unit, e.get("how", "")))
        for name, e in self.initial.items():
            if e["how"] == "fitted per batch":
                vals = list(e["per_batch"].values())
                value = f"{min(vals):.4g}..{max(vals):.4g}"
            else:
                value = "" if e.get("value") is None else f"{e['value']:.5g}"
            rows.append((name, value, "", REGISTRY[name].unit, e["how"]))
        return rows

    def report(self) -> str:
        """A text report of the model: plant, values with standard errors, fit figures, warnings."""
        lines = [f"roastlab model on plant {self.plant.name if self.plant else '(none)'}"]
        lines.append(f"{'name':<12}{'value':>14}{'std. error':>12}  {'unit':<11}how")
        for r in self.table():
            lines.append(f"{r[0]:<12}{r[1]:>14}{r[2]:>12}  {r[3]:<11}{r[4]}")
        fit = self.doc.get("fit") or {}
        if "SSR" in fit:
            lines.append(f"summed SSR {fit['SSR']:.4g} °C² over {fit.get('n_residuals', '?')} samples")
        avg = (self.doc.get("metrics") or {}).get("average")
        if avg:
            lines.append(f"fit set: FIT {avg['FIT']:.2f} %, MAE {avg['MAE']:.3f} °C, MAPE {avg['MAPE']:.3f} %")
        lines += self.residual_weight_lines()
        lines += [f"warning: {w}" for w in fit.get("warnings", [])]
        return "\n".join(lines)

    def residual_weight_lines(self, units: str = "C") -> list[str]:
        """One line per output whose weight the fit set from its residuals (a spec's ``"residual"``,
        :func:`roastlab.fit.identify.residual_weights`), with the first fit's errors it came from (in
        ``units``, "C" or "F")."""
        from ..metrics.profile import display_temp_delta, temp_symbol

        u = temp_symbol(units)

        def table(d, key) -> dict:  # a model file is a user's file: anything but a table reads as none
            v = d.get(key) if isinstance(d, dict) else None
            return v if isinstance(v, dict) else {}

        fit = table(self.doc, "fit")
        by_residuals, outputs = table(fit, "weights_from_residuals"), table(fit, "outputs")
        first, names = table(by_residuals, "first_pass"), by_residuals.get("outputs")
        lines = []
        for name in [n for n in names if isinstance(n, str)] if isinstance(names, list) else []:
            w = table(outputs, name).get("weight")
            rms = {k: table(first, k).get("rms_C") for k in ("Ta", name)}
            if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (w, *rms.values())):
                lines.append(
                    f"weight of {name} from the residuals: {w:.3g} (a first fit at weight 1 missed Ta by "
                    f"{display_temp_delta(rms['Ta'], units):.2f} {u} RMS and {name} by "
                    f"{display_temp_delta(rms[name], units):.2f} {u} RMS: (Ta/{name})^2)"
                )
        return lines

    def __repr__(self) -> str:
        th = self.theta
        name = self.plant.name if self.plant else "no plant"
        extra = [k for k in self.parameters if k not in THETA_NAMES]
        more = f", +{', '.join(extra)}" if extra else ""
        return f"<FittedModel {name}: hgm={th.hgm:.4g}, hbm={th.hbm:.4g}, Pbm={th.Pbm:.4g}{more}>"

    def _repr_html_(self) -> str:
        head = "".join(f"<th>{h}</th>" for h in ("name", "value", "std. error", "unit", "how"))
        body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in self.table())
        title = html.escape(repr(self))
        return f"<p>{title}</p><table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def load_model(path) -> FittedModel:
    """Read the model file at ``path`` (or a THETA.json of roastlab 0.1)."""
    if not isinstance(path, (str, Path)) or not str(path):
        raise ParameterError(f"load_model needs a model file's path, got {path!r}")
    doc = read_model_document(path)
    doc["_source"] = str(path)
    return FittedModel(doc)


def load_log(path, map=None, name: str | None = None) -> Batch:  # noqa: A002 - the user-facing word
    """Read a roast log into a batch: a batch CSV as is, anything else through a column map.

    ``path`` is the log, ``map`` a MAP.toml path, a :class:`~roastlab.io.importers.mapping.ColumnMap`
    or None (a batch CSV), ``name`` the batch name (default: the file name).
    """
    from ..io.batch import read_batch_csv
    from ..io.importers import import_log, load_map

    if map is None:
        return read_batch_csv(path, name=name)
    cmap = map if isinstance(map, ColumnMap) else load_map(map)
    return import_log(path, cmap, name=name)


def _is_bounds(bounds) -> bool:
    """Whether a model file's ``bounds`` entry is a pair of finite numbers (a user's file: used only then)."""
    return (
        isinstance(bounds, list)
        and len(bounds) == 2
        and all(isinstance(b, (int, float)) and not isinstance(b, bool) and math.isfinite(b) for b in bounds)
    )


def load_log_for(path, model: FittedModel | None, name: str | None = None) -> Batch:
    """A log as ``model`` reads it: a raw log through the column map the model was fitted with, a batch
    CSV as it is (:func:`roastlab.io.importers.mapping.reads_as_log` tells them apart)."""
    from ..io.importers.mapping import reads_as_log

    cmap = None if model is None else model.column_map
    if not reads_as_log(path, cmap):
        return load_log(path, name=name)
    if cmap is None:
        if model is None:
            why = "a raw log is read with a column map: choose a model fitted on this roaster's logs, or give a map"
        else:
            why = "a raw log needs a column map, and the model has none (it was fitted on batch CSVs): give one"
        raise InputError(f"{why} (--map MAP.toml)", path)
    return load_log(path, cmap, name=name)


def provenance(roles: dict[str, list]) -> dict:
    """Provenance of a fit: version, date and every input file with its SHA-256."""
    inputs = []
    for role, paths in roles.items():
        for p in paths:
            if p:
                inputs.append({"role": role, "path": str(p), "sha256": input_digest(p)})
    return {
        "roastlab": _version(),
        "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "inputs": inputs,
    }
