"""Accuracy vs wall time of the air-filled crater's suction cycle (scene ``crater``).

Measures, on one core with a warm JIT cache:

* the suction F~ = (1 - p2/pa) A2/A0 at the preloads eps = 0.2 and 0.4 on the
  meshes size_crater = 0.16, 0.12, 0.09, 0.06, 0.045, 0.035 (element size at
  the crater over the crater radius; P2-P1 Taylor-Hood is the scene's only
  element, so there is no degree study), with its error against a reference:
  a Richardson extrapolation of the finest meshes when the sequence converges
  monotonically, else the finest mesh itself (said so in the md);
* the self-convergence of the smooth functionals V2/V0 and p2/pa, with their
  observed rates;
* the effect of the crater wall's surface energy (the creasing regulariser):
  F~ at eps = 0.3 and 0.4 on the default mesh with surface_energy = 0.005,
  0.01 (default) and 0.02;
* the wall time of one full ``bcfem run crater`` cycle on 2 MPI ranks at
  engineering accuracy (F~ within 1 % of the reference at eps = 0.2), with
  ``/usr/bin/time``.

Every one-core solve runs in its own subprocess pinned to one core (``--core``);
the 2-rank runs use both cores. At most 2 solver processes run at a time.
All of them import one snapshot of ``bcfem/``, copied when the benchmark starts
(``PYTHONPATH``), so that edits to the library during the run cannot mix
versions; its content hash is recorded, and a change of the repository's
library during the run is reported in the md.

Usage (from the repository root)::

    .venv/bin/python benchmarks/crater_air.py              # ~6 min
    .venv/bin/python benchmarks/crater_air.py --repeats 1  # quicker timings

Writes ``docs/benchmarks/crater-air.{csv,md,png}`` (atomically).
"""

from __future__ import annotations

import time

T_START = time.perf_counter()

import argparse  # noqa: E402
import hashlib  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import os  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402
from types import SimpleNamespace  # noqa: E402

from common import (  # noqa: E402
    MONOTONE_MESHES,
    ROOT,
    atomic_text,
    busy_cores,
    cpu_name,
    csv_text,
    emit,
    fmt,
    git_state,
    kept_sections,
    loadavg,
    observed_order,
    one_core_env,
    pinned,
    provenance,
    provenance_note,
    reference,
    render,
    render_again,
    save_figure,
    table,
    wait_idle,
    worker_prologue,
    worker_result,
    write_report,
    write_summary,
)

OUT = ROOT / "docs" / "benchmarks"
BIN = Path(sys.executable).parent
EPS_DEFAULT = [0.2, 0.4]
SIZES_DEFAULT = [0.16, 0.12, 0.09, 0.06, 0.045, 0.035]
REG_EPS = [0.3, 0.4]  # preloads of the regulariser study
REG_GAMMAS = [0.005, 0.01, 0.02]  # halved, default, doubled
GAMMA = 0.01  # the scene default surface_energy
SIZE_DEFAULT = 0.06  # the scene default size_crater
ENGINEERING = 0.01  # "engineering accuracy": F~ within 1 % of the reference
MPI_EPS = 0.2  # preload of the 2-rank timing
MPI_BUDGET = 30.0  # [s] target of the 2-rank cycle
COMMAND = ".venv/bin/python benchmarks/crater_air.py"
TIGHT = "-snes_rtol 1e-14 -snes_atol 1e-13 -snes_stol 1e-15"  # the solver-tolerance check
#: sections of the md that other scripts write: crater_air_edge.py, crater_paths.py
KEPT = ("edge", "paths")
TIMEOUT = 180.0  # [s] a one-core run is killed after this (normal runs take 1-60 s)


# ----------------------------------------------------------------------------------------
# worker: one cycle in a fresh process; prints "RESULT <json>"
# ----------------------------------------------------------------------------------------
def worker(case: dict) -> dict:
    from mpi4py import MPI

    worker_prologue()
    import bcfem
    from bcfem.scenes import crater

    if case.get("petsc"):  # user options win over bcfem's (bcfem.solver.options.merge)
        from petsc4py import PETSc

        PETSc.Options().insertString(case["petsc"])
    t_import = time.perf_counter() - T_START
    out = {**case, "t_import": t_import, "status": "ok", "reason": "", "bcfem": bcfem.__file__}
    t1, c1 = time.perf_counter(), time.process_time()
    try:
        params = crater.Params(preload=case["eps"], size_crater=case["size_crater"],
                               surface_energy=case["surface_energy"])
        _, s = crater.solve(params, MPI.COMM_WORLD)
        out.update(solves=s["newton_solves"], its=s["newton_iterations"])
        kinds = [e["kind"] for e in s["instabilities"]]
        out.update({k: s[k] for k in ("F_tilde", "V1_over_V0", "V2_over_V0", "p2_over_pa", "A2_over_A0",
                                      "eps_at_zero_force", "eps_closure", "dofs")},
                   wall_time_s=s["wall_time_s"], stability_events=kinds.count("stability"),
                   snaps=kinds.count("snap"), events=s["instabilities"])
        out = {k: (float(v) if hasattr(v, "dtype") else v) for k, v in out.items()}
    except Exception as error:  # recorded, with its message
        out.update(status="failed", reason=f"{type(error).__name__}: {error}")
    out.update(t_solve=time.perf_counter() - t1, c_solve=time.process_time() - c1)
    return out


# ----------------------------------------------------------------------------------------
# driver
# ----------------------------------------------------------------------------------------
CORE = "0"
VALUES = ("F_tilde", "V1_over_V0", "V2_over_V0", "p2_over_pa", "A2_over_A0")


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def run_case(case: dict) -> dict:
    """``common.run_worker`` with a time limit: a run that has not finished after ``TIMEOUT``
    seconds is killed and recorded as ``status = "timeout"``."""
    cmd = pinned([sys.executable, __file__, "--worker", json.dumps(case)], CORE)
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, env=one_core_env(), capture_output=True, text=True, cwd=ROOT, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        t = time.perf_counter() - t0
        return {**case, "status": "timeout", "reason": f"killed after {TIMEOUT:g} s without a result",
                "t_solve": t, "c_solve": math.nan, "t_process": t, "t_import": math.nan, "its": None}
    t_process = time.perf_counter() - t0
    result = worker_result(proc.stdout)
    if proc.returncode != 0 or result is None:
        raise RuntimeError(f"case {case} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    return {**result, "t_process": t_process}


def timed(case: dict, repeats: int) -> dict:
    """Best of ``repeats`` runs (the minimum is the least disturbed by other load); the values
    are the first run's, and ``reproducible`` says whether every run gave the same ones."""
    runs = [run_case(case)]
    if runs[0]["status"] != "timeout":  # a run that hit the time limit is not repeated
        runs += [run_case(case) for _ in range(repeats - 1)]
    res = dict(runs[0])
    for key in ("t_solve", "c_solve", "t_process", "t_import"):
        res[key] = min(r[key] for r in runs)
    res["wall_time_s"] = min((r.get("wall_time_s") or r["t_solve"]) for r in runs)
    res["runs"] = len(runs)
    res["reproducible"] = all(r["status"] == res["status"] and all(r.get(k) == res.get(k) for k in VALUES)
                              for r in runs)
    return res


def mpi_cycle(size: float, repeats: int) -> dict:
    """``mpirun -n 2 bcfem run crater --preload MPI_EPS --size-crater size --quiet --out DIR`` under
    ``/usr/bin/time``: best of ``repeats`` (the values are the first run's)."""
    runs = []
    for _ in range(repeats):
        out = Path(tempfile.mkdtemp(prefix="bcfem-crater-bench-"))
        cmd = ["/usr/bin/time", "-f", "TIME %e %U %S", str(BIN / "mpirun"), "-n", "2", str(BIN / "bcfem"), "run",
               "crater", "--preload", str(MPI_EPS), "--size-crater", str(size), "--quiet", "--out", str(out)]
        env = one_core_env(PATH=f"{BIN}:{os.environ.get('PATH', '')}")
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT)
        line = [ln for ln in proc.stderr.splitlines() if ln.startswith("TIME ")]
        run = {"status": "ok" if proc.returncode == 0 else "failed", "reason": "",
               "time": float(line[-1].split()[1]) if line else math.nan,
               "user": float(line[-1].split()[2]) if line else math.nan}
        try:
            s = json.loads((out / "summary.json").read_text())
            run.update({k: s[k] for k in (*VALUES, "dofs", "wall_time_s", "ranks")})
        except (OSError, ValueError, KeyError) as error:
            run.update(status="failed", reason=f"exit {proc.returncode}: {error}; {proc.stderr[-500:]}")
        shutil.rmtree(out, ignore_errors=True)
        runs.append(run)
    res = dict(runs[0])
    res["times"] = [r["time"] for r in runs]
    res["time"] = min(res["times"])
    res["wall_time_s"] = min(r.get("wall_time_s", math.nan) for r in runs)
    res["command"] = (f"/usr/bin/time mpirun -n 2 bcfem run crater --preload {MPI_EPS} --size-crater {size} "
                      "--quiet --out DIR")
    return res


def library_hash(pkg: Path) -> str:
    """sha256 over the library's files (paths and contents), __pycache__ excluded."""
    h = hashlib.sha256()
    for f in sorted(p for p in pkg.rglob("*") if p.is_file() and "__pycache__" not in p.parts):
        h.update(str(f.relative_to(pkg)).encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:12]


def snapshot_library() -> tuple[Path, str]:
    """Copy bcfem/ to a temporary directory and put it first on the workers' PYTHONPATH."""
    tmp = Path(tempfile.mkdtemp(prefix="bcfem-crater-bench-lib-"))
    shutil.copytree(ROOT / "bcfem", tmp / "bcfem", ignore=shutil.ignore_patterns("__pycache__"))
    os.environ["PYTHONPATH"] = os.pathsep.join([str(tmp), *filter(None, [os.environ.get("PYTHONPATH")])])
    return tmp, library_hash(tmp / "bcfem")


def self_convergence(series, key):
    """Per mesh: the relative change to the next finer mesh and the rate of those changes;
    the fitted slope of log|q - q_finest| against log h; the number of sign changes."""
    h = [r["size_crater"] for r in series]
    q = [r[key] for r in series]
    delta = [abs(b - a) / abs(b) if b else math.nan for a, b in zip(q, q[1:])] + [math.nan]
    rates = [math.nan] + [math.log(a / b) / math.log(h[i] / h[i + 1]) if a > 0 and b > 0 else math.nan
                          for i, (a, b) in enumerate(zip(delta, delta[1:-1]))] + [math.nan]
    rates = rates[: len(q)]
    d = [b - a for a, b in zip(q, q[1:])]
    pts = [(math.log(hh), math.log(abs(v - q[-1]))) for hh, v in zip(h[:-1], q[:-1]) if v != q[-1]]
    slope = math.nan
    if len(pts) >= 2:
        mx = sum(x for x, _ in pts) / len(pts)
        my = sum(y for _, y in pts) / len(pts)
        slope = sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)
    return {"values": q, "delta": delta, "rates": rates, "fit": slope,
            "sign_changes": sum(1 for a, b in zip(d, d[1:]) if a * b < 0),
            "order3": observed_order(h[-3:], q[-3:]) if len(q) >= 3 else None}


def references(rows, preloads) -> dict:
    """Per preload of the mesh study: the reference F~ (:func:`common.reference`) of its successful
    meshes and their self-convergence (``conv``)."""
    refs = {}
    for eps in preloads:
        series = [r for r in rows if r["study"] == "mesh" and r["eps"] == eps and r["status"] == "ok"]
        if series:
            refs[eps] = reference(series)
            refs[eps]["conv"] = {k: self_convergence(series, k) for k in ("F_tilde", "V2_over_V0", "p2_over_pa",
                                                                           "A2_over_A0")}
    return refs


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=2, help="runs per case (the best time is kept)")
    ap.add_argument("--core", default="0", help="the core the one-core solves are pinned to (taskset -c)")
    ap.add_argument("--eps", type=float, nargs="+", default=EPS_DEFAULT, help="preloads of the mesh study")
    ap.add_argument("--sizes", type=float, nargs="+", default=SIZES_DEFAULT, help="size_crater of the meshes")
    ap.add_argument("--reg-eps", type=float, nargs="*", default=REG_EPS,
                    help="preloads of the regulariser study (none: skip it)")
    ap.add_argument("--idle-wait", type=float, default=600.0,
                    help="seconds to wait for an idle machine before each 2-rank timing")
    ap.add_argument("--render-only", action="store_true",
                    help="render crater-air.md again from the crater-air.csv and .json that are there")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.render_only:
        render_again("crater-air", report)
        return
    global CORE
    CORE = args.core
    if args.worker:
        emit(worker(json.loads(args.worker)))
        return

    from mpi4py import MPI

    if MPI.COMM_WORLD.size > 1:
        sys.exit("the benchmark drives its own processes: run it without mpirun")
    sys.path.insert(0, str(Path(__file__).parent))

    args.sizes = sorted(args.sizes, reverse=True)  # coarse to fine
    args.load = [loadavg()]
    args.git = git_state()  # the repository's state when the snapshot is taken
    snapshot, args.lib_hash = snapshot_library()
    log(f"bcfem snapshot {args.lib_hash} of {args.git} in {snapshot}")
    t_bench = time.perf_counter()
    try:
        rows, refs, mpi = measure(args)
    finally:
        shutil.rmtree(snapshot, ignore_errors=True)
    args.load.append(loadavg())
    args.lib_hash_end = library_hash(ROOT / "bcfem")
    args.git_end = git_state()
    args.wall = time.perf_counter() - t_bench
    write_outputs(rows, refs, mpi, args)


def measure(args):

    # warm the JIT cache (the forms do not depend on the mesh; a crater that closes adds the vacuum term)
    warm = run_case({"eps": 0.2, "size_crater": 0.16, "surface_energy": GAMMA})
    if not warm["bcfem"].startswith(os.environ["PYTHONPATH"].split(os.pathsep)[0]):
        raise RuntimeError(f"the workers import bcfem from {warm['bcfem']}, not from the snapshot")

    rows = []
    # -- mesh convergence ----------------------------------------------------------------
    for eps in args.eps:
        for size in args.sizes:
            r = timed({"eps": eps, "size_crater": size, "surface_energy": GAMMA}, args.repeats)
            rows.append({"study": "mesh", **r})
            log(f"eps {eps} size {size}: {r['status']} F~={r.get('F_tilde')!r} {r['t_solve']:.2f} s "
                f"({r.get('stability_events')} stability, {r.get('snaps')} snaps) {r['reason'][:200]}")

    refs = references(rows, args.eps)
    for eps in refs:
        series = [r for r in rows if r["study"] == "mesh" and r["eps"] == eps and r["status"] == "ok"]
        for r in series:
            is_ref = refs[eps]["kind"] == "finest" and r["size_crater"] == refs[eps]["finest"]
            r["error"] = math.nan if is_ref else abs(r["F_tilde"] - refs[eps]["F"]) / abs(refs[eps]["F"])
    for r in rows:
        r.setdefault("error", math.nan)

    # -- regulariser ---------------------------------------------------------------------
    for eps in args.reg_eps:
        for gamma in REG_GAMMAS:  # the default is run again: a check that the mesh study's run reproduces
            r = {"study": "regulariser",
                 **timed({"eps": eps, "size_crater": SIZE_DEFAULT, "surface_energy": gamma}, args.repeats)}
            rows.append(r)
            log(f"regulariser eps {eps} gamma {gamma}: {r['status']} F~={r.get('F_tilde')!r} "
                f"{r['t_solve']:.2f} s {r['reason'][:200]}")
        reg = [r for r in rows if r["study"] == "regulariser" and r["eps"] == eps]
        default = next(r for r in reg if r["surface_energy"] == GAMMA)
        for r in reg:
            r["error"] = (abs(r["F_tilde"] / default["F_tilde"] - 1)
                          if r["status"] == "ok" and default["status"] == "ok" and r is not default else math.nan)

    # -- solver tolerance: is the mesh-to-mesh scatter discretisation or Newton's stopping test?
    for eps in args.eps:
        ms = [r for r in rows if r["study"] == "mesh" and r["eps"] == eps and r["status"] == "ok"]
        # the default mesh, and the finest one where its path is smooth (no stability events, no snaps)
        smooth_finest = [ms[-1]["size_crater"]] if ms and not (ms[-1]["stability_events"] or ms[-1]["snaps"]) else []
        for base in [r for r in ms if r["size_crater"] in (SIZE_DEFAULT, *smooth_finest)]:
            r = run_case({k: base[k] for k in ("eps", "size_crater", "surface_energy")} | {"petsc": TIGHT})
            r.update(study="tolerance", runs=1, reproducible=True, error=math.nan,
                     tol_change=(abs(r["F_tilde"] / base["F_tilde"] - 1) if r["status"] == "ok" else math.nan))
            rows.append(r)
            log(f"tight tolerances eps {eps} size {base['size_crater']}: {r['status']} F~={r.get('F_tilde')!r} "
                f"(change {r['tol_change']:.1e}) {r['reason'][:200]}")

    # -- 2 ranks, engineering accuracy ---------------------------------------------------
    mpi = []
    if MPI_EPS in refs:
        ok = [r for r in rows if r["study"] == "mesh" and r["eps"] == MPI_EPS and r["status"] == "ok"
              and (r["error"] < ENGINEERING or math.isnan(r["error"]))]
        chosen = min(ok, key=lambda r: r["t_solve"])
        sizes = [chosen["size_crater"]] + ([SIZE_DEFAULT] if chosen["size_crater"] != SIZE_DEFAULT else [])
        for size in sizes:
            waited, busy = wait_idle(args.idle_wait)
            log(f"mpirun -n 2: waited {waited:.0f} s for an idle machine; {busy:.2f} cores busy")
            m = mpi_cycle(size, args.repeats)
            m["load"] = f"{busy:.1f} / {busy_cores():.1f}"
            m["waited"] = waited
            m.update(size_crater=size, eps=MPI_EPS, engineering=size == chosen["size_crater"])
            serial = next((r for r in rows if r["study"] == "mesh" and r["eps"] == MPI_EPS
                           and r["size_crater"] == size and r["status"] == "ok"), None)
            m["serial_F"], m["serial_t"] = (serial["F_tilde"], serial["t_solve"]) if serial else (None, None)
            mpi.append(m)
            rows.append({"study": "mpi2", "eps": MPI_EPS, "size_crater": size, "surface_energy": GAMMA,
                         "ranks": 2, "dofs": m.get("dofs"), "wall_time_s": m["time"],
                         **{k: m.get(k) for k in VALUES}, "status": m["status"], "reason": m["reason"],
                         "error": (abs(m["F_tilde"] - refs[MPI_EPS]["F"]) / abs(refs[MPI_EPS]["F"])
                                   if m["status"] == "ok" else math.nan),
                         "t_solve": m["wall_time_s"], "t_process": m["time"]})
            log(f"mpirun -n 2, size {size}: {m['status']} {m['times']} s, F~={m.get('F_tilde')!r}")

    for r in rows:
        r.setdefault("ranks", 1)
    return rows, refs, mpi


# ----------------------------------------------------------------------------------------
# outputs
# ----------------------------------------------------------------------------------------
COLUMNS = ["eps", "size_crater", "surface_energy", "ranks", "dofs", "wall_time_s", "F_tilde", "V2_over_V0",
           "p2_over_pa", "A2_over_A0", "error", "status", "study", "petsc", "tol_change", "V1_over_V0", "eps_at_zero_force", "eps_closure",
           "t_solve", "c_solve", "t_process", "stability_events", "snaps", "its", "runs", "reproducible", "reason"]


def write_outputs(rows, refs, mpi, args):
    from bcfem.plots import pyplot

    for r in rows:  # the CSV's wall time: the one-core solve (build + both stages), or the 2-rank process
        if r["study"] != "mpi2":
            r["wall_time_s"] = r["t_solve"]
    atomic_text(OUT / "crater-air.csv", csv_text(rows, COLUMNS))
    plt = pyplot()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12.5, 4.8))
    colours = {0.2: "tab:blue", 0.3: "tab:green", 0.4: "tab:red"}
    errs = [r["error"] for r in rows if r["study"] == "mesh" and r["status"] == "ok" and not math.isnan(r["error"])]
    top = 10 ** math.ceil(math.log10(max(errs + [1e-3]) * 3))
    omitted = []  # quantities that are 0 on the finest mesh (no relative difference)
    for eps, ref in refs.items():
        c = colours.get(eps, "tab:purple")
        ms = [r for r in rows if r["study"] == "mesh" and r["eps"] == eps]
        ok = [r for r in ms if r["status"] == "ok" and not math.isnan(r["error"])]
        label = (f"eps = {eps:g}: vs Richardson (p = {ref['order']:.2f})" if ref["kind"] == "richardson"
                 else f"eps = {eps:g}: vs finest mesh ({ref['finest']:g}, not monotone)")
        ax.loglog([r["t_solve"] for r in ok], [max(r["error"], 1e-12) for r in ok], "o-", color=c, label=label)
        for r in ok:
            ax.annotate(f"{r['size_crater']:g}", (r["t_solve"], max(r["error"], 1e-12)), fontsize=6.5,
                        xytext=(3, 3), textcoords="offset points", color=c)
        failed = [r for r in ms if r["status"] != "ok"]
        if failed:
            ax.loglog([r["t_solve"] for r in failed], [top / 2] * len(failed), "x", color=c, ms=9, mew=2,
                      label=f"eps = {eps:g}: failed run (size " + ", ".join(f"{r['size_crater']:g}" for r in failed)
                      + ")")
        # self-convergence of the smooth functionals
        conv = ref["conv"]
        ser = [r for r in ms if r["status"] == "ok"]
        for key, style in (("V2_over_V0", "s--"), ("p2_over_pa", "^:"), ("F_tilde", "o-")):
            q = conv[key]["values"]
            pts = [(r["size_crater"], abs(v / q[-1] - 1)) for r, v in zip(ser[:-1], q[:-1]) if q[-1] and v != q[-1]]
            if not q[-1]:
                omitted.append(f"{key.replace('_over_', '/')} at eps = {eps:g}")
            if pts:
                bx.loglog(*zip(*pts), style, color=c, mfc="none" if key != "F_tilde" else c,
                          label=f"eps = {eps:g}: {key.replace('_over_', '/').replace('_tilde', '~')}")
    ax.axhline(ENGINEERING, color="k", lw=0.8, ls="--", label="engineering accuracy (1 %)")
    ax.set_ylim(top=top)
    ax.set_xlabel("wall time of build + both stages [s] (one core, warm JIT cache; import excluded)")
    ax.set_ylabel("relative error of F~ (numbers: size_crater)")
    ax.set_title("F~ error against wall time", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    bx.set_xlabel("size_crater (element size at the crater / a)")
    bx.set_ylabel("|q / q(finest mesh) - 1|")
    bx.set_title("self-convergence against the finest mesh"
                 + (f" ({', '.join(omitted)}: 0 on the finest mesh, omitted)" if omitted else ""), fontsize=8)
    bx.grid(alpha=0.3, which="both")
    bx.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=3)
    fig.suptitle("air-filled crater (alpha = 1, beta = 0.467), P2-P1 Taylor-Hood, surface_energy = 0.01",
                 fontsize=10)
    fig.tight_layout()
    save_figure(fig, OUT / "crater-air.png")
    plt.close(fig)
    summary = {"settings": {k: getattr(args, k) for k in ("repeats", "core", "eps", "sizes", "reg_eps", "idle_wait")},
               "wall_s": args.wall, "load": args.load, "git": args.git, "lib_hash": args.lib_hash,
               "git_end": args.git_end, "lib_hash_end": args.lib_hash_end, "cpu": cpu_name(), "cores": os.cpu_count(),
               "mpi": [{k: m[k] for k in ("size_crater", "times", "load", "engineering")} for m in mpi],
               "provenance": provenance()}
    write_summary("crater-air", summary)
    write_report(OUT / "crater-air.md", report(rows, summary))


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report from the rows (CSV) and the summary (JSON: the settings, the machine,
    the library's copy and the 2-rank runs' timings), with the sections that other scripts keep
    in the file (``KEPT``) carried over."""
    args = SimpleNamespace(**summary["settings"], **{k: summary[k] for k in (
        "wall_s", "load", "git", "lib_hash", "git_end", "lib_hash_end", "cpu", "cores")})
    refs = references(rows, args.eps)
    mpi = []
    for m in summary["mpi"]:
        run = next(r for r in rows if r["study"] == "mpi2" and r["size_crater"] == m["size_crater"])
        serial = next((r for r in rows if r["study"] == "mesh" and r["eps"] == MPI_EPS
                       and r["size_crater"] == m["size_crater"] and r["status"] == "ok"), None)
        mpi.append({**m, "status": run["status"], "reason": run["reason"] or "", "dofs": run["dofs"],
                    "time": run["t_process"], "wall_time_s": run["t_solve"], "F_tilde": run["F_tilde"],
                    "serial_F": serial and serial["F_tilde"], "serial_t": serial and serial["t_solve"]})
    text = markdown(rows, refs, mpi, args, summary)
    if kept := kept_sections(OUT / "crater-air.md", KEPT):
        text = text.rstrip("\n") + "\n\n" + kept + "\n"
    return text


def events_text(r) -> str:
    if r["status"] != "ok":
        return ""
    return f"{r['stability_events']} / {r['snaps']}"


def markdown(rows, refs, mpi, args, summary) -> str:
    """benchmarks/templates/crater-air.md filled: its page, and its sections once per case."""
    T = "crater-air.md"

    def part(section, **fields):
        return render(T, rows, summary, section=section, **fields)

    opts = "".join([f" --repeats {args.repeats}" if args.repeats != 2 else "",
                    f" --core {args.core}" if args.core != "0" else "",
                    " --eps " + " ".join(map(str, args.eps)) if args.eps != EPS_DEFAULT else "",
                    " --sizes " + " ".join(map(str, args.sizes)) if sorted(args.sizes) != sorted(SIZES_DEFAULT) else "",
                    (" --reg-eps " + " ".join(map(str, args.reg_eps))).rstrip() if args.reg_eps != REG_EPS else "",
                    f" --idle-wait {args.idle_wait:g}" if args.idle_wait != 600 else ""])
    library = (f"`{args.git}`, copied at the start (content hash {args.lib_hash}); every run of this benchmark "
               "imports that copy")
    if args.lib_hash_end != args.lib_hash:
        library += (f". **The repository's library changed during the run** (now `{args.git_end}`, hash "
                    f"{args.lib_hash_end}): these results are for the copy, not for the library as it is now")

    references_ = []
    for eps, ref in refs.items():
        signs = ", ".join(f"{x:+.2e}" for x in ref["differences"])
        if ref["kind"] == "richardson":
            references_.append(part("reference-richardson", eps=eps, F=ref["F"], coarse=ref["meshes_used"][0],
                                    fine=ref["meshes_used"][1], order=ref["order"], monotone=MONOTONE_MESHES,
                                    signs=signs))
        else:
            why = (f"the finest {MONOTONE_MESHES} meshes do not converge monotonically" if not ref["monotone"]
                   else "the observed order of the three finest meshes is "
                   + (f"{ref['order']:.2f}, outside [0.5, 8]" if ref["order"] is not None else "undefined"))
            references_.append(part("reference-finest", eps=eps, why=why, signs=signs,
                                    sign_changes=ref["sign_changes"], finest=ref["finest"], F=ref["F"]))

    meshes = []
    for eps, ref in refs.items():
        ms = [r for r in rows if r["study"] == "mesh" and r["eps"] == eps]
        good = [r for r in ms if r["status"] == "ok"]

        def cells(r, ok_cells, failed_cells):
            return ok_cells(r) if r["status"] == "ok" else failed_cells(r)

        mesh_table = table(ms, [
            ("size_crater", "{size_crater:g}"), ("dofs", lambda r: cells(r, lambda r: f"{r['dofs']}", lambda r: "")),
            ("F~", lambda r: cells(r, lambda r: f"{r['F_tilde']:.6f}", lambda r: "")),
            ("rel. error of F~", lambda r: cells(r, lambda r: fmt(r["error"]) or "ref", lambda r: "")),
            *[(head, lambda r, k=k: cells(r, lambda r: f"{r[k]:.6f}", lambda r: ""))
              for head, k in (("V2/V0", "V2_over_V0"), ("p2/pa", "p2_over_pa"), ("A2/A0", "A2_over_A0"),
                              ("V1/V0", "V1_over_V0"))],
            ("t [s]", "{t_solve:.2f}"),
            ("cpu [s]", lambda r: cells(r, lambda r: f"{r['c_solve']:.2f}", lambda r: fmt(r["c_solve"], ".2f"))),
            ("process [s]", "{t_process:.2f}"), ("stab / snaps", events_text),
            ("Newton its", lambda r: cells(r, lambda r: f"{r['its']}", lambda r: f"{r['its'] or ''}")),
            ("status", lambda r: cells(r, lambda r: "ok" + ("" if r["reproducible"] else " (**runs differ**)"),
                                       lambda r: f"**{r['status']}**: {r['reason'][:220]}"))])
        conv_columns = [("quantity", lambda k: k.replace("_over_", "/").replace("_tilde", "~"))]
        conv_columns += [(f"change {r['size_crater']:g}", lambda k, i=i: fmt(ref["conv"][k]["delta"][i], ".1e"))
                         for i, r in enumerate(good)]
        conv_columns += [
            ("rates", lambda k: ", ".join(fmt(x, ".2f") for x in ref["conv"][k]["rates"] if not math.isnan(x))),
            ("fit", lambda k: fmt(ref["conv"][k]["fit"], ".2f")), ("p(3 finest)", lambda k: fmt(ref["conv"][k]["order3"], ".2f")),
            ("sign changes", lambda k: f"{ref['conv'][k]['sign_changes']}")]
        self_conv = table(("F_tilde", "V2_over_V0", "p2_over_pa", "A2_over_A0"), conv_columns)
        eng = [r for r in good if not math.isnan(r["error"]) and r["error"] < ENGINEERING]
        if eng:
            best = min(eng, key=lambda r: r["t_solve"])
            fastest = (f"Fastest run with F~ within {100 * ENGINEERING:g} % of the reference: size_crater "
                       f"{best['size_crater']:g}, error {best['error']:.1e}, {best['t_solve']:.2f} s on one core.")
        else:
            fastest = f"No mesh other than the reference is within {100 * ENGINEERING:g} % of it."
        meshes.append(part("mesh", eps=eps, gamma=GAMMA, table=mesh_table, self_convergence=self_conv,
                           fastest=fastest))

    # -- regulariser
    reg_rows, verdicts = [], []
    for eps in args.reg_eps:
        reg = [r for r in rows if r["study"] == "regulariser" and r["eps"] == eps]
        reg_rows += reg
        half = next(r for r in reg if r["surface_energy"] == REG_GAMMAS[0])
        if half["status"] == "ok" and not math.isnan(half["error"]):
            verdicts.append(f"eps = {eps:g}: halving changes F~ by {half['error']:.2%} "
                            f"({'meets' if half['error'] < 0.01 else 'does NOT meet'} the < 1 % requirement)")
        else:
            verdicts.append(f"eps = {eps:g}: not measured (a run failed)")

    def ok_only(fmt_ok):
        return lambda r: fmt_ok(r) if r["status"] == "ok" else ""

    regulariser = table(reg_rows, [
        ("eps", "{eps:g}"), ("surface_energy", "{surface_energy:g}"), ("F~", ok_only(lambda r: f"{r['F_tilde']:.6f}")),
        ("change vs 0.01", ok_only(lambda r: fmt(r["error"], ".2%") or "-")),
        ("V2/V0", ok_only(lambda r: f"{r['V2_over_V0']:.6f}")), ("p2/pa", ok_only(lambda r: f"{r['p2_over_pa']:.6f}")),
        ("A2/A0", ok_only(lambda r: f"{r['A2_over_A0']:.6f}")), ("t [s]", "{t_solve:.2f}"),
        ("stab / snaps", events_text),
        ("status", lambda r: "ok" if r["status"] == "ok" else f"**{r['status']}**: {r['reason'][:220]}")])

    # -- 2 ranks
    if mpi:
        def mpi_ok(fmt_ok):
            return lambda m: fmt_ok(m) if m["status"] == "ok" else ""

        times = lambda m: ", ".join(f"{t:.2f}" for t in m["times"])  # noqa: E731
        error = lambda m: abs(m["F_tilde"] - refs[MPI_EPS]["F"]) / abs(refs[MPI_EPS]["F"])  # noqa: E731
        mpi_table = table(mpi, [
            ("size_crater", "{size_crater:g}"),
            ("engineering accuracy?", mpi_ok(lambda m: "yes (fastest such mesh)" if m["engineering"] else "default mesh")),
            ("dofs", mpi_ok(lambda m: f"{m['dofs']}")),
            ("elapsed [s] (all runs)", lambda m: f"{m['time']:.2f} ({times(m)})" if m["status"] == "ok" else times(m)),
            ("in solve [s]", mpi_ok(lambda m: f"{m['wall_time_s']:.2f}")),
            ("one core, in solve [s]", mpi_ok(lambda m: fmt(m["serial_t"], ".2f"))),
            ("F~ (2 ranks)", mpi_ok(lambda m: f"{m['F_tilde']:.6f}")), ("rel. error", mpi_ok(lambda m: f"{error(m):.1e}")),
            ("2 ranks vs 1 rank", mpi_ok(lambda m: fmt(m["serial_F"] and abs(m["F_tilde"] / m["serial_F"] - 1), ".1e"))),
            ("cores busy before / after", "{load}"),
            ("status", lambda m: "ok" if m["status"] == "ok" else f"**failed**: {m['reason'][:200]}")])
        eng = next((m for m in mpi if m["engineering"] and m["status"] == "ok"), None)
        verdict = (f"\nVerdict: one cycle at engineering accuracy takes {eng['time']:.1f} s on 2 cores "
                   f"({'met' if eng['time'] < MPI_BUDGET else 'NOT met'}: target < {MPI_BUDGET:g} s).\n") if eng else ""
        mpi_text = part("mpi", mpi_eps=MPI_EPS, repeats=args.repeats, idle_wait=args.idle_wait, budget=MPI_BUDGET,
                        table=mpi_table, verdict=verdict)
    else:
        mpi_text = part("mpi-none", mpi_eps=MPI_EPS)

    # -- solver tolerance
    tol = [r for r in rows if r["study"] == "tolerance"]
    tolerance = ""
    if tol:
        def base(r):
            return next(q for q in rows if q["study"] == "mesh" and q["eps"] == r["eps"]
                        and q["size_crater"] == r["size_crater"])

        tolerance = part("tolerance", tight=TIGHT, table=table(tol, [
            ("eps", "{eps:g}"), ("size_crater", "{size_crater:g}"),
            ("F~ (default tolerances)", lambda r: f"{base(r)['F_tilde']:.10f}"),
            ("F~ (tight)", ok_only(lambda r: f"{r['F_tilde']:.10f}")), ("change", ok_only(lambda r: f"{r['tol_change']:.1e}")),
            ("stab / snaps (tight)", events_text),
            ("status", lambda r: "ok" if r["status"] == "ok" else f"**{r['status']}**: {r['reason'][:200]}")]))

    return render(T, rows, summary, command=COMMAND + opts, wall_min=args.wall_s / 60, load_start=args.load[0],
                  load_end=args.load[1], library=library, provenance=provenance_note(summary),
                  references="".join(references_).rstrip("\n"), differences=MONOTONE_MESHES - 1,
                  meshes="".join(meshes), size_default=SIZE_DEFAULT, regulariser=regulariser,
                  regulariser_verdict=("Verdict: " + "; ".join(verdicts) + ".") if verdicts
                  else "Not run (`--reg-eps` empty).",
                  mpi=mpi_text, tolerance=tolerance, notes=notes(rows, refs, part))


def notes(rows, refs, part) -> str:
    """The Notes: per preload, what the mesh study, the failures and the tolerance runs showed."""
    L = []
    for eps, ref in refs.items():
        ms = [r for r in rows if r["study"] == "mesh" and r["eps"] == eps]
        failed = [r for r in ms if r["status"] != "ok"]
        snapped = [r for r in ms if r["status"] == "ok" and (r["stability_events"] or r["snaps"])]
        closed = [r for r in ms if r["status"] == "ok" and r["V1_over_V0"] <= 1e-8]
        F = ref["conv"]["F_tilde"]["values"]
        parts = [f"eps = {eps:g}: F~ over the {len(F)} successful meshes spans {min(F):.6f} - {max(F):.6f} "
                 f"(a spread of {(max(F) - min(F)) / abs(ref['F']):.1e} of the reference; {ref['sign_changes']} sign "
                 "changes of its successive differences)"]
        if snapped:
            parts.append("the path has stability events or snaps on " + ", ".join(f"{r['size_crater']:g}"
                                                                               for r in snapped))
        negative = [r for r in closed if r["V1_over_V0"] < 0]
        if negative:
            parts.append("V1 < 0 on " + ", ".join(f"{r['size_crater']:g} (V1/V0 = {r['V1_over_V0']:.1e})"
                                                    for r in negative)
                         + ": the closed crater wall overlaps itself (self-contact is a penalty, and misses a node that one Newton step carries deeper than a quarter segment)")
        if closed:
            parts.append("the crater closes in stage 1 (V1 = 0, vacuum, p2 = 0) on " + ", ".join(
                f"{r['size_crater']:g}" for r in closed) + " but not on the other meshes")
        if failed:
            parts.append("no result on " + "; ".join(f"{r['size_crater']:g} ({r['status']}: {r['reason'][:160]})"
                                                     for r in failed))
        for r in (r for r in rows if r["study"] == "tolerance" and r["eps"] == eps):
            if r["status"] == "ok":
                parts.append(f"with tight Newton tolerances F~ on {r['size_crater']:g} moves by {r['tol_change']:.0e}")
            else:
                parts.append(f"with tight Newton tolerances the run on {r['size_crater']:g} gives no result "
                             f"({r['status']}: {r['reason'][:120]}; the default run takes "
                             f"{next(q['t_solve'] for q in ms if q['size_crater'] == r['size_crater']):.0f} s): past "
                             "the instabilities Newton does not reach those tolerances, so the steps are cut back "
                             "and relaxed until the run gives up or hits the time limit")
        L.append("* " + "; ".join(parts) + ".")
        if not snapped and not failed and ref["kind"] == "finest":
            changes = " ".join(f"{name}: mesh-to-mesh changes from {fmt(c['delta'][0], '.1e')} (coarsest) to "
                               f"{fmt(c['delta'][-2], '.1e')} (finest pair), smallest {fmt(min(c['delta'][:-1]), '.1e')}, "
                               f"{c['sign_changes']} sign changes, fitted order {fmt(c['fit'], '.1f')}."
                               for name, c in (("V2/V0", ref["conv"]["V2_over_V0"]),
                                               ("p2/pa", ref["conv"]["p2_over_pa"])))
            L.append(part("note-smooth", eps=eps, changes=changes).rstrip("\n"))
        if snapped or failed:
            L.append(part("note-unstable", eps=eps).rstrip("\n"))
    nonrep = [r for r in rows if r["study"] != "mpi2" and not r.get("reproducible", True)]
    L.append("* Repeated runs of a case gave " + ("bit-identical values in every case." if not nonrep else
             "different values for " + ", ".join(f"eps {r['eps']:g}/size {r['size_crater']:g}/g {r['surface_energy']:g}"
                                                 for r in nonrep) + "."))
    return "\n".join(L)


if __name__ == "__main__":
    main()
