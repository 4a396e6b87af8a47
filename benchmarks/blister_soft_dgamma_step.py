"""A step in the adhesion pins the debond front (dgamma(R), eq. 10.1 axisymmetric).

Fig. 4.5's tensions (gamma_l = gamma_ls = 0.5 mu_f t0), neo-Hookean membrane, stiffness ratio
mu_s R0/(mu_f t0) = 2, L = 10, default mesh, adhesive edge, one process:

* dgamma = step:1.1:0.5:0.1 (window w = 0.05 R0): the debonding cost gamma_l + gamma_ls - dgamma
  rises from 0.5 to 0.9 at R_s = 1.1 R0; against the uniform dgamma = 0.5 and 0.1 branches;
* the rigid substrate (``blister-rigid --edge adhesive``) with the same cost,
  adhesion = gamma_ls - dgamma = step:1.1:0:0.4, and its uniform 0 and 0.4 branches;
* the state where each step branch leaves the window (R1 = R_s + w/2), traced to it, against
  the uniform-outer branch traced to the same R1: the two energies are equal there, so are
  the states.

Usage (from the repository root)::

    .venv/bin/python benchmarks/blister_soft_dgamma_step.py      # ~3 min on one core

Writes ``docs/figures/blister_soft/`` ``dgamma_step.{csv,json,png}``.
"""

from __future__ import annotations

import json
import time

import dolfinx_solver  # noqa: F401  (before dolfinx / petsc4py)
from mpi4py import MPI

from blister_soft import FIGURES
from common import atomic_text, csv_text, save_figure

RATIO, V_MAX = 2.0, 1.0
R_S, WIDTH = 1.1, 0.05
SOFT = {"step": f"step:{R_S}:0.5:0.1:{WIDTH}", "inner": "0.5", "outer": "0.1"}  # dgamma
RIGID = {"step": f"step:{R_S}:0:0.4:{WIDTH}", "inner": "0", "outer": "0.4"}  # gamma_ls - dgamma
KEYS = ("V_over_V0", "P", "R1_over_R0", "r1_over_R0")


def soft(text: str, front: float | None = None):
    """The soft branch of dgamma ``text`` to V_MAX, or to R1 = ``front``."""
    from bcfem.radial_profile import parse
    from bcfem.run.trace import branch_of
    from bcfem.scenes import blister_soft

    params = blister_soft.Params(edge="adhesive", stiffness_ratio=RATIO, alpha=0.5, gamma_ls=0.5,
                                 delta_gamma=parse(text), v_max=V_MAX)
    scene = blister_soft.build(params, MPI.COMM_SELF)
    if front is not None:
        scene.end = lambda values: values["R1_over_R0"] - front
    return branch_of(scene)


def rigid(text: str, front: float = float("inf")):
    from bcfem.radial_profile import parse
    from bcfem.run.trace import branch_of
    from bcfem.scenes import blister_rigid

    params = blister_rigid.Params(material="neo-hookean", alpha=0.5, edge="adhesive", adhesion=parse(text),
                                  v_max=V_MAX, stop_radius=front)
    return branch_of(blister_rigid.build(params, MPI.COMM_SELF))


def main() -> None:
    t0 = time.perf_counter()
    rows, summary = [], {"stiffness_ratio": RATIO, "R_s": R_S, "width": WIDTH, "soft": SOFT, "rigid": RIGID}
    for model, cases, trace in (("soft", SOFT, soft), ("rigid", RIGID, rigid)):
        for case, text in cases.items():
            branch = trace(text)
            rows += [{"model": model, "case": case, **{k: float(r[k]) for k in KEYS}} for r in branch.rows]
            if case == "step":
                summary[f"{model}_onset"] = {k: float(branch.events[0][k]) for k in ("V_over_V0", "P")}
        leave = R_S + WIDTH / 2
        step, outer = (trace(cases[c], leave).rows[-1] for c in ("step", "outer"))
        arrive = next(r for r in rows if r["model"] == model and r["case"] == "step"
                      and r["R1_over_R0"] >= R_S - WIDTH / 2)
        summary[f"{model}_window"] = {
            "arrive": {k: arrive[k] for k in KEYS},
            "leave": {k: float(step[k]) for k in KEYS}, "outer_at_leave": {k: float(outer[k]) for k in KEYS},
            "leave_minus_outer": {k: float(step[k] - outer[k]) for k in ("V_over_V0", "P")}}
    summary["wall_time_s"] = time.perf_counter() - t0
    FIGURES.mkdir(parents=True, exist_ok=True)
    atomic_text(FIGURES / "dgamma_step.csv", csv_text(rows, ["model", "case", *KEYS]))
    atomic_text(FIGURES / "dgamma_step.json", json.dumps(summary, indent=1) + "\n")
    plot(rows, summary)
    print(json.dumps(summary, indent=1))


def plot(rows, summary) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"step": "r", "inner": "0.55", "outer": "b"}
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for model, line in (("soft", "-"), ("rigid", "--")):
        texts = SOFT if model == "soft" else RIGID
        for case, colour in colours.items():
            part = [r for r in rows if r["model"] == model and r["case"] == case]
            v = [r["V_over_V0"] for r in part]
            label = f"{model}, {'dgamma' if model == 'soft' else 'adhesion'} {texts[case]}"
            axes[0].plot(v, [r["P"] for r in part], color=colour, ls=line, lw=1.2, label=label)
            axes[1].plot(v, [r["R1_over_R0"] for r in part], color=colour, ls=line, lw=1.2, label=label)
        leave = summary[f"{model}_window"]["leave"]
        axes[0].plot(leave["V_over_V0"], leave["P"], "ko", mfc="none")
    axes[1].axhspan(R_S - WIDTH / 2, R_S + WIDTH / 2, color="r", alpha=0.12, label="the step's window")
    axes[0].set_ylabel("P = Δp R0/(μf t0)")
    axes[1].set_ylabel("R1/R0")
    for ax in axes:
        ax.set_xlabel("V/V0")
    axes[1].legend(fontsize=7)
    fig.suptitle(f"a step in the debonding cost at R = {R_S} R0 (0.5 to 0.9 μf t0) pins the front; "
                 f"stiffness ratio {RATIO:g} and rigid", fontsize=9)
    fig.tight_layout()
    save_figure(fig, FIGURES / "dgamma_step.png")


if __name__ == "__main__":
    main()
