"""Figure 3.5 of demos/blister_surface_tension.py: elasto-capillary clamped blisters."""

from bcfem import io


def draw(results) -> None:
    """Draw and save Figure 3.5 (rank 0) from the demo's ``Results``."""
    from matplotlib.lines import Line2D

    from bcfem.plots import pyplot

    plt = pyplot()
    colors = dict(zip(results.alphas, ["k", "C0", "C2", "C3"]))
    styles = {"neo-hookean": "-", "gent-Jm100": "--"}
    panels = [("P", r"$P = \Delta p\,R_0/(\mu t_0)$", (0, 7)),
              ("aspect", r"aspect ratio $z(0)/R_0$", (0, 3.6)),
              ("contact_angle_deg", r"contact angle $\theta = \pi - \phi_0$ (deg)", (0, 180))]
    fig, axes = plt.subplots(1, 3, figsize=(13.0, 4.2))
    for ax, (key, label, ylim), tag in zip(axes, panels, "abc"):
        for (name, alpha), branch in results.branches.items():
            ax.plot(branch.column("V_over_V0"), branch.column(key), styles[name], color=colors[alpha], lw=1.5)
            if key == "P":
                for lp in branch.limit_points:
                    ax.plot(lp.values["V_over_V0"], lp.values["P"], "o", ms=5, mfc="white",
                            mec=colors[alpha], zorder=3)
        ax.set_xlim(0, results.v_max)
        ax.set_ylim(*ylim)
        ax.set_xlabel(r"$V/V_0$")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.text(0.03, 0.95, f"({tag})", transform=ax.transAxes, va="top", fontweight="bold")
    axes[2].set_yticks(range(0, 181, 30))
    alpha_handles = [Line2D([], [], color=colors[a], lw=1.5, label=rf"$\alpha = {a:g}$") for a in results.alphas]
    law_handles = [Line2D([], [], color="0.3", ls="-", lw=1.5, label="neo-Hookean"),
                   Line2D([], [], color="0.3", ls="--", lw=1.5, label=rf"Gent $J_m = {results.jm:g}$")]
    axes[0].legend(handles=alpha_handles + law_handles, fontsize=8, loc="upper right", ncol=2,
                   framealpha=0.95)
    fig.suptitle(r"Clamped elasto-capillary blister, $\alpha = \gamma_l/(\mu t_0)$", fontsize=10)
    fig.tight_layout()
    out = results.run.out
    io.save_figure(fig, out / "surface_tension.png", results.run.comm)
    plt.close(fig)
    results.run.report(f"wrote {out / 'curves.csv'}, {out / 'summary.json'}, {out / 'surface_tension.png'}")
