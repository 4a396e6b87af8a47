"""The hemisphere's equilibrium diagram: the fundamental branch against the
stable path, docs/figures/crater_paths/{paths.csv,end_states.csv,equilibrium_diagram.png}.

Default crater (alpha = 1, beta = 0.467, air, gamma/(mu a) = 0.01, default mesh):

* the loading branch connected to the rest state (`bcfem run crater --path fundamental
  --preload closure`, traced by arc-length in the platen displacement), with the unstable
  axisymmetric modes at each point, against the stable path's loading (`--preload 0.45`,
  load stepping that relaxes past each instability);
* F~ against the preload: on the fundamental branch (`bcfem sweep crater --path fundamental
  --preload 0.025:0.375:0.025`), on the stable path (`bcfem sweep crater --preload
  0:0.5:0.025`), and the spread of stable end states at eps = 0.4 over load steps
  (`bcfem sweep crater --preload 0.4 --grid strain_step=0.005:0.02:4`);
* the stable path against benchmarks/crater_regulariser.py's kept gamma = 0.01 series, which
  took A2 at the midpoint between wall nodes (before bcfem/contact/plate_edge.py): the sub-element
  edge's effect on F~ (`edge_rule_effect` in summary.json);
* the section "paths" of docs/benchmarks/crater-air.md: the cost of the fundamental branch.

An end state of the stable path lies on the fundamental branch where their F~ agree (to
1e-6); the paths part at the stable path's first snap on loading. Sweeps are kept and
resumable; the two single runs are redone each time (about 2 min).

Run from the repository root: `.venv/bin/python benchmarks/crater_paths.py`; `--render-only` writes its
section of docs/benchmarks/crater-air.md again from the kept summary.json (the section's prose is
`benchmarks/templates/crater-air-paths.md`).
"""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys

from common import ROOT, atomic_text, csv_text, mpirun_bcfem, put_section, render, save_figure, table

OUT = ROOT / "docs" / "figures" / "crater_paths"
REGULARISER = ROOT / "docs" / "benchmarks" / "crater-regulariser"
AGREE = 1e-6


def read(path) -> list[dict]:
    with open(path) as f:
        return list(csv.DictReader(f))


def by_preload(rows) -> dict[float, dict]:
    return {round(float(r["preload"]), 6): r for r in rows}


def single(name: str, args: list[str]) -> tuple[list[dict], dict]:
    """One `bcfem run crater` (1 rank); a failed run keeps its converged part."""
    out = OUT / "runs" / name
    try:
        mpirun_bcfem(["run", "crater", *args, "--out", str(out), "--quiet", "--no-plots"], 1, quiet_stdout=True)
    except subprocess.CalledProcessError as error:  # a branch that ends is a result: its summary says where
        print(f"{name}: {error}", file=sys.stderr)
    return read(out / "branch.csv"), json.loads((out / "summary.json").read_text())


def main() -> None:
    mpirun_bcfem(["sweep", "crater", "--preload", "0:0.5:0.025", "--out", str(OUT / "stable"), "--quiet"], 2)
    mpirun_bcfem(["sweep", "crater", "--path", "fundamental", "--preload", "0.025:0.375:0.025",
                  "--out", str(OUT / "fundamental"), "--quiet"], 2)
    mpirun_bcfem(["sweep", "crater", "--preload", "0.4", "--grid", "strain_step=0.005:0.02:4",
                  "--out", str(OUT / "spread"), "--quiet"], 2)
    branch, fundamental = single("fundamental", ["--path", "fundamental", "--preload", "closure"])
    stepped, stable = single("stable", ["--preload", "0.45"])
    load = [r for r in branch if r["stage"] == "load"]
    atomic_text(OUT / "paths.csv", csv_text(
        [{"path": "fundamental", **r} for r in load] + [{"path": "stable", **r} for r in stepped if r["stage"] == "load"],
        ["path", "eps", "V_over_V0", "A_over_A0", "unstable"]))
    ends = end_states()
    atomic_text(OUT / "end_states.csv", csv_text(ends, list(ends[0])))
    snaps = [e for e in stable["instabilities"] if e["stage"] == "load" and e["kind"] == "snap"]
    summary = {"fundamental_end": fundamental.get("error") or f"closure at eps = {fundamental.get('eps_m')}",
               "fundamental_last_eps": float(load[-1]["eps"]),
               "fundamental_stability_changes": [(e["stage"], e["eps"], e["detail"]) for e in
                                                 fundamental["instabilities"]],
               "fundamental_folds": fundamental.get("folds", []),
               "fundamental_continuation": fundamental.get("continuation", {}),
               "fundamental_wall_time_s": fundamental["wall_time_s"],
               "edge_rule_effect": edge_rule_effect(),
               "stable_first_snap_on_loading": snaps[0]["eps"] if snaps else None,
               "stable_first_instability_on_loading": next(
                   (e["eps"] for e in stable["instabilities"] if e["stage"] == "load"), None)}
    atomic_text(OUT / "summary.json", json.dumps(summary, indent=1) + "\n")
    plot(load, [r for r in stepped if r["stage"] == "load"], ends, summary)
    put_section(ROOT / "docs" / "benchmarks" / "crater-air.md", "paths", cost_section(summary))
    print(json.dumps(summary, indent=1))


def edge_rule_effect() -> list[dict]:
    """Per preload: F~ of the stable path now and in the kept regulariser series (the
    midpoint edge rule), where they differ by more than 1e-9."""
    now = by_preload(read(OUT / "stable" / "sweep.csv"))
    before = by_preload(read(REGULARISER / "gamma=0.01" / "sweep.csv"))
    moved = []
    for eps in sorted(set(now) & set(before)):
        a, b = value(before[eps]), value(now[eps])
        if math.isfinite(a) and math.isfinite(b) and abs(b - a) > 1e-9 * max(abs(a), 1e-3):
            moved.append({"preload": eps, "F_midpoint_rule": a, "F_located_edge": b, "relative": b / a - 1})
    return moved


def cost_section(summary: dict) -> str:
    """The fundamental branch's cost, for docs/benchmarks/crater-air.md: the template
    benchmarks/templates/crater-air-paths.md filled from the summary and the sweep's points."""
    points = sorted((json.loads(p.read_text()) for p in (OUT / "fundamental" / "points").glob("*.json")),
                    key=lambda r: float(r["preload"]))
    stages = table(list(summary["fundamental_continuation"].items()), [
        ("stage", lambda sc: sc[0]), ("points", lambda sc: f"{sc[1]['points']}"),
        ("Newton its", lambda sc: f"{sc[1]['newton_iterations']}"), ("failed steps", lambda sc: f"{sc[1]['failed_steps']}"),
        ("jumps rejected", lambda sc: f"{sc[1]['jumps_rejected']}"),
        ("trace time [s]", lambda sc: f"{sc[1]['wall_time_s']:.1f}")])
    folds = ", ".join(f"{f['kind']} {f['eps']:.5f} (V/V0 = {f['V_over_V0']:.4f})" for f in summary["fundamental_folds"])
    return render("crater-air-paths.md", points, summary, stages=stages, folds=folds,
                  per_preload=", ".join(f"{float(r['preload']):g}: {float(r['solve_time_s']):.1f} s" for r in points),
                  longest=max(float(r["solve_time_s"]) for r in points)).rstrip("\n")


def value(point: dict | None) -> float:
    """A sweep point's F~, nan if it is missing or failed."""
    return float(point["F_tilde"]) if point and point["status"] == "ok" else math.nan


def end_states() -> list[dict]:
    """F~ per preload on each path; whether the stable path's end state is on the fundamental branch."""
    fundamental = by_preload(read(OUT / "fundamental" / "sweep.csv"))
    stepped = by_preload(read(OUT / "stable" / "sweep.csv"))
    spread = read(OUT / "spread" / "sweep.csv")
    rows = []
    for eps in sorted(set(stepped) | set(fundamental)):
        f, s = fundamental.get(eps), stepped.get(eps)
        F_f, F_s = value(f), value(s)
        rows.append({"preload": eps, "F_fundamental": F_f,
                     "fundamental": (f["stability"] if f["status"] == "ok" else "failed: " + f["reason"][:120])
                     if f else "not traced",
                     "unstable_at_end_fundamental": f.get("final_unstable_modes", "") if f else "",
                     "F_stable": F_s,
                     "stable": s["stability"] if s else "", "unstable_at_end_stable": s.get("final_unstable_modes", "")
                     if s else "",
                     "stable_end_on_fundamental": (abs(F_s - F_f) <= AGREE * max(abs(F_f), 1e-3))
                     if math.isfinite(F_f) and math.isfinite(F_s) else ""})
    for p in spread:
        rows.append({"preload": 0.4, "F_fundamental": math.nan, "fundamental": "not traced",
                     "unstable_at_end_fundamental": "", "F_stable": value(p),
                     "stable": f"strain_step {float(p['strain_step']):g}",
                     "unstable_at_end_stable": p.get("final_unstable_modes", ""), "stable_end_on_fundamental": ""})
    return rows


def plot(load, stepped, ends, summary) -> None:
    from bcfem.plots import pyplot

    plt = pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    eps = [float(r["eps"]) for r in load]
    V = [float(r["V_over_V0"]) for r in load]
    a.plot([float(r["eps"]) for r in stepped], [float(r["V_over_V0"]) for r in stepped], "s", ms=3, color="0.6",
           label="stable path (relaxes past instabilities)")
    a.plot(eps, V, "-", color="C0", lw=1, label="fundamental branch")
    for count, style in ((0, "o"), (1, "x"), (2, "^")):
        pts = [(e, v) for e, v, r in zip(eps, V, load) if int(float(r["unstable"])) == count]
        if pts:
            a.plot(*zip(*pts), style, ms=4, color=f"C{count}", label=f"{count} unstable axisymmetric modes")
    a.axvline(summary["fundamental_last_eps"], ls=":", color="k", lw=0.8)
    a.set_xlabel("preload ε")
    a.set_ylabel("V/V0 on loading")
    a.set_title("loading: where the branch goes and where it is stable", fontsize=9)
    a.legend(fontsize=7)
    main_rows = [r for r in ends if not str(r["stable"]).startswith("strain_step")]
    spread = [r for r in ends if str(r["stable"]).startswith("strain_step")]
    b.plot([r["preload"] for r in main_rows], [r["F_stable"] for r in main_rows], "s-", ms=3, color="0.6",
           label="stable path")
    b.plot([r["preload"] for r in spread], [r["F_stable"] for r in spread], "v", ms=5, color="C3",
           label="stable end states at ε = 0.4 over load steps")
    b.plot([r["preload"] for r in main_rows], [r["F_fundamental"] for r in main_rows], "o-", ms=4, color="C0",
           label="fundamental branch (unloaded along its own branch)")
    b.set_xlabel("preload ε")
    b.set_ylabel("F~")
    b.set_title("suction force: which end states lie on which branch", fontsize=9)
    b.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, OUT / "equilibrium_diagram.png")


if __name__ == "__main__":
    if sys.argv[1:] == ["--render-only"]:  # the crater-air.md section again from the kept summary.json
        put_section(ROOT / "docs" / "benchmarks" / "crater-air.md", "paths",
                    cost_section(json.loads((OUT / "summary.json").read_text())))
    else:
        main()
