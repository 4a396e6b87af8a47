"""Figure 3.2 of demos/blister_theories.py: the membrane theories' P-V and P-z(0) curves."""

from bcfem import io

LABELS = {"gent-Jm100": r"Gent $J_m=100$", "gent-Jm200": r"Gent $J_m=200$",
          "neo-hookean": r"neo-Hookean ($J_m\to\infty$)"}
V_ZOOM, P_ZOOM, Z_ZOOM = 0.15, 0.5, 0.3  # the small-deflection window of frames (b) and (d)


def draw(results) -> None:
    """Draw and save Figure 3.2 (rank 0) from the demo's ``Results``."""
    from matplotlib.patches import Rectangle

    from bcfem.plots import pyplot

    plt = pyplot()
    colors = dict(zip(results.branches, ["C3", "C0", "C2"]))
    fig, axes = plt.subplots(2, 2, figsize=(9.0, 7.2))
    (ax_a, ax_b), (ax_c, ax_d) = axes
    for ax_full, ax_zoom, x_key, x_label, x_full, x_zoom in (
            (ax_a, ax_b, "V_over_V0", r"$V/V_0$", results.v_max, V_ZOOM),
            (ax_c, ax_d, "aspect", r"$z(0)/R_0$", 4.0, Z_ZOOM)):
        for ax in (ax_full, ax_zoom):
            for name, model in results.theories.items():
                if x_key == "V_over_V0":
                    x, y = results.v_theory, model["P_of_V"](results.v_theory)
                else:
                    x, y = model["z_of_P"](results.p_theory), results.p_theory
                ax.plot(x, y, model["style"], color="k", lw=1.2, label=name)
            for label, branch in results.branches.items():
                ax.plot(branch.column(x_key), branch.column("P"), "-", color=colors[label],
                        lw=1.6, label=f"nonlinear, {LABELS[label]}")
                for lp in branch.limit_points:
                    ax.plot(lp.values[x_key], lp.values["P"], "o", ms=5, mfc="white",
                            mec=colors[label], zorder=3)
            ax.set_xlabel(x_label)
            ax.set_ylabel(r"$P = \Delta p\,R_0/(\mu t_0)$")
            ax.grid(alpha=0.3)
        ax_full.set_xlim(0, x_full)
        ax_full.set_ylim(0, 3.0)
        ax_zoom.set_xlim(0, x_zoom)
        ax_zoom.set_ylim(0, P_ZOOM)
        ax_full.add_patch(Rectangle((0, 0), x_zoom, P_ZOOM, fill=False, ec="red", lw=1.0, zorder=4))
    for ax, tag in zip(axes.flat, "abcd"):
        ax.text(0.03, 0.95, f"({tag})", transform=ax.transAxes, va="top", fontweight="bold")
    ax_d.axvline(0.15, color="0.4", ls=":", lw=1.0)
    ax_d.text(0.152, 0.47, r"$z(0)/R_0 = 0.15$", color="0.3", fontsize=8, va="top")
    ax_b.legend(fontsize=8, loc="upper left", bbox_to_anchor=(0.0, 0.9), framealpha=0.95)
    fig.suptitle("Clamped blister: simple, moderate (Föppl) and nonlinear membrane theories",
                 fontsize=10)
    fig.tight_layout()
    out = results.run.out
    io.save_figure(fig, out / "theories.png", results.run.comm)
    plt.close(fig)
    results.run.report(f"wrote {out / 'curves.csv'}, {out / 'summary.json'}, {out / 'theories.png'}")
