"""What a cell's cycle draws: the crater's pressure, the suction force per crater and the
lateral strain against the platen strain, loading and unloading."""

from __future__ import annotations


def plot(rows, summary):
    """(p - p_a)/p_a, F_tilde and e_x against eps."""
    from bcfem.plots import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.3))
    loaded = [r for r in rows if r["stage"] == "load"]
    for stage, colour in (("load", "tab:red"), ("unload", "tab:blue")):
        part = loaded if stage == "load" else loaded[-1:] + [r for r in rows if r["stage"] == "unload"]
        if len(part) < 2:
            continue
        eps = [r["eps"] for r in part]
        for ax, key in zip(axes, ("p_over_pa", "F_tilde", "lateral_strain_x")):
            ax.plot(eps, [r[key] - (1 if key == "p_over_pa" else 0) for r in part], "-o", ms=2.5,
                    color=colour, label=stage)
    for ax, label in zip(axes, ("(p - p_a) / p_a", "F~ = (1 - p) A2/A0 per crater", "lateral strain e_x")):
        ax.set_xlabel("platen strain ε")
        ax.set_ylabel(label)
        ax.legend(fontsize=7)
    if summary["status"] == "ok":
        axes[1].set_title(f"F~ = {summary['F_tilde']:.4g} at zero platen force", fontsize=9)
    fig.suptitle(f"crater-cell: {summary['parameters'].get('lattice')} lattice, "
                 f"F = {summary['parameters'].get('filling'):.3g}", fontsize=10)
    fig.tight_layout()
    return fig
