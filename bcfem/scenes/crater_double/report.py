"""What a double-crater cycle draws: each chamber's pressure change against eps (Fig. 9.10),
and the walls' deformed shapes at the cycle's key states."""

from __future__ import annotations

import numpy as np


def stage_rows(rows, stage: str) -> list[dict]:
    """The rows of ``stage``; unloading starts from the last loaded state, so that its curve
    joins the loading one."""
    loaded = [r for r in rows if r["stage"] == "load"]
    return loaded if stage == "load" else loaded[-1:] + [r for r in rows if r["stage"] == stage]


def plot_cycle(rows, summary):
    """(p_ci - p_a)/p_a against eps, loading and unloading, C1 solid and C2 dashed (Fig. 9.10a),
    and F_tilde."""
    from bcfem.plots import pyplot

    plt = pyplot()
    fig, (ax, axf) = plt.subplots(1, 2, figsize=(9, 3.4))
    for stage, colour in (("load", "tab:red"), ("unload", "tab:blue")):
        part = stage_rows(rows, stage)
        if len(part) < (1 if stage == "load" else 2):  # not reached (a failed run): no curve, no entry
            continue
        eps = [r["eps"] for r in part]
        ax.plot(eps, [r["p_c1_over_pa"] - 1 for r in part], "-", color=colour, label=f"C1, {stage}")
        two = [r for r in part if r["chambers"] == 2]
        if two:  # C2 exists only while the chambers are split
            ax.plot([r["eps"] for r in two], [r["p_c2_over_pa"] - 1 for r in two], "--o", ms=2.5,
                    color=colour, label=f"C2, {stage}")
        axf.plot(eps, [r["F_tilde"] for r in part], "-", color=colour, label=stage)
    split = summary.get("split")
    for a in (ax, axf):
        if split:
            a.axvline(split["eps"], color="0.6", lw=0.8, ls=":")
        a.set_xlabel("platen strain ε")
    ax.set_ylabel("(p_ci - p_a) / p_a")
    axf.set_ylabel("F~ = (p_a - p_c1) A_c1 / (p_a A0)")
    ax.legend(fontsize=7)
    axf.legend(fontsize=7)
    if summary["status"] == "ok":
        axf.set_title(f"F~ = {summary['F_tilde']:.4g}, "
                      + (f"split at ε = {split['eps']:.4g}" if split else "no split"), fontsize=9)
    else:
        axf.set_title("failed: the converged part", fontsize=9)
    fig.tight_layout()
    return fig


def plot_shapes(shapes):
    """The cavity's walls (sidewall, roof, protuberance) at each kept state, side by side, in
    units of the crater height H: deformed (solid), at rest (dotted) and the plate (black)."""
    from bcfem.plots import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, max(len(shapes), 1), figsize=(2.3 * max(len(shapes), 1), 3.0), squeeze=False)
    rest = shapes[0]["x"] if shapes else np.empty((0, 2))
    for i, (ax, shape) in enumerate(zip(axes[0], shapes)):
        segments = shape["segments"]
        for x, style in ((rest, dict(color="0.6", lw=0.6, ls=":", label="at rest")),
                         (shape["x"], dict(color="C0", lw=1.2, label="deformed"))):
            ends = x[segments]  # (segments, 2 ends, 2 coordinates)
            lines = np.full((len(ends), 3, 2), np.nan)
            lines[:, :2] = ends
            ax.plot(lines[:, :, 0].ravel(), lines[:, :, 1].ravel(), **style)
        ax.axhline(0, color="k", lw=1.2, label="plate")
        ax.set_aspect("equal")
        ax.set_xlim(0, 1.3 * rest[:, 0].max())
        ax.set_ylim(-0.05, 1.1 * rest[:, 1].max())
        ax.set_title(f"{shape['label']}, ε = {shape['eps']:.3g}", fontsize=8)
        ax.set_xlabel("r / H", fontsize=8)
        if i == 0:
            ax.set_ylabel("z / H", fontsize=8)
        ax.tick_params(labelsize=7)
    if shapes:  # below the panels, where it hides no wall
        fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="lower center", ncol=3, fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return fig
