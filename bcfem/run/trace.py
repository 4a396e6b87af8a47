"""Tracing an arc-length scene's branch (:class:`bcfem.run.scene.BranchScene`): its problem,
its first point, a trace back from it where the scene asks, and the trace forward."""

from __future__ import annotations

from bcfem import log
from bcfem.path.continuation import ArcLength, Branch, ContinuationError
from bcfem.solver.problem import Problem


def trace(scene, on_accept=None, run=None, arc: ArcLength | None = None,
          problem: Problem | None = None, quiet: bool = False) -> tuple[Branch, Problem]:
    """Build the arc-length problem of ``scene``, start it and follow the branch.

    The scene's hooks say how: ``arc_length()`` measures the steps, ``energy_scale`` is the
    residual's unit, ``first_point`` converges the start, and ``trace_back`` may first trace
    the branch backwards from there (without switches, and without field output); the rows
    are then joined in path order, with negative arc lengths before the start. With a ``run`` the problem is the
    run's (stage ``branch``); a :class:`ContinuationError` then carries the converged
    part as ``err.branch`` and the problem as ``err.problem``. A given ``arc`` and ``problem``
    (built for this scene's model, e.g. kept by :class:`bcfem.run.session.Session`) are reused.
    A script whose log has no handler sees the command line's progress lines on rank 0, unless
    ``quiet`` (:func:`bcfem.log.ensure`).
    """
    log.ensure(scene.ctx.mesh.comm, quiet)
    arc = arc or scene.arc_length()
    if problem is None:
        arguments = (scene.ctx, scene.terms, scene.bcs)
        options = dict(petsc_options=scene.petsc_options, rows={**scene.rows, **arc.rows()},
                       energy_scale=scene.energy_scale)
        problem = run.problem("branch", *arguments, **options) if run else Problem(*arguments, scene.prefix, **options)
    back = None
    try:
        scene.first_point(arc, problem)
        forward = arc.forward_sign(problem, scene.observe, scene.grows) if scene.grows else 1
        back, forward = scene.trace_back(arc, problem, forward)
        branch = arc.trace(problem, scene.observe, scene.end, scene.progress_keys, on_accept=on_accept,
                           guard=scene.guard, switches=scene.switches, direction=forward, kept=scene.kept)
    except ContinuationError as err:
        err.problem = problem
        raise
    if back is not None:
        branch = _join(back, branch)
    return branch, problem


def _join(back: Branch, forward: Branch) -> Branch:
    """A backward and a forward branch from the same start, as one branch in path order."""
    def flip(values):
        return {**values, "s": -values["s"]}

    for lp in back.limit_points:
        lp.s, lp.values = -lp.s, flip(lp.values)
    return Branch(rows=[flip(r) for r in reversed(back.rows[1:])] + forward.rows,
                  limit_points=list(reversed(back.limit_points)) + forward.limit_points,
                  events=forward.events,
                  newton_iterations=back.newton_iterations + forward.newton_iterations,
                  failed_steps=back.failed_steps + forward.failed_steps,
                  wall_time_s=back.wall_time_s + forward.wall_time_s)


def branch_of(scene, on_accept=None) -> Branch:
    """Trace ``scene`` and destroy its PETSc objects at once, also when the trace fails
    (``on_accept(row)`` at every accepted point).

    For scripts that need only the branch; left to the garbage collector, the
    objects can deadlock at exit under MPI.
    """
    try:
        branch, problem = trace(scene, on_accept)
    except ContinuationError as error:
        if error.problem is not None:
            error.problem.close()
        raise
    problem.close()
    return branch


def start(arc, problem, scene, attempts: int = 6) -> None:
    """Converge the first point; if the guess is too far, start closer to the unloaded state.

    Each retry halves the starting load level of the scene's guess (a flatter
    cap is closer to its equilibrium); the last failure is raised.
    """
    for attempt in range(attempts):
        try:
            arc.start(problem, scene.start(0.5**attempt))
            return
        except ContinuationError:
            if attempt == attempts - 1:
                raise
