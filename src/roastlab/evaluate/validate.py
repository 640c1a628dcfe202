"""Score predictions against measurements (Table 2 metrics, section 6.2).

Predictions come from :meth:`roastlab.workflows.model.FittedModel.validate`, the one path
that applies a model to batches; this module only compares and tabulates.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..metrics.profile import beans_at_first_crack
from ..model.constants import FIRST_CRACK_BEAN_C
from ..model.parameters import MODEL_OF_OUTPUT
from ..report.result import Result, draw_curves
from .metrics import METRIC_NAMES, absolute_error_moments, average_metrics, batch_metrics, metrics_in_units

#: Predicted states written beside measured and predicted Ta (Ta itself is Ta_pred_C).
PREDICTED_STATES = ("Tb_C", "Tm_C", "X_kg_kg", "He_kJ_kg")
#: Fewest samples of a second bean reading for a batch to be scored on it.
MIN_SECOND_OUTPUT_SAMPLES = 3


@dataclass
class ValidationResult(Result):
    """Per-batch predictions and metrics of one dataset."""

    names: list[str]
    time_s: list[np.ndarray]
    measured: list[np.ndarray]
    predicted: list[np.ndarray]
    states: list[np.ndarray]
    rows: list[dict]
    plant: str
    notes: list[str] = field(default_factory=list)
    results: list = field(default_factory=list)  # the SimulationResult of each batch, when known
    #: Metrics of further outputs: {"Tb2": {"names": [...], "rows": [...]}}, the model's Tb
    #: against a second measured bean reading, over the batches (and samples) that have one.
    outputs: dict = field(default_factory=dict)
    #: The model's bean temperature at each log's first-crack mark [degC], by log name, where the log
    #: marks one (:func:`roastlab.metrics.profile.beans_at_first_crack`): coffee cracks at about
    #: :data:`roastlab.model.constants.FIRST_CRACK_BEAN_C`, so it shows whether the model has the beans
    #: where they are, which the probe's metrics cannot.
    first_crack_beans_C: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        a = self.average
        return f"<ValidationResult {len(self.names)} batch(es) on {self.plant}: FIT {a['FIT']:.2f} %, MAE {a['MAE']:.3f} °C>"

    def to_frame(self):
        """Metrics per batch as a pandas DataFrame (one row a batch)."""
        import pandas as pd

        return pd.DataFrame(self.rows, index=pd.Index(self.names, name="batch"))

    def frames(self) -> dict:
        """Per batch, a DataFrame of time, measured and predicted Ta, states and inputs as applied."""
        import pandas as pd

        out = {}
        for r in self.results:
            cols = {"time_s": r.time_s, "Ta_C": r.Ta_measured_C, "Ta_pred_C": r.Ta_C}
            cols.update({k: r.states[:, j] for j, k in enumerate(PREDICTED_STATES)})
            if r.Tb2_measured_C is not None:
                cols["Tb2_C"] = r.Tb2_measured_C
            cols.update({"Tgo_C": r.Tgo_C, "Gg_kg_s": r.Gg_kg_s, "Tgi_C": r.Tgi_C})
            out[r.name] = pd.DataFrame(cols)
        return out

    def summary(self) -> str:
        """The metrics table (:meth:`table`)."""
        return self.table()

    def _figure(self, path, outputs, title=None):
        """Measured vs predicted BT per batch with residuals."""
        from ..report.figures import plot_fit

        return plot_fit(self, path, title, outputs=outputs)

    def _draw(self, ax) -> None:
        curves = {}
        for name, t, m, p in list(zip(self.names, self.time_s, self.measured, self.predicted))[:4]:
            curves[f"{name} measured"] = (t, m)
            curves[f"{name} predicted"] = (t, p)
        draw_curves(ax, curves, "BT [°C]")

    @property
    def average(self) -> dict:
        return average_metrics(self.rows)

    @property
    def errors(self) -> list[np.ndarray]:
        return [m - p for m, p in zip(self.measured, self.predicted)]

    @property
    def error_moments(self) -> dict:
        return absolute_error_moments(self.errors)

    def output_average(self, name: str) -> dict:
        """Mean metrics of a further output (e.g. ``"Tb2"``) over the batches that have it."""
        return average_metrics(self.outputs[name]["rows"])

    def to_json_dict(self) -> dict:
        out = {
            "plant": self.plant,
            "batches": [{"name": name, **row} for name, row in zip(self.names, self.rows)],
            "average": self.average,
            "absolute_error": self.error_moments,
        }
        if self.first_crack_beans_C:
            out["first_crack_beans_C"] = self.first_crack_beans_C
        if self.outputs:  # per output: the probe (the top-level figures) and each further one
            out["outputs"] = {"Ta": {"compared": "model Ta with the measured bean probe", "average": self.average}}
            for name, o in self.outputs.items():
                out["outputs"][name] = {
                    "compared": o["compared"],
                    "batches": [{"name": n, **row} for n, row in zip(o["names"], o["rows"])],
                    "average": self.output_average(name),
                }
        return out

    def table(self, title: str | None = None, units: str = "C") -> str:
        """A readable text table of the metrics (columns sized to their contents), its temperature
        differences in ``units`` ("C" or "F"; :func:`~roastlab.evaluate.metrics.metrics_in_units`)."""
        from ..metrics.profile import display_temp, display_temp_delta, temp_symbol

        u, scale = temp_symbol(units), display_temp_delta(1.0, units)

        def line(name, row):
            row = metrics_in_units(row, units)
            return f"{name:<{w}}" + "".join(_fmt(key, row[key]) for key in METRIC_NAMES)

        w = max([len("average")] + [len(n) for n in self.names]) + 2
        head = f"{'batch':<{w}}" + "".join(f"{k:>11}" for k in METRIC_NAMES)
        lines = ([title] if title else []) + ([f"SSR in {u}², norm and MAE in {u}; MPE and MAPE in % of the reading in °C "
                                               "(Table 2); FIT in %"] if units == "F" else [])  # fmt: skip
        lines += [head, "-" * len(head)]
        lines += [line(name, row) for name, row in zip(self.names, self.rows)]
        lines += ["-" * len(head), line("average", self.average)]
        em = self.error_moments
        lines.append(
            f"|e| over {em['samples']} samples: mean {scale * em['mean_abs_error']:.3f} {u}, "
            f"variance {scale**2 * em['var_abs_error']:.3f} {u}²"
        )
        for name, o in self.outputs.items():
            lines += ["", f"second output {name}: {o['compared']}", head, "-" * len(head)]
            lines += [line(n, row) for n, row in zip(o["names"], o["rows"])]
            lines += ["-" * len(head), line("average", self.output_average(name))]
        if self.first_crack_beans_C:
            v = display_temp(np.array(list(self.first_crack_beans_C.values())), units)
            lines += [
                "",
                f"model beans at the logs' first-crack marks: median {np.median(v):.0f} {u} ({v.min():.0f}-{v.max():.0f} {u}, "
                f"{v.size} log{'s' * (v.size > 1)}); coffee cracks at about {display_temp(FIRST_CRACK_BEAN_C, units):.0f} {u}",
            ]
        return "\n".join(lines)


def metrics_by_size(rows: list[dict], masses_kg, scored=None) -> list[dict]:
    """The mean metrics (:func:`~roastlab.evaluate.metrics.average_metrics`) of ``rows`` by batch size
    (:func:`~roastlab.evaluate.metrics.size_groups` of all their green weights ``masses_kg`` [kg], lightest
    first): ``[{"size", "logs", **metrics}]`` over the rows whose position is in ``scored`` (default all;
    the held-out ones, say), a size with none of them left out; empty unless the rows make more than one size.

    >>> rows = [{k: v for k in METRIC_NAMES} for v in (80.0, 90.0, 70.0)]
    >>> [(g["size"], g["logs"], g["FIT"]) for g in metrics_by_size(rows, [0.5, 0.49, 0.2], scored={1, 2})]
    [('0.2 kg', 1, 70.0), ('0.49-0.5 kg', 1, 90.0)]
    """
    from .metrics import size_groups

    keep = set(range(len(rows))) if scored is None else set(scored)
    out = []
    for label, at in size_groups(masses_kg):
        members = [rows[i] for i in at if i in keep]
        if members:
            out.append({"size": label, "logs": len(members), **average_metrics(members)})
    return out


def each_size_in_turn(masses_kg, scored=None) -> list[int]:
    """Positions of the batches by size in turn: the first scored batch (``scored``, default all) of each
    batch size (:func:`~roastlab.evaluate.metrics.size_groups`, lightest first), then the second of each,
    and so on; what a figure of a few panels shows of logs of several sizes. Empty for one size.

    >>> each_size_in_turn([0.5, 0.49, 0.2, 0.5, 0.9], scored={1, 2, 3, 4})
    [2, 1, 4, 3]
    """
    from .metrics import size_groups

    keep = set(range(len(list(masses_kg)))) if scored is None else set(scored)
    groups = [[i for i in at if i in keep] for _, at in size_groups(masses_kg)]
    return [g[k] for k in range(max((len(g) for g in groups), default=0)) for g in groups if k < len(g)]


def panels_by_size(names, masses_kg, scored=None) -> dict:
    """:func:`~roastlab.report.figures.plot_fit`'s ``which`` and ``labels`` for logs of several sizes: the
    scored logs (``scored``, default all; the held-out ones, say) of each size in turn
    (:func:`each_size_in_turn`), each panel named with its batch; ``{}`` for logs of one size."""
    turns = each_size_in_turn(masses_kg, scored)
    if not turns:
        return {}
    some = scored is not None and len(set(scored)) < len(names)
    why = f"each size's {'held-out ' if some else ''}logs in turn:"
    return {"which": (turns, why), "labels": {i: f"{names[i]} ({masses_kg[i]:.3g} kg)" for i in turns}}


def _fmt(key, value) -> str:
    if key == "n":
        return f"{int(value):>11d}"
    if key == "SSR":
        return f"{value:>11.1f}"
    return f"{value:>11.3f}" if key != "rho" else f"{value:>11.4f}"


def score(results, plant_name: str) -> ValidationResult:
    """Score simulated batches (:class:`~roastlab.sim.simulate.SimulationResult` with a measured Ta)."""
    rows, meas, pred, times, states = [], [], [], [], []
    for r in results:
        rows.append(batch_metrics(r.Ta_measured_C, r.Ta_C))
        meas.append(np.asarray(r.Ta_measured_C))
        pred.append(r.Ta_C.copy())
        times.append(r.time_s)
        states.append(np.column_stack([r.states, r.Tgo_C]))
    out = ValidationResult([r.name for r in results], times, meas, pred, states, rows, str(plant_name))
    out.results = list(results)
    out.first_crack_beans_C = {r.name: mark[1] for r in results if (mark := beans_at_first_crack(r)) is not None}
    # further outputs: each measured series (<output>_measured_C) against its model quantity
    for name, compared in (
        ("Tb2", "model Tb (eq. 15a) with the second measured bean reading"),
        ("ET", "model outlet gas Tgo (eq. 15e) with the logged ET"),
    ):
        model = f"{MODEL_OF_OUTPUT[name]}_C"
        pairs = [(r.name, y, getattr(r, model)) for r in results if (y := getattr(r, f"{name}_measured_C")) is not None]
        scored = [(n, y[ok], m[ok]) for n, y, m in pairs if (ok := np.isfinite(y)).sum() >= MIN_SECOND_OUTPUT_SAMPLES]
        if scored:
            out.outputs[name] = {
                "compared": compared,
                "names": [n for n, _, _ in scored],
                "rows": [batch_metrics(y, m) for _, y, m in scored],
            }
    return out
