"""Studies on the blister scene: onset by energy comparison, maps after onset, inverse fit.

After delamination onset an adhesive blister grows self-similarly (eq. 3.88):
V/V1, dp R1/(mu_f t0), z(0)/R1 and the contact angle stay constant, with R1
the current debond radius and V1 = 4/3 pi R1^3. They are therefore the values
at the onset point itself, which is where a map point stops.

Map points and fit evaluations that differ only in the run-time parameters
(``blister_rigid.RUN_TIME``: alpha, adhesion, ...) trace one composed blister again
(:mod:`bcfem.run.session`); :func:`reusing` scopes that, and the sessions are closed at exit.
"""

from __future__ import annotations

import math
from dataclasses import asdict, replace

import numpy as np
from dolfinx import fem

from bcfem.mpi import global_sum, real_value
from bcfem.params import Bound, require
from bcfem.path.continuation import ContinuationError
from bcfem.path.volume_control import VolumeControl
from bcfem.physics.protocols import total_energy
from bcfem.run.session import Sessions
from bcfem.scenes.blister_rigid import V0, Params, build, compose, scene_for, structure
from bcfem.solver.problem import Problem

#: the blister of the last structure traced by this process's map points and fits
_sessions = Sessions()


def reusing() -> Sessions:
    """The sessions of :func:`after_onset`, as a context that closes them on leaving
    (e.g. around a sweep, whose worker communicator is freed when it ends)."""
    return _sessions


def onset_by_energy(params: Params, comm, bracket: tuple[float, float], h: float = 1e-4,
                    xtol: float = 1e-12) -> dict:
    """Delamination onset by comparing energies at fixed volume (the dissertation's method).

    At fixed V the stable state minimises the Helmholtz free energy
    F = U + gamma_l A + (gamma_ls - dgamma) pi r1^2 (= Pi + dp V). The clamped
    blister starts to propagate at the volume where moving the edge stops
    costing energy: F(V, 1 + h) = F(V, 1 - h), compared by solving the blister
    with the debond radius held at 1 +- h. Independent of the transversality
    row dPi/dR1 that the continuation uses.

    Args:
        params: an adhesive-edge parameter set.
        bracket: (V/V0 below, V/V0 above) the onset.
        h: the virtual edge advance.

    Returns:
        {"V_over_V0": Vc/V0, "P": pressure at onset, "dF_dR1": residual slope}.
    """
    from scipy.optimize import brentq  # lazily: scipy.optimize costs ~0.4 s to import

    require(params.edge in ("adhesive", "slippery"), "onset_by_energy needs a moving front (adhesive, slippery)")
    scene = build(params, comm)
    ctx = scene.ctx
    held = ctx.constant("debond_radius_held")
    R1 = ctx.states["debond_radius"]
    scene.start(1.0)
    with Problem(ctx, scene.terms, scene.bcs, scene.prefix, scene.petsc_options, rows=scene.rows,
                 energy_scale=scene.load_scale) as problem:
        control = VolumeControl.membrane(ctx)
        energy = fem.form(total_energy(ctx, scene.terms))

        def helmholtz(v, radius):
            held.value = radius
            R1.x.array[:] = radius
            control.solve_to(problem, v * V0)
            return global_sum(energy) / math.pi  # the multiplier term vanishes at V = V-hat

        def slope(v):
            return (helmholtz(v, 1 + h) - helmholtz(v, 1 - h)) / (2 * h)

        vc = brentq(slope, *bracket, xtol=xtol)
        held.value = np.asarray(1.0)
        R1.x.array[:] = 1.0
        control.solve_to(problem, vc * V0)
        return {"V_over_V0": vc, "P": real_value(ctx.states["pressure"]), "dF_dR1": slope(vc),
                "newton_solves": problem.newton_solves, "newton_iterations": problem.newton_iterations}


MAP_COLUMNS = [("V_over_V1", "V/V1"), ("P1", "Δp R1/(μ t0)"), ("aspect1", "z(0)/R1"),
               ("contact_angle_deg", "contact angle [deg]")]


def after_onset(params: Params, comm) -> dict:
    """The self-similar state of a delaminating blister (a map point of Figs 3.15-3.16).

    Traces the adhesive blister to a little past onset (R1 = 1.02 R0), checks
    that the state is self-similar there, and returns the onset values.
    ``onset: false`` (and no values) when the blister reaches v_max without
    delaminating, as neo-Hookean blisters with strong adhesion do.
    """
    params = onset_params(params)
    session = _sessions.get(structure(params), comm, lambda: compose(params, comm))
    branch = session.trace(scene_for(session.model, params))
    onset = next((e for e in branch.events if e["name"] == "delamination onset"), None)
    if onset is None:
        return {"onset": False}
    last = branch.rows[-1]
    # self-similarity after onset: V P^3 is invariant (eq. 3.88)
    drift = abs(last["V_over_V0"] * last["P"] ** 3 / (onset["V_over_V0"] * onset["P"] ** 3) - 1)
    return {"onset": True, "V_over_V1": onset["V_over_V0"], "P1": onset["P"], "aspect1": onset["aspect"],
            "contact_angle_deg": onset["contact_angle_deg"], "self_similarity_drift": drift}


def onset_params(params: Params) -> Params:
    """``params`` as :func:`after_onset` solves them: an adhesive edge, traced to R1 = 1.02 R0."""
    return replace(params, edge="adhesive", stop_radius=1.02)


def fit(aspect: float, P1: float, params: Params, comm, guess=(1.0, 5.0), tol: float = 1e-10) -> dict:
    """(alpha, adhesion) from a delaminating blister's aspect z(0)/R1 and dp R1/(mu_f t0),
    with the discretisation uncertainty: the fit is repeated on twice the cells and
    the change is reported as the uncertainty of the finer result."""
    coarse = solve_fit(aspect, P1, params, comm, guess, tol)
    fine_params = Params(**{**params.__dict__, "cells": 2 * params.cells})
    fine = solve_fit(aspect, P1, fine_params, comm, (coarse["alpha"], coarse["adhesion"]), tol)
    return {**fine, "alpha_uncertainty": abs(fine["alpha"] - coarse["alpha"]),
            "adhesion_uncertainty": abs(fine["adhesion"] - coarse["adhesion"]),
            "converged": coarse["converged"] and fine["converged"], "cells": fine_params.cells,
            "evaluations": coarse["evaluations"] + fine["evaluations"],
            "parameters": {**asdict(onset_params(fine_params)), "alpha": fine["alpha"],
                           "adhesion": fine["adhesion"]}}


def solve_fit(aspect: float, P1: float, params: Params, comm, guess, tol: float) -> dict:
    """Solve the two self-similar conditions with Powell's hybrid method; each
    evaluation is one traced branch."""
    for name, value in (("aspect", aspect), ("P1", P1)):
        bound = FIT_TARGETS[name][1]
        require(bound.admits(value), f"--{name} must be {bound} (got {value})")
    from scipy.optimize import root

    evaluations = []

    def residual(x):
        alpha, adhesion = x
        if alpha < 0:
            return [1e3 * (1 - alpha), 1e3]
        try:
            values = after_onset(Params(**{**params.__dict__, "alpha": alpha, "adhesion": adhesion}), comm)
        except ContinuationError as error:  # e.g. Gent locking before any onset
            values = {"onset": False, "reason": str(error)}
        evaluations.append((alpha, adhesion, values))
        if not values["onset"]:
            return [1e3, 1e3]
        return [values["aspect1"] / aspect - 1, values["P1"] / P1 - 1]

    with reusing():  # every evaluation has the structure of params: one blister, closed at the end
        solution = root(residual, guess, method="hybr", options={"xtol": tol})
    alpha, adhesion = map(float, solution.x)
    return {"alpha": alpha, "adhesion": adhesion, "converged": bool(solution.success),
            "residual": [float(r) for r in solution.fun], "evaluations": len(evaluations),
            "message": str(solution.message)}


#: What ``bcfem sweep`` computes at each point, and the maps it draws.
SWEEP = {"solve": after_onset, "maps": MAP_COLUMNS,
         "title": "after delamination onset (self-similar growth)"}
#: What ``bcfem fit`` matches: target name -> (help, the range it is checked against).
FIT_TARGETS = {"aspect": ("measured z(0)/R1 of a delaminating blister", Bound(0, 10, open_low=True)),
               "P1": ("measured dp R1/(mu_f t0) of a delaminating blister", Bound(0, 1e3, open_low=True))}
