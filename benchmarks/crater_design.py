"""Benchmark of the crater design space: docs/benchmarks/crater-design.{csv,md,png}.

1. Mesh convergence of the suction force at three representative points of the maps
   (an air crater at full closure, a liquid hemisphere, a reinforced liquid crater):
   the relative error of F~ (F^ = F~/beta, the same relative error) against the wall
   time of one cycle on one core, for four meshes; the reference is a Richardson
   extrapolation when the meshes converge monotonically, else the finest mesh
   (`common.reference`, the same criterion as the air-crater benchmark).
2. The wall time of each published map and the time per point, from the
   `timing.json` that `bcfem sweep` writes next to each map's `sweep.csv`
   (`docs/figures/crater_design/sweeps/<map>/`, made by `make report` or by the
   commands in docs/craters.md).
3. `--two-ranks MAP ...` (or `all`): solves each named map again from nothing with its
   command on `mpirun -n 2` in a scratch directory, times it, and checks that every point
   equals the kept one (the sweep is rank-count invariant); recorded in the map's
   `timing_2ranks.json` and shown in the map table.

Run from the repository root: `.venv/bin/python benchmarks/crater_design.py` (part of
`make bench`).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path

from common import (
    ROOT,
    atomic_text,
    busy_cores,
    csv_text,
    emit,
    fmt,
    mpirun_bcfem,
    provenance,
    provenance_note,
    reference,
    render,
    render_again,
    run_worker,
    save_figure,
    table,
    wait_idle,
    worker_prologue,
    write_report,
    write_summary,
)

from bcfem.scenes.crater.params import PRELOAD_TO_CLOSURE  # dolfinx-free

OUT = ROOT / "docs" / "benchmarks"
MAPS = ROOT / "docs" / "figures" / "crater_design" / "sweeps"
TEMPLATE = "crater-design.md"
POINTS = {
    "air, alpha 0.7, beta 1, full closure (Fig. 7.9)": dict(alpha=0.7, beta=1.0, preload=PRELOAD_TO_CLOSURE),
    "liquid, hemisphere, eps 0.25 (Fig. 8.4)": dict(fluid="liquid", alpha=1.0, preload=0.25),
    "liquid, alpha 0.85, layer 0.03/30, eps 0.25 (Fig. 8.7b)": dict(
        fluid="liquid", alpha=0.85, preload=0.25, layer_thickness=0.03, layer_stiffness=30.0),
}
SIZES = [0.12, 0.085, 0.06, 0.042]  # size_crater, coarse to fine (0.06 is the scene's default)
COLUMNS = ["point", "size_crater", "status", "dofs", "F_tilde", "F_hat", "error", "A2_over_A0", "V2_over_V0",
           "p2_over_pa", "preload", "stability", "wall_time_s", "t_process", "reason"]


def worker(case: dict) -> dict:
    from mpi4py import MPI

    worker_prologue()
    from bcfem.scenes import crater

    out = {**case, "status": "ok", "reason": ""}
    try:
        _, s = crater.solve(crater.Params(**case["params"], size_crater=case["size_crater"]), MPI.COMM_WORLD)
        out.update({k: float(s[k]) for k in ("F_tilde", "F_hat", "A2_over_A0", "V2_over_V0", "p2_over_pa", "preload",
                                              "wall_time_s")}, dofs=s["dofs"], stability=s["stability"])
    except Exception as error:  # recorded, with its message
        out.update(status="failed", reason=f"{type(error).__name__}: {error}")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=float, nargs="+", default=SIZES)
    ap.add_argument("--two-ranks", nargs="+", default=[], metavar="MAP",
                    help="solve these maps again on 2 ranks, timed and compared with the kept points ('all': every map)")
    ap.add_argument("--render-only", action="store_true",
                    help="render crater-design.md again from the crater-design.csv and .json that are there")
    args = ap.parse_args()
    if args.render_only:
        render_again("crater-design", report)
        return
    known = sorted(p.parent.name for p in MAPS.glob("*/sweep.csv"))
    if unknown := sorted(set(args.two_ranks) - set(known) - {"all"}):
        ap.error(f"--two-ranks: no kept map {', '.join(unknown)} (allowed: all, {', '.join(known)})")
    for name in known if args.two_ranks == ["all"] else args.two_ranks:
        two_ranks(name)
    _, busy = wait_idle(300.0)
    t0 = time.perf_counter()
    load = [f"{busy:.2f}"]
    rows, refs = [], {}
    for name, params in POINTS.items():
        series = []
        for size in sorted(args.sizes, reverse=True):
            r = run_worker(__file__, {"point": name, "params": params, "size_crater": size})
            print(f"{name}, size {size:g}: {r['status']} F~ = {r.get('F_tilde')} ({r.get('wall_time_s')} s)",
                  file=sys.stderr, flush=True)
            rows.append(r)
            if r["status"] == "ok":
                series.append(r)
        refs[name] = reference(series) if series else None
        for r in series:
            ref = refs[name]["F"]
            r["error"] = abs(r["F_tilde"] / ref - 1) if ref else math.nan
    load.append(f"{busy_cores():.2f}")
    write(rows, refs, maps(), time.perf_counter() - t0, load)


def two_ranks(name: str) -> None:
    """Solve map ``name`` again with its own command on 2 ranks in a scratch directory; keep the
    wall time and the largest relative difference of F~ from the kept points."""
    import shlex
    import tempfile

    command = json.loads((MAPS.parent / "summary.json").read_text())["commands"][name]
    argv = shlex.split(command)
    kept = {r["key"]: r for r in map_rows(MAPS / name)}
    with tempfile.TemporaryDirectory() as scratch:
        argv[argv.index("--out") + 1] = scratch
        t0 = time.perf_counter()
        mpirun_bcfem([*argv[argv.index("bcfem") + 1:], "--quiet"], ranks=2, quiet_stdout=True)
        wall = time.perf_counter() - t0
        again = {r["key"]: r for r in map_rows(Path(scratch))}
    assert again.keys() == kept.keys(), (name, sorted(again.keys() ^ kept.keys()))
    status = all(again[k]["status"] == kept[k]["status"] for k in kept)
    diff = max((abs(float(again[k]["F_tilde"]) / float(kept[k]["F_tilde"]) - 1) if float(kept[k]["F_tilde"]) else
                abs(float(again[k]["F_tilde"])) for k in kept if kept[k]["status"] == "ok"), default=0.0)
    record = {"ranks": 2, "wall_time_s": wall, "points": len(kept), "same_status": status,
              "max_rel_diff_F_tilde": diff, "busy_cores_after": busy_cores()}
    atomic_text(MAPS / name / "timing_2ranks.json", json.dumps(record, indent=1) + "\n")
    print(f"{name} on 2 ranks: {wall:.0f} s, max |dF~/F~| = {diff:.1e} against the kept points", file=sys.stderr)


def map_rows(directory) -> list[dict]:
    """A sweep directory's points, each with its file key (the grid values and the settings' digest)."""
    return [{**json.loads(p.read_text()), "key": p.stem} for p in (Path(directory) / "points").glob("*.json")]


def maps() -> list[dict]:
    """Each map's cost: its points' own solve times (``solve_time_s`` in each point's record:
    the sum over every run that solved them, interrupted ones included), and the last run's
    ``timing.json`` (points solved and reused, ranks, wall time)."""
    out = []
    for path in sorted(MAPS.glob("*/sweep.csv")):
        timing_file = path.parent / "timing.json"
        timing = json.loads(timing_file.read_text()) if timing_file.exists() else {}
        rows = list(csv.DictReader(path.open()))
        records = [json.loads(p.read_text()) for p in (path.parent / "points").glob("*.json")]
        timed = [r["solve_time_s"] for r in records if "solve_time_s" in r]
        # points and failures as the map stands now (a later rerun may have solved a failed point)
        out.append({"map": path.parent.name, "points": len(rows), "failed": sum(r["status"] != "ok" for r in rows),
                    "timed": len(timed), "core_seconds": sum(timed),
                    "slowest_point_s": max(timed, default=math.nan),
                    "last_run": {k: timing.get(k) for k in ("solved", "reused", "ranks", "wall_time_s")},
                    "two_ranks": json.loads(two.read_text()) if (two := path.parent / "timing_2ranks.json").exists()
                    else None})
    return out


def write(rows, refs, timings, wall, load) -> None:
    from bcfem.plots import pyplot

    atomic_text(OUT / "crater-design.csv", csv_text(rows, COLUMNS))
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for i, (name, ref) in enumerate(refs.items()):
        ok = [r for r in rows if r["point"] == name and r["status"] == "ok" and r.get("error", 0) > 0]
        if not ok:
            continue
        kind = "Richardson" if ref["kind"] == "richardson" else "finest mesh"
        ax.loglog([r["wall_time_s"] for r in ok], [r["error"] for r in ok], "o-", color=f"C{i}",
                  label=f"{name} (vs {kind})")
        for r in ok:
            ax.annotate(f"{r['size_crater']:g}", (r["wall_time_s"], r["error"]), fontsize=6.5, xytext=(3, 3),
                        textcoords="offset points", color=f"C{i}")
    ax.axhline(0.01, color="k", lw=0.8, ls="--", label="1 %")
    ax.set_xlabel("wall time of one cycle [s] (one core, warm JIT cache)")
    ax.set_ylabel("relative error of F~ (numbers: size_crater)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title("crater design space: mesh convergence of the suction force", fontsize=9)
    fig.tight_layout()
    save_figure(fig, OUT / "crater-design.png")
    plt.close(fig)
    summary = {"wall_s": wall, "busy": load, "maps": timings, "provenance": provenance()}
    write_summary("crater-design", summary)
    write_report(OUT / "crater-design.md", report(rows, summary))


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report: benchmarks/templates/crater-design.md filled from the mesh study's rows
    (CSV; the references are recomputed from them) and the summary (JSON: the maps' costs as they
    were read, the study's wall time, the busy cores)."""
    timings = summary["maps"]

    def timed(t, i):
        if not t["timed"]:
            return "-"
        return [f"{t['core_seconds']:.0f}", f"{t['core_seconds'] / t['timed']:.1f}", f"{t['slowest_point_s']:.0f}",
                f"{t['core_seconds'] / 120:.1f}" + ("" if t["timed"] == t["points"] else " (timed points)")][i]

    def measured(t):
        two = t["two_ranks"]
        return "-" if two is None else (f"{two['wall_time_s'] / 60:.1f}, {two['max_rel_diff_F_tilde']:.0e}"
                                        + ("" if two["same_status"] else ", status differs"))

    def last(t):
        run = t["last_run"]
        return "-" if run["wall_time_s"] is None else \
            f"{run['solved']} / {run['reused']}, {run['ranks']}, {run['wall_time_s']:.0f}"

    maps_table = table(timings, [
        ("map", "{map}"), ("points", "{points}"), ("failed", "{failed}"), ("timed", "{timed}"),
        *[(head, lambda t, i=i: timed(t, i)) for i, head in enumerate(
            ("core-s", "core-s per point", "slowest point [s]", "est. wall on 2 ranks [min]"))],
        ("measured on 2 ranks: wall [min], max dF~/F~", measured),
        ("last run: solved / reused, ranks, wall [s]", last)])
    maps_total = ""
    if timings:
        total = sum(t["core_seconds"] for t in timings)
        untimed = sum(t["points"] - t["timed"] for t in timings)
        maps_total = ("\n" + f"All timed points: {total / 3600:.2f} core-hours, {total / 120:.0f} min on 2 ranks"
                      + (f"; {untimed} points carry no time and are not counted (their maps' `last run` column "
                         "gives the wall time of the run that solved them, where it solved them all)" if untimed else "")
                      + ".\n")
    points = []
    for name in POINTS:
        series = [r for r in rows if r["point"] == name and r["status"] == "ok"]
        if not series:
            points.append(render(TEMPLATE, rows, summary, section="point-failed", name=name))
            continue
        ref = reference(series)
        if ref["kind"] == "richardson":
            text = f"Reference F~ = {ref['F']:.6f}: Richardson extrapolation with the observed order p = {ref['order']:.2f}."
        else:
            text = (f"Reference F~ = {ref['F']:.6f}: the finest mesh (size {ref['finest']:g}); the meshes do not "
                    "converge monotonically, so errors are relative to that mesh, not to the exact value.")

        def ok(how):
            return lambda r: how(r) if r["status"] == "ok" else ""

        mesh = table([r for r in rows if r["point"] == name], [
            ("size_crater", "{size_crater:g}"), ("dofs", ok(lambda r: f"{r['dofs']}")),
            ("F~", lambda r: f"{r['F_tilde']:.5f}" if r["status"] == "ok" else f"failed: {r['reason'][:80]}"),
            ("rel. error", ok(lambda r: fmt(r.get("error")))), ("A2/A0", ok(lambda r: f"{r['A2_over_A0']:.4f}")),
            ("eps", ok(lambda r: f"{r['preload']:.4f}")), ("stability", ok(lambda r: f"{r['stability']}")),
            ("wall [s]", ok(lambda r: f"{r['wall_time_s']:.1f}"))])
        points.append(render(TEMPLATE, rows, summary, section="point", name=name, reference=text, table=mesh))
    return render(TEMPLATE, rows, summary, wall_min=summary["wall_s"] / 60, load_start=summary["busy"][0],
                  load_end=summary["busy"][1], maps_table=maps_table, maps_total=maps_total,
                  points="".join(points).rstrip("\n") + "\n", provenance=provenance_note(summary))


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--worker":
        emit(worker(json.loads(sys.argv[2])))
    else:
        main()
