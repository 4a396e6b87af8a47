"""Accuracy against wall time of the three-dimensional blister: the circle, clamped,
neo-Hookean, alpha = 0, whose P_max is known from the axisymmetric scene.

The reference is blister-rigid's P_max on P2 meshes of 800 and 1600 cells, extrapolated
(h^4). Each 3-D case is ``bcfem run blister-3d --v-max 1`` on 1 or 2 ranks over element sizes
and displacement degrees; its wall time is the run's own (summary.json), meshing and JIT
included. Writes ``docs/benchmarks/blister-3d.{csv,json,md,png}``; the report is
``benchmarks/templates/blister-3d.md`` filled from the CSV and the JSON.

Run from the repository root: ``.venv/bin/python benchmarks/blister_3d.py`` (about 5 min);
``--render-only`` renders the report again from the CSV and JSON that are there.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from pathlib import Path

from common import (
    ROOT,
    atomic_text,
    csv_text,
    loadavg,
    mpirun_bcfem,
    provenance,
    provenance_note,
    render,
    render_again,
    richardson,
    save_figure,
    table,
    wait_idle,
    write_report,
    write_summary,
)

OUT = ROOT / "docs" / "benchmarks"
SIZES = {1: [0.4, 0.2, 0.1, 0.05], 2: [0.4, 0.2, 0.1, 0.05], 3: [0.4, 0.2, 0.1]}
RANKS = (1, 2)
COLUMNS = ["degree", "size", "ranks", "dofs", "P_max", "error", "wall_time_s", "V_at_max"]


def axisymmetric_reference() -> float:
    """P_max of blister-rigid (neo-Hookean, alpha = 0), Richardson from 800 and 1600 P2 cells."""
    from mpi4py import MPI

    import bcfem  # noqa: F401
    from bcfem.run.trace import branch_of
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


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report: the template filled with the rows (CSV) and the summary (JSON)."""
    def rate(row):
        previous = next((r for r in rows if r["degree"] == row["degree"] and r["ranks"] == row["ranks"]
                         and r["size"] == 2 * row["size"]), None)
        return f"{math.log2(previous['error'] / row['error']):.2f}" if previous and row["error"] > 0 else ""

    columns = [("degree", "{degree}"), ("size / R0", "{size:g}"), ("ranks", "{ranks}"), ("dofs", "{dofs}"),
               ("P_max", "{P_max:.7f}"), ("relative error", "{error:.2e}"), ("observed rate", rate),
               ("wall time [s]", "{wall_time_s:.1f}")]
    return render("blister-3d.md", rows, summary, table=table(rows, columns), provenance=provenance_note(summary))


def figure(rows: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--render-only", action="store_true",
                        help="render blister-3d.md again from the blister-3d.csv and .json that are there")
    if parser.parse_args().render_only:
        render_again("blister-3d", report)
        return
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
    summary = {"reference": reference, "machine": f"{load} (times on a busy machine are upper bounds)",
               "provenance": provenance()}
    atomic_text(OUT / "blister-3d.csv", csv_text(rows, COLUMNS))
    write_summary("blister-3d", summary)
    write_report(OUT / "blister-3d.md", report(rows, summary))
    figure(rows)


if __name__ == "__main__":
    main()
