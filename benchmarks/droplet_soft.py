"""Accuracy vs wall time of the linear wetting ridge (droplet-soft, ch. 5).

The ridge height u_z(r0) of the linear model at c = μ r0/((1-ν) γs) = 10, ν = 1/2,
γls = γs, against the Hankel solution of ``bcfem.theory.ridge`` (accurate to ~1e-14):

* a half-space, stood in for by a block 80 r0 wide and deep (its finite size shifts
  u_z(r0) by about 0.7 (r0/L)^3 ~ 1e-6 relative);
* a layer r0/h = 2 on a rigid base;

for P2-P1 and P3-P2 Taylor-Hood elements on meshes graded to the contact line
(``--size-contact 0.01``, ``--refine 0..3``: every element size halved), each run as
``mpirun -n 2 bcfem run droplet-soft`` with a warm JIT cache. The wall time is the whole
command's (Python start, meshing, assembly, solve, output) and the scene's own
``wall_time_s`` (the solve).

Usage (from the repository root)::

    .venv/bin/python benchmarks/droplet_soft.py           # the benchmark
    .venv/bin/python benchmarks/droplet_soft.py figures   # chapter 5's figures (serial, ~5 min)
    .venv/bin/python benchmarks/droplet_soft.py figures fig5_6cd   # one of them (names: FIGURES)

    .venv/bin/python benchmarks/droplet_soft.py --render-only   # droplet-soft.md from its CSV and JSON

Writes ``docs/benchmarks/droplet-soft.{csv,json,md,png}`` (the report is
``benchmarks/templates/droplet-soft.md`` filled from the CSV and JSON); ``figures`` writes Figs. 5.4-5.9's
counterparts and their numbers (``numbers.json``) into ``docs/figures/droplet_soft/``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import (
    ROOT,
    atomic_text,
    csv_text,
    fmt,
    loadavg,
    provenance,
    provenance_note,
    render,
    render_again,
    table,
    write_report,
    write_summary,
)

OUT = ROOT / "docs" / "benchmarks"
BIN = Path(sys.executable).parent
GAMMA_S = 0.2  # c = 1/((1 - ν) γs) = 10 at ν = 1/2
CASES = {"half-space": ["--thickness", "0", "--width", "80"], "layer r0/h=2": ["--thickness", "0.5", "--width", "10"]}
MESHES = {2: [0, 1, 2, 3], 3: [0, 1, 2]}
COLUMNS = ["case", "degree", "refine", "dofs", "ridge_height", "ridge_height_theory", "error", "t_command_s",
           "t_solve_s"]


def run(case: str, degree: int, refine: int, ranks: int = 2) -> dict:
    with tempfile.TemporaryDirectory() as out:
        args = ["run", "droplet-soft", "--gamma-s", str(GAMMA_S), "--gamma-ls", str(GAMMA_S), "--gamma-l", "0.1",
                "--nu", "0.5", "--size-contact", "0.01", "--degree", str(degree), "--refine", str(refine),
                *CASES[case], "--quiet", "--out", out]
        env = {**os.environ, "PATH": f"{BIN}:{os.environ['PATH']}"}
        env.pop("PETSC_OPTIONS", None)
        t0 = time.perf_counter()
        subprocess.run([str(BIN / "mpirun"), "-n", str(ranks), str(BIN / "bcfem"), *args], env=env, check=True,
                       stdout=subprocess.DEVNULL, cwd=ROOT)
        elapsed = time.perf_counter() - t0
        summary = json.loads((Path(out) / "summary.json").read_text())
    return {"case": case, "degree": degree, "refine": refine, "dofs": summary["dofs"],
            "ridge_height": summary["ridge_height"], "ridge_height_theory": summary["ridge_height_theory"],
            "error": summary["ridge_height_error"], "t_command_s": elapsed, "t_solve_s": summary["wall_time_s"]}


def figure(rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for (case, marker) in zip(CASES, "os"):
        for degree, colour in ((2, "C0"), (3, "C3")):
            sel = [r for r in rows if r["case"] == case and r["degree"] == degree]
            ax.loglog([r["t_command_s"] for r in sel], [abs(r["error"]) for r in sel], marker=marker, color=colour,
                      ls="-" if marker == "o" else "--", label=f"{case}, P{degree}-P{degree - 1}")
    ax.axhline(1e-3, color="0.6", lw=0.8)
    ax.set_xlabel("wall time of mpirun -n 2 bcfem run droplet-soft [s]")
    ax.set_ylabel("|relative error| of u_z(r0)")
    ax.set_title("droplet-soft, linear: ridge height at c = 10, nu = 0.5", fontsize=10)
    ax.legend(fontsize=8)
    return fig


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report: the template filled with the rows (CSV) and the summary (JSON)."""
    columns = [("case", "{case}"), ("element", lambda r: f"P{r['degree']}-P{r['degree'] - 1}"),
               ("refine", "{refine}"), ("dofs", "{dofs}"), ("u_z(r0)/r0", "{ridge_height:.7f}"),
               ("relative error", lambda r: fmt(r["error"], "+.2e")), ("t_command [s]", "{t_command_s:.1f}"),
               ("t_solve [s]", "{t_solve_s:.2f}")]
    return render("droplet-soft.md", rows, summary, table=table(rows, columns), provenance=provenance_note(summary))


def main() -> None:
    if sys.argv[1:2] == ["--render-only"]:
        render_again("droplet-soft", report)
        return
    run("half-space", 2, 0)  # warm the JIT cache
    rows = [run(case, degree, refine) for case in CASES for degree, refines in MESHES.items() for refine in refines]
    OUT.mkdir(parents=True, exist_ok=True)
    summary = {"load": loadavg(), "provenance": provenance()}
    atomic_text(OUT / "droplet-soft.csv", csv_text(rows, COLUMNS))
    write_summary("droplet-soft", summary)
    text = report(rows, summary)
    write_report(OUT / "droplet-soft.md", text)
    fig = figure(rows)
    fig.savefig(OUT / "droplet-soft.png", dpi=150, bbox_inches="tight")
    print(text)


if __name__ == "__main__":
    if sys.argv[1:2] == ["figures"]:
        from droplet_soft_figures import main as figures

        figures(sys.argv[2:])
    else:
        main()
