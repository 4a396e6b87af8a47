# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
# ---

# %% [markdown]
# # Maps of a delaminating blister and the inverse fit (dissertation Figures 3.15-3.17)
#
# The adhesive blister of `blister_adhesive.py`: a membrane (Gent $J_m = 100$
# or neo-Hookean) over a liquid on a rigid substrate, debonded over
# $R < R_1$, with the free energy (eq. 3.42)
#
# \begin{align*}
# \Pi[\boldsymbol u, R_1] = {} & \int_0^{R_1} \bigl[t_0\, W(I_1) + \gamma_l\,\lambda_r\lambda_\theta\bigr]
#   \, 2\pi R\, \mathrm{d}R \\
#   & - \Delta p\, V[\boldsymbol u] + (\gamma_{ls} - \Delta\gamma)\,\pi r_1^2, \tag{3.42}
# \end{align*}
#
# $R_1$ held at $R_0$ until the energy release rate $-\partial\Pi/\partial R_1$
# reaches zero, then free. Once the edge moves the blister grows
# self-similarly (eq. 3.88): $V/V_1$ ($V_1 = \tfrac43\pi R_1^3$),
# $\Delta p R_1/(\mu t_0)$, the aspect ratio $z(0)/R_1$ and the contact angle
# $\pi - \phi_0^-$ depend only on $\alpha = \gamma_l/(\mu t_0)$ and
# $(\gamma_{ls}-\Delta\gamma)/(\mu t_0)$. They are the values at the onset, which
# is where each map point is taken (`blister_studies.after_onset`).
#
# **Axes.** The dissertation plots them "in $\gamma_l/\mu t_0 \sim
# (\gamma_{ls}-\Delta\gamma)/\mu t_0$ space", and says that the *left* border
# of every frame is the limit $V \to 0$, where $\gamma_l = \Delta\gamma -
# \gamma_{ls}$ (eq. 3.89). There the membrane is flat and unstrained, and the
# edge condition eq. 3.71 reduces to Young's law $\cos\theta =
# -(\gamma_{ls}-\Delta\gamma)/\gamma_l$ with $\theta \to 0$. That border is the
# line $(\gamma_{ls}-\Delta\gamma)/\mu t_0 = -\alpha$; it is a left border of
# the frame only with $(\gamma_{ls}-\Delta\gamma)/(\mu t_0)$ on the abscissa and
# $\alpha$ on the ordinate, as here. Left of it (debonding gains more than the
# liquid's tension costs) no blister is stable: the liquid spreads at any
# volume, and no point is solved there. The axis ranges are not in the text;
# $\alpha \in [0, 10]$ and $(\gamma_{ls}-\Delta\gamma)/(\mu t_0) \in [-10, 20]$
# contain the border and the example of Fig. 3.17, $(5.1, 15.9)$.
#
# **Neo-Hookean blisters that never delaminate.** Before onset the energy
# release rate $g(V) = -\tfrac{1}{2\pi}\partial\Pi/\partial R_1 +
# (\gamma_{ls}-\Delta\gamma)/(\mu t_0)$ (per unit of the adhesion parameter) does not
# depend on the adhesion, and onset happens where $g(V)$ reaches it. For Gent,
# $g$ diverges as the membrane locks, so every blister delaminates. For
# neo-Hookean, $g(V)$ grows but saturates; above $\sup_V g$ the edge never
# moves, the blister just inflates until it breaks. Numerically "never" means
# "not up to $V/V_0 = 50$" (`v_max`), where the meridional stretch at the edge
# is about 7 — beyond the rupture of any elastomer; $g(50)$ is within a few
# per cent of its limit, which an Aitken extrapolation of $g(12.5), g(25), g(50)$
# estimates. The map's blank (hatched) region is bounded by that curve.
#
# **Inverse fit (Fig. 3.17).** A measured aspect ratio and pressure after onset
# fix both parameters: $z(0)/R_1 = 2$, $\Delta p R_1/(\mu t_0) = 10$ (Gent).
# The starting guess is read off the computed maps, as the dissertation reads
# its Fig. 3.17, and `blister_studies.fit` then solves the two conditions and
# repeats the fit on twice the cells for its uncertainty.

# %%
import contextlib
import hashlib
import json
import logging
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace

from mpi4py import MPI

import numpy as np
from scipy.interpolate import CubicSpline

import bcfem  # noqa: F401  (before dolfinx / petsc4py)
from bcfem import ContinuationParams, io
from bcfem.log import logger
from bcfem.path.continuation import ContinuationError
from bcfem.run import demo, sweep
from bcfem.run.study import Study
from bcfem.scenes import blister_rigid, blister_studies

# %% [markdown]
# ## Parameters

# %%
MATERIALS = {  # name -> material fields and v_max (V/V0) of a map point
    "gent-Jm100": dict(fields=dict(material="gent", Jm=100.0), v_max=30.0),
    "neo-hookean": dict(fields=dict(material="neo-hookean"), v_max=50.0),
}
ALPHA_RANGE = (0.0, 10.0)  # gamma_l/(mu t0), ordinate
ADHESION_RANGE = (-10.0, 20.0)  # (gamma_ls - dgamma)/(mu t0), abscissa
GRID = {"default": (6, 6), "full": (21, 31)}  # (alpha, adhesion) points; the default grid is in the full one
CELLS = 80  # P2 cells across the blister (the fit repeats on 160)
DEGREE = 2
# ds_max = 0.1 (the scene default) fails at a few points with small adhesion: the state right after
# the onset does not converge, or the first step after it lands on a collapsed state (V <= 0);
# 0.05 fails at fewer, and a failed point is retried with ds_max halved (see `after_onset_retried`)
CONTINUATION = ContinuationParams(ds=0.05, ds_max=0.05)
RETRIES = 2
NEVER_ADHESION = 1e3  # a neo-Hookean blister traced with this adhesion never delaminates: g(V) on its branch
FIT_TARGET = {"aspect": 2.0, "P1": 10.0}
DISSERTATION_FIT = {"alpha": 5.1, "adhesion": 15.9}  # read off its Fig. 3.17
NEAR_BORDER = [(10.0, -9.5), (10.0, -9.8)]  # (alpha, adhesion) approaching the V -> 0 border
DRIFT_TOL = 1e-8  # V P^3 between the onset and R1 = 1.02 R0 (eq. 3.88)
FIT_TOL = 1e-6  # the fitted parameters reproduce the targets, relative
YOUNG_TOL = 1e-2  # (1 - cos theta) alpha/(alpha + adhesion) - 1 near the border (membrane correction)

comm = MPI.COMM_WORLD
args, report = demo.setup("blister_maps", "Dissertation Figures 3.15-3.17: maps after delamination onset", comm,
                          full="{} x {} (alpha, adhesion) points per material instead of {} x {}".format(
                              *GRID["full"], *GRID["default"]),
                          refine=f"{2 * CELLS} P{DEGREE} cells across the blister instead of {CELLS}")
study = Study("blister_maps", comm, args.out)  # every solve counted; summary.json in the runner's schema
CELLS *= 2 if args.refine else 1
full = args.full
n_alpha, n_adhesion = GRID["full" if full else "default"]
ALPHAS = np.linspace(*ALPHA_RANGE, n_alpha)
ADHESIONS = np.linspace(*ADHESION_RANGE, n_adhesion)


def base_params(name: str, **changes) -> blister_rigid.Params:
    case = MATERIALS[name]
    return blister_rigid.Params(**case["fields"], edge="adhesive", v_max=case["v_max"], cells=CELLS,
                                degree=DEGREE, continuation=CONTINUATION, **changes)


@contextlib.contextmanager
def quiet():
    """No per-step progress lines from single branches (as inside a sweep point)."""
    level = logger.level
    logger.setLevel(logging.WARNING)
    try:
        yield
    finally:
        logger.setLevel(level)


def sweep_dir(kind: str, base) -> object:
    """One results directory per base parameter set: sweep points are reused only if nothing but
    the grid values differs (a point's file name holds the grid values alone)."""
    digest = hashlib.sha1(json.dumps({**asdict(base), "retries": RETRIES}, sort_keys=True,
                                     default=str).encode()).hexdigest()[:10]
    return args.out / "sweeps" / f"{kind}-{digest}"


# %% [markdown]
# ## The maps
#
# One `sweep.run` per material over the points right of the border
# ($(\gamma_{ls}-\Delta\gamma)/\mu t_0 > -\alpha$). Points are spread over the
# ranks, each solved on its own communicator, and written as they finish, so a
# rerun (or `--full` after the default grid) reuses them.

# %%
def after_onset_retried(params, comm) -> dict:
    """`blister_studies.after_onset`, retried with ds_max halved (up to RETRIES times) when the
    trace fails; the step cap used is recorded as ``ds_max``."""
    for attempt in range(RETRIES + 1):
        ds_max = params.continuation.ds_max * 0.5**attempt
        continuation = replace(params.continuation, ds=min(params.continuation.ds, ds_max), ds_max=ds_max)
        try:
            return {**blister_studies.after_onset(replace(params, continuation=continuation), comm),
                    "ds_max": ds_max}
        except ContinuationError:
            if attempt == RETRIES:
                raise


t0 = time.perf_counter()
maps = {}
for name in MATERIALS:
    base = base_params(name)
    points = [(values, p) for values, p in sweep.grid_points(base, [("alpha", ALPHAS), ("adhesion", ADHESIONS)])
              if values["adhesion"] + values["alpha"] > 1e-12]
    maps[name] = sweep.run(points, after_onset_retried, sweep_dir(name, base), comm)
    ok = [r for r in maps[name] if r["status"] == "ok"]
    report(f"{name:12s}: {len(maps[name])} points, {sum(r['onset'] for r in ok)} delaminate, "
           f"{sum(not r['onset'] for r in ok)} never (V/V0 <= {MATERIALS[name]['v_max']:g}), "
           f"{len(maps[name]) - len(ok)} failed, {sum(r['ds_max'] < CONTINUATION.ds_max for r in ok)} "
           "needed a smaller step")
t_maps = time.perf_counter() - t0

# %% [markdown]
# ## Where neo-Hookean blisters never delaminate
#
# For each $\alpha$ of the grid, one neo-Hookean branch with an adhesion that
# is never reached, to $V/V_0 = 50$; $g(V) = A - \tfrac12\,\partial\Pi/\partial R_1$
# in the normalisation of the `dPi_dR1` column, $A$ = that adhesion. Also a
# `sweep`, with its own solve function.

# %%
def release_rate_limit(params, comm) -> dict:
    """sup g(V) for V/V0 <= v_max, its Aitken extrapolation from V/V0 = v_max/4, v_max/2, v_max,
    and the blister at v_max: the map values of the adhesion g_sup, whose onset is at v_max."""
    branch = study.branch(blister_rigid.build(params, comm))
    assert not branch.events, "the never-reached adhesion was reached"
    V = branch.column("V_over_V0")
    g = params.adhesion - 0.5 * branch.column("dPi_dR1")
    g1, g2, g3 = CubicSpline(V, g)([params.v_max / 4, params.v_max / 2, params.v_max])
    end = branch.rows[-1]
    return {"g_sup": float(np.max(g)), "V_at_sup": float(V[np.argmax(g)]),
            "g_limit": float(g3 - (g3 - g2) ** 2 / ((g3 - g2) - (g2 - g1))),
            "monotone": bool(np.all(np.diff(g[V > 1.0]) > 0)),
            "V_over_V1": end["V_over_V0"], "P1": end["P"], "aspect1": end["aspect"],
            "contact_angle_deg": end["contact_angle_deg"]}


t0 = time.perf_counter()
never_base = base_params("neo-hookean", adhesion=NEVER_ADHESION)
never = sweep.run(sweep.grid_points(never_base, [("alpha", ALPHAS)]), release_rate_limit,
                  sweep_dir("neo-hookean-release-rate", never_base), comm)
never = sorted(never, key=lambda r: r["alpha"])
report("neo-Hookean: largest adhesion that delaminates by V/V0 = 50 (extrapolated to V -> oo): "
       + ", ".join(f"alpha={r['alpha']:g}: {r['g_sup']:.3f} ({r['g_limit']:.3f})" for r in never))
t_never = time.perf_counter() - t0

# %% [markdown]
# ## Near the left border: the droplet limit
#
# As $(\gamma_{ls}-\Delta\gamma)/\mu t_0 \to -\alpha$ the onset volume goes to
# zero, the membrane's own tension vanishes next to $\gamma_l$, and the
# contact angle obeys Young's law (eq. 3.73 with $\gamma_s \to \Delta\gamma$):
# $1 - \cos\theta = (\alpha + (\gamma_{ls}-\Delta\gamma)/\mu t_0)/\alpha$, with a
# membrane correction that shrinks towards the border.

# %%
near = []
for alpha, adhesion in NEAR_BORDER:
    with quiet():
        values = blister_studies.after_onset(base_params("gent-Jm100", alpha=alpha, adhesion=adhesion), comm)
    theta = math.radians(values["contact_angle_deg"])
    near.append({"alpha": alpha, "adhesion": adhesion, **values,
                 "young_deviation": (1 - math.cos(theta)) * alpha / (alpha + adhesion) - 1,
                 "laplace_deviation": values["P1"] / (2 * alpha * math.sin(theta)) - 1})
report("near the border: " + ", ".join(
    f"({r['alpha']:g}, {r['adhesion']:g}): theta = {r['contact_angle_deg']:.3f} deg, Young {r['young_deviation']:+.1e}, "
    f"Laplace {r['laplace_deviation']:+.1e}" for r in near))

# %% [markdown]
# ## Inverse fit (Fig. 3.17)
#
# The guess: the point of the valid region where the linear interpolants of the
# Gent maps come closest to both targets (this is reading Fig. 3.17 off the
# computed maps). Then the fit on 80 and 160 cells.

# %%
def triangulation(name, key):
    """Delaunay triangulation of the delaminating points and of the region's borders: the
    V -> 0 border, where every map quantity tends to 0 (flat blister, theta -> 0), and for
    neo-Hookean the never-delaminating boundary, where onset is at v_max (values of the
    never-delaminating branch there)."""
    import matplotlib.tri as mtri

    done = [r for r in maps[name] if r["status"] == "ok" and r["onset"]]
    x = [r["adhesion"] for r in done] + [-a for a in ALPHAS]
    y = [r["alpha"] for r in done] + list(ALPHAS)
    z = [r[key] for r in done] + [0.0] * len(ALPHAS)
    if name == "neo-hookean":
        x += [r["g_sup"] for r in never]
        y += [r["alpha"] for r in never]
        z += [r[key] for r in never]
    return mtri.Triangulation(x, y), np.array(z)


def map_guess(name):
    import matplotlib.tri as mtri

    X, Y = np.meshgrid(np.linspace(*ADHESION_RANGE, 301), np.linspace(*ALPHA_RANGE, 201))
    aspect = mtri.LinearTriInterpolator(*triangulation(name, "aspect1"))(X, Y)
    P1 = mtri.LinearTriInterpolator(*triangulation(name, "P1"))(X, Y)
    miss = (aspect / FIT_TARGET["aspect"] - 1) ** 2 + (P1 / FIT_TARGET["P1"] - 1) ** 2
    k = np.unravel_index(np.ma.argmin(miss), miss.shape)
    return float(Y[k]), float(X[k])  # (alpha, adhesion)


t0 = time.perf_counter()
guess = comm.bcast(map_guess("gent-Jm100") if comm.rank == 0 else None, root=0)
fit_base = base_params("gent-Jm100")
with quiet():
    fit = blister_studies.fit(FIT_TARGET["aspect"], FIT_TARGET["P1"], fit_base, comm, guess=guess)
    check_fit = blister_studies.after_onset(
        replace(fit_base, cells=fit["cells"], alpha=fit["alpha"], adhesion=fit["adhesion"]), comm)
    at_dissertation = blister_studies.after_onset(replace(fit_base, **DISSERTATION_FIT), comm)
t_fit = time.perf_counter() - t0
report(f"fit (aspect = {FIT_TARGET['aspect']:g}, P1 = {FIT_TARGET['P1']:g}) from the map guess "
       f"({guess[0]:.2f}, {guess[1]:.2f}): alpha = {fit['alpha']:.6f} +- {fit['alpha_uncertainty']:.1e}, "
       f"adhesion = {fit['adhesion']:.6f} +- {fit['adhesion_uncertainty']:.1e} "
       f"({fit['evaluations']} branches); dissertation (5.1, 15.9)")
report(f"at the dissertation's (5.1, 15.9) our blister has aspect {at_dissertation['aspect1']:.3f} "
       f"and P1 = {at_dissertation['P1']:.3f}")

# %% [markdown]
# ## Write results
#
# `maps.csv` (both materials, one row per grid point: status, onset, the four
# map values and the self-similarity drift), `never.csv` (the neo-Hookean
# boundary) and `summary.json` (parameters, fit, checks, timings).

# %%
MAP_KEYS = ["V_over_V1", "P1", "aspect1", "contact_angle_deg", "self_similarity_drift"]
io.write_csv(args.out / "maps.csv", [{"model": name, **r} for name, rows in maps.items() for r in rows], comm,
             columns=["model", "alpha", "adhesion", "status", "onset", *MAP_KEYS, "ds_max", "reason"])
io.write_csv(args.out / "never.csv", never, comm,
             columns=["alpha", "status", "g_sup", "V_at_sup", "g_limit", "monotone", "reason"])

ok_points = {name: [r for r in rows if r["status"] == "ok"] for name, rows in maps.items()}
A_star = dict((r["alpha"], r["g_sup"]) for r in never)
onset_consistent = all(r["onset"] == (r["adhesion"] < A_star[r["alpha"]]) for r in ok_points["neo-hookean"])
checks = {
    "failed_points": {name: [(r["alpha"], r["adhesion"], r["reason"]) for r in rows if r["status"] != "ok"]
                      for name, rows in maps.items()},
    "max_self_similarity_drift": {name: max(r["self_similarity_drift"] for r in rows if r["onset"])
                                  for name, rows in ok_points.items()},
    "retried_points": {name: [(r["alpha"], r["adhesion"], r["ds_max"]) for r in rows
                              if r["status"] == "ok" and r["ds_max"] < CONTINUATION.ds_max]
                       for name, rows in maps.items()},
    "gent_always_delaminates": all(r["onset"] for r in ok_points["gent-Jm100"]),
    "neo_hookean_never_points": [(r["alpha"], r["adhesion"]) for r in ok_points["neo-hookean"] if not r["onset"]],
    "neo_hookean_onset_iff_below_sup_g": onset_consistent,
    "fit_reproduces_targets": {"aspect1": check_fit["aspect1"], "P1": check_fit["P1"]},
    "near_border": near,
}
study.write({
    "parameters": {"alpha_range": ALPHA_RANGE, "adhesion_range": ADHESION_RANGE, "grid": [n_alpha, n_adhesion],
                   "cells": CELLS, "degree": DEGREE, "never_adhesion": NEVER_ADHESION,
                   "materials": {k: {**v["fields"], "v_max": v["v_max"]} for k, v in MATERIALS.items()},
                   "continuation": asdict(CONTINUATION)},
    "fit": {"target": FIT_TARGET, "guess_from_maps": guess, **fit,
            "dissertation": DISSERTATION_FIT,
            "relative_difference": {k: fit[k] / DISSERTATION_FIT[k] - 1 for k in DISSERTATION_FIT},
            "ours_at_dissertation_point": at_dissertation},
    "neo_hookean_never_boundary": never,
    "checks": checks,
    "parts_s": {"maps": t_maps, "never_boundary": t_never, "fit": t_fit},
})

# %% [markdown]
# ## Plot (rank 0)
#
# `maps_gent.png` (Fig. 3.15) and `maps_neo_hookean.png` (Fig. 3.16): filled
# contours over the delaminating points and the border (black line, where all
# four quantities vanish); grey dots are the solved points (default grid). On
# the neo-Hookean maps the hatched region never delaminates (its edge: $\sup g$
# up to $V/V_0 = 50$; dotted: extrapolated to $V \to \infty$), crosses are the
# grid points there. `fit.png` (Fig. 3.17): the contours aspect $= 2$ and
# $\Delta p R_1/\mu t_0 = 10$ of the Gent maps, their intersection from the
# fit, and the dissertation's reading.

# %%
@dataclass(frozen=True)
class Results:
    """What the figures draw: the solved map points by material, the neo-Hookean never-delaminating
    boundary, the fit and its target, the dissertation's reading of it, the demo's ``triangulation``
    of a map quantity, the grid (ranges, points per axis, materials) and the run."""

    ok_points: dict
    never: list
    fit: dict
    fit_target: dict
    dissertation_fit: dict
    triangulation: Callable
    alpha_range: tuple
    adhesion_range: tuple
    n_alpha: int
    n_adhesion: int
    materials: dict
    run: demo.Run


if comm.rank == 0:
    from _figures_blister_maps import draw

    draw(Results(
        ok_points=ok_points, never=never, fit=fit, fit_target=FIT_TARGET, dissertation_fit=DISSERTATION_FIT,
        triangulation=triangulation, alpha_range=ALPHA_RANGE, adhesion_range=ADHESION_RANGE, n_alpha=n_alpha,
        n_adhesion=n_adhesion, materials=MATERIALS, run=demo.Run(args, comm, report)))

# %% [markdown]
# ## Assert
#
# 1. Every point is solved, and at every delaminating point $V P^3$ is the same
#    at the onset and at $R_1 = 1.02 R_0$ (self-similar growth, eq. 3.88).
# 2. Gent blisters always delaminate; a neo-Hookean one delaminates exactly
#    where its adhesion is below $\sup_V g$, computed independently from one
#    never-delaminating branch per $\alpha$; and there is a never-region.
# 3. The fitted parameters reproduce the targets on the fit's finer mesh, and
#    the mesh uncertainty of the fit is small.
# 4. Near the border, Young's law holds up to a membrane correction that
#    shrinks towards the border, and the pressure is Laplace's $2\gamma_l\sin\theta/R_1$.

# %%
assert not any(checks["failed_points"].values()), checks["failed_points"]
assert all(r["status"] == "ok" and r["monotone"] for r in never), never
for name, drift in checks["max_self_similarity_drift"].items():
    assert drift < DRIFT_TOL, (name, drift)
assert checks["gent_always_delaminates"]
assert checks["neo_hookean_never_points"], "no neo-Hookean point without onset: the never-region is missing"
assert onset_consistent, [(r["alpha"], r["adhesion"], r["onset"], A_star[r["alpha"]]) for r in ok_points["neo-hookean"]]
assert all(r["g_sup"] < r["g_limit"] < 1.1 * r["g_sup"] for r in never), never
assert fit["converged"], fit
assert abs(check_fit["aspect1"] / FIT_TARGET["aspect"] - 1) < FIT_TOL, check_fit
assert abs(check_fit["P1"] / FIT_TARGET["P1"] - 1) < FIT_TOL, check_fit
assert fit["alpha_uncertainty"] < 1e-4 and fit["adhesion_uncertainty"] < 1e-4, fit
assert all(abs(r["young_deviation"]) < YOUNG_TOL for r in near), near
assert abs(near[1]["young_deviation"]) < abs(near[0]["young_deviation"]), near
assert all(abs(r["laplace_deviation"]) < YOUNG_TOL for r in near), near
report("checks passed")
