"""The double-chamber crater (ch. 9): split strain and suction against wall time, and Fig. 9.10.

Mesh study: the cell of a confined array (``--cell array``, outer radius 2 r0, height 2 H,
the dissertation's crater r0 = 0.52 H, R0 = 0.5 H, s = 0.03 H, mu = p_a, sticking plate),
whose sidewall reaches the protuberance at eps_a ~ 0.012, cycled bonded to a preload of
0.02 and back to eps = 0, on three meshes (element sizes on the walls and at the contact
halved each time). Each run is ``mpirun -n 2 bcfem run crater-double`` with a warm JIT
cache; eps_a, F~ and the chambers' pressures are compared with the Richardson value of the
two finest meshes.

Fig. 9.10: (p_ci - p_a)/p_a against eps, loading and unloading to the dissertation's preload
0.14, for its crater in an isolated specimen (the defaults: the cavity never splits) and in a
specimen bonded to a rigid backing (``--top bonded``, 5 r0 wide, 1.375 H tall: the sidewall
reaches the protuberance at eps_a = 0.131, the dissertation's 0.13), bonded contact.

Usage (from the repository root)::

    .venv/bin/python benchmarks/crater_double.py        # the benchmark and the figure
    .venv/bin/python benchmarks/crater_double.py draw   # the figure again from fig9_10.json
    .venv/bin/python benchmarks/crater_double.py --render-only   # the .md again from CSV + JSON

Writes ``docs/benchmarks/crater-double.{csv,json,md,png}`` (the report is
``benchmarks/templates/crater-double.md`` filled from them) and
``docs/figures/crater_double/fig9_10.{png,json}``.
"""

from __future__ import annotations

import csv
import json
import math
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
    save_figure,
    table,
    write_report,
    write_summary,
)

OUT = ROOT / "docs" / "benchmarks"
FIGURES = ROOT / "docs" / "figures" / "crater_double"
BIN = Path(sys.executable).parent
CELL = ["--cell", "array", "--specimen-radius", "2", "--specimen-height", "2", "--contact", "bonded",
        "--preload", "0.02", "--strain-step", "0.005"]
MESHES = [(0.16, 0.04), (0.08, 0.02), (0.04, 0.01)]
#: the dissertation's crater on a rigid backing, whose split comes at its eps_a ~ 0.13
BACKED = ["--top", "bonded", "--specimen-height", "1.375", "--contact", "bonded", "--size-wall", "0.04",
          "--size-contact", "0.01"]
KEYS = ("eps_contact", "F_tilde", "p_c1_over_pa", "p_c2_over_pa")
COLUMNS = ["size_wall", "size_contact", "dofs", *KEYS, *(f"error_{k}" for k in KEYS), "newton_iterations",
           "t_command_s", "t_solve_s"]
COMMAND = ".venv/bin/python benchmarks/crater_double.py"


def run(args: list[str], ranks: int = 2) -> tuple[dict, list[dict], float]:
    """(summary, rows, the whole command's seconds) of ``mpirun -n ranks bcfem run crater-double ARGS``."""
    with tempfile.TemporaryDirectory() as out:
        env = {**os.environ, "PATH": f"{BIN}:{os.environ['PATH']}"}
        env.pop("PETSC_OPTIONS", None)
        t0 = time.perf_counter()
        subprocess.run([str(BIN / "mpirun"), "-n", str(ranks), str(BIN / "bcfem"), "run", "crater-double", *args,
                        "--quiet", "--no-plots", "--out", out], env=env, check=True, stdout=subprocess.DEVNULL, cwd=ROOT)
        elapsed = time.perf_counter() - t0
        summary = json.loads((Path(out) / "summary.json").read_text())
        with open(Path(out) / "branch.csv") as f:
            rows = [{k: (float(v) if k != "stage" and v != "" else v) for k, v in r.items()} for r in csv.DictReader(f)]
    return summary, rows, elapsed


def mesh_study() -> tuple[list[dict], tuple[dict, list[dict]]]:
    """The rows of the table, and the finest run's (summary, rows)."""
    results, finest = [], None
    for wall, contact in MESHES:
        summary, rows, elapsed = run([*CELL, "--size-wall", str(wall), "--size-contact", str(contact)])
        results.append({"size_wall": wall, "size_contact": contact, "dofs": summary["dofs"],
                        **{k: summary[k] for k in KEYS}, "newton_iterations": summary["newton_iterations"],
                        "t_command_s": elapsed, "t_solve_s": summary["wall_time_s"]})
        finest = summary, rows
        print(results[-1], flush=True)
    for key in KEYS:  # against the two finest meshes' Richardson value at the observed order
        a, b, c = (r[key] for r in results)
        ratio = (b - a) / (c - b) if c != b else float("nan")
        order = max(min(math.log2(abs(ratio)), 4.0), 1.0) if math.isfinite(ratio) and ratio else 2.0
        reference = c + (c - b) / (2**order - 1)
        for r in results:
            r[f"error_{key}"] = r[key] - reference
        results[-1][f"order_{key}"] = order
    return results, finest


def figure(isolated_rows, backed_rows, split_eps):
    """Fig. 9.10's axes for both specimens, and the chambers' pressure difference on the backing."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    from bcfem.scenes.crater_double.report import stage_rows

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    for ax, rows, title in ((axes[0], isolated_rows, "dissertation's crater, isolated specimen"),
                            (axes[1], backed_rows, "the same crater, specimen on a rigid backing")):
        for stage, colour in (("load", "tab:red"), ("unload", "tab:blue")):
            part = stage_rows(rows, stage)
            ax.plot([r["eps"] for r in part], [r["p_c1_over_pa"] - 1 for r in part], "-", color=colour,
                    label=f"C1 {stage}")
            two = [r for r in part if r["chambers"] == 2]
            if two:
                ax.plot([r["eps"] for r in two], [r["p_c2_over_pa"] - 1 for r in two], "--", color=colour,
                        label=f"C2 {stage}")
        ax.set_ylabel("(p_ci - p_a)/p_a")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=7)
    for stage, colour in (("load", "tab:red"), ("unload", "tab:blue")):
        part = stage_rows(backed_rows, stage)
        two = [r for r in part if r["chambers"] == 2]
        axes[2].plot([r["eps"] for r in two], [r["p_c1_over_pa"] - r["p_c2_over_pa"] for r in two], "-o", ms=3,
                     color=colour, label=stage)
    axes[2].set_ylabel("(p_c1 - p_c2)/p_a")
    axes[2].set_title("the chambers after the split (backing)", fontsize=9)
    axes[2].legend(fontsize=7)
    for ax in axes:
        ax.set_xlabel("ε")
        ax.xaxis.set_major_locator(MaxNLocator(5))
    for ax in axes[1:]:
        ax.axvline(split_eps, color="0.6", ls=":", lw=0.8)
    fig.tight_layout()
    return fig


def main() -> None:
    results, (cell, cell_rows) = mesh_study()
    isolated, isolated_rows, t_isolated = run(["--contact", "bonded"])
    backed, backed_rows, t_backed = run(BACKED)
    atomic_text(OUT / "crater-double.csv", csv_text(results, COLUMNS))
    numbers = {"isolated": {k: isolated[k] for k in ("eps_contact", "F_tilde", "p_c1_over_pa", "p_c2_over_pa",
                                                      "wall_time_s", "dofs")}
               | {"p_max_over_pa": max(r["p_c1_over_pa"] for r in isolated_rows), "t_command_s": t_isolated},
               "cell": {k: cell[k] for k in ("eps_contact", "F_tilde", "p_c1_over_pa", "p_c2_over_pa", "split")},
               "backed": {k: backed[k] for k in ("eps_contact", "F_tilde", "p_c1_over_pa", "p_c2_over_pa", "split",
                                                 "least_sidewall_gap", "wall_time_s", "dofs")}
               | {"t_command_s": t_backed, "sidewall_gap_at_end": backed_rows[-1]["sidewall_gap"]},
               "rows": {"isolated": isolated_rows, "backed": backed_rows}}
    atomic_text(FIGURES / "fig9_10.json", json.dumps(numbers, indent=1) + "\n")
    draw()
    save_figure(error_figure(results), OUT / "crater-double.png")
    summary = {"load": loadavg(), "orders": {k: results[-1][f"order_{k}"] for k in KEYS}, "provenance": provenance()}
    write_summary("crater-double", summary)
    write_report(OUT / "crater-double.md", report(results, summary, numbers))


def report(results: list[dict], summary: dict, numbers: dict) -> str:
    """The Markdown report: benchmarks/templates/crater-double.md filled from the mesh study's rows
    (CSV), the summary (JSON: load, observed orders, provenance) and the isolated and backed runs
    (``fig9_10.json``)."""
    rows = table(results, [
        ("sizes wall / contact [H]", "{size_wall} / {size_contact}"), ("dofs", "{dofs}"),
        ("eps_a", "{eps_contact:.6f}"), ("error", lambda r: fmt(r["error_eps_contact"])), ("F~", "{F_tilde:.5f}"),
        ("error", lambda r: fmt(r["error_F_tilde"])), ("p_c1/p_a", "{p_c1_over_pa:.5f}"),
        ("p_c2/p_a", "{p_c2_over_pa:.5f}"), ("Newton its", lambda r: f"{int(r['newton_iterations'])}"),
        ("t_command [s]", "{t_command_s:.1f}"), ("t_solve [s]", "{t_solve_s:.1f}")])
    # engineering accuracy: F~ to 1e-3 of the full suction scale (A_c1 = A0, p_c1 = 0) and eps_a to 1e-5
    engineering = next((r for r in results if abs(r["error_F_tilde"]) < 1e-3 and abs(r["error_eps_contact"]) < 1e-5),
                       None)
    cheapest = (f"the {engineering['size_wall']} / {engineering['size_contact']} mesh, {engineering['t_command_s']:.0f} s "
                "for the whole command on 2 ranks" if engineering else "none of these meshes")
    return render("crater-double.md", results, summary, table=rows, cheapest=cheapest,
                  orders=", ".join(f"{k} {v:.2f}" for k, v in summary["orders"].items()),
                  isolated=numbers["isolated"], backed=numbers["backed"], backed_flags=" ".join(BACKED),
                  provenance=provenance_note(summary))


def draw() -> None:
    """Fig. 9.10 from the kept numbers (``fig9_10.json``)."""
    numbers = json.loads((FIGURES / "fig9_10.json").read_text())
    rows = numbers["rows"]
    save_figure(figure(rows["isolated"], rows["backed"], numbers["backed"]["split"]["eps"]), FIGURES / "fig9_10.png")


def error_figure(results):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.6))
    times = [r["t_solve_s"] for r in results[:-1]]
    for key, marker in (("eps_contact", "o"), ("F_tilde", "s"), ("p_c1_over_pa", "^")):
        ax.loglog(times, [abs(r[f"error_{key}"]) for r in results[:-1]], marker + "-", label=key)
    ax.set_xlabel("solve wall time on 2 ranks [s]")
    ax.set_ylabel("|error| against Richardson")
    ax.legend(fontsize=8)
    ax.set_title("crater-double, array cell, bonded", fontsize=9)
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    if sys.argv[1:] == ["draw"]:
        draw()
    elif sys.argv[1:] == ["--render-only"]:
        numbers = json.loads((FIGURES / "fig9_10.json").read_text())
        render_again("crater-double", lambda rows, summary: report(rows, summary, numbers))
    else:
        main()
