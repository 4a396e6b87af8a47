"""The load path of ``blister-soft``: a stiff start, softened to the substrate's modulus,
then arc-length in the pressure.

A soft substrate cannot be reached from a flat guess: the line force of the membrane and
the interfaces at the contact line indents it by O(gamma/mu_s), of the order of R0 at
mu_s R0/(mu_f t0) = 1. So the first point is converged on a stiff substrate (the blister is
then close to the rigid one, and a cap is a good guess), and the modulus k (a run-time
constant) is lowered to its value in geometric steps, the membrane's shape held by the
arc-length start row (its amplitude along the cap). The branch is then traced in P from
that point, first back to ``v_start`` if it moved, then forwards to ``v_max``.
"""

from __future__ import annotations

import math

from bcfem.continuation import ArcLength, ContinuationError
from bcfem.log import logger
from bcfem.runner import _join, start
from bcfem.scene import Scene

#: the modulus of the first point: stiff enough for Newton from a cap on a flat substrate
STIFF_START = 1e3


class SoftScene(Scene):
    """An arc-length scene whose arc length is measured on the wetted surface by the
    substrate's displacement and the membrane's lift together (``norm``, ``mean``), and whose
    start is softened from a stiff substrate (:func:`soften`)."""

    norm: dict | None = None
    mean: object = None
    model: object = None

    def solve(self, run) -> None:
        run.watch(self.fields)
        try:
            branch = trace(self, run.on_accept, run)
        except ContinuationError as err:
            self._report(run, getattr(err, "branch", None) or _empty())
            raise
        self._report(run, branch)


def _empty():
    from bcfem.branch import Branch

    return Branch()


def soften(problem, constant, target: float, first: float, factor: float = 0.5, min_factor: float = 0.97) -> int:
    """Lower ``constant`` from ``first`` to ``target`` by steps of ``factor`` (halved in log
    on failure, down to ``min_factor``); returns the number of solves. The problem's rows stay
    as they are (the arc-length start row)."""
    k, solves = first, 0
    while k > target:
        saved = problem.save()
        trial = max(k * factor, target)
        constant.value = trial
        solves += 1
        if problem.solve():
            k = trial
            continue
        problem.restore(saved)
        constant.value = k
        factor = math.sqrt(factor)
        if factor > min_factor:
            raise ContinuationError(f"softening the substrate stalled at stiffness ratio {k:.6g} "
                                    f"(target {target:g}; {problem.failure})")
    return solves


def trace(scene: SoftScene, on_accept=None, run=None):
    """Start stiff, soften, trace back to ``v_start`` if needed, then forward; returns the branch
    (the problem is the run's, or closed here)."""
    params = scene.params
    arc = ArcLength(scene.ctx, scene.load, scene.continuation, scene.load_scale, norm=scene.norm, mean=scene.mean)
    arguments = (scene.ctx, scene.terms, scene.bcs)
    options = dict(petsc_options=scene.petsc_options, rows=arc.rows(), energy_scale=scene.load_scale)
    if run is not None:
        problem = run.problem("branch", *arguments, **options)
    else:
        from bcfem.problem import Problem
        problem = Problem(*arguments, scene.prefix, **options)
    stiffness = scene.ctx.constant("stiffness_ratio")
    target = params.stiffness_ratio
    try:
        stiffness.value = max(target, STIFF_START)
        start(arc, problem, scene)
        solves = soften(problem, stiffness, target, max(target, STIFF_START))
        logger.info(f"blister-soft: softened the substrate to {target:g} in {solves} solves")
        arc.restart_row(problem)
        forward = arc.forward_sign(problem, scene.observe, scene.grows)
        back = None
        if scene.observe()["V_over_V0"] > params.v_start * (1 + 1e-9):
            origin = problem.save()
            back = arc.trace(problem, scene.observe, lambda v: params.v_start - v["V_over_V0"],
                             scene.progress_keys, guard=scene.guard, direction=-forward)
            problem.restore(origin)
            arc.restart_row(problem)
        branch = arc.trace(problem, scene.observe, scene.end, scene.progress_keys, on_accept=on_accept,
                           guard=scene.guard, direction=forward)
        if back is not None:
            branch = _join(back, branch)
    finally:
        if run is None:
            problem.close()
    return branch
