"""Figures 3.12-3.14 of demos/blister_adhesive.py: delamination of an adhesive blister."""

import numpy as np

from bcfem import io

LABELS = {"gent-Jm100": r"Gent $J_m = 100$", "neo-hookean": "neo-Hookean"}

def draw(results) -> None:
    """Draw and save Figures 3.12-3.14 (rank 0) from the demo's ``Results``."""

    def split_at_R0(pr):
        """The profile as (delaminated, bonded) pieces, split exactly at R = R0 (linear in R)."""
        R, r, z = pr["R"], pr["r"], pr["z"]
        if R[-1] <= 1.0 + 1e-12:
            return (r, z), None
        k = int(np.searchsorted(R, 1.0))
        t = (1.0 - R[k - 1]) / (R[k] - R[k - 1])
        r1, z1 = r[k - 1] + t * (r[k] - r[k - 1]), z[k - 1] + t * (z[k] - z[k - 1])
        return (np.r_[r[:k], r1], np.r_[z[:k], z1]), (np.r_[r1, r[k:]], np.r_[z1, z[k:]])

    from matplotlib.lines import Line2D

    from bcfem.plots import pyplot

    plt = pyplot()
    blue, red = "#1f5fbf", "#d62728"
    fig, ax = plt.subplots(figsize=(9.0, 3.9))
    extent = 2.2
    ax.axhspan(-0.25, 0.0, color="0.85", zorder=0)
    for edge, style in (("clamped", "--"), ("adhesive", "-")):
        pr = results.profiles[edge]
        delaminated, bonded = split_at_R0(pr)
        edge_r = pr["r"][-1]
        for sign in (1, -1):
            ax.plot(sign * delaminated[0], delaminated[1], style, color=blue, lw=1.8)
            if bonded is not None:
                ax.plot(sign * bonded[0], bonded[1], style, color=red, lw=1.8)
            ax.plot(sign * np.array([edge_r, extent]), [0.0, 0.0], style, color=red, lw=1.8)  # still bonded
    F3 = results.compare["energy_at_V3_gent"]["ours"]["F"]
    R1_end = results.branches["gent-Jm100", "adhesive"].rows[-1]["R1_over_R0"]
    handles = [Line2D([], [], color="0.2", ls="--",
                      label=rf"clamped: $F = {F3['without_propagation']:.2f}\,\pi R_0^2\mu t_0$"),
               Line2D([], [], color="0.2", ls="-",
                      label=rf"propagated to $R_1 = {R1_end:.3f}\,R_0$: $F = {F3['with_propagation']:.2f}\,\pi R_0^2\mu t_0$"),
               Line2D([], [], color=blue, label=r"initially delaminated, $R < R_0$"),
               Line2D([], [], color=red, label=r"initially bonded, $R > R_0$")]
    ax.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0), framealpha=0.95)
    ax.set_aspect("equal")
    ax.set_xlim(-extent, extent)
    ax.set_ylim(-0.25, 2.9)
    ax.set_xlabel(r"$r/R_0$")
    ax.set_ylabel(r"$z/R_0$")
    ax.set_title(rf"Adhesive blister at $V/V_0 = {results.v_side:g}$: Gent $J_m = 100$, "
                 rf"$\alpha = {results.alpha:g}$, $(\gamma_{{ls}}-\Delta\gamma)/(\mu t_0) = {results.adhesion:g}$ "
                 "(dissertation Fig. 3.12)", fontsize=9)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "side_views.png", results.run.comm)
    plt.close(fig)

    panels = [("P", r"$P = \Delta p\,R_0/(\mu t_0)$"),
              ("F", r"$F = \Pi + \Delta p V$  $[\pi R_0^2\mu t_0]$"),
              ("dF", r"$F - F_{\rm clamped}$  $[\pi R_0^2\mu t_0]$"),
              ("Pi", r"$\Pi$  $[\pi R_0^2\mu t_0]$")]

    def values(name, key, V, y):
        """``y`` of ``key``, or for 'dF' the difference of F to the clamped branch at the same V."""
        return y - results.clamped_at(name, "F", V) if key == "dF" else y

    fig, axes = plt.subplots(len(results.materials), len(panels), figsize=(15.5, 7.2))
    for row_axes, name, tags in zip(axes, results.materials, ("abcd", "efgh")):
        vc = results.onsets[name]["event"]["V_over_V0"]
        v_max = results.materials[name]["v_max"]
        V_below = np.linspace(0.35 * vc, vc, 100)
        V_above = np.linspace(vc, v_max, 100)
        onset = results.with_energies(results.onsets[name]["event"], "adhesive")
        for ax, (key, label), tag in zip(row_axes, panels, tags):
            y_key = "F" if key == "dF" else key
            Vc_, yc = results.column((name, "clamped"), "V_over_V0"), results.column((name, "clamped"), y_key)
            ax.plot(Vc_, values(name, key, Vc_, yc), "-", color="k", lw=1.5, label="clamped (without propagation)")
            Va, ya = results.column((name, "adhesive"), "V_over_V0"), results.column((name, "adhesive"), y_key)
            keep = Va >= vc
            ax.plot(Va[keep], values(name, key, Va[keep], ya[keep]), "-", color=red, lw=2.4, alpha=0.8,
                    label="adhesive (with propagation)")
            for V, style, lab in ((V_above, "--", r"eq. 3.88: $V P^3$ = const, $F \propto V^{2/3}$"),
                                  (V_below, ":", r"self-similar family continued to $R_1 < R_0$")):
                ax.plot(V, values(name, key, V, results.self_similar(name, V)[y_key]), style, color="k" if style == "--" else red,
                        lw=1.0 if style == "--" else 1.3, label=lab)
            ax.plot(vc, values(name, key, vc, onset[y_key]), "o", ms=6, mfc="white", mec=blue, mew=1.6, zorder=4,
                    label=rf"onset, $V_c/V_0 = {vc:.3f}$")
            ax.set_xlim(0, v_max)
            ax.set_xlabel(r"$V/V_0$")
            ax.set_ylabel(label)
            ax.set_title(LABELS[name], fontsize=9)
            ax.grid(alpha=0.3)
            ax.text(0.03, 0.95, f"({tag})", transform=ax.transAxes, va="top", fontweight="bold")
        row_axes[0].set_ylim(0, 4.5)
        row_axes[1].set_ylim(0, None)
        row_axes[2].axhline(0.0, color="0.5", lw=0.6)
    axes[0, 0].legend(fontsize=7, loc="lower right", framealpha=0.95)
    fig.suptitle(rf"Adhesive blister, $\alpha = {results.alpha:g}$, "
                 rf"$(\gamma_{{ls}}-\Delta\gamma)/(\mu t_0) = {results.adhesion:g}$ "
                 "(dissertation Figs. 3.13 Gent, 3.14 neo-Hookean)", fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "pv_energy.png", results.run.comm)
    plt.close(fig)
    out = results.run.out
    results.run.report(f"wrote {out / 'curves.csv'}, {out / 'profiles.csv'}, {out / 'summary.json'}, "
                       f"{out / 'side_views.png'}, {out / 'pv_energy.png'}")
