"""Figs. 4.8-4.10: delamination of the adhesive edge on a soft substrate (stiffness ratio 2).

At the dissertation's parameters, mu_s R0/(mu_f t0) = 2 with gamma_l = gamma_ls = 0.5 mu_f t0
and dgamma = 0, neo-Hookean membrane, L = 10, default mesh, one process:

* P, contact angle and central deflection z_f(0)/R0 against V/V0 (Fig. 4.8a-c) of
  the bonded edge (R1 = R0 throughout) and the adhesive edge (the front released at the
  onset, then dPi/dR1 = 0) traced to V/V0 = 3;
  The start at the default V/V0 = 0.05 fails (the contact line is dragged inwards and the
  free membrane is compressed), so each soft branch begins where the scene's start traced
  back to (``branch_start`` in ``fig4_8.json``); the bonded branch is started at V/V0 = 0.3
  (the default start's step control stalls at a singular point near V/V0 = 2.70, which a
  start at 0.3 steps across); a branch that still fails is drawn as far as it converged;
* the rigid substrate (``blister-rigid``, clamped and adhesive with adhesion
  gamma_ls - dgamma = 0.5);
* the dissertation's method: models held at R1/R0 = 1.2, 1.4, ..., 2.2, each traced until
  its release rate -dPi/dR1 reaches zero (the hollow circles of Fig. 4.8, the frames of
  Fig. 4.9);
* the onset found again from the free energies of two held models at fixed V
  (:func:`bcfem.scenes.blister_soft.onset.onset_by_energy`).

Usage (from the repository root)::

    .venv/bin/python benchmarks/blister_soft_delamination.py      # ~10 min on one core

Writes ``docs/figures/blister_soft/`` ``fig4_8.{csv,json,png}``, ``fig4_9.png`` and
``fig4_10.png``.
"""

from __future__ import annotations

import json
import sys
import time

import dolfinx_solver  # noqa: F401  (before dolfinx / petsc4py)
from mpi4py import MPI

from blister_soft import FIGURES, profiles
from common import atomic_text, csv_text, save_figure

RATIO = 2.0
V_MAX = 3.0
TENSIONS = {"alpha": 0.5, "gamma_ls": 0.5, "delta_gamma": 0.0}  # Fig. 4.8's
BONDED_START = 0.3
HELD = (1.2, 1.4, 1.6, 1.8, 2.0, 2.2)
KEYS = ("V_over_V0", "P", "aspect", "contact_angle_deg", "indentation", "r1_over_R0", "R1_over_R0", "z_apex",
        "J_min", "compressed_fraction")


def rows_of(branch, model: str) -> list[dict]:
    """The branch's rows; z_apex is the apex height over R0 (the rigid scene's ``aspect``)."""
    rows = [{"model": model, **{k: float(r[k]) for k in KEYS if k in r}} for r in branch.rows]
    for row in rows:
        row.setdefault("z_apex", row["aspect"])
    return rows


def soft(edge: str, **extra):
    from bcfem.scenes import blister_soft

    params = blister_soft.Params(edge=edge, stiffness_ratio=RATIO, v_max=V_MAX, **TENSIONS, **extra)
    return blister_soft.build(params, MPI.COMM_SELF)


def traced(scene) -> tuple:
    """The branch and a note: None, or why it ends before V_MAX (its converged part is kept)."""
    from bcfem.path.continuation import ContinuationError
    from bcfem.run.trace import branch_of

    try:
        return branch_of(scene), None
    except ContinuationError as err:
        return err.branch, str(err)


def main() -> None:
    from bcfem.run.trace import branch_of
    from bcfem.scenes import blister_rigid
    from bcfem.scenes.blister_soft.onset import critical_point, onset_by_energy

    t0 = time.perf_counter()
    bonded = soft("bonded", v_start=BONDED_START)
    branch, bonded_end = traced(bonded)
    rows = rows_of(branch, "soft bonded")
    starts = {"bonded": bonded.start_report}
    adhesive = soft("adhesive")
    branch = branch_of(adhesive)
    starts["adhesive"] = adhesive.start_report
    rows += rows_of(branch, "soft adhesive")
    (event,) = branch.events
    onset = {k: float(event[k]) for k in KEYS if k in event}
    for edge in ("clamped", "adhesive"):
        params = blister_rigid.Params(material="neo-hookean", alpha=TENSIONS["alpha"], edge=edge,
                                      adhesion=TENSIONS["gamma_ls"] - TENSIONS["delta_gamma"], v_max=V_MAX)
        rigid = branch_of(blister_rigid.build(params, MPI.COMM_SELF))
        rows += rows_of(rigid, f"rigid {edge}")
        if edge == "adhesive":
            rigid_onset = {k: float(rigid.events[0][k]) for k in ("V_over_V0", "P")}
    by_energy = onset_by_energy(adhesive, (0.98 * onset["V_over_V0"], 1.02 * onset["V_over_V0"]))
    held = []
    for radius in HELD:
        row = critical_point(adhesive, radius)
        held.append({"R1_over_R0": radius, **{k: float(row[k]) for k in KEYS if k in row},
                     **profiles(adhesive.model, extent=3.0)})
    wall = time.perf_counter() - t0
    FIGURES.mkdir(parents=True, exist_ok=True)
    atomic_text(FIGURES / "fig4_8.csv", csv_text(rows, ["model", *KEYS]))
    summary = {"stiffness_ratio": RATIO, "tensions": TENSIONS, "branch_start": starts,
               "bonded_end": bonded_end, "J_min": min(r["J_min"] for r in rows if "J_min" in r), "onset_switch": onset,
               "onset_energy": by_energy, "onset_rigid": rigid_onset,
               "held": [{k: v for k, v in h.items() if k not in ("substrate", "membrane")} for h in held],
               "wall_time_s": wall}
    atomic_text(FIGURES / "fig4_8.json", json.dumps(summary, indent=1) + "\n")
    plot(rows, onset, rigid_onset, held)
    print(json.dumps(summary, indent=1))


def plot(rows, onset, rigid_onset, held) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    styles = {"soft bonded": ("k", "-"), "soft adhesive": ("r", "-"), "rigid clamped": ("k", "--"),
              "rigid adhesive": ("r", "--")}
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for model, (colour, line) in styles.items():
        part = [r for r in rows if r["model"] == model]
        v = [r["V_over_V0"] for r in part]
        for ax, key in zip(axes, ("P", "contact_angle_deg", "z_apex")):
            ax.plot(v, [r[key] for r in part], color=colour, ls=line, lw=1.2, label=model)
    for ax, key in zip(axes, ("P", "contact_angle_deg", "z_apex")):
        ax.plot([h["V_over_V0"] for h in held], [h[key] for h in held], "o", mfc="none", mec="r",
                label="held R1, dPi/dR1 = 0")
        ax.plot(onset["V_over_V0"], onset[key], "bD", label="onset (soft)")
        ax.set_xlabel("V/V0")
    axes[0].plot(rigid_onset["V_over_V0"], rigid_onset["P"], "bs", label="onset (rigid)")
    for ax, name in zip(axes, ("P = Δp R0/(μf t0)", "contact angle [deg]", "central deflection z_f(0)/R0")):
        ax.set_ylabel(name)
    axes[0].legend(fontsize=7)
    fig.suptitle("Fig. 4.8: μs R0/(μf t0) = 2, γl = γls = 0.5 μf t0, Δγ = 0", fontsize=10)
    fig.tight_layout()
    save_figure(fig, FIGURES / "fig4_8.png")
    fig, axes = plt.subplots(2, 3, figsize=(12, 5.5), sharex=True, sharey=True)
    for ax, h in zip(axes.flat, held):
        for part, style in (("substrate", "b-"), ("membrane", "r-")):
            xy = np.array(h[part])
            ax.plot(xy[:, 0], xy[:, 1], style, lw=1.2)
        ax.axhline(0.0, color="0.6", lw=0.6, ls="--")
        ax.set_aspect("equal")
        ax.set_title(f"R1/R0 = {h['R1_over_R0']:.1f}: V/V0 = {h['V_over_V0']:.2f}, r1/R0 = {h['r1_over_R0']:.2f}",
                     fontsize=8)
    fig.suptitle("Fig. 4.9: delaminating blister at μs R0/(μf t0) = 2 (dashed: undeformed top)", fontsize=10)
    fig.tight_layout()
    save_figure(fig, FIGURES / "fig4_9.png")
    fig, ax = plt.subplots(figsize=(5, 4))
    for model in ("soft bonded", "soft adhesive"):
        part = [r for r in rows if r["model"] == model]
        colour, line = styles[model]
        ax.plot([r["V_over_V0"] for r in part], [r["r1_over_R0"] for r in part], color=colour, ls=line, label=model)
    ax.plot([h["V_over_V0"] for h in held], [h["r1_over_R0"] for h in held], "o", mfc="none", mec="r",
            label="held R1, dPi/dR1 = 0")
    ax.plot(onset["V_over_V0"], onset["r1_over_R0"], "bo", label="onset")
    ax.set_xlabel("V/V0")
    ax.set_ylabel("contact line r1/R0")
    ax.legend(fontsize=8)
    ax.set_title("Fig. 4.10: μs R0/(μf t0) = 2", fontsize=10)
    fig.tight_layout()
    save_figure(fig, FIGURES / "fig4_10.png")


if __name__ == "__main__":
    sys.exit(main())
