"""The load path of ``blister-soft``: a stiff start, softened to the substrate's modulus,
then arc-length in the pressure.

A soft substrate cannot be reached from a flat guess: the line force of the membrane and
the interfaces at the contact line indents it by O(gamma/mu_s), of the order of R0 at
mu_s R0/(mu_f t0) = 1. So the first point is converged on a stiff substrate (the blister is
then close to the rigid one, and a cap is a good guess), and the modulus k (a run-time
constant) is lowered to its value in geometric steps (and large interface energies raised
from O(1) to theirs), the membrane's shape held by the arc-length start row (its amplitude
along the cap). The branch is then traced in P from
that point, first back to ``v_start`` if it moved, then forwards to ``v_max``. Where no
start converges at ``v_start`` the cap's volume is doubled (:func:`begin`) and the branch is
traced back as far as it goes.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from bcfem.log import logger
from bcfem.path.continuation import ArcLength, ContinuationError
from bcfem.radial_profile import scale_of
from bcfem.run.scene import BranchScene
from bcfem.run.trace import start

#: the modulus of the first point: stiff enough for Newton from a cap on a flat substrate
STIFF_START = 1e3
#: Newton iterations an arc-length step may take before it is halved. Near the pressure maximum
#: of a stiff substrate a long Newton path from the predictor lands on another equilibrium (the
#: free membrane's material points crowded at the contact line, higher free energy at the same
#: V) that the step's norm, a mean over the wetted top, barely sees; branch steps take 2-5.
STEP_ITERATIONS = 8


class SoftScene(BranchScene):
    """An arc-length scene whose arc length is measured on the wetted surface by the
    substrate's displacement and the membrane's lift together (``norm``, ``mean``), whose
    start is softened from a stiff substrate (:func:`homotopy`), and whose branch is traced
    back to ``v_start`` where it can be: hooks of :func:`bcfem.run.runner.trace`."""

    norm: dict | None = None
    mean: Callable | None = None
    model: Any = None
    #: set by the trace: None, or where the branch begins when it cannot reach ``v_start``
    start_report: dict | None = None

    def arc_length(self) -> ArcLength:
        return ArcLength(self.ctx, self.load, self.continuation, self.load_scale, norm=self.norm, mean=self.mean)

    @property
    def energy_scale(self) -> float:
        """The load's unit, or a stiff substrate's modulus over 1000. Round-off in the
        substrate's residual grows with its modulus k (about 1e-13 k) and stalled Newton above
        its absolute tolerance on the adhesive edge at k = 1e4 (the scene's ``snes_atol`` sits
        above it). A larger unit (k/100) let the step control grow steps until the bonded
        branch jumped at k = 1e4."""
        return max(self.load_scale, self.params.stiffness_ratio / 1000)

    def first_point(self, arc, problem) -> None:
        """A cap on a stiff substrate softened to the parameters (:func:`begin`); then steps of
        at most ``STEP_ITERATIONS`` Newton iterations."""
        self.start_report = None
        self.start_volume = begin(self, arc, problem, start_path(self.ctx, self.params))
        arc.restart_row(problem)
        problem.snes.setTolerances(max_it=STEP_ITERATIONS)

    def trace_back(self, arc, problem, forward: int):
        """Back to ``v_start`` when the start lies beyond it. Where no regular state lies between
        (the start itself failed there), the branch begins where the trace back ended, and
        ``start_report`` says why; where the end lies behind the start, the branch runs forward
        from ``v_start``."""
        params = self.params
        here = self.observe()
        if here["V_over_V0"] <= params.v_start * (1 + 1e-9):
            return None, forward
        origin = problem.save()
        try:
            back = arc.trace(problem, self.observe, lambda v: params.v_start - v["V_over_V0"],
                             self.progress_keys, guard=self.guard, direction=-forward)
        except ContinuationError as err:
            back = err.branch if err.branch.rows else None
            first = back.rows[-1]["V_over_V0"] if back else here["V_over_V0"]
            self.start_report = {"v_start": params.v_start, "start_volume": self.start_volume,
                                 "V_over_V0": first, "reason": str(err)}
            logger.warning(f"blister-soft: the branch begins at V/V0 = {first:.4g}, not at --v-start "
                           f"{params.v_start:g}: the start failed there and tracing back stopped ({err})")
        arc.restart_row(problem)
        if self.end(here) >= 0:  # the end lies behind the start: the whole branch from v_start
            return None, arc.forward_sign(problem, self.observe, self.grows)
        problem.restore(origin)
        arc.restart_row(problem)
        return back, forward


def homotopy(problem, path, dt: float = 0.125, dt_min: float = 1e-3) -> int:
    """Move the model along ``path(t)`` (it sets run-time constants) from t = 0, where the
    problem's states are converged, to t = 1, re-solving at each step (halved on failure,
    doubled after a success, down to ``dt_min``); returns the number of solves. The
    problem's rows stay as they are (the arc-length start row)."""
    t, solves = 0.0, 0
    rejections = problem.rejections
    while t < 1.0:
        saved = problem.save()
        trial = min(1.0, t + dt)
        path(trial)
        solves += 1
        if problem.solve():
            t, dt = trial, 2 * dt
            continue
        problem.restore(saved)
        path(t)
        dt /= 2
        if dt < dt_min:
            rejected = problem.rejections - rejections
            raise ContinuationError(f"the start homotopy stalled at t = {t:.6g} ({problem.failure})"
                                    + (f"; {rejected} converged states on the way were rejected, the last as: "
                                       f"{problem.last_rejection}" if rejected else ""))
    return solves


def start_path(ctx, params):
    """The homotopy from a stiff substrate with interface energies of at most O(1) to the
    parameters: the stiffness ratio geometrically, the interface energies linearly."""
    k1 = params.stiffness_ratio
    k0 = max(k1, STIFF_START)
    # the constants of the interface terms the scene holds (only those > 0)
    gammas = {name: scale_of(getattr(params, attr)) for name, attr in
              (("gamma_l", "alpha"), ("gamma_ls", "gamma_ls"), ("delta_gamma", "delta_gamma"))
              if scale_of(getattr(params, attr)) > 0}
    shrink = min(1.0, 1.0 / max([*gammas.values(), 1e-300]))

    def path(t):
        ctx.set("stiffness_ratio", k0 * (k1 / k0) ** t)
        for name, gamma in gammas.items():
            ctx.set(name, gamma * (shrink + t * (1 - shrink)))

    return path


def begin(scene, arc, problem, path) -> float:
    """Converge the first point at the parameters, from a cap of volume ``v_start`` on a stiff
    substrate; returns the cap's volume. Where that fails (the homotopy stalls, or the state is
    refused), the cap's volume is doubled, up to ``v_max``: a blister whose contact line the
    interface tensions drag inwards has its free membrane in compression at small volumes,
    where the softened state may not exist, and the branch is then traced back from a larger one."""
    params = scene.params
    built, volume = problem.save(), params.v_start
    while True:
        path(0.0)
        try:
            start(arc, problem, _Start(scene.model, volume))
            solves = homotopy(problem, path)
            message = scene.guard(scene.observe())
            if message is None:
                logger.info(f"blister-soft: reached the parameters from a stiff start at V/V0 = {volume:g} "
                            f"in {solves} solves")
                return volume
            failure = f"at the start: {message}"
        except ContinuationError as err:
            failure = str(err)
        if 2 * volume >= params.v_max:
            raise ContinuationError(failure)
        logger.warning(f"blister-soft: no start at V/V0 = {volume:g} ({failure}); trying {2 * volume:g}")
        problem.restore(built)
        volume *= 2


class _Start:
    """The scene's start guess (a cap, :meth:`Model.cap_guess`) at a given volume, for :func:`start`."""

    def __init__(self, model, volume: float):
        self.model, self.volume = model, volume

    def start(self, fraction: float) -> float:
        return self.model.cap_guess(fraction * self.volume)
