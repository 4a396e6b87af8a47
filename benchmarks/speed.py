"""Before and after, in one run: the crater cycles and the blister, at two commits.

Each case runs as a whole ``bcfem run`` process pinned to one core (one BLAS thread), with
the code of two commits: ``--before`` (checked out into a temporary git worktree) and the
working tree. Rounds interleave the versions and cases in shuffled order so that both see
the machine alike; the best wall time is kept, and the median shown beside it. One more
run of each case under PETSc's ``-log_view`` counts the factorisations and assemblies.
The blister's yardstick is the scipy shooting code of ``blister_shooting.py`` at the
tolerance whose error matches the default mesh's.

Cases: the hemisphere's cycle (``bcfem run crater``) at preload 0.2, 0.3 and closure, and
``bcfem run blister-rigid --material neo-hookean --alpha 0 --v-max 1``.

Usage (from the repository root, on an otherwise idle machine)::

    .venv/bin/python benchmarks/speed.py --before COMMIT              # 3 rounds, about 8 min
    .venv/bin/python benchmarks/speed.py --before COMMIT --repeats 5
    .venv/bin/python benchmarks/speed.py --before COMMIT --maps-only  # after the maps were solved again

Writes ``docs/benchmarks/speed.{csv,md,png}``.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import (
    ROOT,
    atomic_text,
    busy_cores,
    commit,
    cpu_name,
    csv_text,
    loadavg,
    one_core_env,
    pinned,
    provenance,
    provenance_note,
    render,
    render_again,
    save_figure,
    table,
    worker_result,
    write_report,
    write_summary,
)

OUT = ROOT / "docs" / "benchmarks"
BCFEM = ROOT / ".venv" / "bin" / "bcfem"
CASES = {
    "crater 0.2": ["crater", "--preload", "0.2"],
    "crater 0.3": ["crater", "--preload", "0.3"],
    "crater closure": ["crater", "--preload", "closure"],
    "blister": ["blister-rigid", "--material", "neo-hookean", "--alpha", "0", "--v-max", "1"],
}
#: the shooting code's ODE tolerance: error 6e-12 in P_max, the default blister mesh's 3e-11
SHOOTING_RTOL = 1e-10
#: PETSc events counted from -log_view (a factorisation is an LU or an LDL^T one)
COUNTED = ("MatLUFactorSym", "MatLUFactorNum", "MatCholFctrSym", "MatCholFctrNum", "SNESJacobianEval",
           "SNESFunctionEval", "MatCreateSubMats")
#: the JIT cache of these runs: ffcx lists its directory at every form it loads, so a cache shared
#: with years of other forms would add its own start-up time to both versions
JIT_CACHE = Path.home() / ".cache" / "bcfem-speed"
#: the parts of the split spent inside Newton solves
NEWTON = ("assembly", "discrete_terms", "factorisation", "linear_solve", "newton_other")
SPLIT = ("assembly", "discrete_terms", "factorisation", "linear_solve", "newton_other", "stability", "other")


def environment() -> dict:
    return one_core_env(XDG_CACHE_HOME=str(JIT_CACHE))


def run_case(code: Path, case: str, out: Path, log_view: Path | None = None) -> dict:
    """One whole ``bcfem run`` process with the package at ``code``."""
    env = environment()
    env["PYTHONPATH"] = str(code)
    if log_view:
        env["PETSC_OPTIONS"] = f"-log_view :{log_view}"
    cmd = pinned([str(BCFEM), "run", *CASES[case], "--out", str(out), "--quiet", "--no-plots"])
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=tempfile.gettempdir(), capture_output=True, text=True)
    process = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"{case} with {code} failed:\n{proc.stderr[-2000:]}")
    summary = json.loads((out / "summary.json").read_text())
    split = summary["time_split_s"]
    if "linear_solve_and_newton" in split:  # the older split: one part for all of Newton's rest
        split = {**split, "newton_other": split.pop("linear_solve_and_newton")}
    result = (summary["F_tilde"] if case.startswith("crater") else
              next(lp["P"] for lp in summary["limit_points"] if lp["kind"] == "max"))
    its = max(summary["newton_iterations"], 1)
    newton = sum(split.get(k, 0.0) for k in NEWTON)
    return {"process": process, "run": summary["wall_time_s"], "result": result,
            "ms_per_iteration": 1e3 * newton / its, "factorisation_ms_per_iteration": 1e3 * split.get("factorisation", 0) / its,
            "steps": summary["steps"], "newton_iterations": summary["newton_iterations"],
            "failed_solves": summary["failed_solves"], "stability": summary.get("stability", ""),
            **{f"split_{k}": split.get(k, 0.0) for k in SPLIT}}


def shooting() -> dict:
    cmd = pinned([sys.executable, "-c", "import blister_shooting as b; b.main()", "--shoot",
                  json.dumps({"rtol": SHOOTING_RTOL})])
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=environment(), cwd=ROOT / "benchmarks", capture_output=True, text=True,
                          check=True)
    process = time.perf_counter() - t0
    return {"process": process, "result": worker_result(proc.stdout)["P_max"]}


def counts(log: Path) -> dict:
    """Event counts from a -log_view file."""
    found = dict.fromkeys(COUNTED, 0)
    for line in log.read_text().splitlines():
        m = re.match(r"^(\w+)\s+(\d+)\s", line)
        if m and m.group(1) in found:
            found[m.group(1)] = int(m.group(2))
    return found


def worktree(commit: str) -> Path:
    path = Path(tempfile.mkdtemp(prefix="bcfem-before-"))
    subprocess.run(["git", "worktree", "add", "--detach", str(path), commit], cwd=ROOT, check=True,
                   capture_output=True)
    return path


def measure(before: Path, repeats: int, cases) -> tuple[list[dict], dict]:
    versions = {"before": before, "after": ROOT}
    jobs = [(v, c) for v in versions for c in cases] + ([("shooting", "blister")] if "blister" in cases else [])
    times: dict = {job: [] for job in jobs}
    last: dict = {}
    scratch = Path(tempfile.mkdtemp(prefix="bcfem-speed-"))
    for version, case in jobs:  # untimed: compiles what the JIT cache lacks
        if version != "shooting":
            run_case(versions[version], case, scratch / f"warm-{version}-{case.replace(' ', '_')}")
    for rnd in range(repeats):
        random.Random(rnd).shuffle(jobs)
        for version, case in jobs:
            out = scratch / f"{version}-{case.replace(' ', '_')}-{rnd}"
            r = shooting() if version == "shooting" else run_case(versions[version], case, out)
            times[(version, case)].append(r)
            last[(version, case)] = r
            print(f"round {rnd + 1}/{repeats}  {version:8s} {case:15s} {r['process']:7.2f} s", flush=True)
    rows = []
    for (version, case), rs in sorted(times.items(), key=lambda kv: (kv[0][1], kv[0][0] != "before")):
        best = min(rs, key=lambda r: r["process"])
        row = {"version": version, "case": case, **best, "process_median": statistics.median(r["process"] for r in rs),
               "repeats": len(rs), "results_spread": max(r["result"] for r in rs) - min(r["result"] for r in rs)}
        if version != "shooting":
            log = scratch / f"log-{version}-{case.replace(' ', '_')}.txt"
            run_case(versions[version], case, scratch / f"counted-{version}-{case.replace(' ', '_')}", log)
            row.update(counts(log))
        rows.append(row)
    shutil.rmtree(scratch, ignore_errors=True)
    return rows, {"load_start": loadavg()}


COLUMNS = ["case", "version", "process", "process_median", "run", "result", "steps", "newton_iterations",
           "ms_per_iteration", "factorisation_ms_per_iteration",
           "failed_solves", "stability", *COUNTED, *(f"split_{k}" for k in SPLIT), "repeats", "results_spread"]


def runs_table(rows: list[dict], commit: str) -> str:
    """The cases' table: both versions' runs and the shooting code's."""
    def bcfem(how):
        return lambda r: "" if r["version"] == "shooting" else how(r)

    return table(rows, [
        ("case", "{case}"),
        ("version", lambda r: f"shooting, rtol {SHOOTING_RTOL:.0e}" if r["version"] == "shooting"
         else f"before ({commit})" if r["version"] == "before" else r["version"]),
        ("process [s] (median)", "{process:.2f} ({process_median:.2f})"), ("run [s]", bcfem(lambda r: f"{r['run']:.2f}")),
        ("F~ or P_max", lambda r: f"{r['result']:.13f}" if r["version"] == "shooting" else f"{r['result']:.13g}"),
        ("Newton its", bcfem(lambda r: f"{r['newton_iterations']}")),
        ("ms per it (factorisation)", bcfem(lambda r: f"{r['ms_per_iteration']:.1f} ({r['factorisation_ms_per_iteration']:.1f})")),
        ("failed solves", bcfem(lambda r: f"{r['failed_solves']}")),
        ("analyses / factorisations", bcfem(lambda r: f"{r['MatLUFactorSym'] + r['MatCholFctrSym']} / "
                                                      f"{r['MatLUFactorNum'] + r['MatCholFctrNum']}")),
        ("Jacobians / residuals", bcfem(lambda r: f"{r['SNESJacobianEval']} / {r['SNESFunctionEval']}")),
        *[(head, bcfem(lambda r, k=k: f"{r[f'split_{k}']:.2f}")) for head, k in zip(
            ("assembly", "discrete", "factorisation", "solve", "Newton rest", "stability", "other"), SPLIT)]])


def figure(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = [r for r in rows if r["version"] != "shooting"]
    fig, ax = plt.subplots(figsize=(8, 4))
    labels = [f"{r['case']}\n{r['version']}" for r in runs]
    bottom = [0.0] * len(runs)
    for k in SPLIT:
        values = [r[f"split_{k}"] for r in runs]
        ax.bar(labels, values, bottom=bottom, label=k)
        bottom = [b + v for b, v in zip(bottom, values)]
    ax.set_ylabel("wall time of the run [s] (one core)")
    ax.set_title("bcfem run: where the time goes, before and after")
    ax.legend(fontsize=7)
    ax.tick_params(axis="x", labelsize=7)
    fig.tight_layout()
    save_figure(fig, path)


MAPS = Path("docs/figures/crater_design/sweeps")
TEMPLATE = "speed.md"


def map_timings(commit: str) -> str:
    """The design maps' section: each map's ``timing.json`` now, and at ``commit`` (git)."""
    lines, wall, core, core_old, ranks = [], 0.0, 0.0, 0.0, set()
    for path in sorted((ROOT / MAPS).glob("*/timing.json")):
        now = json.loads(path.read_text())
        old = subprocess.run(["git", "show", f"{commit}:{MAPS / path.parent.name / 'timing.json'}"], cwd=ROOT,
                             capture_output=True, text=True)
        old = json.loads(old.stdout) if old.returncode == 0 else None
        pooled = now.get("pooled_sweeps", 1) > 1
        core_now = now["point_solve_time_s"] if pooled else now["wall_time_s"] * now["ranks"]
        wall = max(wall, now["wall_time_s"]) if pooled else wall + now["wall_time_s"]
        core += core_now
        ranks.add(now["ranks"])
        core_old += old["wall_time_s"] * old["ranks"] if old else float("nan")
        lines.append({"map": path.parent.name, "solved": now["solved"], "failed": now["failed"], "core": core_now,
                      "old": f"{old['wall_time_s'] * old['ranks'] if old else float('nan'):.0f} "
                             f"({old['ranks'] if old else ''})"})
    rows = table(lines, [("map", "{map}"), ("points", "{solved}"), ("failed", "{failed}"), ("core-s", "{core:.0f}"),
                         (f"before ({commit}): core-s (ranks)", "{old}")])
    rows += f"\n| **all** | | | {core:.0f} | {core_old:.0f} |"
    return render(TEMPLATE, lines, {}, section="maps", maps_dir=MAPS, before=commit, table=rows, wall=wall,
                  wall_min=wall / 60, ranks=" or ".join(map(str, sorted(ranks)))).rstrip("\n")


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report: benchmarks/templates/speed.md filled from the runs (CSV), the summary
    (JSON: settings, machine, the two commits) and the maps' ``timing.json`` files."""
    return render(TEMPLATE, rows, summary, runs=runs_table(rows, summary["before"]),
                  maps=map_timings(summary["before"]), provenance=provenance_note(summary))


def positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1 (got {text})")
    return value

def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", help="the commit to compare with (required unless --render-only)")
    parser.add_argument("--repeats", type=positive_int, default=3, help="rounds, >= 1 (default 3)")
    parser.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES), metavar="CASE",
                        help=f"a subset of: {', '.join(CASES)}")
    parser.add_argument("--maps-only", action="store_true",
                        help="rewrite only speed.md's maps section, from the kept maps' timing.json")
    parser.add_argument("--render-only", action="store_true",
                        help="render speed.md again from the speed.csv and .json that are there")
    args = parser.parse_args(argv)
    if not args.render_only and not args.before:
        parser.error("--before COMMIT is required: the code to compare this checkout with")
    if args.render_only:
        render_again("speed", report)
        print(f"wrote {OUT / 'speed.md'}")
        return
    if args.maps_only:
        text = (OUT / "speed.md").read_text()
        kept = text[:text.index("## The twelve design maps")]
        write_report(OUT / "speed.md", kept + map_timings(args.before))
        print(f"wrote {OUT / 'speed.md'}")
        return
    busy = busy_cores()
    before = worktree(args.before)
    try:
        rows, info = measure(before, args.repeats, args.cases)
    finally:
        subprocess.run(["git", "worktree", "remove", "--force", str(before)], cwd=ROOT, capture_output=True)
    atomic_text(OUT / "speed.csv", csv_text(rows, COLUMNS))
    figure(rows, OUT / "speed.png")
    summary = {"repeats": args.repeats, "cpu": cpu_name(), "cores": os.cpu_count(), "busy": busy,
               "load_start": info["load_start"], "before": args.before, "after": commit(),
               "jit_cache": f"~/{JIT_CACHE.relative_to(Path.home())}", "provenance": provenance()}
    write_summary("speed", summary)
    write_report(OUT / "speed.md", report(rows, summary))
    print(f"wrote {OUT / 'speed.md'}")


if __name__ == "__main__":
    main()
