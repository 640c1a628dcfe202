"""The one interface of every result roastlab returns.

Whatever produced it (a simulation, a fit, a validation, a what-if, a transfer, a closed-loop run,
a controller comparison, a fleet report), a result has

* ``summary() -> str``: what a person reads first, the text the command line prints;
* ``to_dict() -> dict``: JSON-safe (plain floats, lists; no NaN: missing values are ``None``),
  what ``--json`` writes;
* ``to_frame()``: a pandas DataFrame where the result is tabular (a trace, per-batch rows);
* ``plot(path=None, ax=None) -> Figure``: its figure, saved to ``path`` when given (PNG, SVG or
  PDF by suffix); with ``ax`` (a Matplotlib Axes) its main curves are drawn into that axes, in
  minutes and degC, and that axes' figure is returned;
* ``_repr_html_()``: the summary and the table's head, for Jupyter.

Subclasses implement ``summary``, ``to_json_dict`` (any JSON-able structure, NumPy allowed),
``_figure(path, outputs, **options)`` (the full figure) and ``_draw(ax)`` (the main panel), and
``to_frame`` where tabular.
"""

from __future__ import annotations

import html


class Result:
    """Mixin of the result interface (see the module docstring)."""

    def summary(self) -> str:  # pragma: no cover - every subclass implements it
        raise NotImplementedError

    def to_json_dict(self) -> dict:  # pragma: no cover - every subclass implements it
        raise NotImplementedError

    def to_dict(self) -> dict:
        """JSON-safe dictionary of the result (NaN as None, NumPy values as plain numbers)."""
        from ..io.modelfile import jsonable

        return jsonable(self.to_json_dict())

    def to_frame(self):
        """The result as a pandas DataFrame; results that are not tabular raise NotImplementedError."""
        raise NotImplementedError(f"{type(self).__name__} is not tabular")

    def _figure(self, path, outputs, **options):  # pragma: no cover - every subclass implements it
        raise NotImplementedError

    def _draw(self, ax) -> None:  # pragma: no cover - every subclass implements it
        raise NotImplementedError

    def plot(self, path=None, ax=None, *, outputs=None, **options):
        """The result's figure, saved to ``path`` if given; returns the Matplotlib Figure.

        ``ax``: draw the main curves into this Axes instead of a new figure. ``outputs``: an
        :class:`~roastlab.io.files.Outputs` transaction to write the file into (the command line
        writes all of a run's files together). Other keywords go to the full figure (e.g.
        ``title``).
        """
        if ax is not None:
            self._draw(ax)
            if path is not None:
                from .figures import save_figure

                save_figure(ax.figure, path, outputs)
            return ax.figure
        return self._figure(path, outputs, **options)

    def _repr_html_(self) -> str:
        out = f"<pre>{html.escape(self.summary())}</pre>"
        try:
            frame = self.to_frame()
        except NotImplementedError:
            return out
        return out + frame.head(12).to_html(float_format=lambda v: f"{v:.4g}")


def aligned(rows: list[list], left: int = 1) -> list[str]:
    """Rows of cells as text lines in aligned columns, two spaces apart: the first ``left`` columns
    left-aligned (names), the others right-aligned (numbers)."""
    widths = [max(len(str(row[i])) for row in rows) for i in range(len(rows[0]))]
    return [
        "  ".join(str(c).ljust(w) if i < left else str(c).rjust(w) for i, (c, w) in enumerate(zip(row, widths)))
        for row in rows
    ]


def draw_curves(ax, curves: dict, ylabel: str = "temperature [°C]") -> None:
    """``curves`` {label: (time_s, values)} on ``ax`` against minutes, labelled and with a legend."""
    import numpy as np

    for label, (t, y) in curves.items():
        if y is not None:
            ax.plot(np.asarray(t, dtype=float) / 60.0, y, lw=1.2, label=label)
    ax.set_xlabel("time [min]")
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=8)
