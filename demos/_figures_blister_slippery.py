"""Figures 3.18-3.20 of demos/blister_slippery.py: blisters with a slippery edge."""

import numpy as np

from bcfem import io


def draw(results) -> None:
    """Draw and save Figures 3.18-3.20 (rank 0) from the demo's ``Results``."""
    from matplotlib.lines import Line2D

    from bcfem.plots import pyplot

    plt = pyplot()
    styles = {"with": "-", "without": "--"}
    BLUE, RED = "C0", "C3"

    def split(d):
        """(initially delaminated R <= 1, initially bonded R >= 1) parts of a zone's samples."""
        inner = d["R"] <= 1.0 + 1e-12
        outer = d["R"] >= 1.0 - 1e-12
        return inner, outer

    # Fig. 3.18
    fig, ax = plt.subplots(figsize=(10.0, 3.6))
    ax.axhline(0, color="0.75", lw=4, zorder=0)
    for case, zones in results.hoop.items():
        for d in zones.values():
            inner, outer = split(d)
            for part, color in ((inner, BLUE), (outer, RED)):
                if part.sum() > 1:
                    for sign in (1, -1):
                        ax.plot(sign * d["r"][part], d["z"][part], styles[case], color=color, lw=1.6)
        bonded = zones["bonded"]
        r_front = bonded["r"][0]
        ax.plot([-r_front, r_front], [0, 0], "o", ms=5, mfc="white" if case == "without" else "k", mec="k",
                zorder=4)
        for R_mark in (2.0, 3.0, results.outer_radius):
            r_mark = float(np.interp(R_mark, bonded["R"], bonded["r"]))
            y = -0.06 if case == "with" else -0.12
            ax.plot([-r_mark, r_mark], [y, y], "|", ms=7, color="k" if case == "with" else "0.45")
    ax.set_aspect("equal")
    ax.set_xlim(-results.outer_radius - 0.2, results.outer_radius + 0.2)
    ax.set_ylim(-0.2, 2.2)
    ax.set_xlabel(r"$r/R_0$")
    ax.set_ylabel(r"$z/R_0$")
    handles = [Line2D([], [], color="k", ls="-", lw=1.6, label="with propagation"),
               Line2D([], [], color="k", ls="--", lw=1.6, label="without propagation"),
               Line2D([], [], color=BLUE, lw=3, label=r"initially delaminated ($R < R_0$)"),
               Line2D([], [], color=RED, lw=3, label=r"initially bonded ($R > R_0$)"),
               Line2D([], [], ls="none", marker="o", mfc="k", mec="k", label=r"front $r_1$ (open: without)"),
               Line2D([], [], ls="none", marker="|", ms=7, color="k",
                      label=r"$R = 2, 3, 4R_0$ (grey: without)")]
    ax.legend(handles=handles, fontsize=8, loc="upper right", ncol=1, framealpha=0.95)
    ax.set_title(rf"Slippery edge at $V/V_0 = {results.v_side:g}$: Gent $J_m = {results.jm:g}$, "
                 rf"$\alpha = {results.alpha:g}$, $(\gamma_{{ls}} - \Delta\gamma)/(\mu t_0) = {results.adhesion:g}$, "
                 rf"$n = {results.outer_radius:g}$", fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "slippery_fig3_18.png", results.run.comm)
    plt.close(fig)

    # Fig. 3.19
    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    ax.axhline(0, color="0.5", lw=0.8)
    for case, zones in results.hoop.items():
        for d in zones.values():
            inner, outer = split(d)
            for part, color in ((inner, BLUE), (outer, RED)):
                if part.sum() > 1:
                    ax.plot(d["R"][part], d["N_theta"][part], styles[case], color=color, lw=1.6)
        R1 = results.side_rows[case]["R1_over_R0"]
        ax.axvline(R1, color="0.4", ls=styles[case], lw=0.8)
        ax.annotate(rf"front $R_1 = {R1:.2f}R_0$" + (" (held)" if case == "without" else ""),
                    (R1, 1.25 if case == "with" else 1.45), xytext=(4, 0), textcoords="offset points",
                    fontsize=8, color="0.3")
    ax.set_xlim(0, results.outer_radius)
    ax.set_ylim(-1.2, 1.6)
    ax.set_xlabel(r"reference radius $R/R_0$")
    ax.set_ylabel(r"hoop traction $N_\theta/(\mu t_0)$")
    ax.grid(alpha=0.3)
    ax.legend(handles=handles[:4], fontsize=8, loc="lower right", framealpha=0.95)
    ax.set_title(rf"Hoop traction at $V/V_0 = {results.v_side:g}$ (negative: compressive, may wrinkle)", fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "slippery_fig3_19.png", results.run.comm)
    plt.close(fig)

    # Fig. 3.20
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.0))
    colors = {"with": "C3", "without": "k"}
    vc = results.event["V_over_V0"]
    for case, b in results.branches.items():
        V = b.column("V_over_V0")
        axes[0].plot(V, b.column("P"), color=colors[case], lw=1.6, label=f"{case} propagation")
        axes[1].plot(V, results.F_branches[case], color=colors[case], lw=1.6, label=f"{case} propagation")
    axes[0].plot(vc, results.event["P"], "o", ms=6, mfc="white", mec="C3", zorder=4,
                 label=rf"onset $V_c = {vc:.3f}V_0$")
    axes[1].plot(vc, results.F_onset, "o", ms=6, mfc="white", mec="C3", zorder=4)
    axes[1].plot([results.v_side] * 2, [results.F_side["with"], results.F_side["without"]], "s", ms=4, color="0.4",
                 label=rf"$V/V_0 = {results.v_side:g}$ (Fig. 3.18)")
    for ax, label, tag in ((axes[0], r"$P = \Delta p\,R_0/(\mu t_0)$", "a"),
                           (axes[1], r"$F = (\Pi + \Delta p V)/(\pi R_0^2 \mu t_0)$", "b")):
        ax.set_xlim(0, results.v_max)
        ax.set_ylim(0, 4.4 if tag == "a" else None)
        ax.set_xlabel(r"$V/V_0$")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="lower right" if tag == "b" else "upper right")
        ax.text(0.03, 0.96, f"({tag})", transform=ax.transAxes, va="top", fontweight="bold",
                bbox=dict(fc="white", ec="none", pad=1))
    fig.suptitle("Slippery edge: pressure and free energy at fixed volume", fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "slippery_fig3_20.png", results.run.comm)
    plt.close(fig)
    results.run.report(f"wrote branches.csv, profiles_V1.5.csv, summary.json and three PNGs to {results.run.out}")
