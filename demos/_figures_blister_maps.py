"""Figures 3.15-3.17 of demos/blister_maps.py: maps after delamination onset and the fit."""

import numpy as np

from bcfem import io

LABELS = {"gent-Jm100": r"Gent $J_m = 100$", "neo-hookean": "neo-Hookean"}
PANELS = [("V_over_V1", r"$V/V_1$"), ("P1", r"$\Delta p R_1/(\mu t_0)$"),
          ("aspect1", r"aspect ratio $z(0)/R_1$"), ("contact_angle_deg", r"contact angle $\pi - \phi_0^-$ [deg]")]
LEVELS = {  # the same for both materials; V/V1 spans 0 ... v_max, so its levels are graded
    "V_over_V1": [0, 0.25, 0.5, 1, 1.5, 2, 3, 4, 5, 6, 8, 10, 12.5, 15, 20, 30, 40, 50],
    "P1": list(range(0, 25, 2)),
    "aspect1": list(np.arange(0, 6.01, 0.5)),
    "contact_angle_deg": list(range(0, 181, 15)),
}
XLABEL, YLABEL = r"$(\gamma_{ls}-\Delta\gamma)/(\mu t_0)$", r"$\gamma_l/(\mu t_0)$"

def draw(results) -> None:
    """Draw and save Figures 3.15-3.17 (rank 0) from the demo's ``Results``."""

    def decorate(ax, name):
        ax.plot([0.0, -results.alpha_range[1]], [0.0, results.alpha_range[1]], "-", color="k", lw=1.2)
        ax.fill_between([results.adhesion_range[0], 0.0], [results.alpha_range[0]] * 2, [-results.adhesion_range[0], 0.0], color="0.93", zorder=0)
        ax.text(results.adhesion_range[0] + 0.6, 0.25 * results.alpha_range[1], "no blister:\nspreads at\n" r"$V \to 0$",
                fontsize=7, color="0.35")
        if name == "neo-hookean":
            alphas = [r["alpha"] for r in results.never]
            ax.fill_betweenx(alphas, [r["g_sup"] for r in results.never], results.adhesion_range[1] + 1, facecolor="white",
                             edgecolor="0.45", hatch="///", lw=0.0, zorder=2)
            ax.plot([r["g_sup"] for r in results.never], alphas, "-", color="0.2", lw=1.2, zorder=3)
            ax.plot([r["g_limit"] for r in results.never], alphas, ":", color="0.2", lw=1.2, zorder=3)
            ax.text(0.97 * results.adhesion_range[1], 0.5 * results.alpha_range[1], "never\ndelaminates",
                    ha="right", fontsize=8, zorder=6, bbox=dict(fc="white", ec="none", pad=1.5))
            if not results.run.args.full:  # the grid points; on the full grid they would hide the maps
                x = [r["adhesion"] for r in results.ok_points[name] if not r["onset"]]
                y = [r["alpha"] for r in results.ok_points[name] if not r["onset"]]
                ax.plot(x, y, "x", color="0.3", ms=4, zorder=4)
        if not results.run.args.full:
            done = [r for r in results.ok_points[name] if r["onset"]]
            ax.plot([r["adhesion"] for r in done], [r["alpha"] for r in done], ".", color="0.5", ms=2.5, zorder=4)
        ax.set_xlim(*results.adhesion_range)
        ax.set_ylim(*results.alpha_range)
        ax.set_xlabel(XLABEL)
        ax.set_ylabel(YLABEL)

    from matplotlib.colors import BoundaryNorm

    from bcfem.plots import pyplot

    plt = pyplot()
    files = {"gent-Jm100": "maps_gent.png", "neo-hookean": "maps_neo_hookean.png"}
    for name, figure in files.items():
        fig, axes = plt.subplots(2, 2, figsize=(10.5, 7.6))
        for ax, (key, label), tag in zip(axes.flat, PANELS, "abcd"):
            tri, z = results.triangulation(name, key)
            # V/V1 is interpolated in log(1 + V/V1): it grows steeply towards the neo-Hookean boundary
            f = np.log1p if key == "V_over_V1" else (lambda v: np.asarray(v, dtype=float))
            levels = f(LEVELS[key])
            norm = BoundaryNorm(levels, plt.get_cmap("viridis").N)
            cs = ax.tricontourf(tri, f(z), levels=levels, cmap="viridis", norm=norm, zorder=1, extend="max")
            ax.tricontour(tri, f(z), levels=levels, colors="k", linewidths=0.3, zorder=1)
            bar = fig.colorbar(cs, ax=ax, label=label, spacing="uniform")
            bar.set_ticks(levels[::2], labels=[f"{v:g}" for v in LEVELS[key][::2]])
            decorate(ax, name)
            ax.text(0.97, 0.04, f"({tag})", transform=ax.transAxes, ha="right", fontweight="bold", zorder=5)
        fig.suptitle(f"After delamination onset (self-similar growth), {LABELS[name]}: "
                     f"{results.n_alpha}x{results.n_adhesion} grid, v_max = {results.materials[name]['v_max']:g} V0 "
                     f"(dissertation Fig. 3.{15 if name == 'gent-Jm100' else 16})", fontsize=10)
        fig.tight_layout()
        io.save_figure(fig, results.run.out / figure, results.run.comm)
        plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for key, level, color in (("aspect1", results.fit_target["aspect"], "C0"), ("P1", results.fit_target["P1"], "C3")):
        tri, z = results.triangulation("gent-Jm100", key)
        ax.tricontour(tri, z, levels=[level], colors=color, linewidths=1.6, zorder=3)
        ax.plot([], [], "-", color=color, label=(r"$z(0)/R_1 = $" if key == "aspect1" else r"$\Delta p R_1/\mu t_0 = $")
                + f"{level:g} (maps)")
    decorate(ax, "gent-Jm100")
    ax.plot(results.fit["adhesion"], results.fit["alpha"], "o", ms=7, mfc="white", mec="k", mew=1.5, zorder=5,
            label=f"fit: ({results.fit['alpha']:.3f}, {results.fit['adhesion']:.3f})")
    ax.plot(results.dissertation_fit["adhesion"], results.dissertation_fit["alpha"], "s", ms=6, mfc="none", mec="C2", mew=1.5,
            zorder=5, label="dissertation's reading (5.1, 15.9)")
    ax.legend(fontsize=7.5, loc="upper right", framealpha=0.95)
    ax.set_title(r"Inverse fit, Gent $J_m = 100$: $z(0)/R_1 = 2$ and $\Delta p R_1/(\mu t_0) = 10$ "
                 "(dissertation Fig. 3.17)", fontsize=9)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "fit.png", results.run.comm)
    plt.close(fig)
    out = results.run.out
    results.run.report(f"wrote {out / 'maps.csv'}, {out / 'never.csv'}, {out / 'summary.json'}, "
                       f"{', '.join(str(out / f) for f in files.values())}, {out / 'fit.png'}")
