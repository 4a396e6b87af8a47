"""The wedge's first non-axisymmetric bifurcation by the inertia of its 3-D tangent, and the
path past it on the bifurcated branch (:mod:`bcfem.scenes.crater_sector.branch`)."""

from __future__ import annotations

from contextlib import contextmanager

from bcfem.log import progress
from bcfem.scenes.crater_sector.model import Sector
from bcfem.solver.problem import Problem

#: halvings of a load step that Newton fails, towards the last stable state
CUTBACKS = 3


class _Failed(RuntimeError):
    """A load step that Newton could not solve."""


def standalone(comm):
    """Problems outside a run: each under ``bcfem_crater_sector_<stage>_<ranks>_``, closed on leaving
    (a run's :meth:`bcfem.run.runner.Run.stage` opens them in the scene's stead, and counts them)."""

    @contextmanager
    def open_problem(stage: str, ctx, terms, bcs, petsc_options=None, **kwargs):
        with Problem(ctx, terms, bcs, f"bcfem_crater_sector_{stage}_{comm.size}_", petsc_options, **kwargs) as problem:
            yield problem

    return open_problem


def first_onset(model: Sector, terms, set_load, loads, bisections: int, name: str, observe=None,
                beyond=None, open_problem=None, stage: str = "onset") -> dict:
    """The load raised through the increasing ``loads`` with the wall in frictionless contact with the
    plate (bounds of the variational-inequality solver), the unstable modes counted after every
    step by the inertia of the 3-D tangent (:func:`bcfem.stability.inertia.unstable_modes`: unknowns
    on the plate held, the multipliers subtracted). The wedge pi/m's modes are those of the
    axisymmetric scene's n-blocks with n = 0, m, 2m, ... (cos n theta, symmetric about both
    mirror planes), one per unstable block. The first change of the count is bisected.

    With ``beyond``, a callable (problem, load), it is called with the problem at the last stable
    state below the onset, and what it returns (a dict) joins the result (e.g. the bifurcated
    branch, :func:`bcfem.scenes.crater_sector.branch.wave_branch`).

    Returns {"rows": [(load, unstable[, observed])], "onset": (load below, load above) or None,
    "failure": None or why the last step failed after its cut-backs (the path ends there; a
    bisection step that Newton fails is retried nearer the stable end), "dofs"}. The states are
    left at the last stable solution below the onset or the failure (at ``beyond``'s last state if
    it was called). The problem is ``open_problem``'s stage ``stage`` (default: :func:`standalone`)
    (collective)."""
    from bcfem.stability.inertia import unstable_modes

    comm = model.mesh.comm
    rows, onset = [], None
    with (open_problem or standalone(comm))(stage, model.ctx, terms, model.bcs, {"snes_type": "vinewtonrsls"},
                                            energy_scale=model.energy_scale,
                                            line_search_fallbacks=("bt", "cp")) as problem:
        model.contact_bounds(problem)

        def solve_at(load):
            set_load(load)
            if not problem.solve():
                raise _Failed(f"Newton failed at {name} = {load:g} ({problem.failure})")
            count = unstable_modes(problem)
            rows.append((load, count, *((observe(),) if observe else ())))
            progress(f"crater sector: {name} = {load:.6g}, unstable modes {count}")
            return count

        before, saved, failure = 0.0, problem.save(), None

        def count_at(load):
            """The count at ``load`` solved from the saved state, or None if Newton fails."""
            problem.restore(saved)
            try:
                return solve_at(load)
            except _Failed as error:
                nonlocal failure
                failure = str(error)
                return None

        def climb(pending):
            """Solve through ``pending`` from ``saved`` at ``before``, halving failed steps; stops
            at the first unstable count (returns its load) or a failure (None)."""
            nonlocal before, saved, failure
            pending = list(pending)
            while pending:
                target = load = pending[0]
                for _ in range(CUTBACKS + 1):  # near a singular tangent Newton may fail: halve the step
                    count = count_at(load)
                    if count is not None:
                        break
                    load = 0.5 * (before + load)
                if count is None:
                    return None
                if count > 0:
                    return load
                before, saved, failure = load, problem.save(), None
                if load == target:  # else cut back: on to the target from here
                    pending.pop(0)
            return None

        above = climb(loads)
        if above is not None:
            below, trial = before, above
            for _ in range(bisections):
                mid = 0.5 * (below + trial)
                count = count_at(mid)
                if count is None:  # Newton fails near the singular point: try nearer the stable end
                    trial = mid
                elif count > 0:
                    above = trial = mid
                else:
                    below, before, saved, trial = mid, mid, problem.save(), above
            onset, failure = (below, above), None  # a bisection step that failed ended no path
        problem.restore(saved)
        result = {"rows": rows, "onset": onset, "failure": failure, "dofs": problem.global_size(problem.names)}
        if onset is not None and beyond is not None:
            result.update(beyond(problem, before))
        return result
