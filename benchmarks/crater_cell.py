"""Work precision of ``crater-cell``: F~ of a sparse square cell against wall time, dofs, time per
Newton iteration and peak memory, serial and on 2 ranks.

The cell is the square lattice at F = pi/64 (d = 8a), the hemisphere of the experiment, air,
preload 0.1. Each case is ``bcfem run crater-cell`` with the scene's three size flags scaled
together from the default (``--size-wall 0.3 --size-rim 0.1 --size-far 0.8``, scale 1) over
SCALES, run in a worker under ``mpirun -n RANKS`` pinned to the first RANKS cores (one thread) that
adds each rank's peak resident memory (``getrusage`` maxrss) to the run's summary.json.

The error is against the Richardson reference of the cell's own serial series (order observed on
the three finest meshes); the distance to the isolated axisymmetric crater
(``bcfem run crater --specimen-radius R --surface-energy 0 --self-contact 0``, its default mesh) is
reported beside it for R = d/sqrt(pi) (the cell's area) and R = 2d (wide). The time per Newton
iteration is the run's Newton time (assembly, discrete terms, factorisation, solve, the rest of
Newton; summary.json ``time_split_s``) over its ``newton_iterations``; the tangent's inertia checks
(``stability``) are apart. Power laws in the dofs are fitted to both and to the memory.

Writes ``docs/benchmarks/crater-cell.{csv,json,md,png}``; the report is
``benchmarks/templates/crater-cell.md`` filled from the CSV and the JSON.

Run from the repository root: ``.venv/bin/python benchmarks/crater_cell.py`` (about 10 min on 2 free cores);
``--render-only`` renders the report again from the CSV and JSON that are there.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from common import (
    ROOT,
    atomic_text,
    csv_text,
    loadavg,
    observed_order,
    one_core_env,
    pinned,
    provenance,
    provenance_note,
    read_csv,
    render,
    render_again,
    save_figure,
    table,
    wait_idle,
    write_report,
    write_summary,
)

OUT = ROOT / "docs" / "benchmarks"
FILLING = math.pi / 64
PRELOAD = 0.1
DEFAULT = {"wall": 0.3, "rim": 0.1, "far": 0.8}
SCALES = (2.0, 1.5, 1.0, 0.75)
RANKS = (1, 2)
NEWTON_PARTS = ("assembly", "discrete_terms", "factorisation", "linear_solve", "newton_other")
COLUMNS = ["scale", "size_wall", "ranks", "dofs", "F_tilde", "error", "wall_time_s", "newton_iterations",
           "newton_time_s", "time_per_iteration_s", "stability_time_s", "max_rss_rank_mb", "max_rss_total_mb",
           "mumps_mb_total", "mumps_flops"]
#: the split's runs: a weak-scaling pair (about 6.6e4 dofs a rank) and the largest cell that
#: fits this machine (about 1e6 dofs), each with LARGE_FLAGS
LARGE = ({"name": "weak scaling, 1 rank", "ranks": 1, "sizes": (0.15, 0.05, 0.4)},
         {"name": "weak scaling, 2 ranks", "ranks": 2, "sizes": (0.119, 0.0397, 0.317)},
         {"name": "largest", "ranks": 2, "sizes": (0.058, 0.0193, 0.15)})
LARGE_FLAGS = ["--strain-step", "0.05", "--solver", "split", "--stability", "none"]
LARGE_COLUMNS = ["name", "ranks", "size_wall", "size_rim", "size_far", "dofs", "status", "eps_reached", "F_tilde",
                 "wall_time_s",
                 "newton_iterations", "assembly_s", "solver_s", "time_per_iteration_s", "peak_rss_rank_mb"]
#: MUMPS's statistics of every factorisation of the loading stage (printed on stdout)
MUMPS_REPORT = ["-bcfem_crater_cell_load_mat_mumps_icntl_4", "2"]
MUMPS_MEMORY = re.compile(r"Memory effectively used, total in Mbytes\s+\(INFOG\(22\)\):\s+(\d+)")
MUMPS_FLOPS = re.compile(r"RINFOG\(1\) Operations during elimination \(estim\)=\s*([\d.]+)D([+-]\d+)")


def cell_args(scale: float) -> list[str]:
    return ["run", "crater-cell", "--lattice", "square", "--filling", repr(FILLING), "--preload", str(PRELOAD),
            "--size-wall", f"{DEFAULT['wall'] * scale:g}", "--size-rim", f"{DEFAULT['rim'] * scale:g}",
            "--size-far", f"{DEFAULT['far'] * scale:g}", "--quiet", "--no-plots"]


def large_args(sizes: tuple[float, float, float]) -> list[str]:
    wall, rim, far = sizes
    return ["run", "crater-cell", "--lattice", "square", "--filling", "0.0490873852", "--preload", str(PRELOAD),
            "--size-wall", f"{wall:g}", "--size-rim", f"{rim:g}", "--size-far", f"{far:g}", *LARGE_FLAGS, "--quiet",
            "--no-plots"]


def large_row(case: dict, summary: dict) -> dict:
    """A row of the split's runs from a run's summary.json."""
    split = summary["time_split_s"]
    newton = sum(split.get(k, 0.0) for k in NEWTON_PARTS)
    return {"name": case["name"], "ranks": case["ranks"], "size_wall": case["sizes"][0], "size_rim": case["sizes"][1],
            "size_far": case["sizes"][2], "dofs": summary["dofs"], "status": summary["status"],
            "eps_reached": max(r["eps"] for r in summary_rows(summary)), "F_tilde": summary.get("F_tilde"),
            "wall_time_s": summary["wall_time_s"], "newton_iterations": summary["newton_iterations"],
            "assembly_s": split["assembly"], "solver_s": newton - split["assembly"],
            "time_per_iteration_s": newton / summary["newton_iterations"],
            "peak_rss_rank_mb": max(summary["peak_rss_mb"])}


def summary_rows(summary: dict) -> list[dict]:
    """The accepted rows of the run whose summary.json this is (its branch.csv beside it)."""
    return read_csv(Path(summary["out"]) / "branch.csv")


def large_case(case: dict, imported: Path | None) -> dict:
    """The row of one LARGE run: run now, or read from ``imported`` (a run made with its command)."""
    if imported is not None:
        summary = json.loads((imported / "summary.json").read_text())
        assert summary["parameters"]["size_wall"] == case["sizes"][0], (case, summary["parameters"])
        return large_row(case, {**summary, "out": imported})
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        return large_row(case, {**run([*large_args(case["sizes"]), "--out", str(out)], case["ranks"]), "out": out})


def large(imported: dict[str, Path]) -> None:
    """The LARGE runs into docs/benchmarks/crater-cell-large.csv (see :func:`large_case`)."""
    rows = []
    for case in LARGE:
        rows.append(large_case(case, imported.get(case["name"])))
        print(rows[-1], flush=True)
    atomic_text(OUT / "crater-cell-large.csv", csv_text(rows, LARGE_COLUMNS))


def worker(argv: list[str]) -> None:
    """One bcfem command in this process (under mpirun), then every rank's peak memory into its
    summary.json (rank 0 writes)."""
    import resource

    import dolfinx_solver  # noqa: F401  (before dolfinx / petsc4py)
    from mpi4py import MPI

    from bcfem.cli import main as bcfem_main

    status = bcfem_main(argv)
    rss = MPI.COMM_WORLD.gather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, root=0)  # kB -> MB
    if MPI.COMM_WORLD.rank == 0:
        path = Path(argv[argv.index("--out") + 1]) / "summary.json"
        summary = json.loads(path.read_text())
        summary["max_rss_mb"] = rss
        path.write_text(json.dumps(summary, indent=1))
    sys.exit(status)


def run(argv: list[str], ranks: int) -> dict:
    """``argv`` (a bcfem command with ``--out``) in :func:`worker` on ``ranks`` pinned ranks; its summary,
    with MUMPS's largest memory (INFOG(22), MB over all ranks) and operation count (RINFOG(1)) where it
    printed them."""
    bin_dir = ROOT / ".venv" / "bin"
    env = one_core_env(PATH=f"{bin_dir}:{os.environ['PATH']}")
    cores = ",".join(str(c) for c in range(ranks))
    cmd = pinned([str(bin_dir / "mpirun"), "-n", str(ranks), sys.executable, __file__, "--worker", *argv], cores)
    proc = subprocess.run(cmd, cwd=ROOT, env=env, check=True, stdin=subprocess.DEVNULL, capture_output=True,
                          text=True)
    summary = json.loads((Path(argv[argv.index("--out") + 1]) / "summary.json").read_text())
    memory = [int(m) for m in MUMPS_MEMORY.findall(proc.stdout)]
    flops = [float(f"{m}e{e}") for m, e in MUMPS_FLOPS.findall(proc.stdout)]
    return {**summary, "mumps_mb_total": max(memory, default=None), "mumps_flops": max(flops, default=None)}


def case(scale: float, ranks: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        s = run([*cell_args(scale), "--out", str(Path(tmp) / "run"), *MUMPS_REPORT], ranks)
    split = s["time_split_s"]
    newton = sum(split.get(k, 0.0) for k in NEWTON_PARTS)
    return {"scale": scale, "size_wall": DEFAULT["wall"] * scale, "ranks": ranks, "dofs": s["dofs"],
            "F_tilde": s["F_tilde"], "wall_time_s": s["wall_time_s"], "newton_iterations": s["newton_iterations"],
            "newton_time_s": newton, "time_per_iteration_s": newton / s["newton_iterations"],
            "stability_time_s": split.get("stability", 0.0), "max_rss_rank_mb": max(s["max_rss_mb"]),
            "max_rss_total_mb": sum(s["max_rss_mb"]), "mumps_mb_total": s["mumps_mb_total"],
            "mumps_flops": s["mumps_flops"]}


def isolated(radius: float) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        s = run(["run", "crater", "--preload", str(PRELOAD), "--specimen-radius", f"{radius:.6g}",
                 "--surface-energy", "0", "--self-contact", "0", "--quiet", "--no-plots",
                 "--out", str(Path(tmp) / "run")], 1)
    return {"specimen_radius": radius, "F_tilde": s["F_tilde"], "dofs": s["dofs"], "wall_time_s": s["wall_time_s"]}


def power_law(rows: list[dict], key: str) -> dict:
    """key ~ c dofs^k, least squares in logs over the rows."""
    x = [math.log(r["dofs"]) for r in rows]
    y = [math.log(r[key]) for r in rows]
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    k = sum((a - mx) * (b - my) for a, b in zip(x, y)) / sum((a - mx) ** 2 for a in x)
    return {"exponent": k, "coefficient": math.exp(my - k * mx)}


def fits(rows: list[dict]) -> dict:
    """Power laws of the time per Newton iteration and of the memory per rank (each rank count),
    over the meshes past the coarsest, and their extrapolation to 10^6 dofs (serial and 2 ranks)."""
    out = {}
    for ranks in RANKS:
        series = [r for r in rows if r["ranks"] == ranks][1:]
        for key in ("time_per_iteration_s", "max_rss_rank_mb", "mumps_mb_total", "mumps_flops"):
            law = power_law(series, key)
            law["at_1e6"] = law["coefficient"] * 1e6 ** law["exponent"]
            out[f"{key}_{ranks}"] = law
    return out


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report: the template filled with the rows (CSV) and the summary (JSON)."""
    columns = [("scale", "{scale:g}"), ("size-wall / a", "{size_wall:g}"), ("ranks", "{ranks}"), ("dofs", "{dofs}"),
               ("F~", "{F_tilde:.6f}"), ("error vs Richardson", "{error:.2e}"),
               ("wall time [s]", "{wall_time_s:.1f}"), ("Newton its", "{newton_iterations}"),
               ("s / Newton it", "{time_per_iteration_s:.3f}"), ("inertia checks [s]", "{stability_time_s:.1f}"),
               ("peak RSS per rank [MB]", "{max_rss_rank_mb:.0f}"), ("MUMPS [MB]", "{mumps_mb_total}"),
               ("MUMPS operations", "{mumps_flops:.2e}")]
    iso = [(f"R = {r['specimen_radius']:.4g} mm ({r['name']})", r) for r in summary["isolated"]]
    isolated_table = table([{"name": n, **r} for n, r in iso], [
        ("isolated crater", "{name}"), ("F~", "{F_tilde:.6f}"), ("dofs", "{dofs}"),
        ("cell's Richardson F~ / it - 1", lambda r: f"{summary['reference']['F'] / r['F_tilde'] - 1:+.2%}"),
        ("cell's finest F~ / it - 1", lambda r: f"{summary['finest_serial'] / r['F_tilde'] - 1:+.2%}")])
    fit_rows = [{"what": what, "ranks": ranks, **summary["fits"][f"{key}_{ranks}"]}
                for key, what in (("time_per_iteration_s", "s per Newton iteration"),
                                  ("max_rss_rank_mb", "peak RSS per rank [MB]"),
                                  ("mumps_mb_total", "MUMPS memory, all ranks [MB]"),
                                  ("mumps_flops", "MUMPS operations per factorisation")) for ranks in RANKS]
    fit_table = table(fit_rows, [("quantity", "{what}"), ("ranks", "{ranks}"), ("exponent k (∝ dofs^k)", "{exponent:.2f}"),
                                 ("at 10^6 dofs", "{at_1e6:.3g}")])
    large_path = OUT / "crater-cell-large.csv"
    large_rows = read_csv(large_path) if large_path.exists() else []
    large_table = table(large_rows, [
        ("run", "{name}"), ("ranks", "{ranks}"), ("size wall / rim / far", "{size_wall:g} / {size_rim:g} / {size_far:g}"),
        ("dofs", "{dofs:,}"), ("status", "{status}"), ("largest eps", "{eps_reached:g}"),
        ("F~", lambda r: "–" if r["F_tilde"] is None else f"{r['F_tilde']:.6f}"), ("wall time [s]", "{wall_time_s:.0f}"),
        ("Newton its", "{newton_iterations}"), ("assembly [s]", "{assembly_s:.0f}"), ("solver [s]", "{solver_s:.0f}"),
        ("s / Newton it", "{time_per_iteration_s:.2f}"), ("peak RSS per rank [MB]", "{peak_rss_rank_mb:.0f}")])
    return render("crater-cell.md", rows, summary, table=table(rows, columns), isolated=isolated_table,
                  fits=fit_table, large=large_table, provenance=provenance_note(summary),
                  order=("none (not monotone)" if summary["reference"]["order"] is None
                         else f"{summary['reference']['order']:.2f}"))


def figure(rows: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx, cx) = plt.subplots(1, 3, figsize=(13, 4))
    for ranks, style in zip(RANKS, ("-o", "--s")):
        series = [r for r in rows if r["ranks"] == ranks and r["error"] > 0]
        label = f"{ranks} rank{'s' if ranks > 1 else ''}"
        ax.loglog([r["wall_time_s"] for r in series], [r["error"] for r in series], style, label=label)
        bx.loglog([r["dofs"] for r in series], [r["error"] for r in series], style, label=label)
        every = [r for r in rows if r["ranks"] == ranks]
        cx.loglog([r["dofs"] for r in every], [r["time_per_iteration_s"] for r in every], style,
                  label=f"s / Newton iteration, {label}")
        cx.loglog([r["dofs"] for r in every], [r["max_rss_rank_mb"] / 1000 for r in every], style, mfc="none",
                  label=f"peak RSS per rank [GB], {label}")
    large_path = OUT / "crater-cell-large.csv"
    for r in read_csv(large_path) if large_path.exists() else []:
        cx.loglog([r["dofs"]], [r["time_per_iteration_s"]], "^" if r["ranks"] == 1 else "v", color="C2",
                  label=f"split, {r['name']}")
    serial = [r for r in rows if r["ranks"] == 1]
    n0, t0 = serial[0]["dofs"], serial[0]["time_per_iteration_s"]
    n1 = max(1e6, serial[-1]["dofs"])
    cx.loglog([n0, n1], [t0, t0 * n1 / n0], ":", color="gray", label="∝ dofs¹ (from the coarsest)")
    ax.set_xlabel("wall time [s]")
    bx.set_xlabel("dofs")
    cx.set_xlabel("dofs")
    for a in (ax, bx):
        a.set_ylabel("relative error of F~ (vs Richardson)")
    for a in (ax, bx, cx):
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle(f"crater-cell, square, F = π/64 (d = 8a), air, preload {PRELOAD}")
    fig.tight_layout()
    save_figure(fig, OUT / "crater-cell.png")


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker(sys.argv[2:])
        return
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--render-only", action="store_true",
                        help="render crater-cell.md again from the crater-cell.csv and .json that are there")
    parser.add_argument("--large", action="store_true",
                        help="run the split's weak-scaling pair and the largest cell (LARGE; hours on 2 cores) "
                             "into crater-cell-large.csv, then render the page again")
    parser.add_argument("--import", dest="imported", nargs=2, action="append", default=[], metavar=("NAME", "DIR"),
                        help="with --large: take the run NAME of LARGE from DIR (made with its command)")
    args = parser.parse_args()
    if args.large:
        large({name: Path(d) for name, d in args.imported})
        figure(read_csv(OUT / "crater-cell.csv"))
    if args.render_only or args.large:
        render_again("crater-cell", report)
        return
    waited, busy = wait_idle(30)
    load = f"{busy:.1f} cores busy after {waited:.0f} s of waiting; load average {loadavg()}"
    rows = []
    for ranks in RANKS:
        for scale in SCALES:
            rows.append(case(scale, ranks))
            print(rows[-1], flush=True)
    serial = [r for r in rows if r["ranks"] == 1]
    h, F = [r["scale"] for r in serial], [r["F_tilde"] for r in serial]
    order = observed_order(h[-3:], F[-3:])
    ref = {"order": order, "meshes_used": h[-2:]}
    ref["F"] = F[-1] + (F[-1] - F[-2]) / ((h[-2] / h[-1]) ** order - 1) if order else F[-1]
    ref["kind"] = "richardson" if order else "finest"
    for r in rows:
        r["error"] = abs(r["F_tilde"] - ref["F"]) / ref["F"]
    spacing = math.sqrt(math.pi / FILLING) * 6.35
    iso = [{**isolated(spacing / math.sqrt(math.pi)), "name": "the cell's area"},
           {**isolated(2 * spacing), "name": "wide, 2d"}]
    summary = {"reference": ref, "finest_serial": F[-1], "isolated": iso, "fits": fits(rows),
               "filling": FILLING, "preload": PRELOAD, "spacing_mm": spacing,
               "machine": f"{load} (times on a busy machine are upper bounds)", "provenance": provenance()}
    atomic_text(OUT / "crater-cell.csv", csv_text(rows, COLUMNS))
    write_summary("crater-cell", summary)
    write_report(OUT / "crater-cell.md", report(rows, summary))
    figure(rows)


if __name__ == "__main__":
    main()
