r"""Pseudo-time relaxation: passing an instability the way the body does, by moving
downhill in energy at a fixed load until it settles in a stable equilibrium.

Each pseudo-time step minimises the energy plus a viscous (proximal) term,

.. math:: \Pi(u) + \frac{c}{2} \int |u - u_{prev}|^2 \, dV,

whose Hessian c·M makes every step well posed past a limit or bifurcation point.
The term vanishes at rest (u = u_prev) and is switched off (c = 0) for the
final Newton solve, so an accepted state is an equilibrium of Π alone: the
regularisation picks which stable state the body falls into, not the state.
"""

from __future__ import annotations

from bcfem.physics.viscosity import Viscosity


def relax(problem, viscosity: Viscosity, stiffness: float, rtol: float = 1e-3,
          max_steps: int = 300) -> tuple[bool, int, float]:
    """Pseudo-time steps at the current load from the current (converged) state until
    Newton without viscosity converges.

    A pseudo-time step that fails takes more viscosity (c x 4) rather than the problem's
    line-search fallbacks, which cost several Newton solves each. Where that gives up (c
    past 1e6 times ``stiffness``: the body falls too far for a step of Newton to follow it,
    or its active set cycles at every c), the relaxation starts again from the same state
    with the fallbacks in every step.

    Args:
        stiffness: initial c (an elastic modulus over a length squared of the model).
        rtol: the body counts as at rest once the force out of balance at the end of a
            step, the viscous c·|Δu|, is below rtol times the largest so far (a step's length
            alone is small whenever c is large); only then, and every 10th step, is Newton
            without viscosity tried.

    Returns:
        (converged, steps, dissipated): the energy the viscous forces took out, the sum of
        c ‖Δu‖² over the steps (what Abaqus reports as ALLSD). On failure the states are those
        of the last relaxed step, which is *not* an equilibrium; the caller must restore or stop.
    """
    start = problem.save()
    for line_searches in (False, True):
        problem.restore(start)
        converged, steps, dissipated = _relax(problem, viscosity, stiffness, rtol, max_steps, line_searches)
        if converged:
            break
    return converged, steps, dissipated


def _relax(problem, viscosity: Viscosity, stiffness: float, rtol: float, max_steps: int,
           line_searches: bool) -> tuple[bool, int, float]:
    c, largest, dissipated = stiffness, 0.0, 0.0
    knob = problem.ctx.constant("viscosity")
    for step in range(1, max_steps + 1):
        viscosity.previous.x.array[:] = problem.ctx.u.x.array
        knob.value = c
        if not problem.solve(fallbacks=line_searches):
            c *= 4.0  # too large a pseudo-time step: more viscosity
            if c > 1e6 * stiffness:  # not even a tiny step is solvable: give up
                break
            continue
        increment = viscosity.increment(problem.ctx)
        force = c * increment
        dissipated += force * increment
        largest = max(largest, force)
        if force <= rtol * largest or step % 10 == 0:
            knob.value = 0.0
            if problem.solve():
                return True, step, dissipated
        c *= 0.7
    knob.value = 0.0
    return False, step, dissipated
