"""Figures and tables: simulation plots, fit plots, the reproduce report."""

from __future__ import annotations

import io

import numpy as np


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


def _finish(plt, fig, path, title):
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path)
        plt.close(fig)
    return fig


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
    return _finish(plt, fig, path, title)


def plot_fit(result, path=None, title=None, max_panels: int = 8):
    """Measured vs simulated probe temperature for each batch of a ValidationResult."""
    plt = _pyplot()
    k = min(len(result.names), max_panels)
    cols = 2 if k > 1 else 1
    rows = (k + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(6 * cols, 3.4 * rows), squeeze=False)
    for i in range(k):
        ax = axes[i // cols][i % cols]
        _profile_panel(ax, result, i)
    for j in range(k, rows * cols):
        axes[j // cols][j % cols].axis("off")
    if len(result.names) > k:
        title = f"{title or ''} (first {k} of {len(result.names)} batches)".strip()
    return _finish(plt, fig, path, title)


def _profile_panel(ax, result, i, label=None):
    t = result.time_s[i] / 60.0
    row = result.rows[i]
    ax.plot(t, result.predicted[i], color="tab:green", lw=2, label="Ysim (simulated Ta)")
    ax.plot(t, result.measured[i], "--", color="tab:pink", lw=2, label="Y (measured Ta)")
    ax.set_title(f"{label or result.names[i]}: FIT {row['FIT']:.1f} %, MAE {row['MAE']:.2f} °C", fontsize=10)
    ax.set_xlabel("time [min]")
    ax.set_ylabel("Ta [°C]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)


def plot_fig2(ident, valid, path, note="synthetic data"):
    """Paper Fig. 2: worst (left) and best (right) batch by FIT of each dataset."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(12, 7.5))
    for r, (res, label) in enumerate(((ident, "dataset-I"), (valid, "dataset-V"))):
        fits = [row["FIT"] for row in res.rows]
        worst, best = int(np.argmin(fits)), int(np.argmax(fits))
        left, right = ("a", "b") if r == 0 else ("c", "d")
        _profile_panel(axes[r][0], res, worst, f"{left}) {label} {res.names[worst]} (worst)")
        _profile_panel(axes[r][1], res, best, f"{right}) {label} {res.names[best]} (best)")
    fig.suptitle(f"Temperature profiles, measured vs simulated ({note})")
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def plot_fig3(ident, valid, path, note="synthetic data"):
    """Paper Fig. 3: distribution of the absolute prediction error per dataset."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    data = [np.abs(np.concatenate(ident.errors)), np.abs(np.concatenate(valid.errors))]
    parts = ax.violinplot(data, showmeans=True, showextrema=True)
    for body in parts["bodies"]:
        body.set_alpha(0.4)
    ax.boxplot(data, widths=0.12)
    ax.set_xticks([1, 2], [f"identification\n(dataset-I, {ident.plant})", f"validation\n(dataset-V, {valid.plant})"])
    ax.set_ylabel("absolute error |Ta − T̂a| [°C]")
    for x, d in zip((1, 2), data):
        ax.annotate(f"mean {d.mean():.2f}\nvar {d.var(ddof=1):.2f}", (x + 0.18, d.mean()), fontsize=8)
    ax.set_title(f"Absolute error distribution ({note})")
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)
