"""Figures and tables: simulation plots, fit plots, the reproduce report."""

from __future__ import annotations

import io


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path) -> None:
    """Save a matplotlib figure atomically (PNG/SVG/PDF by suffix)."""
    from pathlib import Path

    from .io import atomic_write_bytes

    buf = io.BytesIO()
    fmt = Path(path).suffix.lstrip(".").lower() or "png"
    fig.savefig(buf, format=fmt, dpi=120, bbox_inches="tight")
    atomic_write_bytes(path, buf.getvalue())


def plot_simulation(result, path=None, title=None):
    """Three panels: temperatures (bean, probe, metal, gas in/out), moisture, heat flows."""
    plt = _pyplot()
    t_min = result.time_s / 60.0
    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True, gridspec_kw={"height_ratios": [3, 1.2, 1.6]})
    ax = axes[0]
    ax.plot(t_min, result.Tb_C, label="Tb bean", color="tab:brown")
    ax.plot(t_min, result.Ta_C, label="Ta probe (model)", color="tab:orange")
    if result.Ta_measured_C is not None:
        ax.plot(t_min, result.Ta_measured_C, "k.", ms=4, label="Ta measured")
    ax.plot(t_min, result.Tm_C, label="Tm metal", color="tab:gray")
    ax.plot(t_min, result.Tgi_C, "--", label="Tgi gas in", color="tab:red")
    ax.plot(t_min, result.Tgo_C, ":", label="Tgo gas out", color="tab:red")
    ax.set_ylabel("temperature [°C]")
    ax.legend(fontsize=8, ncol=2)
    ax.grid(alpha=0.3)
    axes[1].plot(t_min, result.X_kg_kg, color="tab:blue")
    axes[1].set_ylabel("X [kg/kg dry]")
    axes[1].grid(alpha=0.3)
    q = result.heat_flows()
    for key, style in (("Qgb_kW", "-"), ("Qgm_kW", "--"), ("Qbm_kW", "-."), ("Qr_kW", ":")):
        axes[2].plot(t_min, q[key], style, label=key.replace("_kW", ""))
    axes[2].set_ylabel("heat flow [kW]")
    axes[2].set_xlabel("time [min]")
    axes[2].legend(fontsize=8, ncol=4)
    axes[2].grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path)
        plt.close(fig)
    return fig
