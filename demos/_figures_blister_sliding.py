"""Figures 3.7, 3.8 and 3.10 of demos/blister_sliding.py: blisters with a sliding edge."""

import math

import numpy as np

from bcfem import io


def draw(results) -> None:
    """Draw and save Figures 3.7, 3.8 and 3.10 (rank 0) from the demo's ``Results``."""
    from matplotlib.lines import Line2D

    from bcfem.plots import pyplot

    plt = pyplot()

    def z_over_r1(branch):
        return branch.column("aspect") / branch.column("r1_over_R0")

    def unresolved(phi_Y, alpha):
        """Curves whose small-volume end has the unresolved edge layer of check 2."""
        return alpha == 0.0 or (phi_Y == 90.0 and alpha < math.inf)

    def draw(ax, branch, y, dotted_below=None, **style):
        """Plot y against V/V0; dotted where V/V0 < dotted_below (the unresolved edge layer)."""
        V = branch.column("V_over_V0")
        if dotted_below is None or not np.any(V < dotted_below):
            ax.plot(V, y, **style)
            return
        i = int(np.argmax(V >= dotted_below))  # V grows along these paths
        ax.plot(V[: i + 1], y[: i + 1], **{**style, "ls": ":"})
        ax.plot(V[i:], y[i:], **style)

    def frame(ax, ylim, label, tag):
        """Axes of a V/V0 panel: limits, labels, grid and the panel letter."""
        ax.set_xlim(0, results.v_max)
        ax.set_ylim(*ylim)
        ax.set_xlabel(r"$V/V_0$")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.text(0.03, 0.96, f"({tag})", transform=ax.transAxes, va="top", fontweight="bold",
                bbox=dict(fc="white", ec="none", pad=1))

    # Fig. 3.7
    colors = dict(zip(results.alphas, ["k", "C0", "C2", "C1", "C3"]))
    fig, axes = plt.subplots(1, 3, figsize=(13.0, 4.2))
    panels = [("P", r"$P = \Delta p\,R_0/(\mu t_0)$", (1e-3, 40)),
              ("z0_over_r1", r"aspect ratio $z(0)/r_1$", (0, 2.8)),
              ("contact_angle_deg", r"contact angle $\theta = \pi - \phi_0^-$ (deg)", (60, 185))]
    for ax, (key, label, ylim), tag in zip(axes, panels, "abc"):
        for alpha in (*results.alphas, math.inf):
            b = results.branches[results.phi_y_main, alpha]
            if alpha == math.inf and key == "P":
                continue
            y = z_over_r1(b) if key == "z0_over_r1" else b.column(key)
            style = (dict(ls="-.", color="0.35", lw=1.5) if alpha == math.inf
                     else dict(ls="-", color=colors[alpha], lw=1.5))
            draw(ax, b, y, results.v_edge if unresolved(results.phi_y_main, alpha) else None, **style)
            if key == "P":
                for lp in b.limit_points:
                    ax.plot(lp.values["V_over_V0"], lp.values["P"], "o", ms=5, mfc="white", mec=colors[alpha],
                            zorder=3)
        frame(ax, ylim, label, tag)
    axes[0].set_yscale("log")
    axes[1].axhline(results.printed_aspect, color="0.35", ls=":", lw=1.0)
    axes[1].text(3.0, results.printed_aspect - 0.04, r"printed $1+\sqrt{2}/2$ (likely typo)", fontsize=8,
                 color="0.3", va="top")
    axes[1].text(3.0, 1 + math.sqrt(2) + 0.04, r"cap: $1+\sqrt{2}$", fontsize=8, color="0.3", va="bottom")
    axes[2].set_yticks(range(60, 181, 15))
    handles = [Line2D([], [], color=colors[a], lw=1.5, label=rf"$\alpha = {a:g}$") for a in results.alphas]
    handles.append(Line2D([], [], color="0.35", ls="-.", lw=1.5, label=r"droplet ($\alpha\to\infty$)"))
    handles.append(Line2D([], [], ls="none", marker="o", ms=5, mfc="white", mec="0.3", label="max of $P$"))
    axes[2].legend(handles=handles, fontsize=8, loc="upper right", ncol=2, framealpha=0.95)
    fig.suptitle(r"Sliding edge, neo-Hookean, $\phi_Y = 3\pi/4$ (dotted: edge layer not resolved, "
                 r"$V/V_0 < %g$)" % results.v_edge, fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "sliding_fig3_7.png", results.run.comm)
    plt.close(fig)

    # Fig. 3.8
    cmaps = {45.0: plt.get_cmap("Greens"), 90.0: plt.get_cmap("Blues"), 135.0: plt.get_cmap("Reds")}
    shade = dict(zip(results.alphas[1:], (0.4, 0.55, 0.7, 0.9)))
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.4))
    for ax, key, label, ylim, tag in ((axes[0], "z0_over_r1", r"aspect ratio $z(0)/r_1$", (0, 2.7), "a"),
                                      (axes[1], "contact_angle_deg", r"contact angle $\theta$ (deg)", (0, 185), "b")):
        for phi_Y in results.phi_y_deg:
            for alpha in (*results.alphas[1:], math.inf):
                b = results.branches[phi_Y, alpha]
                y = z_over_r1(b) if key == "z0_over_r1" else b.column(key)
                if alpha == math.inf:
                    style = dict(ls="-.", color=cmaps[phi_Y](0.9), lw=1.5)
                else:
                    style = dict(ls="-", color=cmaps[phi_Y](shade[alpha]), lw=1.3)
                draw(ax, b, y, results.v_edge if unresolved(phi_Y, alpha) else None, **style)
        y = z_over_r1(results.plain) if key == "z0_over_r1" else results.plain.column(key)
        draw(ax, results.plain, y, results.v_edge, ls="-", color="k", lw=1.8, zorder=3)
        frame(ax, ylim, label, tag)
    axes[1].set_yticks(range(0, 181, 30))
    handles = [Line2D([], [], color=cmaps[p](0.75), lw=2, label=rf"$\phi_Y = {p:g}°$") for p in results.phi_y_deg]
    handles += [Line2D([], [], color="0.3", ls="-.", lw=1.5, label=r"$\alpha = \infty$ (droplet)"),
                Line2D([], [], color="0.25", lw=1.3, label=r"$\alpha = 5, 2, 1, 0.5$ (dark to light)"),
                Line2D([], [], color="k", lw=1.8, label=r"$\alpha = 0$ (any $\phi_Y$)")]
    axes[1].legend(handles=handles, fontsize=8, loc="lower right", ncol=2, framealpha=0.95)
    fig.suptitle(r"Sliding edge, neo-Hookean: Young angle $\phi_Y$ and $\alpha = \gamma_l/(\mu t_0)$ "
                 r"(dotted: edge layer not resolved)", fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "sliding_fig3_8.png", results.run.comm)
    plt.close(fig)

    # Fig. 3.10
    fig, ax = plt.subplots(figsize=(6.4, 3.0))
    ax.axhline(0, color="0.5", lw=2.5, zorder=0)
    for alpha, ls in zip(results.alpha_wrap, ("-", "--")):
        prof = results.wrapped[alpha]
        r, z = prof["r"], prof["z"]
        ax.plot(np.concatenate([-r[::-1], r]), np.concatenate([z[::-1], z]), ls, color="k", lw=1.6,
                label=rf"$\alpha = {alpha:g}$: $r_1 = {r[-1]:.2f}R_0$, $\theta = "
                      rf"{results.wrapped_rows[alpha]['contact_angle_deg']:.0f}°$")
    ax.plot([-1, 1], [0, 0], "o", ms=4, color="0.4", label=r"initial edge $R_0$")
    ax.set_aspect("equal")
    ax.set_xlim(-1.15, 1.15)
    ax.set_ylim(-0.05, 0.72)
    ax.set_xlabel(r"$r/R_0$")
    ax.set_ylabel(r"$z/R_0$")
    ax.legend(fontsize=8, loc="upper center", ncol=2, columnspacing=1.0)
    ax.set_title(rf"Sliding edge at $V/V_0 = {results.v_wrap:g}$, $\phi_Y = 3\pi/4$: elasto-capillary wrapping",
                 fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "sliding_fig3_10.png", results.run.comm)
    plt.close(fig)
    results.run.report(f"wrote curves.csv, profiles_V0.1.csv, summary.json and three PNGs to {results.run.out}")
