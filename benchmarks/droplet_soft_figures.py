"""Chapter 5's figures from the droplet-soft scene (serial, in one process).

``.venv/bin/python benchmarks/droplet_soft.py figures`` writes into ``docs/figures/droplet_soft/``:

* ``fig5_4.png``: half-space, ν = 1/2, c = 1, 10, 100, 1000: FE surfaces and the Hankel
  solutions; the ridge height against c with the corrected asymptote and eq. 5.34 as printed;
* ``fig5_5.png``: ν = 0.3, c = 10, r0/h = 0 (half-space), 2, 5, 10;
* ``fig5_6.png``: ν = 1/2, r0/h = 2, μ r0/γs = 1 against the analytic solution, and Young
  angles π/4, π/2, 3π/4 (μ r0/γs = μ r0/γl = 10), pull as eq. 5.22 and balanced;
* ``fig5_6cd.png``: Fig. 5.6c-d, the displacement field μ u_r/γl and μ u_z/γl in the layer
  (ν = 1/2, r0/h = 2, μ r0/γs = 1, the case of Fig. 5.6a-b), contours on the reference section;
* ``fig5_7.png``: linear (ν = 1/2) against neo-Hookean, R0/h = 2, γ/(μ R0) = 0.01, 0.2, 0.5;
* ``fig5_8.png``: Fig. 5.8's systems at Table 5.1's parameters (no experimental profile is
  given in numbers, so nothing is fitted): (a) EG 40 %/gel at E = 1.5, 3, 4.5 kPa and the
  text's best fit 6 kPa, (b) water/PDMS at 16, 20, 24 kPa, ridge tips translated to the tip
  as the dissertation does; (c) glycerol/gel at 4.5 kPa, R0 = 26.8 ... 225.5 um, and R0 such
  that the deformed r0 is 26.8 um (the text's explanation of its mismatch at that radius);
* ``fig5_9.png``: the four systems of Table 5.1: the neo-Hookean tip angles against Neumann's;
* ``numbers.json``: every number quoted in ``docs/results.md``.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "figures" / "droplet_soft"

#: Table 5.1: E [kPa] (the dissertation's best fit where it gives one), R0 [um], thickness [um],
#: gamma_l, gamma_s, gamma_ls [mN/m], Young angle [deg] as printed
TABLE_5_1 = {
    "water/PDMS": (16.0, 1000.0, 50.0, 72.0, 59.0, 16.0, 108.1),
    "EG 40%/silicone gel": (3.0, 1000.0, 50.0, 58.0, 42.0, 23.0, 92.3),
    "glycerol/silicone gel": (4.5, 74.5, 50.0, 46.0, 31.0, 36.0, 90.0),
    "fluorinated oil/silicone gel": (4.5, 200.0, 23.0, 17.0, 28.0, 16.0, 40.0),
}


#: Fig. 5.8c-d: the glycerol drops' radii [um]
GLYCEROL_RADII = (26.8, 74.5, 176.7, 225.5)


def table_params(system: str, E: float | None = None, R0: float | None = None, **extra) -> dict:
    """The droplet-soft parameters of a Table 5.1 system (E [kPa], R0 [um] overriding the
    table's), μ = E/3 (incompressible), the rest cap at the printed φl, the mesh graded to the
    smallest tension's length γ/μ."""
    E0, R00, h, gl, gs, gls, angle = TABLE_5_1[system]
    E, R0 = E or E0, R0 or R00
    mu_r0 = E * 1e3 / 3 * R0 * 1e-6 * 1e3  # mu R0 in mN/m
    tensions = {"gamma_l": gl / mu_r0, "gamma_s": gs / mu_r0, "gamma_ls": gls / mu_r0}
    tip = min(tensions.values()) * 0.05
    return {"model": "neo-hookean", "thickness": h / R0, "width": min(6.0, 1 + 40 * h / R0),
            "size_contact": max(1e-4, min(2e-3, tip)), "load_step": 0.1, "cap_angle": angle, **tensions, **extra}


def solve(**kwargs):
    from mpi4py import MPI

    from bcfem.scenes import droplet_soft as ds

    scene, rows, summary = ds.solve(ds.Params(**kwargs), MPI.COMM_SELF)
    return scene.profile, rows, summary


def columns(profile, *keys, lo=0.0, hi=3.0):
    rows = [r for r in profile if lo <= r["R_over_R0"] <= hi]
    return [np.array([r[k] for r in rows]) for k in keys]


def fig5_4(plt, numbers):
    from bcfem.theory import ridge

    nu, gamma_l = 0.5, 0.1
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    heights = {}
    for k, c in enumerate((1, 10, 100, 1000)):
        gamma_s = 1 / ((1 - nu) * c)
        profile, _, s = solve(gamma_s=gamma_s, gamma_ls=gamma_s, gamma_l=gamma_l, nu=nu,
                              size_contact=min(2e-3, 0.2 * gamma_s), width=80)
        R, ur, uz = columns(profile, "R_over_R0", "u_r", "u_z")
        exact = ridge.surface_displacement(R[R != 1], c, nu)
        for ax, fe, th in ((axes[0], ur, exact.u_r), (axes[1], uz, exact.u_z)):
            ax.plot(R, fe / gamma_l, f"C{k}-", label=f"c = {c}")
            ax.plot(R[R != 1], th, "k--", lw=0.8)
        heights[c] = {"fe": s["ridge_height"] / gamma_l, "theory": s["ridge_height_theory"] / gamma_l,
                      "error": s["ridge_height_error"]}
    axes[0].set_ylabel("mu u_r / gamma_l")
    axes[1].set_ylabel("mu u_z / gamma_l")
    for ax in axes[:2]:
        ax.set_xlabel("r / r0")
        ax.legend(fontsize=8)
    cs = np.logspace(0, 3.5, 30)
    theory = [ridge.ridge_height(c, nu) / (1 - nu) for c in cs]
    axes[2].semilogx(cs, theory, "C0-", label="Hankel solution")
    axes[2].semilogx(cs, [ridge.ridge_height_asymptote(c, nu) / (1 - nu) for c in cs], "k--",
                     label="(ln c + C)/pi + 1/c (corrected asymptote)")
    axes[2].semilogx(cs, np.log(cs) / np.pi**0.25, "C1:", label="ln c / pi^(1/4) (eq. 5.34 as printed)")
    axes[2].semilogx(list(heights), [h["fe"] / (1 - nu) for h in heights.values()], "ro", label="FE")
    axes[2].set_xlabel("c = mu r0 / ((1 - nu) gamma_s)")
    axes[2].set_ylabel("mu u_z(r0) / ((1 - nu) gamma_l)")
    axes[2].legend(fontsize=7)
    fig.suptitle("Fig. 5.4: half-space, nu = 0.5 (dashed: theory/ridge.py)", fontsize=10)
    numbers["fig5_4"] = {str(c): h for c, h in heights.items()}
    return fig


def fig5_5(plt, numbers):
    from bcfem.theory import ridge

    nu, c, gamma_l = 0.3, 10.0, 0.1
    gamma_s = 1 / ((1 - nu) * c)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    found = {}
    for k, ratio in enumerate((0, 2, 5, 10)):
        thickness = 1 / ratio if ratio else 0.0
        profile, _, s = solve(gamma_s=gamma_s, gamma_ls=gamma_s, gamma_l=gamma_l, nu=nu, thickness=thickness,
                              width=80 if ratio == 0 else 6)
        R, ur, uz = columns(profile, "R_over_R0", "u_r", "u_z")
        exact = ridge.surface_displacement(R[R != 1], c, nu, thickness=thickness or None)
        for ax, fe, th in ((axes[0], ur, exact.u_r), (axes[1], uz, exact.u_z)):
            ax.plot(R, fe / gamma_l, f"C{k}-", label=f"r0/h = {ratio}")
            ax.plot(R[R != 1], th, "k--", lw=0.8)
        found[ratio] = {"fe": s["ridge_height"] / gamma_l, "theory": s["ridge_height_theory"] / gamma_l,
                        "error": s["ridge_height_error"]}
    for ax, label in zip(axes[:2], ("mu u_r / gamma_l", "mu u_z / gamma_l")):
        ax.set_xlabel("r / r0")
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
    axes[2].plot(list(found), [f["fe"] for f in found.values()], "ro-", label="FE")
    axes[2].plot(list(found), [f["theory"] for f in found.values()], "k+", ms=10, label="Hankel")
    axes[2].set_xlabel("r0 / h (0: half-space)")
    axes[2].set_ylabel("mu u_z(r0) / gamma_l")
    axes[2].legend(fontsize=8)
    fig.suptitle("Fig. 5.5: layers, nu = 0.3, c = 10", fontsize=10)
    numbers["fig5_5"] = {str(k): v for k, v in found.items()}
    return fig


def fig5_6(plt, numbers):
    from bcfem.theory import ridge

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    gamma_l = 0.1
    profile, _, s = solve(gamma_s=1.0, gamma_ls=1.0, gamma_l=gamma_l, nu=0.5, thickness=0.5, width=6)
    R, ur, uz = columns(profile, "R_over_R0", "u_r", "u_z")
    exact = ridge.surface_displacement(R[R != 1], 2.0, 0.5, thickness=0.5)
    for ax, fe, th, label in ((axes[0], ur, exact.u_r, "mu u_r / gamma_l"), (axes[1], uz, exact.u_z,
                                                                             "mu u_z / gamma_l")):
        ax.plot(R, fe / gamma_l, "r-", label="FE")
        ax.plot(R[R != 1], th, "k--", label="analytic")
        ax.set_xlabel("r / r0")
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
    numbers["fig5_6"] = {"ridge_height": s["ridge_height"] / gamma_l, "theory": s["ridge_height_theory"] / gamma_l,
                         "error": s["ridge_height_error"],
                         "max_u_r_deviation": float(np.max(np.abs(ur[R != 1] / gamma_l - exact.u_r)))}
    young = {}
    for k, theta in enumerate((math.pi / 4, math.pi / 2, 3 * math.pi / 4)):
        gamma_ls = 0.1 - 0.1 * math.cos(theta)
        for force, style in (("liquid", "-"), ("balanced", ":")):
            profile, _, s = solve(gamma_s=0.1, gamma_ls=gamma_ls, gamma_l=0.1, nu=0.5, thickness=0.5, width=6,
                                  contact_force=force)
            R, r, z = columns(profile, "R_over_R0", "r", "z")
            label = f"theta_Y = {round(math.degrees(theta))} deg, {force}"
            axes[2].plot(r, z / 0.1, f"C{k}{style}", label=label)
            young[label] = {"ridge_height": s["ridge_height"] / 0.1, "u_r_tip": (s["tip_r"] - 1) / 0.1}
    axes[2].set_xlabel("r / r0")
    axes[2].set_ylabel("mu z / gamma_l")
    axes[2].legend(fontsize=6)
    fig.suptitle("Fig. 5.6: nu = 0.5, r0/h = 2; (a, b) mu r0/gamma_s = 1; (c) mu r0/gamma_s = mu r0/gamma_l = 10",
                 fontsize=10)
    numbers["fig5_6e"] = young
    return fig


def fig5_6cd(plt, numbers):
    """Contours of the FE displacement field of Fig. 5.6a-b's case on the layer's section."""
    from mpi4py import MPI

    from bcfem.mpi import sample
    from bcfem.scenes import droplet_soft as ds

    gamma_l, thickness = 0.1, 0.5
    scene, _, s = ds.solve(ds.Params(gamma_s=1.0, gamma_ls=1.0, gamma_l=gamma_l, nu=0.5, thickness=thickness,
                                     width=6), MPI.COMM_SELF)
    r = np.linspace(0.0, 3.0, 241)
    z = np.linspace(-thickness, 0.0, 81)
    R, Z = np.meshgrid(r, z)
    points = np.column_stack([R.ravel(), Z.ravel(), np.zeros(R.size)])
    u = sample(scene.u, points) / gamma_l
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.2), sharex=True)
    found = {}
    for ax, k, name in ((axes[0], 0, "mu u_r / gamma_l"), (axes[1], 1, "mu u_z / gamma_l")):
        field = u[:, k].reshape(R.shape)
        limit = float(np.nanmax(np.abs(field)))
        filled = ax.contourf(R, Z, field, levels=np.linspace(-limit, limit, 21), cmap="RdBu_r")
        ax.contour(R, Z, field, levels=np.linspace(-limit, limit, 21), colors="k", linewidths=0.3)
        fig.colorbar(filled, ax=ax, label=name)
        ax.axvline(1.0, color="0.3", lw=0.6, ls=":")
        ax.set_ylabel("z / r0")
        ax.set_aspect("equal")
        found[name] = {"min": float(np.nanmin(field)), "max": float(np.nanmax(field))}
    axes[1].set_xlabel("r / r0 (reference section; dotted: the contact line)")
    fig.suptitle("Fig. 5.6c-d: displacement field, nu = 0.5, r0/h = 2, mu r0/gamma_s = 1 (linear FE)", fontsize=10)
    found["ridge_height"] = s["ridge_height"] / gamma_l
    numbers["fig5_6cd"] = found
    return fig


def fig5_7(plt, numbers):
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    found = {}
    for ax, gamma in zip(axes, (0.01, 0.2, 0.5)):
        tensions = {"gamma_s": gamma, "gamma_l": gamma, "gamma_ls": gamma}
        lin, _, sl = solve(nu=0.5, thickness=0.5, width=6, **tensions)
        nh, _, sn = solve(model="neo-hookean", thickness=0.5, width=6, load_step=0.1, **tensions)
        for profile, style, label in ((lin, "r--", "linear, nu = 0.5"), (nh, "b-", "neo-Hookean")):
            _, r, z = columns(profile, "R_over_R0", "r", "z", hi=2.5)
            ax.plot(r, z, style, label=label)
        ax.set_title(f"gamma / (mu R0) = {gamma}", fontsize=9)
        ax.set_xlabel("r / R0")
        ax.set_ylabel("z / R0")
        ax.legend(fontsize=8)
        found[str(gamma)] = {"linear": sl["ridge_height"], "neo_hookean": sn["ridge_height"],
                             "r0_over_R0": sn["tip_r"], "cap_angle_deg": sn["cap_angle_deg"],
                             "cusp_angle_deg": sn["cusp_angle_deg"], "linear_cusp_angle_deg": sl["cusp_angle_deg"]}
    fig.suptitle("Fig. 5.7: R0/h = 2, gamma_l = gamma_s = gamma_ls", fontsize=10)
    numbers["fig5_7"] = found
    return fig


def fig5_8(plt, numbers):
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    found: dict = {}
    for ax, system, moduli in ((axes[0], "EG 40%/silicone gel", (1.5, 3.0, 4.5, 6.0)),
                               (axes[1], "water/PDMS", (16.0, 20.0, 24.0))):
        R0 = TABLE_5_1[system][1]
        for k, E in enumerate(moduli):
            profile, _, s = solve(**table_params(system, E=E))
            _, r, z = columns(profile, "R_over_R0", "r", "z", lo=0.9, hi=1.1)
            ax.plot((r - s["tip_r"]) * R0, (z - s["tip_z"]) * R0, f"C{k}-", label=f"E = {E:g} kPa")
            found[f"{system}, E = {E:g} kPa"] = {
                "ridge_height_um": s["ridge_height"] * R0, "tip_z_um": s["tip_z"] * R0,
                "cusp_angle_deg": s["cusp_angle_deg"], "cusp_angle_chord_deg": s["cusp_angle_chord_deg"],
                "cap_angle_deg": s["cap_angle_deg"], "neumann_residual": s["neumann_residual"]}
        ax.set_xlim(-20, 20)
        ax.set_ylim(-25, 5)
        ax.set_aspect("equal")
        ax.set_xlabel("x' = r - r_tip [um]")
        ax.set_ylabel("z' = z - z_tip [um]")
        ax.set_title(f"{system}: ridge tips, translated to the tip", fontsize=9)
        ax.legend(fontsize=7)
    system = "glycerol/silicone gel"
    ax = axes[2]
    for k, R0 in enumerate(GLYCEROL_RADII):
        profile, _, s = solve(**table_params(system, R0=R0))
        _, r, z = columns(profile, "R_over_R0", "r", "z", hi=300 / R0)
        ax.plot(r * R0, z * R0, f"C{k}-", label=f"R0 = {R0:g} um")
        found[f"{system}, R0 = {R0:g} um"] = {
            "r0_um": s["tip_r"] * R0, "ridge_height_um": s["ridge_height"] * R0, "cap_angle_deg": s["cap_angle_deg"],
            "laplace_pressure_Pa": s["laplace_pressure"] * TABLE_5_1[system][3] / R0 * 1e3,
            "centre_dip_um": float(z[0]) * R0, "cusp_angle_deg": s["cusp_angle_deg"]}
    # the text's explanation of the 26.8 um mismatch: R0 such that the deformed r0 is 26.8 um
    target, R0 = GLYCEROL_RADII[0], GLYCEROL_RADII[0]
    for _ in range(3):  # r0/R0 changes slowly with R0: a fixed-point iteration
        profile, _, s = solve(**table_params(system, R0=R0))
        R0 = target / s["tip_r"]
    profile, _, s = solve(**table_params(system, R0=R0))
    _, r, z = columns(profile, "R_over_R0", "r", "z", hi=300 / R0)
    ax.plot(r * R0, z * R0, "k--", lw=1, label=f"R0 = {R0:.2f} um (r0 = {s['tip_r'] * R0:.2f} um)")
    found[f"{system}, r0 = {target:g} um"] = {
        "R0_um": R0, "r0_um": s["tip_r"] * R0, "ridge_height_um": s["ridge_height"] * R0,
        "laplace_pressure_Pa": s["laplace_pressure"] * TABLE_5_1[system][3] / R0 * 1e3,
        "centre_dip_um": float(z[0]) * R0}
    ax.set_xlim(0, 300)
    ax.set_xlabel("r [um]")
    ax.set_ylabel("z [um]")
    ax.set_title("glycerol/silicone gel, E = 4.5 kPa (Fig. 5.8d)", fontsize=9)
    ax.legend(fontsize=7)
    fig.suptitle("Fig. 5.8 at Table 5.1's parameters (neo-Hookean FE; the experimental images are not "
                 "given in numbers)", fontsize=10)
    numbers["fig5_8"] = found
    return fig


def fig5_9(plt, numbers):
    found = {}
    for name, (E, R0, h, gl, gs, gls, angle) in TABLE_5_1.items():
        mu_r0 = E * 1e3 / 3 * R0 * 1e-6 * 1e3  # mu R0 in mN/m (incompressible: mu = E/3)
        tensions = {"gamma_l": gl / mu_r0, "gamma_s": gs / mu_r0, "gamma_ls": gls / mu_r0}
        tip = min(tensions.values()) * 0.05
        _, _, s = solve(model="neo-hookean", thickness=h / R0, width=min(6.0, 1 + 40 * h / R0),
                        size_contact=max(1e-4, min(2e-3, tip)), load_step=0.1, cap_angle=angle, **tensions)
        found[name] = {"E_kPa": E, "gamma_over_mu_R0": tensions, "h_over_R0": h / R0,
                       "young_deg": s["young_angle_deg"], "rest_angle_deg": angle, "cap_angle_deg": s["cap_angle_deg"],
                       "cusp_angle_deg": s["cusp_angle_deg"], "cusp_angle_chord_deg": s["cusp_angle_chord_deg"],
                       "liquid_angle_deg": s["liquid_angle_deg"], "vapour_angle_deg": s["vapour_angle_deg"],
                       "neumann_deg": s["neumann_angles_deg"], "neumann_residual": s["neumann_residual"],
                       "ridge_height_um": s["ridge_height"] * R0, "status": s["status"]}
    fig, ax = plt.subplots(figsize=(7, 3.8))
    names = list(found)
    x = np.arange(len(names))
    ax.bar(x - 0.2, [found[n]["cusp_angle_deg"] for n in names], 0.4, label="FE neo-Hookean, tip (extrapolated)")
    ax.bar(x + 0.2, [found[n]["neumann_deg"]["solid"] for n in names], 0.4, label="Neumann's triangle")
    ax.set_xticks(x, [n.replace("/", "/\n") for n in names], fontsize=7)
    ax.set_ylabel("solid (cusp) angle theta_s [deg]")
    ax.legend(fontsize=8)
    ax.set_title("Fig. 5.9: cusp angles of Table 5.1's systems", fontsize=10)
    numbers["fig5_9"] = found
    return fig


FIGURES = {"fig5_4": fig5_4, "fig5_5": fig5_5, "fig5_6": fig5_6, "fig5_6cd": fig5_6cd, "fig5_7": fig5_7,
           "fig5_8": fig5_8, "fig5_9": fig5_9}


def main(names=None) -> None:
    """Draw ``names`` (all by default) and merge their numbers into ``numbers.json``."""
    import matplotlib

    matplotlib.use("Agg")
    import dolfinx_solver  # noqa: F401  (before dolfinx / petsc4py)
    from mpi4py import MPI

    import matplotlib.pyplot as plt

    from bcfem.log import configure

    configure(MPI.COMM_WORLD, quiet=True)
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / "numbers.json"
    numbers: dict = json.loads(path.read_text()) if path.exists() else {}
    for name in names or FIGURES:
        fig = FIGURES[name](plt, numbers)
        fig.savefig(OUT / f"{name}.png", dpi=130, bbox_inches="tight")
        plt.close(fig)
        (OUT / "numbers.json").write_text(json.dumps(numbers, indent=1))
        print(name, json.dumps(numbers[name] if name in numbers else None)[:2000], flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
