"""Figures 7.5b, 7.6 and 7.7a of demos/crater_air.py: the air crater's suction cycle."""

import numpy as np

from bcfem import io
from bcfem.scenes.crater import frames as crater_frames
from bcfem.theory.crater import eshelby_air as eshelby

SHAPE_LOAD = [0.0, 0.1, 0.2, 0.25, 0.3]  # loading states drawn (nearest accepted step), up to the preload
SHAPE_PANELS_UNLOAD = 5  # unloading states drawn, from the preload to zero platen force
EVENT_STYLE = {"stability": dict(marker="o", ms=11, mfc="none", mec="C1", mew=1.4, ls="none"),
               "snap": dict(marker="x", ms=9, color="C3", mew=1.6, ls="none")}

def draw(results) -> None:
    """Draw and save Figures 7.5b, 7.6 and 7.7a (rank 0) from the demo's ``Results``."""

    def marks(ax, key_of, with_labels):
        def label(text):
            return text if with_labels else None

        for kind, style in EVENT_STYLE.items():
            hit = [r for r in results.ok if any(e["kind"] == kind for e in r["events"])]
            ax.plot([r["preload"] for r in hit], [key_of(r) for r in hit], **style,
                    label=label(f"cycle reported {'an instability' if kind == 'stability' else 'a snap'}"))
        if results.loading_instability:
            ax.plot([d["eps"] for d in results.loading_instability], [0.015] * len(results.loading_instability), "^",
                    color="C1", ms=6,
                    transform=ax.get_xaxis_transform(), clip_on=False,
                    label=label("first unstable mode on loading (one per cycle)"))
        if "bracket" in results.closure:
            ax.axvspan(*results.closure["bracket"], color="C2", alpha=0.25, lw=0)
            ax.axvline(results.closure["first_closed"], color="C2", ls=":", lw=1.5,
                       label=label(f"ours: closure, first $V_1 = 0$ at $\\varepsilon$ = {results.closure['first_closed']:.3f}"))
        ax.axvline(results.dissertation["eps_c"], color="0.3", ls="--", lw=1,
                   label=label(f"dissertation: $\\varepsilon_c$ = {results.dissertation['eps_c']} (non-axisymmetric)"))
        ax.axvline(results.dissertation["eps_closure"], color="0.6", ls="--", lw=1,
                   label=label(f"dissertation: closure at $\\varepsilon$ = {results.dissertation['eps_closure']}"))
        ax.set_xlim(0, 0.5)
        ax.set_xlabel(r"preload $\varepsilon = -\Delta L/L$")
        ax.grid(alpha=0.3)

    from bcfem.plots import pyplot

    plt = pyplot()
    eps = [r["preload"] for r in results.ok]
    left_out = ", ".join(f"{f['preload']:g}" for f in results.failed)
    grid_note = f"{len(results.ok)} preloads" + (f"; failed, left out: {left_out}" if results.failed else "")

    # Fig. 7.6
    PANELS = [(lambda r: 1 - r["V2_over_V0"], r"$(V_0 - V_2)/V_0$"),
              (lambda r: 1 - r["p2_over_pa"], r"$-\Delta p/p_a = 1 - p_2/p_a$"),
              (lambda r: r["A2_over_A0"], r"$A_2/A_0$"),
              (lambda r: r["F_tilde"], r"$\tilde F = F/(p_a A_0)$")]
    fig, axes = plt.subplots(2, 2, figsize=(10.5, 8.0))
    for ax, (key_of, ylabel), tag in zip(axes.flat, PANELS, "abcd"):
        ax.plot(eps, [key_of(r) for r in results.ok], "-s", color="C0", ms=4, label="this model (axisymmetric FE)")
        marks(ax, key_of, with_labels=tag == "a")
        ax.set_ylabel(ylabel)
        ax.set_ylim(0, 1.05 * max(1e-3, max(key_of(r) for r in results.ok)))
        ax.text(0.97, 0.06, f"({tag})", transform=ax.transAxes, ha="right", fontweight="bold")
    axes[0, 1].set_ylim(0, 1.05)
    axes[0, 1].axhline(results.dissertation["dp_c_over_pa"], color="0.3", ls="--", lw=1)
    axes[0, 1].text(0.02, results.dissertation["dp_c_over_pa"] + 0.015, r"$-\Delta p_c = 0.83\,p_a$ (dissertation)",
                    fontsize=8, color="0.3")
    fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.suptitle(f"Air crater (hemisphere, a = {results.base.crater_radius} mm, $\\mu/p_a$ = {results.base.beta:.3f}): end of the "
                 f"suction cycle against the preload\n({grid_note}; dissertation Fig. 7.6)", fontsize=10)
    fig.tight_layout(rect=(0, 0.09, 1, 1))
    io.save_figure(fig, results.run.out / "fig7_6.png", results.run.comm)
    plt.close(fig)

    # Fig. 7.7a, and beside it the ratio to eq. 7.12
    fig, (ax, ratio) = plt.subplots(1, 2, figsize=(11.5, 5.0), gridspec_kw={"width_ratios": [1.25, 1]})
    fine = np.linspace(0, 0.5, 201)
    ax.plot(fine, [eshelby(e, results.base.beta) for e in fine], "k--", lw=1.3, label="linear (Eshelby), eq. 7.12")
    ax.plot(eps, [r["F_tilde"] for r in results.ok], "-s", color="C0", ms=4, label="simulation (this model)")
    marks(ax, lambda r: r["F_tilde"], with_labels=True)
    ax.set_ylim(0, 1.05 * max(r["F_tilde"] for r in results.ok))
    ax.set_ylabel(r"$\tilde F = F/(p_a A_0)$")
    ax.legend(fontsize=7, loc="upper left", framealpha=0.95)
    ax.set_title(f"(a) suction force against preload (dissertation Fig. 7.7a); {grid_note}", fontsize=9)
    done_large = [r for r in results.large if r["status"] == "ok"]
    ratio.axhline(1.0, color="k", ls="--", lw=1.3, label="eq. 7.12")
    ratio.plot(eps, [r["F_tilde"] / eshelby(r["preload"], results.base.beta) for r in results.ok], "-s", color="C0", ms=4,
               label=f"experiment's specimen ({results.base.specimen_radius} x {results.base.specimen_height} mm, "
                     f"$\\gamma/\\mu a$ = {results.base.surface_energy:g})")
    ratio.plot([r["preload"] for r in done_large],
               [r["F_tilde"] / eshelby(r["preload"], results.large_params.beta) for r in done_large],
               "o", mfc="none", mec="k", ms=7, mew=1.3,
               label=f"large specimen ({results.large_params.specimen_radius} x {results.large_params.specimen_height} mm, $\\gamma$ = 0)")
    SMALL = 0.2  # the panel's range of preloads
    shown = [r["F_tilde"] / eshelby(r["preload"], results.base.beta) for r in results.ok if r["preload"] <= SMALL] + \
        [r["F_tilde"] / eshelby(r["preload"], results.large_params.beta) for r in done_large] + [1.0]
    ratio.set_xlim(0, SMALL)
    ratio.set_ylim(min(shown) - 0.05, max(shown) + 0.05)
    ratio.set_xlabel(r"preload $\varepsilon = -\Delta L/L$")
    ratio.set_ylabel(r"$\tilde F / \tilde F_{7.12}$")
    ratio.grid(alpha=0.3)
    ratio.legend(fontsize=7, loc="upper left", framealpha=0.95)
    ratio.set_title("(b) small preloads, ratio to eq. 7.12: the large specimen tends to it as "
                    "$\\varepsilon \\to 0$", fontsize=9)
    fig.suptitle(f"Air crater, hemisphere a = {results.base.crater_radius} mm, $\\mu/p_a$ = {results.base.beta:.3f}", fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "fig7_7a.png", results.run.comm)
    plt.close(fig)

    # Fig. 7.5b
    loading = [s for s in results.shape.states if s["stage"] == "load"]
    unloading = [s for s in results.shape.states if s["stage"] == "unload"]
    targets = np.linspace(results.shape_preload, unloading[-1]["eps"], SHAPE_PANELS_UNLOAD)
    drawn = [[crater_frames.nearest(results.shape.states, "load", e) for e in SHAPE_LOAD if e <= results.shape_preload],
             [loading[-1]] + [crater_frames.nearest(results.shape.states, "unload", e) for e in targets[1:-1]]
             + [unloading[-1]]]
    ncol = max(len(r) for r in drawn)
    fig, axes = plt.subplots(2, ncol, figsize=(3.0 * ncol, 6.8), sharex=True, sharey=True)
    for i, (states, name) in enumerate(zip(drawn, ("loading, vent open", "unloading, sealed"))):
        for j, s in enumerate(states):
            ax = axes[i, j]
            text = f"$\\varepsilon$ = {s['eps']:.3f}\n$V/V_0$ = {s['V_over_V0']:.3f}"
            if i == 1:
                text += f"\n$p/p_a$ = {s['p_over_pa']:.3f}"
            if i == 1 and j == len(states) - 1:
                text += f"\nzero force: $\\tilde F$ = {s['F_tilde']:.3f}"
            crater_frames.draw(ax, results.shape, s, extent=10.0, text=text)
            ax.set_xticks([0, 5, 10])
            if j == 0:
                ax.set_ylabel(f"{name}\nz [mm]")
            if i == 1:
                ax.set_xlabel("r [mm]")
        for ax in axes[i, len(states):]:
            ax.set_visible(False)
    fig.suptitle(f"Deformed cross-section near the crater, one cycle at preload $\\varepsilon$ = {results.shape_preload} "
                 f"(dissertation Fig. 7.5b; a = {results.base.crater_radius} mm)\nblue: crater wall, dotted: wall at rest, "
                 "black: the plate; grey: the specimen's mesh"
                 + (" (P1 interpolation of the P2 displacement)" if results.base.element == "p2p1" else ""), fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, results.run.out / "fig7_5b.png", results.run.comm)
    plt.close(fig)
    results.run.report("wrote " + ", ".join(str(results.run.out / f) for f in
                                            ("fig7_6.png", "fig7_7a.png", "fig7_5b.png", "crater_air.csv",
                                             "summary.json")))
