"""The wedge's first non-axisymmetric bifurcation by the inertia of its 3-D tangent, and the
path past it on the bifurcated branch (:mod:`bcfem.scenes.crater_sector.branch`)."""

from __future__ import annotations

from bcfem.log import progress
from bcfem.scenes.crater_sector.branch import critical_mode
from bcfem.scenes.crater_sector.model import Sector
from bcfem.solver.problem import Problem

#: halvings of a load step that Newton fails, towards the last stable state
CUTBACKS = 3


class _Failed(RuntimeError):
    """A load step that Newton could not solve."""


def first_onset(model: Sector, terms, set_load, loads, bisections: int, name: str, observe=None,
                past=(), amplitude: float = 0.02, waves: int = 4) -> dict:
    """The load raised through the increasing ``loads`` with the wall in frictionless contact with the
    plate (bounds of the variational-inequality solver), the unstable modes counted after every
    step by the inertia of the 3-D tangent (:func:`bcfem.stability.inertia.unstable_modes`: unknowns
    on the plate held, the multipliers subtracted). The wedge pi/m's modes are those of the
    axisymmetric scene's n-blocks with n = 0, m, 2m, ... (cos n theta, symmetric about both
    mirror planes), one per unstable block. The first change of the count is bisected.

    With ``past`` (loads beyond the onset, increasing), the branch is switched there: the critical
    mode (:func:`~bcfem.scenes.crater_sector.branch.critical_mode`) at the last stable state below
    the onset, its wall's largest cos n theta content scaled to ``amplitude`` a, is added to that
    state, and the path goes on through ``past`` from it, with the same cut-backs.

    Returns {"rows": [(load, unstable[, observed])], "onset": (load below, load above) or None,
    "failure": None or why the last step failed after its cut-backs (the path ends there; a
    failed bisection step ends the bisection), and with ``past``: "mode" {"mu": eigenvalue,
    "fourier": {n: content}} and "post": [{"load", "unstable", "observed", "fourier"}] with the
    wall's cos n theta content of the displacement, n = 0, m, ..., ``waves`` m}. Without ``past``
    the states are left at the last stable solution below the onset or the failure; with it, at
    the last post-buckled state (collective)."""
    from bcfem.stability.inertia import unstable_modes

    comm = model.mesh.comm
    rows, onset = [], None
    harmonics = [k * model.sector.wedge_waves for k in range(waves + 1)]
    with Problem(model.ctx, terms, model.bcs, f"bcfem_crater_sector_onset_{comm.size}_",
                 {"snes_type": "vinewtonrsls"}, energy_scale=model.energy_scale,
                 line_search_fallbacks=("bt", "cp")) as problem:
        model.contact_bounds(problem)

        def solve_at(load, record=rows):
            set_load(load)
            if not problem.solve():
                raise _Failed(f"Newton failed at {name} = {load:g} ({problem.failure})")
            count = unstable_modes(problem)
            observed = (observe(),) if observe else ()
            if record is rows:
                rows.append((load, count, *observed))
            else:
                record.append({"load": load, "unstable": count, "observed": observed[0] if observed else None,
                               "fourier": model.wall_fourier(model.u, harmonics)})
            progress(f"crater sector: {name} = {load:.6g}, unstable modes {count}")
            return count

        before, saved, failure = 0.0, problem.save(), None

        def count_at(load, record=rows):
            """The count at ``load`` solved from the saved state, or None if Newton fails."""
            problem.restore(saved)
            try:
                return solve_at(load, record)
            except _Failed as error:
                nonlocal failure
                failure = str(error)
                return None

        def climb(pending, record=rows):
            """Solve through ``pending`` from ``saved`` at ``before``, halving failed steps; stops
            at the first unstable count (returned with its load) or a failure (None)."""
            nonlocal before, saved, failure
            pending = list(pending)
            while pending:
                target = load = pending[0]
                for _ in range(CUTBACKS + 1):  # near a singular tangent Newton may fail: halve the step
                    count = count_at(load, record)
                    if count is not None:
                        break
                    load = 0.5 * (before + load)
                if count is None:
                    return None
                if count > 0 and record is rows:
                    return load
                before, saved, failure = load, problem.save(), None
                if load == target:  # else cut back: on to the target from here
                    pending.pop(0)
            return None

        above = climb(loads)
        if above is not None:
            below = before
            for _ in range(bisections):
                mid = 0.5 * (below + above)
                count = count_at(mid)
                if count is None:
                    break
                if count > 0:
                    above = mid
                else:
                    below, before, saved = mid, mid, problem.save()
            onset = (below, above)
        problem.restore(saved)
        result = {"rows": rows, "onset": onset, "failure": failure}
        if onset is None or not past:
            return result
        mode, mu, content = critical_mode(problem, model, harmonics[1:])
        progress(f"crater sector: critical mode at {name} = {before:.6g}: mu = {mu:.3e}, "
                 f"cos n theta content {content}")
        for state, direction in zip(problem.states, mode):
            state.x.array[:] += amplitude * direction.x.array
        saved = problem.save()
        post: list = []
        climb([load for load in past if load > before], post)
        result["mode"] = {"mu": mu, "fourier": content}
        result["post"] = post
        result["failure"] = failure
        return result
