"""The droplet-soft scene's figure: the deformed top surface, with the linear theory."""

from __future__ import annotations

import math

import numpy as np


def theory_profile(params, radii):
    """(u_r, u_z)/R0 of ``bcfem.theory.ridge`` at ``radii`` (γls = γs only), else None."""
    if params.model != "linear" or params.gamma_s != params.gamma_ls or params.gamma_s == 0:
        return None
    from bcfem.theory import ridge

    d = ridge.surface_displacement(radii, params.c, params.nu, params.young_angle, params.thickness or None)
    return d.u_r * params.gamma_l, d.u_z * params.gamma_l


def profile_figure(profile, params, summary):
    """z against r of the top surface near the drop (and the cap for the neo-Hookean model)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    R = np.array([row["R_over_R0"] for row in profile])
    r = np.array([row["r"] for row in profile])
    z = np.array([row["z"] for row in profile])
    keep = R <= 3.0
    ax.plot(r[keep], z[keep], "C3-", label=f"FE, {params.model}")
    theory = theory_profile(params, R[keep & (R != 1.0)])
    if theory is not None:
        Rt = R[keep & (R != 1.0)]
        ax.plot(Rt + theory[0], theory[1], "k--", lw=1, label="Hankel solution (theory/ridge.py)")
    if params.model == "neo-hookean" and summary.get("tip_r") is not None:
        rc, zc, theta = summary["tip_r"], summary["tip_z"], math.radians(summary["cap_angle_deg"])
        radius = rc / math.sin(theta)
        centre = zc - radius * math.cos(theta)
        phi = np.linspace(-theta, theta, 200)
        ax.plot(radius * np.sin(phi[phi >= 0]), centre + radius * np.cos(phi[phi >= 0]), "C0-", lw=1, label="cap")
    ax.set_xlabel("r / R0")
    ax.set_ylabel("z / R0")
    ax.set_title(f"droplet-soft: gamma_l = {params.gamma_l:g}, gamma_s = {params.gamma_s:g}, "
                 f"gamma_ls = {params.gamma_ls:g} (mu R0)", fontsize=9)
    ax.legend(fontsize=8)
    return fig
