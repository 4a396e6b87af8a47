"""Onset volume of the moving blister edges: accuracy against wall time.

The onset of delamination Vc (dissertation section 3.2.3, alpha = 0.5,
(gamma_ls - dgamma)/(mu t0) = 2.5) is measured for

* the adhesive edge, Gent Jm = 100 (Fig. 3.13, Vc ~ 1.27 V0), branch to V/V0 = 1.4;
* the adhesive edge, neo-Hookean (Fig. 3.14, Vc ~ 3.06 V0), branch to V/V0 = 3.3;
* the slippery edge, Gent Jm = 100 (Fig. 3.20, Vc ~ 0.35 V0), branch to V/V0 = 0.45
  started at V/V0 = 0.3 (``start_volume``) and traced both ways;

with P1 and P2 displacements on several meshes, by two methods: the located
event of the traced branch (``trace``, where dPi/dR1 changes sign) and, for
P2, ``blister_studies.onset_by_energy`` (Brent on F(V, R0 + h) = F(V, R0 - h)).
The error is against a Richardson extrapolation of the event values on the two
finest P2 meshes (order 4: Vc is fixed by an energy-like functional). Each
solve runs in a fresh process pinned to one core, with a warm JIT cache.

A second study records what the slippery edge does for several start volumes.
The sliding edge has no onset (its edge slides from the start) and is not
benchmarked.

Usage (from the repository root)::

    .venv/bin/python benchmarks/blister_edges.py              # ~10 min
    .venv/bin/python benchmarks/blister_edges.py --repeats 1  # quicker timings

Writes ``docs/benchmarks/blister-edges.{csv,md,png}`` (atomically).
"""

from __future__ import annotations

import time

T_START = time.perf_counter()

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402

from common import (  # noqa: E402
    ROOT,
    atomic_text,
    cpu_name,
    csv_text,
    emit,
    fmt,
    git_state,
    loadavg,
    provenance,
    provenance_note,
    render,
    render_again,
    richardson,
    run_worker,
    save_figure,
    table,
    worker_prologue,
    write_report,
    write_summary,
)

OUT = ROOT / "docs" / "benchmarks"
COMMON = {"alpha": 0.5, "adhesion": 2.5}
CASES = {  # name -> (Params fields, bracket of Vc for the energy method, dissertation's Vc)
    "adhesive-gent": (dict(material="gent", Jm=100.0, edge="adhesive", v_max=1.4), (1.0, 1.6), 1.27),
    "adhesive-neo-hookean": (dict(material="neo-hookean", edge="adhesive", v_max=3.3), (2.6, 3.6), 3.06),
    "slippery-gent": (dict(material="gent", Jm=100.0, edge="slippery", v_max=0.45, start_volume=0.3),
                      (0.31, 0.45), 0.35),
}
TITLES = {"adhesive-gent": "adhesive edge, Gent Jm = 100", "adhesive-neo-hookean": "adhesive edge, neo-Hookean",
          "slippery-gent": "slippery edge, Gent Jm = 100"}
CELLS = {1: [20, 40, 80, 160, 320, 640, 1280], 2: [10, 20, 40, 80, 160, 320, 640]}
ENERGY_CELLS = [10, 20, 40, 80, 160]  # P2 meshes of the energy-comparison method
ORDER = 4  # observed for P2 (and 2 for P1): Vc is fixed by dPi/dR1, an energy-like functional
# (start_volume, v_max) of the slippery start study at P2/80; start_volume 0: the scene default
SLIPPERY_STARTS = [(0.0, 1.0), (0.0, 0.45), (0.05, 1.0), (0.1, 1.0), (0.2, 1.0), (0.25, 1.0), (0.3, 1.0),
                   (0.4, 1.0), (0.5, 1.0), (0.6, 1.0)]
TEMPLATE = "blister-edges.md"


# ----------------------------------------------------------------------------------------
# worker: one solve in a fresh process; prints "RESULT <json>"
# ----------------------------------------------------------------------------------------
def worker(case: dict) -> dict:
    from mpi4py import MPI

    worker_prologue()
    from bcfem.path.continuation import ContinuationError
    from bcfem.run.trace import trace
    from bcfem.scenes import blister_rigid, blister_studies

    t_import = time.perf_counter() - T_START
    fields, bracket, _ = CASES[case["case"]]
    fields = {**fields, **case.get("fields", {})}
    t1, c1 = time.perf_counter(), time.process_time()
    params = blister_rigid.Params(**fields, **COMMON, cells=case["cells"], degree=case["degree"])
    out = {**case, "t_import": t_import, "status": "ok", "reason": ""}
    try:
        if case["method"] == "event":
            branch, problem = trace(blister_rigid.build(params, MPI.COMM_WORLD))
            its = problem.newton_iterations
            problem.close()
            onset = next((e for e in branch.events if e["name"] == "delamination onset"), None)
            if onset is None:
                raise ContinuationError(f"no onset up to V/V0 = {params.v_max}")
            start = next(r for r in branch.rows if r["s"] == 0.0)  # the converged start point
            out.update(Vc=onset["V_over_V0"], Pc=onset["P"], steps=len(branch.rows) - 1,
                       V_start=start["V_over_V0"], N_theta_min=min(r["N_theta_min"] for r in branch.rows))
        else:
            onset = blister_studies.onset_by_energy(params, MPI.COMM_WORLD, bracket=bracket)
            its = onset["newton_iterations"]
            out.update(Vc=onset["V_over_V0"], Pc=onset["P"])
    except Exception as error:  # recorded: the slippery start study wants the message
        out.update(status="failed", reason=f"{type(error).__name__}: {error}")
        its = None
    out.update(t_solve=time.perf_counter() - t1, c_solve=time.process_time() - c1, its=its,
               dofs=2 * (params.degree * params.cells * (2 if params.edge == "slippery" else 1) + 1) + 2)
    return out


# ----------------------------------------------------------------------------------------
# driver
# ----------------------------------------------------------------------------------------
CORE = "0"  # the core the workers are pinned to (--core)


def run_case(case: dict) -> dict:
    """Run ``case`` in a subprocess on one core."""
    return run_worker(__file__, case, CORE)


def timed(case: dict, repeats: int) -> dict:
    """Best of ``repeats`` warm runs (the minimum is the least disturbed by other load)."""
    runs = [run_case(case) for _ in range(repeats)]
    res = dict(runs[0])
    for key in ("t_solve", "c_solve", "t_process", "t_import"):
        res[key] = min(r[key] for r in runs)
    return res






def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=2, help="warm runs per case (the best time is kept)")
    ap.add_argument("--core", default="0", help="the core the solves are pinned to (taskset -c)")
    ap.add_argument("--render-only", action="store_true",
                    help="render blister-edges.md again from the blister-edges.csv and .json that are there")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.render_only:
        render_again("blister-edges", report)
        return
    global CORE
    CORE = args.core
    if args.worker:
        emit(worker(json.loads(args.worker)))
        return

    from mpi4py import MPI

    if MPI.COMM_WORLD.size > 1:
        sys.exit("the benchmark is serial (one core): run it without mpirun")
    log = lambda msg: print(msg, file=sys.stderr, flush=True)  # noqa: E731
    load = [loadavg()]
    t_bench = time.perf_counter()

    # warm the JIT cache (forms depend on the case and the degree, not on the mesh)
    for name in CASES:
        for degree in (1, 2):
            run_case({"case": name, "degree": degree, "cells": 20, "method": "event"})
        run_case({"case": name, "degree": 2, "cells": 20, "method": "energy"})

    rows = []
    for name in CASES:
        for degree, cells_list in CELLS.items():
            for cells in cells_list:
                r = timed({"case": name, "degree": degree, "cells": cells, "method": "event"}, args.repeats)
                rows.append({"study": "convergence", **r})
                log(f"{name:22s} P{degree} {cells:5d} event : {r['status']} Vc={r.get('Vc')!r} {r['t_solve']:.3f} s")
        for cells in ENERGY_CELLS:
            r = timed({"case": name, "degree": 2, "cells": cells, "method": "energy"}, args.repeats)
            rows.append({"study": "convergence", **r})
            log(f"{name:22s} P2 {cells:5d} energy: {r['status']} Vc={r.get('Vc')!r} {r['t_solve']:.3f} s")

    refs = references(rows)
    for r in rows:
        is_ref = r["degree"] == 2 and r["method"] == "event" and r["cells"] == CELLS[2][-1]
        r["err"] = math.nan if is_ref or r["status"] != "ok" else abs(r["Vc"] - refs[r["case"]]["Vc"]) / refs[r["case"]]["Vc"]

    # the slippery edge from several start volumes
    for start, v_max in SLIPPERY_STARTS:
        fields = {"start_volume": start, "v_max": v_max}
        r = run_case({"case": "slippery-gent", "degree": 2, "cells": 80, "method": "event", "fields": fields})
        rows.append({"study": "slippery_start", "start_volume": start, "v_max": v_max, **r})
        log(f"slippery start {start}: {r['status']} {r.get('Vc')} {r['reason'][:120]}")

    load.append(loadavg())
    args.load = load
    args.wall = time.perf_counter() - t_bench
    write_outputs(rows, refs, args)


# ----------------------------------------------------------------------------------------
# outputs
# ----------------------------------------------------------------------------------------
COLUMNS = ["study", "case", "method", "degree", "cells", "dofs", "start_volume", "v_max", "status", "Vc", "Pc", "err",
           "t_solve", "c_solve", "t_process", "t_import", "steps", "its", "V_start", "N_theta_min", "reason"]






def references(rows) -> dict:
    """Per case: Richardson on the two finest P2 event values (``Vc``), its uncertainty from the
    next-coarser pair (``floor``), the correction, the observed P2 orders and the dissertation's Vc."""
    refs = {}
    for name in CASES:
        vc = {r["cells"]: r["Vc"] for r in rows if r["study"] == "convergence" and r["case"] == name
              and r["degree"] == 2 and r["method"] == "event" and r["status"] == "ok"}
        n = CELLS[2]
        ref = richardson(vc[n[-2]], vc[n[-1]], ORDER)
        refs[name] = {"Vc": ref, "floor": abs(richardson(vc[n[-3]], vc[n[-2]], ORDER) - ref),
                      "correction": abs(ref - vc[n[-1]]),
                      "observed_order": [math.log2(abs(vc[a] - vc[b]) / abs(vc[b] - vc[c]))
                                         for a, b, c in zip(n, n[1:], n[2:]) if vc[b] != vc[c]],
                      "dissertation": CASES[name][2]}
    return refs


def series(rows, name, degree, method):
    return sorted((r for r in rows if r["study"] == "convergence" and r["case"] == name and r["degree"] == degree
                   and r["method"] == method and r["status"] == "ok" and not math.isnan(r["err"])),
                  key=lambda r: r["cells"])


def write_outputs(rows, refs, args):
    from bcfem.plots import pyplot

    atomic_text(OUT / "blister-edges.csv", csv_text(rows, COLUMNS))
    plt = pyplot()
    fig, axes = plt.subplots(1, len(CASES), figsize=(14.5, 4.4), sharey=True)
    styles = {(1, "event"): ("o-", "tab:blue", "P1, event of the traced branch"),
              (2, "event"): ("s-", "tab:red", "P2, event of the traced branch"),
              (2, "energy"): ("^--", "tab:green", "P2, energy comparison (onset_by_energy)")}
    for ax, name in zip(axes, CASES):
        for (degree, method), (style, colour, label) in styles.items():
            rs = series(rows, name, degree, method)
            ax.loglog([r["t_solve"] for r in rs], [max(r["err"], 1e-16) for r in rs], style, color=colour,
                      mfc="white" if method == "energy" else colour, ms=5, label=label)
            for r in rs:
                ax.annotate(str(r["cells"]), (r["t_solve"], max(r["err"], 1e-16)), fontsize=6, xytext=(3, 3),
                            textcoords="offset points", color=colour)
        ax.axhline(max(refs[name]["floor"], 1e-15), color="k", lw=0.7, ls=":",
                   label="reference uncertainty")
        ax.set_title(f"{TITLES[name]}: Vc = {refs[name]['Vc']:.10f} V0", fontsize=9)
        ax.set_xlabel("wall time of build + solve [s] (one core, warm JIT cache)")
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("relative error of the onset volume Vc")
    axes[0].set_ylim(1e-15, 1e-1)
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle("Delamination onset, alpha = 0.5, (gamma_ls - dgamma)/(mu t0) = 2.5: error against wall time "
                 "(numbers: cells across R0)", fontsize=10)
    fig.tight_layout()
    save_figure(fig, OUT / "blister-edges.png")
    plt.close(fig)
    summary = {"repeats": args.repeats, "core": args.core, "load": args.load, "wall_s": args.wall, "cpu": cpu_name(),
               "bcfem": git_state(), "provenance": provenance()}
    write_summary("blister-edges", summary)
    write_report(OUT / "blister-edges.md", report(rows, summary))


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report: benchmarks/templates/blister-edges.md filled from the rows (CSV; the
    references are recomputed from them) and the summary (JSON: settings, load, CPU, commit)."""
    refs = references(rows)
    references_ = table(list(refs.items()), [
        ("case", lambda c: TITLES[c[0]]), ("v_max", lambda c: f"{CASES[c[0]][0]['v_max']:g}"),
        ("Vc reference [V0]", lambda c: f"{c[1]['Vc']:.12f}"), ("uncertainty", lambda c: f"{c[1]['floor']:.1e}"),
        ("Richardson correction", lambda c: f"{c[1]['correction']:.1e}"),
        ("observed P2 orders", lambda c: ", ".join(f"{o:.2f}" for o in c[1]["observed_order"])),
        ("dissertation", lambda c: f"{c[1]['dissertation']:.2f}"),
        ("difference", lambda c: f"{100 * (c[1]['Vc'] / c[1]['dissertation'] - 1):+.1f} %")])

    cases = []
    for name in CASES:
        runs = []
        for (degree, method) in ((1, "event"), (2, "event"), (2, "energy")):
            runs += sorted((r for r in rows if r["study"] == "convergence" and r["case"] == name
                            and r["degree"] == degree and r["method"] == method), key=lambda r: r["cells"])

        def rate(r):
            prev = next((q for q in runs if q["degree"] == r["degree"] and q["method"] == r["method"]
                         and q["cells"] * 2 == r["cells"] and q["status"] == "ok"), None)
            return (fmt(math.log2(prev["err"] / r["err"]), ".2f")
                    if prev and r["err"] > 0 and not math.isnan(r["err"]) and not math.isnan(prev["err"]) else "")

        def ok(how):
            return lambda r: how(r) if r["status"] == "ok" else ""

        mesh = table(runs, [
            ("deg", "P{degree}"), ("method", "{method}"), ("cells", "{cells}"), ("dofs", "{dofs}"),
            ("Vc [V0]", lambda r: f"{r['Vc']:.12f}" if r["status"] == "ok" else f"failed: {r['reason'][:90]}"),
            ("rel. error", ok(lambda r: fmt(r["err"]) or "ref")), ("rate", ok(rate)), ("t_solve [s]", "{t_solve:.3f}"),
            ("cpu [s]", ok(lambda r: f"{r['c_solve']:.3f}")), ("process [s]", ok(lambda r: f"{r['t_process']:.2f}")),
            ("steps", ok(lambda r: f"{'' if r.get('steps') is None else r['steps']}")),
            ("Newton its", ok(lambda r: f"{r['its']}"))])
        fastest = {}
        for tol in (1e-4, 1e-6, 1e-8):
            good = [r for r in rows if r["study"] == "convergence" and r["case"] == name and r["status"] == "ok"
                    and not math.isnan(r["err"]) and r["err"] < tol]
            if good:
                best = min(good, key=lambda r: r["t_solve"])
                fastest[tol] = f"P{best['degree']}/{best['cells']} {best['method']} ({best['t_solve']:.2f} s)"
        cases.append(render(TEMPLATE, rows, summary, section="case", title=TITLES[name], table=mesh,
                            fastest="; ".join(f"{t:g}: {v}" for t, v in fastest.items())))

    ref_slip = refs["slippery-gent"]["Vc"]
    study = [q for q in rows if q["study"] == "slippery_start"]
    for r in study:
        r["outcome"] = r["status"]
        if r["status"] == "ok" and abs(r["Vc"] / ref_slip - 1) > 1e-6:
            r["outcome"] = "wrong onset"
    starts = table(study, [
        ("start_volume", lambda r: f"{r['start_volume']}" if r["start_volume"]
         else f"default ({min(0.3, 0.5 * r['v_max']):g})"),
        ("v_max", "{v_max:g}"),
        ("outcome", lambda r: f"**{r['outcome']}**" if r["outcome"] == "wrong onset" else r["outcome"]),
        ("Vc [V0]", lambda r: fmt(r.get("Vc"), ".6f")), ("V_start [V0]", lambda r: fmt(r.get("V_start"), ".4f")),
        ("min N_theta/(mu t0)", lambda r: fmt(r.get("N_theta_min"), ".3f")),
        ("message", lambda r: (r["reason"] or "")[:160])])
    by = {o: [q for q in study if q["outcome"] == o] for o in ("ok", "failed", "wrong onset")}
    label = lambda q: f"{q['start_volume'] or 'default'} (v_max {q['v_max']:g})"  # noqa: E731
    return render(TEMPLATE, rows, summary, wall_min=summary["wall_s"] / 60, load_start=summary["load"][0],
                  load_end=summary["load"][1], provenance=provenance_note(summary), order=ORDER,
                  ref_coarse=CELLS[2][-2], ref_fine=CELLS[2][-1], references=references_, cases="".join(cases),
                  starts=starts, right=", ".join(map(label, by["ok"])),
                  compressed=", ".join(map(label, by["failed"])) or "none",
                  wrong=", ".join(map(label, by["wrong onset"])) or "none", slippery_vc=ref_slip,
                  slippery_vs_dissertation=100 * (0.35 / ref_slip - 1))


if __name__ == "__main__":
    main()
