# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
# ---

# %% [markdown]
# # Blisters of any outline (the dissertation's outlook, §10.2)
#
# The dissertation's blisters are circular. Its first proposal for future work is a blister
# whose initial delamination is not. Here an incompressible neo-Hookean membrane is clamped
# along a circle, an ellipse, a square, a rectangle and a hexagon of the same area
# $\pi R_0^2$ on a rigid substrate, and inflated by a liquid ($\alpha = 0$). The membrane is
# a flat reference mesh of the outline with a three-component displacement: the surface
# gradient $F$ is $3\times 2$, $C = F^T F$, the thickness stretch $1/\sqrt{\det C}$, and
# the terms are those of the axisymmetric blister,
#
# $$
# \Pi[\boldsymbol u] = \int t_0 \tfrac{\mu}{2}\bigl(\operatorname{tr} C + 1/\det C - 3\bigr)\,\mathrm dA
#   - \Delta p\, V[\boldsymbol u], \qquad V = \int z\,(\boldsymbol x_{,1}\times\boldsymbol x_{,2})_z\,\mathrm dA .
# $$
#
# Corners and straight edges put the membrane in compression across its tension lines. A
# membrane cannot carry compression: with the tension-field relaxation (`--wrinkles relaxed`,
# used throughout) it wrinkles there instead, and the branch stays well posed.
# Normalisation: $P = \Delta p R_0/(\mu t_0)$, $V_0 = \tfrac43\pi R_0^3$.

# %%
import json
from pathlib import Path

from mpi4py import MPI

import numpy as np

import bcfem  # noqa: F401  (before dolfinx / petsc4py)
from bcfem import ContinuationParams, io
from bcfem.run import demo
from bcfem.run.study import Study
from bcfem.scenes import blister_3d, blister_rigid
from bcfem.scenes.blister_3d.report import gather_surface, membrane_figure

comm = MPI.COMM_WORLD
SIZE = 0.15  # element size over R0
STEPS = ContinuationParams(ds=0.02, ds_max=0.04)  # small steps: smooth curves
args, report = demo.setup("blister_3d", "Blisters of any outline in 3-D (dissertation section 10.2)", comm,
                          refine=f"element size {SIZE / 2} R0 instead of {SIZE}")
study = Study("blister_3d", comm, args.out)  # every solve counted; summary.json in the runner's schema
SIZE /= 2 if args.refine else 1
V_END = 0.75  # V/V0: past every maximum (the circle's is at 0.668)
HEXAGON = np.array([[np.cos(t), np.sin(t)] for t in np.linspace(0, 2 * np.pi, 7)[:-1]])

# %% [markdown]
# ## The branches

# %%
args.out.mkdir(parents=True, exist_ok=True)
hexagon_file = args.out / "hexagon.txt"
if comm.rank == 0:
    np.savetxt(hexagon_file, HEXAGON, header="x y: a regular hexagon (scaled to the area pi)")
comm.barrier()
OUTLINES = {"circle": dict(), "ellipse 2:1": dict(outline="ellipse", aspect=2.0), "square": dict(outline="rectangle"),
            "rectangle 2:1": dict(outline="rectangle", aspect=2.0),
            "hexagon": dict(outline="polygon", vertices=str(hexagon_file))}
curves, tops, surfaces = {}, {}, {}
for name, fields in OUTLINES.items():
    # relaxed: a taut membrane with compressed corners can lose Newton (rectangle 2:1 at V/V0 0.43)
    scene = blister_3d.build(blister_3d.Params(size=SIZE, v_max=V_END, wrinkles="relaxed", continuation=STEPS,
                                               **fields), comm)
    branch = study.branch(scene)
    curves[name] = branch.rows
    tops[name] = next(lp.values for lp in branch.limit_points if lp.kind == "max")
    surfaces[name] = gather_surface(scene.fields[0], (scene.fields[1], scene.fields[3]), comm)
    report(f"{name:14s}: P_max = {tops[name]['P']:.6f} at V/V0 = {tops[name]['V_over_V0']:.4f}")
axisymmetric = study.branch(blister_rigid.build(blister_rigid.Params(material="neo-hookean", v_max=V_END), comm))

# %% [markdown]
# ## Wrinkles: a rectangle of aspect 4, taut and relaxed, before its maximum

# %%
wrinkles = {}
for mode in ("taut", "relaxed"):
    # the two paths coincide until the corners compress: steps of their own keep rank 0's
    # progress lines distinct
    steps = STEPS if mode == "relaxed" else ContinuationParams(ds=0.03, ds_max=0.05)
    scene = blister_3d.build(blister_3d.Params(outline="rectangle", aspect=4.0, size=SIZE, v_max=0.35,
                                               wrinkles=mode, continuation=steps), comm)
    branch = study.branch(scene)
    wrinkles[mode] = branch.rows[-1]
    if mode == "relaxed":
        surfaces["rectangle 4:1, relaxed"] = gather_surface(scene.fields[0], (scene.fields[1], scene.fields[3]), comm)
    report(f"rectangle 4:1 {mode:8s}: P = {wrinkles[mode]['P']:.6f} at V/V0 = 0.35, "
           f"wrinkled fraction {wrinkles[mode]['wrinkled_fraction']:.4f}")

# %% [markdown]
# ## Figures and numbers

# %%
if comm.rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot([r["V_over_V0"] for r in axisymmetric.rows], [r["P"] for r in axisymmetric.rows], "k-", lw=3,
            alpha=0.3, label="axisymmetric (blister-rigid)")
    for name, rows in curves.items():
        ax.plot([r["V_over_V0"] for r in rows], [r["P"] for r in rows], label=name)
    ax.set_xlabel("V/V0")
    ax.set_ylabel("P = Δp R0/(μ t0)")
    ax.set_title("Clamped neo-Hookean blisters of equal area")
    ax.legend()
    io.save_figure(fig, args.out / "pv.png", MPI.COMM_SELF)
    for name, parts in surfaces.items():
        colour = "taut minor tension (< 0: wrinkled)" if "relaxed" in name else "major tension N1 / (mu t0)"
        title = f"{name}: V/V0 = {0.35 if 'relaxed' in name else V_END}"
        stem = name.replace(" ", "_").replace(":", "x").replace(",", "")
        io.save_figure(membrane_figure(parts, title, colour), args.out / f"membrane_{stem}.png", MPI.COMM_SELF)
io.write_csv(args.out / "curves.csv",
             [{"outline": name, "V_over_V0": r["V_over_V0"], "P": r["P"], "aspect": r["aspect"],
               "wrinkled_fraction": r["wrinkled_fraction"]} for name, rows in curves.items() for r in rows],
             comm, columns=["outline", "V_over_V0", "P", "aspect", "wrinkled_fraction"])
study.write({"P_max": {n: t["P"] for n, t in tops.items()}, "V_at_P_max": {n: t["V_over_V0"] for n, t in tops.items()},
             "rectangle_4_at_0.35": wrinkles, "size": SIZE})
report(json.dumps({n: round(t["P"], 6) for n, t in tops.items()}))
assert Path(args.out).exists()
