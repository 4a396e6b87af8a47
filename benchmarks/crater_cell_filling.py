"""The suction of a crater array against its area filling factor (scene ``crater-cell``).

F~ per crater and per unit area (F~ x F) at zero platen force after a cycle to the preload
0.1, for the hemisphere (the experiment's a = 6.35 mm, H = 35.13 mm, beta = 0.467), on the
square and hexagonal lattices with air and a liquid, from the sparse
limit (d = 8a) towards close packing; the isolated crater in a wide specimen
(``bcfem run crater --specimen-radius 101.6``) is the F -> 0 reference. One core, the
scene's default mesh (size-wall 0.3, size-rim 0.1, size-far 0.8: at d = 8a, F~ within 0.1 % of
the isolated crater in a wide specimen).

Usage (from the repository root; about 10 min on one free core)::

    .venv/bin/python benchmarks/crater_cell_filling.py

Writes ``docs/figures/crater_cell/filling.{csv,png}``.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

from mpi4py import MPI

from bcfem.run.runner import SolveError
from bcfem.scenes import crater, crater_cell

OUT = Path(__file__).resolve().parent.parent / "docs" / "figures" / "crater_cell"
PRELOAD = 0.1
CASES = [("square", "air", f) for f in (math.pi / 64, 0.1, 0.2, 0.35, 0.5, 0.65)] \
    + [("square", "liquid", f) for f in (math.pi / 64, 0.2, 0.5)] \
    + [("hexagonal", fluid, f) for fluid in ("air", "liquid") for f in (0.2, 0.5, 0.8)]
COLUMNS = ["lattice", "fluid", "filling", "spacing_over_a", "status", "F_tilde", "F_tilde_area", "p2_over_pa",
           "V1_over_V0", "A2_over_A0", "lateral_strain_at_preload", "platen_force_at_preload", "dofs",
           "wall_time_s"]


def main() -> None:
    rows = []
    for fluid in ("air", "liquid"):
        _, isolated = crater.solve(crater.Params(preload=PRELOAD, fluid=fluid, surface_energy=0.0, self_contact=0.0,
                                                 specimen_radius=101.6), MPI.COMM_WORLD)
        rows.append({"lattice": "isolated", "fluid": fluid, "filling": 0.0, "status": "ok",
                     **{k: isolated[k] for k in ("F_tilde", "p2_over_pa", "V1_over_V0", "A2_over_A0", "dofs",
                                                 "wall_time_s")}, "F_tilde_area": 0.0})
    for lattice, fluid, filling in CASES:
        params = crater_cell.Params(lattice=lattice, fluid=fluid, filling=filling, preload=PRELOAD)
        try:
            _, summary = crater_cell.solve(params, MPI.COMM_WORLD)
        except SolveError as err:
            summary = {**err.run.summary, "F_tilde": None}
        row = {"lattice": lattice, "fluid": fluid, "filling": filling,
               "spacing_over_a": params.geometry().spacing / params.crater_radius,
               "status": summary["status"] if summary.get("error") is None else f"failed: {summary['error']}"}
        row.update({k: summary.get(k) for k in COLUMNS if k not in row})
        if isinstance(row["lateral_strain_at_preload"], list):
            row["lateral_strain_at_preload"] = row["lateral_strain_at_preload"][0]
        rows.append(row)
        print(row, flush=True)
    if MPI.COMM_WORLD.rank:
        return
    OUT.mkdir(parents=True, exist_ok=True)
    with open(OUT / "filling.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, COLUMNS, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    plot(rows)


def plot(rows) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, axa) = plt.subplots(1, 2, figsize=(9, 3.4))
    for (lattice, fluid), style in ((("square", "air"), "-o"), (("square", "liquid"), "--s"),
                                    (("hexagonal", "air"), ":^"), (("hexagonal", "liquid"), "-.v")):
        part = [r for r in rows if r["lattice"] == lattice and r["fluid"] == fluid and r["F_tilde"] is not None]
        F = [r["filling"] for r in part]
        ax.plot(F, [r["F_tilde"] for r in part], style, ms=4, label=f"{lattice}, {fluid}")
        axa.plot(F, [r["F_tilde_area"] for r in part], style, ms=4, label=f"{lattice}, {fluid}")
    for r in rows:
        if r["lattice"] == "isolated":
            ax.axhline(r["F_tilde"], color="0.6", lw=0.8, ls="-" if r["fluid"] == "air" else "--")
    ax.set_xlabel("filling factor F = πa²/cell area")
    ax.set_ylabel("F~ per crater = (1 - p) A2/A0")
    axa.set_xlabel("filling factor F")
    axa.set_ylabel("suction per area / p_a = F~ F")
    ax.legend(fontsize=7)
    ax.set_title(f"crater-cell, hemisphere, preload {PRELOAD} (grey: isolated)", fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "filling.png", dpi=150)


if __name__ == "__main__":
    main()
