"""Figures 7.9-7.12, 8.4, 8.6b and 8.7 of demos/crater_design.py: the crater design space."""

import textwrap

import numpy as np

from bcfem import io
from bcfem.scenes import crater
from bcfem.scenes.crater import frames as crater_frames

STABILITY_COLOURS = {"stable": "tab:blue", "unstable-unloading": "tab:red", "unstable-both": "tab:green"}

def draw(results) -> None:
    """Draw and save Figures 7.9-7.12, 8.4, 8.6b and 8.7 (rank 0) from the demo's ``Results``."""

    def field(rows, x, y, key):
        xs, ys = sorted({r[x] for r in rows}), sorted({r[y] for r in rows})
        Z = np.full((len(ys), len(xs)), np.nan)
        for r in rows:
            if r["status"] == "ok":
                Z[ys.index(r[y]), xs.index(r[x])] = r[key]
        return xs, ys, Z

    def contour(ax, name, x, y, key, label, lines=()):
        rows = results.maps.get(name, [])
        if not rows:
            ax.text(0.5, 0.5, "not in the quick grid\n(--full)", ha="center", va="center", transform=ax.transAxes)
            return
        xs, ys, Z = field(rows, x, y, key)
        if len(xs) > 1 and len(ys) > 1:
            cs = ax.contourf(xs, ys, Z, levels=12, cmap="viridis")
            ax.figure.colorbar(cs, ax=ax, label=label)
            for level, style in lines:
                ax.contour(xs, ys, Z, levels=[level], colors="k", linestyles=style, linewidths=1.6)
        for r in rows:
            if results.on_saddle(r):  # ringed: the force of an unstable end state
                ax.plot(r[x], r[y], "o", mfc="none", mec="r", ms=8)
            if results.still_open(name, r):  # boxed: not closed by the closure limit
                ax.plot(r[x], r[y], "s", mfc="none", mec="orange", ms=9)
            if r["status"] == "ok":
                ax.plot(r[x], r[y], ".", color="w" if len(xs) > 1 and len(ys) > 1 else "k", ms=4)
                ax.annotate(f"{r[key]:.2f}", (r[x], r[y]), fontsize=6, xytext=(2, 2), textcoords="offset points")
            else:
                ax.plot(r[x], r[y], "x", color="r", ms=7)
        ax.set_xlabel(x)
        ax.set_ylabel(y)

    def curve(ax, name, x, key, label, **style):
        rows = sorted(results.ok(name), key=lambda r: r[x])
        ax.plot([r[x] for r in rows], [r[key] for r in rows], "-o", ms=4, label=label, **style)
        saddles = [r for r in rows if results.on_saddle(r)]
        ax.plot([r[x] for r in saddles], [r[key] for r in saddles], "o", mfc="none", mec="r", ms=9)
        for r in results.maps.get(name, []):
            if r["status"] != "ok":
                ax.axvline(r[x], color="r", lw=0.6, ls=":")

    from bcfem.plots import pyplot

    plt = pyplot()
    written = []

    def plain_log(ax):
        """A log y axis labelled with plain numbers."""
        from matplotlib.ticker import NullFormatter, ScalarFormatter

        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(ScalarFormatter())
        ax.yaxis.set_minor_formatter(NullFormatter())

    def save(fig, filename):
        fig.tight_layout()
        io.save_figure(fig, results.run.out / filename, results.run.comm)
        plt.close(fig)
        written.append(filename)

    # Fig. 7.9
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.3))
    contour(a, "fig7_9", "alpha", "beta", "F_tilde", r"$\tilde F$", lines=[(0.8, "-")])
    plain_log(a)
    a.set_title(r"(a) $\tilde F$ at full closure; black: $\tilde F = 0.8$ ('good' above)", fontsize=9)
    for beta in sorted({r["beta"] for r in results.ok("fig7_9")}):
        rows = sorted((r for r in results.ok("fig7_9") if r["beta"] == beta), key=lambda r: r["alpha"])
        b.plot([r["alpha"] for r in rows], [r["preload"] for r in rows], "-o", ms=4, label=rf"$\beta$ = {beta:g}")
    b.plot([1.0], [results.dissertation["fig7_9b_eps_m_hemisphere"]], "k*", ms=10, label="dissertation, hemisphere")
    b.set_xlabel(r"$\alpha = b/a$")
    b.set_ylabel(r"$\varepsilon_m$")
    b.legend(fontsize=7)
    b.grid(alpha=0.3)
    b.set_title(r"(b) minimum preload for closure $\varepsilon_m$ (independent of $\beta$)", fontsize=9)
    save(fig, "fig7_9.png")

    # Figs. 7.10 and 7.12: frames
    def frames(cases, columns, title, filename, extent):
        fig, axes = plt.subplots(len(cases), len(columns), figsize=(2.3 * len(columns), 2.4 * len(cases)),
                                 squeeze=False)
        for axrow, (label, (summary, rec)) in zip(axes, cases):
            for ax, (stage, which) in zip(axrow, columns):
                state = which(rec) if callable(which) else crater_frames.nearest(rec.states, stage, which)
                crater_frames.draw(ax, rec, state, extent, text=f"{stage} $\\varepsilon$={state['eps']:.3f}")
                ax.set_xticks([])
                ax.set_yticks([])
            axrow[0].set_ylabel(label, fontsize=8)
        fig.suptitle(title, fontsize=10)
        save(fig, filename)

    grid_7_10 = results.shape_grid_7_10 + results.quick_shapes["7_10"]
    tried_7_10 = list(results.shapes_7_10) + [key for key in results.failed_shapes if key in grid_7_10]
    if tried_7_10:  # rows: beta, columns: alpha
        alphas = sorted({a for a, _ in tried_7_10})
        betas = sorted({b for _, b in tried_7_10})
        fig, axes = plt.subplots(len(betas), len(alphas), figsize=(2.6 * len(alphas), 2.5 * len(betas)),
                                 squeeze=False)
        for alpha, beta in tried_7_10:
            ax = axes[betas.index(beta), alphas.index(alpha)]
            if (alpha, beta) in results.shapes_7_10:
                summary, rec = results.shapes_7_10[(alpha, beta)]
                crater_frames.draw(ax, rec, rec.states[-1], 8.0,
                                   text=f"α={alpha:g}, β={beta:g}\nF~={summary['F_tilde']:.2f}")
            else:  # a failed cycle keeps its panel, with the reason
                ax.text(0.5, 0.5, f"α={alpha:g}, β={beta:g}\nno result:\n"
                        + textwrap.fill(str(results.failed_shapes[(alpha, beta)]), 34),
                        transform=ax.transAxes, ha="center", va="center", fontsize=6, color="tab:red")
            ax.set_xticks([])
            ax.set_yticks([])
        fig.suptitle("Fig. 7.10: craters after complete unloading from full closure (dotted: at rest)", fontsize=10)
        save(fig, "fig7_10.png")
    if results.types_7_12:
        def unloading_frame(fraction):
            def pick(rec):
                part = [s for s in rec.states if s["stage"] == "unload"]
                return part[min(len(part) - 1, int(fraction * (len(part) - 1)))]
            return pick

        cases = [(f"({tag}) α'={results.type_grid_7_12[tag][0]:g}, β'={results.type_grid_7_12[tag][1]:g}\n"
                  f"F~={s['F_tilde']:.2f}, "
                  f"{s['stability']}", (s, rec)) for tag, (s, rec) in results.types_7_12.items()]
        frames(cases, [("load", 0.0), ("load", 0.2), ("load", lambda rec: [s for s in rec.states
                                                                            if s["stage"] == "load"][-1]),
                       ("unload", unloading_frame(0.33)), ("unload", unloading_frame(0.67)),
                       ("unload", lambda rec: rec.states[-1])],
               "Fig. 7.12: reinforced hemispheres (α = β = 1): ε = 0, 0.2, ε_m, unloading, zero force "
               "(red: the layer)", "fig7_12.png", 8.0)

    # Fig. 7.11
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.3))
    for r in results.maps.get("fig7_11b", []):
        colour = STABILITY_COLOURS.get(r.get("stability_waves"), "0.6")
        a.scatter(r["layer_thickness"], r["layer_stiffness"], s=260, c=colour, marker="s" if r["status"] == "ok"
                  else "x")
        if results.on_saddle(r):
            a.scatter(r["layer_thickness"], r["layer_stiffness"], s=420, marker="s", facecolors="none",
                      edgecolors="r", linewidths=1.5)
        if results.still_open("fig7_11b", r):
            a.scatter(r["layer_thickness"], r["layer_stiffness"], s=620, marker="s", facecolors="none",
                      edgecolors="orange", linewidths=1.5)
        if r["status"] == "ok":
            a.annotate(f"{r['F_tilde']:.2f}", (r["layer_thickness"], r["layer_stiffness"]), ha="center",
                       va="center", fontsize=6.5, color="w", weight="bold" if r["F_tilde"] > 1 else "normal")
    low, high = results.dissertation["fig7_11b_F_above_1"]["layer_thickness"], \
        results.dissertation["fig7_11b_F_above_1"]["layer_stiffness"]
    a.add_patch(plt.Rectangle((low[0], high[0]), low[1] - low[0], high[1] - high[0], fill=False, ec="gold", lw=2))
    for label, colour in STABILITY_COLOURS.items():
        a.scatter([], [], c=colour, marker="s", label=label)
    a.plot([], [], color="gold", lw=2, label="dissertation: F~ > 1")
    a.scatter([], [], s=80, marker="s", facecolors="none", edgecolors="r", label="ends on a saddle")
    a.scatter([], [], s=80, marker="s", facecolors="none", edgecolors="orange",
              label=f"open at eps = {crater.MAX_CLOSURE_PRELOAD}")
    plain_log(a)
    a.set_xlabel(r"$\alpha' = t/a$")
    a.set_ylabel(r"$\beta' = \mu_l/\mu$")
    a.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    a.set_title(r"(b) symmetry breaking ($n$ = 1..20) at $\alpha = \beta = 1$ (numbers: $\tilde F$, bold > 1)",
                fontsize=9)
    curve(b, "fig7_11c", "alpha", "F_tilde", r"reinforced $\alpha'$ = 0.03, $\beta'$ = 30")
    plain = sorted((r for r in results.ok("fig7_9") if r["beta"] == 1.0), key=lambda r: r["alpha"])
    b.plot([r["alpha"] for r in plain], [r["F_tilde"] for r in plain], "-s", ms=4, label="unreinforced")
    peak = results.dissertation["fig7_11c_peak"]
    b.plot([peak["alpha"]], [peak["F_tilde"]], "k*", ms=10, label="dissertation peak")
    opt = results.dissertation["fig7_9_optimum_beta1"]
    b.plot([opt["alpha"]], [opt["F_tilde"]], "k^", ms=8, label="dissertation unreinforced optimum")
    b.set_xlabel(r"$\alpha$")
    b.set_ylabel(r"$\tilde F$ (full closure, $\beta = 1$)")
    b.legend(fontsize=7)
    b.grid(alpha=0.3)
    b.set_title("(c) reinforced against unreinforced", fontsize=9)
    save(fig, "fig7_11.png")

    # Fig. 8.4
    fig, axes = plt.subplots(1, 4, figsize=(15, 3.6))
    for ax, (key_of, label) in zip(axes, [(lambda r: 1 - r["V2_over_V0"], r"$(V_0 - V_2)/V_0$"),
                                          (lambda r: 1 - r["p2_over_pa"], r"$-\Delta p/p_a$"),
                                          (lambda r: r["A2_over_A0"], r"$A_2/A_0$"),
                                          (lambda r: r["F_tilde"], r"$\tilde F$")]):
        for name, style in (("fig8_4_air", "-s"), ("fig8_4", "-o")):
            rows = sorted(results.ok(name), key=lambda r: r["preload"])
            ax.plot([r["preload"] for r in rows], [key_of(r) for r in rows], style, ms=4,
                    label="air" if name.endswith("air") else "liquid")
        ax.axvline(results.dissertation["fig8_4_liquid_eps_c"], color="C1", ls="--", lw=1)
        ax.set_xlabel(r"$\varepsilon$")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Fig. 8.4: hemisphere, air against liquid (dashed: the dissertation's non-axisymmetric "
                 "liquid $\\varepsilon_c$ = 0.33)", fontsize=10)
    save(fig, "fig8_4.png")

    # Figs. 8.6b and 8.7
    fig, axes = plt.subplots(2, 3, figsize=(15, 8.2))
    contour(axes[0, 0], "fig8_6b", "alpha", "preload", "F_hat", r"$\hat F$")
    axes[0, 0].set_title(r"8.6b: $\hat F(\alpha, \varepsilon)$, unreinforced", fontsize=9)
    curve(axes[0, 1], "fig8_7b_plain", "alpha", "F_hat", "unreinforced")
    curve(axes[0, 1], "fig8_7b_layer", "alpha", "F_hat", r"$\alpha'$ = 0.03, $\beta'$ = 30")
    for kind, marker in (("plain", "k^"), ("layer", "k*")):
        p = results.dissertation["fig8_7b_peaks"][kind]
        axes[0, 1].plot([p["alpha"]], [p["F_hat"]], marker, ms=9, label=f"dissertation peak ({kind})")
    axes[0, 1].set_xlabel(r"$\alpha$")
    axes[0, 1].set_ylabel(r"$\hat F$")
    axes[0, 1].legend(fontsize=7)
    axes[0, 1].grid(alpha=0.3)
    axes[0, 1].set_title(r"8.7b: $\varepsilon$ = 0.25", fontsize=9)
    contour(axes[0, 2], "fig8_7c", "alpha", "preload", "F_hat", r"$\hat F$")
    axes[0, 2].set_title(r"8.7c: $\alpha'$ = 0.03, $\beta'$ = 30", fontsize=9)
    contour(axes[1, 0], "fig8_7d", "alpha", "preload", "F_hat", r"$\hat F$")
    axes[1, 0].set_title(r"8.7d: $\alpha'$ = 0.05, $\beta'$ = 100", fontsize=9)
    for ax, name, group, fixed in ((axes[1, 1], "fig8_7e", "layer_thickness", r"$\varepsilon$ = 0.4"),
                                   (axes[1, 2], "fig8_7f", "preload", r"$\alpha'$ = 0.05")):
        for value in sorted({r[group] for r in results.ok(name)}):
            rows = sorted((r for r in results.ok(name) if r[group] == value), key=lambda r: r["layer_stiffness"])
            ax.plot([r["layer_stiffness"] for r in rows], [r["F_hat"] for r in rows], "-o", ms=4,
                    label=f"{group} = {value:g}")
        ax.set_xscale("log")
        ax.set_xlabel(r"$\beta'$")
        ax.set_ylabel(r"$\hat F$")
        ax.grid(alpha=0.3)
        if ax.lines:
            ax.legend(fontsize=7)
        ax.set_title(f"8.7{'e' if name.endswith('e') else 'f'}: hemisphere, {fixed}", fontsize=9)
    fig.suptitle(r"Liquid-filled craters: $\hat F = -\Delta p A_2/(\mu A_0)$ (0 where the crater closed on "
                 "loading, eq. 8.8)", fontsize=10)
    save(fig, "fig8_6_8_7.png")
    results.run.report("wrote " + ", ".join(str(results.run.out / f)
                                            for f in written + ["crater_design.csv", "summary.json"]))
