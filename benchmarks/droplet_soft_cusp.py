"""Why the water and ethylene-glycol cusps of Fig. 5.9 miss Neumann's angle (droplet-soft).

For each case: the neo-Hookean solve, the summary's tip angles (chords at δ and 4δ,
extrapolated as δ^{1/2}), and the solid wedge between the chords to R0 ∓ d for d from half
an element to 0.05 R0 (``chords``), to see where the tip angle goes as d -> 0:

* Table 5.1's water/PDMS and EG/gel with the rest cap at the printed φl (108.1°, 92.3°), at
  Young's angle of the printed tensions (53.3°, 70.9°) and with ``--control neumann``; glycerol
  and oil (printed φl within 6° of Young's) for comparison; refine 0 and 1 (water at the
  printed φl also 2);
* water's tension ratios scaled to γl = 0.5 μR0 on a layer h = R0/2, where the tip's length
  γ/μ is 30-100 elements: the cap at Young's angle and far from it (rest angle 95°).

Usage: ``.venv/bin/python benchmarks/droplet_soft_cusp.py`` (serial, ~16 min) writes
``docs/figures/droplet_soft/cusp.json`` and ``cusp.png`` (``... droplet_soft_cusp.py plot``
redraws the figure from the json).
"""

from __future__ import annotations

import json
import math
import sys

import numpy as np
from droplet_soft_figures import OUT, table_params

SCALED = {"model": "neo-hookean", "gamma_l": 0.5, "gamma_s": 0.5 * 59 / 72, "gamma_ls": 0.5 * 16 / 72,
          "thickness": 0.5, "width": 6, "size_contact": 0.004, "load_step": 0.1}
CASES = {
    "water, printed 108.1": [table_params("water/PDMS", refine=k) for k in (0, 1, 2)],
    "water, Young 53.3": [table_params("water/PDMS", cap_angle=0.0, refine=k) for k in (0, 1)],
    "water, --control neumann": [table_params("water/PDMS", control="neumann", refine=k) for k in (0, 1)],
    "EG, printed 92.3": [table_params("EG 40%/silicone gel", refine=k) for k in (0, 1)],
    "EG, Young 70.9": [table_params("EG 40%/silicone gel", cap_angle=0.0, refine=k) for k in (0, 1)],
    "EG, --control neumann": [table_params("EG 40%/silicone gel", control="neumann")],
    "glycerol, printed 90": [table_params("glycerol/silicone gel")],
    "oil, printed 40": [table_params("fluorinated oil/silicone gel")],
    "water ratios x37, Young": [dict(SCALED, refine=k) for k in (0, 1)],
    "water ratios x37, rest 95": [dict(SCALED, cap_angle=95.0, refine=k) for k in (0, 1)],
}
KEYS = ("status", "cap_angle_deg", "drop_volume", "rest_volume", "cusp_angle_deg", "cusp_angle_chord_deg",
        "liquid_angle_deg", "vapour_angle_deg", "neumann_residual", "neumann_misfit", "tip_chord", "wall_time_s")


def study(params: dict) -> dict:
    from mpi4py import MPI

    from bcfem.mpi import sample
    from bcfem.scenes import droplet_soft as ds

    scene, _, s = ds.solve(ds.Params(**params), MPI.COMM_SELF)
    theta = scene.cap_angle()
    chords = []
    for d in np.geomspace(scene.delta / 4, 0.05, 19):
        points = np.array([[1.0, 0.0, 0.0], [1.0 - d, 0.0, 0.0], [1.0 + d, 0.0, 0.0]])
        x = points[:, :2] + sample(scene.u, points)
        chords.append([float(d), *map(math.degrees, scene._wedges(x, 1, 2, theta))])
    return {"refine": params.get("refine", 0), **{k: s[k] for k in KEYS},
            "neumann_solid_deg": s["neumann_angles_deg"]["solid"], "element": scene.delta / 2,
            "ell_min": min(params["gamma_l"], params["gamma_s"], params["gamma_ls"]) or None, "chords": chords}


def figure(found):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, 2, figsize=(13, 4.4))
    for ax, prefix in ((axes[0], ("water", "EG")), (axes[1], ("water ratios",))):
        k = 0
        for name, runs in found.items():
            if not name.startswith(prefix) or (prefix == ("water", "EG") and name.startswith("water ratios")):
                continue
            for run, style in zip(runs, ("-", "--", ":")):
                c = np.array(run["chords"])
                keep = c[:, 0] >= run["element"]  # an element or more
                ax.semilogx(c[keep, 0], c[keep, 1], f"C{k}{style}",
                            label=f"{name}, refine {run['refine']}" + (" (failed)" if run["status"] != "ok" else ""))
            ax.axhline(runs[0]["neumann_solid_deg"], color=f"C{k}", lw=0.6, ls=":")
            k += 1
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("chord length d / R0 (from one element up)")
        ax.set_ylabel("solid wedge between the chords to R0 -/+ d [deg]")
        ax.legend(fontsize=6)
    axes[0].set_title("Table 5.1's water and EG (dotted: Neumann)", fontsize=9)
    axes[1].set_title("water's ratios at gamma_l = 0.5 mu R0, h = R0/2 (dotted: Neumann 40 deg)", fontsize=9)
    return fig


def draw(found) -> None:
    fig = figure({k: [r for r in v if "chords" in r] for k, v in found.items()})
    fig.savefig(OUT / "cusp.png", dpi=130, bbox_inches="tight")


def main() -> None:
    import dolfinx_solver  # noqa: F401  (before dolfinx / petsc4py)
    from mpi4py import MPI

    from bcfem.log import configure

    configure(MPI.COMM_WORLD, quiet=True)
    found = {}
    for name, runs in CASES.items():
        found[name] = []
        for params in runs:
            try:
                found[name].append(study(params))
            except Exception as err:  # a failed case is a result too
                found[name].append({"refine": params.get("refine", 0), "status": f"error: {err}"})
            print(name, {k: found[name][-1].get(k) for k in KEYS}, flush=True)
        (OUT / "cusp.json").write_text(json.dumps(found, indent=1))
    draw(found)


if __name__ == "__main__":
    if sys.argv[1:] == ["plot"]:  # redraw from cusp.json
        draw(json.loads((OUT / "cusp.json").read_text()))
    else:
        main()
