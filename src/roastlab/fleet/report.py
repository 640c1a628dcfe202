"""The fleet report: per machine, each coefficient's history, its drift alarms and outliers."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote

import numpy as np

from ..errors import InputError
from ..report.result import Result
from .drift import CLIP_Z, CUSUM_H, CUSUM_K, OUTLIER_FIT, OUTLIER_RATIO, WARMUP, analyse, machine_history, robust_stats
from .store import open_store, plant_of, store_errors


@dataclass
class MachineHistory:
    """One machine's fitted history (``frame`` in time order, ``wide`` values) and its analysis."""

    name: str
    plant: str
    spec_id: str
    frame: object
    wide: object
    stderr: object
    analysis: dict
    plant_name: str = ""  # the plant's own name (its file's ``name``, a preset's), "" where unknown

    @property
    def params(self) -> list[str]:
        return list(self.wide.columns)

    def to_json_dict(self) -> dict:
        a = self.analysis
        coeffs = {}
        for p in self.params:
            x = self.wide[p].to_numpy(dtype=float)[a["good"]]
            x = x[np.isfinite(x)]
            st = robust_stats(x) or {"median": None, "spread": None}
            med, spread = st["median"], st["spread"]
            coeffs[p] = {
                "median": med,
                "spread": spread,
                "spread_percent": None if not med else round(100 * spread / abs(med), 2),
                "first": float(x[0]) if len(x) else None,
                "last": float(x[-1]) if len(x) else None,
            }
        return {
            "machine": self.name,
            "plant": self.plant,
            "plant_name": self.plant_name,
            "spec_id": self.spec_id,
            "batches": int(len(self.frame)),
            "first_started_at": self.frame["started_at"].iloc[0].isoformat() if len(self.frame) else None,
            "last_started_at": self.frame["started_at"].iloc[-1].isoformat() if len(self.frame) else None,
            "FIT_median": float(np.nanmedian(self.frame["FIT"])) if len(self.frame) else None,
            "coefficients": coeffs,
            "alarms": a["alarms"],
            "outliers": a["outliers"],
            "periods": a["periods"],
        }


@dataclass
class FleetReport(Result):
    machines: list[MachineHistory]
    db: str

    def to_json_dict(self) -> dict:
        return {
            "db": self.db,
            "detector": {
                "method": "self-starting two-sided CUSUM on standardised coefficient residuals (Hawkins 1987)",
                "k": CUSUM_K,
                "h": CUSUM_H,
                "clip_z": CLIP_Z,
                "warmup_batches": WARMUP,
                "outlier_FIT_below_percent": OUTLIER_FIT,
                "outlier_mean_squared_residual_over_median": OUTLIER_RATIO,
            },
            "machines": [m.to_json_dict() for m in self.machines],
        }

    def summary(self) -> str:
        """The report's table (:meth:`table`)."""
        return self.table()

    def to_frame(self):
        """One row per machine and coefficient: batches, median FIT, the coefficient's median and spread."""
        import pandas as pd

        rows = []
        for m in self.machines:
            d = m.to_json_dict()
            for p, c in d["coefficients"].items():
                row = {"machine": m.name, "batches": d["batches"], "FIT_median": d["FIT_median"], "coefficient": p}
                rows.append({**row, "median": c["median"], "spread_percent": c["spread_percent"]})
        return pd.DataFrame(rows)

    def _draw(self, ax) -> None:
        for m in self.machines:
            fit = np.asarray(m.frame["FIT"], dtype=float)
            ax.plot(np.arange(1, fit.size + 1), fit, lw=0.8, label=m.name)
        ax.set_xlabel("batch")
        ax.set_ylabel("FIT of each batch's own fit [%]")
        ax.legend(fontsize=8)

    def _figure(self, path, outputs):
        """An overview of every machine: each batch's FIT in time order (per-machine coefficient
        histories: :meth:`plot_machines`)."""
        from ..report.figures import finish_figure, new_figure

        fig = new_figure(figsize=(8, 4))
        self._draw(fig.add_subplot(1, 1, 1))
        return finish_figure(fig, path, f"fleet: {len(self.machines)} machine(s)", outputs)

    def table(self) -> str:
        """A readable summary: a line per machine and coefficient, then the alarms."""
        lines = [f"{'machine':<18} {'batches':>7} {'FIT %':>6}  {'coefficient':<14} {'median':>10} {'spread %':>8}"]
        for m in self.machines:
            d = m.to_json_dict()
            for k, (p, c) in enumerate(d["coefficients"].items()):
                head = f"{m.name:<18} {d['batches']:>7} {d['FIT_median']:>6.1f}" if k == 0 else " " * 33
                sp = "" if c["spread_percent"] is None else f"{c['spread_percent']:.1f}"
                lines.append(f"{head}  {p:<14} {c['median']:>10.4g} {sp:>8}")
        lines.append("")
        for m in self.machines:
            a = m.analysis
            n = len(m.frame)
            warm = (
                f"; still warming up: the drift detector watches from batch {WARMUP} on, this machine has {n}"
                if n <= WARMUP
                else f" (drift watched from batch {WARMUP} on)"
            )
            lines.append(f"{m.name}: {len(a['alarms'])} alarm(s), {len(a['outliers'])} outlier batch(es){warm}")
            for al in a["alarms"]:
                lines.append(
                    f"  {al['parameter']} {al['direction']} at batch {al['batch_index']} ({al['started_at']}), "
                    f"change from batch {al['change_index']}"
                )
        return "\n".join(lines)

    def plot_machines(self, folder, outputs=None) -> list[Path]:
        """One figure per machine (``<machine>.png``, the name %-escaped so that different names
        never share a file): each coefficient over time, alarms marked.

        Written into ``outputs`` (an :class:`~roastlab.io.files.Outputs`) if given, else all
        together or none.
        """
        from ..io.files import Outputs
        from ..report.figures import plot_fleet_history

        def run(out):
            folder_ = out.folder(folder)
            written = []
            for m in self.machines:
                # escaped, not collapsed: machines "a/b" and "a_b" get different files
                safe = quote(m.name, safe="-_")
                path = folder_ / f"{safe}.png"
                plot_fleet_history(m, path, outputs=out)
                written.append(path)
            return written

        if outputs is not None:
            return run(outputs)
        with Outputs() as out:
            return run(out)


def fleet_report(db) -> FleetReport:
    """Analyse every machine of the store at ``db`` with the spec of its latest fit."""
    con = open_store(db, read_only=True)
    with store_errors(db):
        try:
            rows = con.execute(
                "SELECT m.machine_id, m.name, m.plant, m.plant_toml, "
                "(SELECT f.spec_id FROM fits f JOIN batches b USING (batch_id) WHERE b.machine_id = m.machine_id "
                " ORDER BY f.fitted_at DESC LIMIT 1) FROM machines m ORDER BY m.machine_id"
            ).fetchall()
            if not any(r[4] for r in rows):
                raise InputError("no fits in the store yet: run 'roastlab fleet fit' first", db)
            machines = []
            for mid, name, plant, plant_toml, sid in rows:
                if sid is None:
                    continue
                frame, vals = machine_history(con, mid, sid)
                params = list(dict.fromkeys(vals["parameter"]))
                res = analyse(frame, vals, params)
                err = vals.pivot(index="batch_id", columns="parameter", values="stderr").reindex(frame["batch_id"])
                plant_name = plant_of(name, plant, plant_toml).name
                machines.append(
                    MachineHistory(name, plant, sid, frame, res["wide"][params], err[params], res, plant_name)
                )
        finally:
            con.close()
    return FleetReport(machines, str(db))
