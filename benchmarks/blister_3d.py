"""Accuracy against wall time of the three-dimensional blister: the circle, clamped,
neo-Hookean, alpha = 0, whose P_max is known from the axisymmetric scene.

The reference is blister-rigid's P_max on P2 meshes of 800 and 1600 cells, extrapolated
(h^4). Each 3-D case is ``bcfem run blister-3d --v-max 1`` on 1 or 2 ranks over element sizes
and displacement degrees; its wall time is the run's own (summary.json), meshing and JIT
included. Writes ``docs/benchmarks/blister-3d.{csv,md,png}``.

Run from the repository root: ``.venv/bin/python benchmarks/blister_3d.py`` (about 5 min).
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

from common import ROOT, atomic_text, csv_text, loadavg, mpirun_bcfem, richardson, save_figure, wait_idle

OUT = ROOT / "docs" / "benchmarks"
SIZES = {1: [0.4, 0.2, 0.1, 0.05], 2: [0.4, 0.2, 0.1, 0.05], 3: [0.4, 0.2, 0.1]}
RANKS = (1, 2)
COLUMNS = ["degree", "size", "ranks", "dofs", "P_max", "error", "wall_time_s", "V_at_max"]
COMMAND = "bcfem run blister-3d --size {size} --degree {degree} --v-max 1"


def axisymmetric_reference() -> float:
    """P_max of blister-rigid (neo-Hookean, alpha = 0), Richardson from 800 and 1600 P2 cells."""
    from mpi4py import MPI

    import bcfem  # noqa: F401
    from bcfem.run.runner import branch_of
    from bcfem.scenes import blister_rigid

    values = []
    for cells in (800, 1600):
        params = blister_rigid.Params(material="neo-hookean", alpha=0.0, cells=cells, v_max=1.0)
        branch = branch_of(blister_rigid.build(params, MPI.COMM_SELF))
        values.append(next(lp.values["P"] for lp in branch.limit_points if lp.kind == "max"))
    return richardson(values[0], values[1], 4)


def case(degree: int, size: float, ranks: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        mpirun_bcfem(["run", "blister-3d", "--size", str(size), "--degree", str(degree), "--v-max", "1",
                      "--quiet", "--no-plots", "--out", str(out)], ranks, quiet_stdout=True)
        summary = json.loads((out / "summary.json").read_text())
    top = next(lp for lp in summary["limit_points"] if lp["kind"] == "max")
    return {"degree": degree, "size": size, "ranks": ranks, "dofs": summary["dofs"], "P_max": top["P"],
            "wall_time_s": summary["wall_time_s"], "V_at_max": top["V_over_V0"]}


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    waited, busy = wait_idle(600)
    load = f"{busy:.1f} cores busy after {waited:.0f} s of waiting; load average {loadavg()}"
    reference = axisymmetric_reference()
    rows = []
    for degree, sizes in SIZES.items():
        for size in sizes:
            for ranks in RANKS:
                row = case(degree, size, ranks)
                row["error"] = abs(row["P_max"] - reference) / reference
                rows.append(row)
                print(row, flush=True)
    atomic_text(OUT / "blister-3d.csv", csv_text(rows, COLUMNS))

    lines = ["# blister-3d: P_max of the clamped circle against wall time", "",
             f"Reference: blister-rigid's P_max, neo-Hookean, alpha = 0, P2 on 800 and 1600 cells, "
             f"Richardson (h^4): **{reference:.9f}**. Each row: `{COMMAND}` on 1 or 2 ranks "
             "(`mpirun -n 2`); wall time from summary.json (meshing, JIT and the branch to V/V0 = 1). "
             f"Machine at the start: {load} (times on a busy machine are upper bounds).", "",
             "| degree | size / R0 | ranks | dofs | P_max | relative error | observed rate | wall time [s] |",
             "|---|---|---|---|---|---|---|---|"]
    for row in rows:
        previous = next((r for r in rows if r["degree"] == row["degree"] and r["ranks"] == row["ranks"]
                         and r["size"] == 2 * row["size"]), None)
        rate = (math.log2(previous["error"] / row["error"]) if previous and row["error"] > 0 else None)
        lines.append(f"| {row['degree']} | {row['size']:g} | {row['ranks']} | {row['dofs']} | {row['P_max']:.7f} "
                     f"| {row['error']:.2e} | {'' if rate is None else f'{rate:.2f}'} | {row['wall_time_s']:.1f} |")
    lines += ["", "Reproduce: `.venv/bin/python benchmarks/blister_3d.py`."]
    atomic_text(OUT / "blister-3d.md", "\n".join(lines) + "\n")

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for degree in SIZES:
        for ranks, style in zip(RANKS, ("-o", "--s")):
            series = [r for r in rows if r["degree"] == degree and r["ranks"] == ranks]
            ax.loglog([r["wall_time_s"] for r in series], [r["error"] for r in series], style,
                      label=f"P{degree}, {ranks} rank{'s' if ranks > 1 else ''}")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("relative error of P_max")
    ax.set_title("blister-3d, circle: error against wall time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    save_figure(fig, OUT / "blister-3d.png")


if __name__ == "__main__":
    main()
