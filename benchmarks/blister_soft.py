"""Accuracy vs wall time of the blister on a soft substrate, and the Fig. 4.5 family.

* the pressure maximum P_max at mu_s R0/(mu_f t0) = 1 (gamma_l = gamma_ls = dgamma =
  0.5 mu_f t0, neo-Hookean, L = 10) on the mesh with 0.02 R0 at the contact line (twice the
  default's) refined 0, 1, 2 times (every element size halved each time: the finest has
  0.005 R0), against the Richardson extrapolation of the two finest with the observed order;
  one core per solve;
* the far field: P_max with the block L = 20 R0 instead of 10;
* the Fig. 4.5/4.7 family: stiffness ratios 1, 2, 5, 10 to V/V0 = 3.5 and the rigid
  substrate (``blister-rigid``, clamped, alpha = 0.5), two solves at a time on the 2 cores;
  its total wall time, its limit points and deepest indentations.

Usage (from the repository root)::

    .venv/bin/python benchmarks/blister_soft.py            # ~10 min on 2 cores
    .venv/bin/python benchmarks/blister_soft.py --render-only   # the .md again from its CSV + JSON

Writes ``docs/benchmarks/blister-soft.{csv,json,md,png}`` (the report is
``benchmarks/templates/blister-soft.md`` filled from the CSV and JSON) and the branches of the family in
``docs/figures/blister_soft/`` (``fig4_5.csv``, ``fig4_5.png``, ``fig4_6.png``, ``fig4_7.png``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from concurrent.futures import ThreadPoolExecutor

from common import (
    ROOT,
    atomic_text,
    csv_text,
    emit,
    fmt,
    loadavg,
    provenance,
    provenance_note,
    render,
    render_again,
    run_worker,
    table,
    write_report,
    write_summary,
)

OUT = ROOT / "docs" / "benchmarks"
FIGURES = ROOT / "docs" / "figures" / "blister_soft"
RATIOS = [1.0, 2.0, 5.0, 10.0]
FAMILY_VMAX = 3.5
STUDY_SIZE = 0.02  # the study's coarsest size at the contact line [R0]
FRAME_VOLUMES = (0.5, 1.2, 2.0, 3.0, 3.5)  # Fig. 4.6: the first accepted point past each
FRAME_EXTENT = 3.0  # the substrate's top drawn to R = 3 R0
STUDY_VMAX = 1.5


def worker(case: dict) -> dict:
    t0 = time.perf_counter()
    import dolfinx_solver  # noqa: F401  (before dolfinx / petsc4py)
    from mpi4py import MPI

    t1 = time.perf_counter()
    if case["scene"] == "rigid":
        from bcfem.run.trace import branch_of
        from bcfem.scenes import blister_rigid

        params = blister_rigid.Params(material="neo-hookean", alpha=0.5, v_max=case["v_max"])
        branch = branch_of(blister_rigid.build(params, MPI.COMM_WORLD))
        dofs = 2 * (params.degree * params.cells + 1) + 1
    else:
        from bcfem.run.trace import branch_of
        from bcfem.scenes import blister_soft

        params = blister_soft.Params(stiffness_ratio=case["ratio"], v_max=case["v_max"], refine=case["refine"],
                                     size_factor=case.get("L", 10.0),
                                     size_contact=case.get("size_contact", blister_soft.Params.size_contact))
        scene = blister_soft.build(params, MPI.COMM_WORLD)
        frames = []
        branch = branch_of(scene, on_accept=frame_recorder(scene, frames) if case.get("frames") else None)
        dofs = sum(s.function_space.dofmap.index_map.size_global * s.function_space.dofmap.index_map_bs
                   for s in scene.ctx.states.values())
    lps = [{"kind": lp.kind, **{k: v for k, v in lp.values.items() if isinstance(v, float)}}
           for lp in branch.limit_points]
    keys = ("V_over_V0", "P", "aspect", "contact_angle_deg", "indentation", "r1_over_R0")
    rows = [{k: float(r[k]) for k in keys if k in r} for r in branch.rows]
    return {**case, "t_solve": time.perf_counter() - t1, "t_import": t1 - t0, "dofs": dofs,
            "steps": len(branch.rows) - 1, "limit_points": lps, "rows": rows,
            **({"frames": frames} if case["scene"] == "soft" else {})}


def profiles(model, extent: float = FRAME_EXTENT) -> dict:
    """The current substrate's top (mesh R <= extent) and free membrane, as (r, z) lists."""
    import numpy as np

    from bcfem.mpi import sample

    top = np.column_stack([np.linspace(0.0, extent, 301), np.zeros(301), np.zeros(301)])
    free = np.column_stack([np.linspace(0.0, 1.0, 101), np.zeros(101), np.zeros(101)])
    u_top, u_free, w = sample(model.u, top), sample(model.u, free), sample(model.w, free)
    return {"substrate": (top[:, :2] + u_top).tolist(), "membrane": (free[:, :2] + u_free + w).tolist()}


def frame_recorder(scene, frames: list):
    """An on_accept that keeps the :func:`profiles` at the first accepted point past each of
    FRAME_VOLUMES (Fig. 4.6)."""
    targets = list(FRAME_VOLUMES)

    def on_accept(values):
        if not targets or values["V_over_V0"] < targets[0]:
            return
        targets.pop(0)
        frames.append({"V_over_V0": float(values["V_over_V0"]), "P": float(values["P"]), **profiles(scene.model)})

    return on_accept


def run(case: dict, core: str = "0") -> dict:
    return run_worker(__file__, case, core)


def p_max(result) -> dict:
    return next(lp for lp in result["limit_points"] if lp["kind"] == "max")


def deepest(result) -> dict:
    """The deepest indentation of a branch: a parabola through the three rows around it."""
    import numpy as np

    rows = result["rows"]
    d = np.array([r.get("indentation", 0.0) for r in rows])
    v = np.array([r["V_over_V0"] for r in rows])
    k = int(np.argmax(d))
    if 0 < k < len(d) - 1:
        c = np.polyfit(v[k - 1:k + 2], d[k - 1:k + 2], 2)
        if c[0] < 0:
            x = -c[1] / (2 * c[0])
            return {"V_over_V0": float(x), "depth": float(np.polyval(c, x)), "interior": True}
    return {"V_over_V0": float(v[k]), "depth": float(d[k]), "interior": False}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--levels", type=int, default=3, help="mesh levels of the study (refine 0 .. n-1)")
    parser.add_argument("--render-only", action="store_true",
                        help="render blister-soft.md again from the blister-soft.csv and .json that are there")
    args = parser.parse_args()
    if args.worker:
        emit(worker(json.loads(args.worker)))
        return
    if args.render_only:
        render_again("blister-soft", report)
        return
    load = loadavg()
    # the Fig. 4.5 family, two at a time
    t0 = time.perf_counter()
    cases = [{"scene": "soft", "ratio": k, "refine": 0, "v_max": FAMILY_VMAX, "frames": k == 1.0} for k in RATIOS]
    cases.append({"scene": "rigid", "v_max": FAMILY_VMAX})
    with ThreadPoolExecutor(2) as pool:
        family = list(pool.map(lambda ic: run(ic[1], str(ic[0] % 2)), enumerate(cases)))
    t_family = time.perf_counter() - t0
    # the mesh study at ratio 1, and the far field, one at a time
    study = []
    for r in range(args.levels):  # the default mesh refined twice stalls in the start homotopy (docs/results.md)
        try:
            study.append(run({"scene": "soft", "ratio": 1.0, "refine": r, "v_max": STUDY_VMAX,
                              "size_contact": STUDY_SIZE}))
        except RuntimeError as err:
            print(f"refine {r} failed: {str(err).splitlines()[-1]}", file=sys.stderr)
            break
    far = run({"scene": "soft", "ratio": 1.0, "refine": 0, "v_max": STUDY_VMAX, "L": 20.0, "size_contact": STUDY_SIZE})
    write(study, far, family, t_family, load)


def write(study, far, family, t_family, load) -> None:

    P = [p_max(r)["P"] for r in study]
    # the observed order from three meshes, else 4 (P2: h^(2k) for an energy-like functional)
    order = math.log2(abs(P[-3] - P[-2]) / abs(P[-2] - P[-1])) if len(P) >= 3 else 4.0
    reference = P[-1] + (P[-1] - P[-2]) / (2**order - 1)
    rows = [{"refine": r["refine"], "dofs": r["dofs"], "steps": r["steps"], "t_solve": r["t_solve"],
             "P_max": p_max(r)["P"], "V_at_P_max": p_max(r)["V_over_V0"],
             "error": abs(p_max(r)["P"] / reference - 1)} for r in study]
    columns = ["refine", "dofs", "steps", "t_solve", "P_max", "V_at_P_max", "error"]
    atomic_text(OUT / "blister-soft.csv", csv_text(rows, columns))
    fam_rows = [{"ratio": r.get("ratio", math.inf), **row} for r in family for row in r["rows"]]
    atomic_text(FIGURES / "fig4_5.csv", csv_text(fam_rows, ["ratio", "V_over_V0", "P", "aspect", "contact_angle_deg",
                                                           "indentation", "r1_over_R0"]))
    plot(rows, family)

    def limit(r, kind):
        return next((lp for lp in r["limit_points"] if lp["kind"] == kind), {})

    summary = {"load": load, "order_kind": "observed" if len(P) >= 3 else "assumed (two levels)", "order": order,
               "reference": reference, "far_P_max": p_max(far)["P"], "t_family": t_family,
               "family": [{"ratio": r.get("ratio", "rigid"), "P_max": limit(r, "max")["P"],
                           "V_at_P_max": limit(r, "max")["V_over_V0"], "P_min": limit(r, "min").get("P"),
                           "V_at_P_min": limit(r, "min").get("V_over_V0"), "deepest": deepest(r) if r["scene"] == "soft"
                           else None, "t_solve": r["t_solve"]} for r in family],
               "provenance": provenance()}
    write_summary("blister-soft", summary)
    write_report(OUT / "blister-soft.md", report(rows, summary))


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report: benchmarks/templates/blister-soft.md filled from the mesh study's rows
    (CSV) and the summary (JSON: the reference, the far field, the family's limit points)."""
    study = table(rows, [("refine", "{refine}"), ("dofs", "{dofs}"), ("steps", "{steps}"),
                         ("wall time [s]", "{t_solve:.1f}"), ("P_max", "{P_max:.8f}"),
                         ("V/V0 at P_max", "{V_at_P_max:.5f}"), ("rel. error", lambda r: fmt(r["error"]))], padded=True)
    family = table(summary["family"], [
        ("mu_s R0/(mu_f t0)", "{ratio}"), ("P_max", "{P_max:.5f}"), ("V/V0 at P_max", "{V_at_P_max:.4f}"),
        ("P_min", lambda r: fmt(r["P_min"], ".5f")), ("V/V0 at P_min", lambda r: fmt(r["V_at_P_min"], ".4f")),
        ("deepest indentation", lambda r: fmt(r["deepest"] and r["deepest"]["depth"], ".5f")),
        ("at V/V0", lambda r: fmt(r["deepest"] and r["deepest"]["V_over_V0"], ".4f")
         + ("" if not r["deepest"] or r["deepest"]["interior"] else " (end)")),
        ("wall time [s]", "{t_solve:.1f}")], padded=True)
    coarse = rows[0]["P_max"]
    return render("blister-soft.md", rows, summary, study=study, family=family, coarse_P_max=coarse,
                  far_change=abs(summary["far_P_max"] / coarse - 1), family_vmax=FAMILY_VMAX,
                  provenance=provenance_note(summary))


def plot(rows, family) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, ax = plt.subplots(figsize=(5, 4))
    shown = rows[:-1] if len(rows) > 2 else rows
    ax.loglog([r["t_solve"] for r in shown], [max(r["error"], 1e-16) for r in shown], "o-")
    for r in shown:
        ax.annotate(f"refine {r['refine']}", (r["t_solve"], r["error"]))
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("relative error of P_max")
    ax.set_title("blister-soft, mu_s R0/(mu_f t0) = 1")
    fig.tight_layout()
    fig.savefig(OUT / "blister-soft.png", dpi=120)
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for r in family:
        label = f"{r['ratio']:g}" if r["scene"] == "soft" else "∞ (rigid)"
        v = [row["V_over_V0"] for row in r["rows"]]
        for ax, key in zip(axes, ("P", "aspect", "contact_angle_deg")):
            ax.plot(v, [row[key] for row in r["rows"]], "k-" if r["scene"] == "rigid" else "-", label=label)
    for ax, name in zip(axes, ("P = Δp R0/(μf t0)", "aspect z_f(0)/r0", "contact angle [deg]")):
        ax.set_xlabel("V/V0")
        ax.set_ylabel(name)
    axes[0].legend(title="μs R0/(μf t0)")
    fig.tight_layout()
    fig.savefig(FIGURES / "fig4_5.png", dpi=120)
    one = next(r for r in family if r.get("ratio") == 1.0)
    fig, ax = plt.subplots(figsize=(5, 4))
    v = [row["V_over_V0"] for row in one["rows"]]
    ax.plot(v, [row["P"] for row in one["rows"]], "r-")
    ax.set_xlabel("V/V0")
    ax.set_ylabel("P", color="r")
    ax2 = ax.twinx()
    ax2.plot(v, [row["indentation"] for row in one["rows"]], "b-")
    ax2.set_ylabel("indentation -z_s(0)/R0", color="b")
    ax.set_title("Fig. 4.7: μs R0/(μf t0) = 1")
    fig.tight_layout()
    fig.savefig(FIGURES / "fig4_7.png", dpi=120)
    fig, ax = plt.subplots(figsize=(7, 3.6))
    for k, frame in enumerate(one["frames"]):
        colour = plt.cm.viridis(k / max(1, len(one["frames"]) - 1))
        for part, style in (("substrate", "-"), ("membrane", "--")):
            xy = np.array(frame[part])
            ax.plot(xy[:, 0], xy[:, 1], style, color=colour, lw=1.2,
                    label=f"V/V0 = {frame['V_over_V0']:.2f}, P = {frame['P']:.2f}" if part == "membrane" else None)
    ax.axhline(0.0, color="0.6", lw=0.6, ls=":")
    ax.set_aspect("equal")
    ax.set_xlabel("r/R0")
    ax.set_ylabel("z/R0")
    ax.legend(fontsize=7, loc="upper right")
    ax.set_title("Fig. 4.6: μs R0/(μf t0) = 1; substrate's top (solid), free membrane (dashed)", fontsize=9)
    fig.tight_layout()
    fig.savefig(FIGURES / "fig4_6.png", dpi=120)


if __name__ == "__main__":
    sys.exit(main())
