"""Plots, drawn after the solve on rank 0; matplotlib is imported lazily."""

from __future__ import annotations


def pyplot():
    """matplotlib.pyplot with the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def branch_figure(branch, x: str, y: str, xlabel: str, ylabel: str, title: str = ""):
    """One branch with its limit points marked."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5, 3.8))
    ax.plot(branch.column(x), branch.column(y), "-", lw=1.6)
    for lp in branch.limit_points:
        ax.plot(lp.values[x], lp.values[y], "o", ms=6, mfc="none",
                label=f"{lp.kind}: {ylabel}={lp.values[y]:.6g}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title, fontsize=9)
    if branch.limit_points:
        ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig
