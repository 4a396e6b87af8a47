r"""Load paths: pseudo-arc-length continuation and volume (constraint) stepping.

Arc-length: the load parameter :math:`\lambda` (a real-space state, e.g. the
cavity pressure) gets the arc-length equation as its residual row,

.. math:: \frac{1}{A}\int t_u\cdot(u - u_a)\,dA + t_\lambda(\lambda - \lambda_a) = 0,

a hyperplane through the predictor :math:`x_a = x_k + \sigma t_k` orthogonal
to the unit tangent :math:`t_k` (the λ-part of the inner product is divided
by ``load_scale``², omitted above). The norm is the reference-area mean, so
the step is mesh independent. The row is one more real-space row in the blocked
system, so Newton, step control and retries are ours and the linear algebra is
PETSc's (MUMPS). The tangent at a converged point solves
:math:`[F_x; t_{k-1}^T]\,\tau = e_\lambda`; its λ-component changes sign at a
limit point, which is then located by Brent's method on the arc length,
to ``event_tol``.

Every step is checked: an unconverged or non-finite Newton solve is never
accepted; the step is halved and retried down to ``ds_min``, then
:class:`ContinuationError` names where it stopped.
"""

from __future__ import annotations

import math
import time
from typing import Callable

import numpy as np
import ufl
from dolfinx import fem

from bcfem.branch import Branch, ContinuationError, LimitPoint, Switch
from bcfem.log import progress
from bcfem.mpi import global_sum
from bcfem.params import ContinuationParams

# the records of a branch live in bcfem.branch; they are importable from here too
__all__ = ["ArcLength", "Branch", "ContinuationError", "LimitPoint", "Switch"]



class ArcLength:
    """Pseudo-arc-length continuation in the load parameter ``parameter``.

    Build the problem with ``rows=arc.rows()`` so the parameter's residual is
    the arc-length equation, then call :meth:`trace`.

    Args:
        ctx: the model context (must already hold the parameter state).
        parameter: name of the real-space state that acts as the load.
        params: step control.
        load_scale: typical size of the load; the norm is
            ``||x||^2 = (1/A) int |u|^2 dA + (lambda / load_scale)^2``, so steps
            stay balanced when the load is large (e.g. a strong surface tension).
    """

    def __init__(self, ctx, parameter: str = "pressure", params: ContinuationParams = ContinuationParams(),
                 load_scale: float = 1.0):
        if not load_scale > 0:
            raise ValueError(f"load_scale must be > 0 (got {load_scale})")
        self.ctx = ctx
        self.params = params
        self.load_scale = float(load_scale)
        self.parameter = parameter
        lam = ctx.real_state(parameter)
        u = ctx.u
        V = u.function_space
        self.t_u = fem.Function(V, name="tangent")
        self.u_anchor = fem.Function(V, name="anchor")
        self.t_lam = fem.Constant(ctx.mesh, 0.0)
        self.lam_anchor = fem.Constant(ctx.mesh, 0.0)
        kin, area = ctx.kin, ctx.kin.reference_area
        q = ufl.TestFunction(lam.function_space)
        self._row = kin.integral((ufl.inner(self.t_u, u - self.u_anchor)
                                  + self.t_lam * (lam - self.lam_anchor)) * q / area)
        self._work = fem.Function(V)
        self._norm2 = fem.form(kin.integral(ufl.inner(self._work, self._work) / area))

    def rows(self) -> dict:
        return {self.parameter: self._row}

    # -- vector helpers on lists of local arrays ------------------------------------------
    def _index(self, problem) -> tuple[int, int]:
        return problem.names.index("displacement"), problem.names.index(self.parameter)

    def _norm(self, problem, vec: list[np.ndarray]) -> float:
        iu, il = self._index(problem)
        self._work.x.array[:] = vec[iu]
        return math.sqrt(global_sum(self._norm2) + (float(vec[il][0]) / self.load_scale) ** 2)

    def _set_hyperplane(self, problem, tangent, anchor) -> None:
        iu, il = self._index(problem)
        self.t_u.x.array[:] = tangent[iu]
        self.u_anchor.x.array[:] = anchor[iu]
        # the row is <t, x - x_a> in the scaled inner product
        self.t_lam.value = float(tangent[il][0]) / self.load_scale**2
        self.lam_anchor.value = float(anchor[il][0])

    def _tangent(self, problem) -> list[np.ndarray]:
        """Unit tangent at the current (converged) state, oriented along the current row."""
        rhs_functions = [fem.Function(s.function_space) for s in problem.states]
        rhs_functions[self._index(problem)[1]].x.array[:] = 1.0
        rhs = problem.vector_from(rhs_functions)
        y = problem.solve_jacobian(rhs)
        problem.functions_from(y, rhs_functions)
        # destroyed here, not by the garbage collector (collective; order must match on all ranks)
        rhs.destroy()
        y.destroy()
        tangent = [f.x.array.copy() for f in rhs_functions]
        norm = self._norm(problem, tangent)
        return [t / norm for t in tangent]

    def _oriented(self, problem, tangent, switch) -> list[np.ndarray]:
        """Turn ``tangent`` so that the switch's growing state grows."""
        if switch.grows is None:
            return tangent
        component = float(tangent[problem.names.index(switch.grows)][0])
        return [-t for t in tangent] if component < 0 else tangent

    def _solve_at(self, problem, base, tangent, sigma) -> bool:
        anchor = [b + sigma * t for b, t in zip(base, tangent)]
        self._set_hyperplane(problem, tangent, anchor)
        problem.restore(anchor)  # the predictor is the initial guess
        return problem.solve()

    # -- the path -------------------------------------------------------------------------
    def start(self, problem, value: float) -> None:
        """Converge the first point near the guess in the states, with load guess ``value``.

        The row fixes the projection of u on the guess itself (displacement
        control along the guessed shape), so the load is an unknown from the
        start: this is better posed than a fixed load, which a guess of the
        wrong amplitude, or an unstable or stress-free state, can defeat.
        """
        iu, il = self._index(problem)
        problem.state(self.parameter).x.array[:] = value
        guess = problem.save()
        direction = [np.zeros_like(g) for g in guess]
        direction[iu][:] = guess[iu]
        norm = self._norm(problem, direction)
        if norm == 0:
            raise ContinuationError("the start guess has zero displacement; give a shaped guess")
        self._start_row = ([d / norm for d in direction], guess)
        self.restart_row(problem)
        if not problem.solve():
            raise ContinuationError(
                f"no converged start near the guess ({self.parameter} ~ {value:g}; "
                f"{problem.failure}); give a better initial guess")

    def forward_sign(self, problem, observe, key: str, h: float = 1e-7) -> int:
        """+1 if the start's tangent increases the observable ``key``, else -1.

        The start row only fixes the guessed shape's amplitude, whose growth need
        not mean a growing load (a cap steeper than a hemisphere that contracts).
        """
        here = problem.save()
        before = observe()[key]
        tangent = self._tangent(problem)
        problem.restore([x + h * t for x, t in zip(here, tangent)])
        after = observe()[key]
        problem.restore(here)
        return 1 if after >= before else -1

    def restart_row(self, problem) -> None:
        """Put back the row of :meth:`start`, so a second trace from the start point
        orients its first tangent the same way as the first trace did."""
        self._set_hyperplane(problem, *self._start_row)

    def trace(self, problem, observe, end, progress_keys=(), on_accept=None, guard=None,
              switches=(), direction: int = 1) -> Branch:
        """Follow the branch; see :meth:`_trace`. A :class:`ContinuationError` carries
        the converged part of the branch as ``error.branch``. ``direction=-1`` starts
        against the start's tangent (e.g. towards smaller volumes)."""
        self._partial = Branch()
        self._direction = direction
        try:
            return self._trace(problem, observe, end, progress_keys, on_accept, guard, switches)
        except ContinuationError as error:
            error.branch = self._partial
            raise

    def _trace(self, problem, observe: Callable[[], dict], end: Callable[[dict], float],
              progress_keys: tuple[str, ...] = (), on_accept: Callable[[dict], None] | None = None,
              guard: Callable[[dict], str | None] | None = None, switches=()) -> Branch:
        """Follow the branch from the current converged state until ``end(values)`` crosses zero.

        Args:
            problem: built with ``rows=self.rows()``; its states hold a converged start.
            observe: collective; returns the observables of the current state.
            end: the branch ends where this changes sign from negative to positive
                (located to ``event_tol``, and the last row is that point).
            progress_keys: observables shown in the progress line.
            on_accept: collective; called with the observables at each stored point.
            guard: returns a message when a converged state is physically out of
                range (e.g. a locking Gent membrane); the trace then stops with it.
            switches: :class:`Switch` events (each fires at most once). If the end
                and a switch fall in the same step, the end wins.
        """
        p = self.params
        t0 = time.perf_counter()
        branch = self._partial
        s = 0.0
        values = {**observe(), "s": s}
        base = problem.save()
        tangent = [self._direction * t for t in self._tangent(problem)]
        if end(values) >= 0:
            raise ContinuationError("the branch starts beyond its end point")
        pending = list(switches)
        for switch in [sw for sw in pending if sw.function(values) >= 0]:
            # already past the switch at the start: change the model there
            pending.remove(switch)
            branch.events.append({"name": switch.name, **values})
            tangent = self._switch(problem, switch)
            base, values = problem.save(), {**observe(), "s": s}
        self._record(branch, values, on_accept)
        ds = p.ds
        il = self._index(problem)[1]
        for step in range(1, p.max_steps + 1):
            ds, new_tangent = self._step(problem, base, tangent, ds, branch, step, values, progress_keys)
            its = max(problem.iterations, 1)
            new_values = {**observe(), "s": s + ds}
            accepted = problem.save()
            fired = next((sw for sw in pending if sw.function(values) < 0 <= sw.function(new_values)), None)
            if fired:
                # end the step at the switch (the old model holds up to there) ...
                sigma = self._locate(problem, base, tangent, ds, lambda: fired.function(observe()),
                                     fired.function(values), fired.function(new_values))
                switch_values = observe()
                if end(switch_values) >= 0:
                    fired = None  # ... unless the end comes first
                    problem.restore(accepted)
                else:
                    pending.remove(fired)
                    ds, accepted, new_values = sigma, problem.save(), {**switch_values, "s": s + sigma}
                    new_tangent = self._tangent(problem)
            if not fired and end(new_values) >= 0:
                sigma = self._locate(problem, base, tangent, ds,
                                     lambda: end(observe()), end(values), end(new_values))
                last = {**observe(), "s": s + sigma}
                last_state, last_tangent = problem.save(), self._tangent(problem)
                if np.sign(last_tangent[il][0]) != np.sign(tangent[il][0]):
                    branch.limit_points.append(self._locate_fold(
                        problem, base, tangent, sigma, s, observe, float(last_tangent[il][0])))
                    problem.restore(last_state)
                self._record(branch, last, on_accept)
                break
            # the end point is located before the guard looks: past it nothing counts. A step
            # that lands outside the physical range is cut back like a failed one.
            if guard and (message := guard(new_values)):
                branch.failed_steps += 1
                ds *= 0.5
                problem.restore(base)
                if fired:
                    pending.append(fired)  # not reached after all
                if ds < p.ds_min:
                    raise ContinuationError(f"step {step}: {message}")
                continue
            if np.sign(new_tangent[il][0]) != np.sign(tangent[il][0]):
                branch.limit_points.append(self._locate_fold(
                    problem, base, tangent, ds, s, observe, float(new_tangent[il][0])))
                problem.restore(accepted)
            if fired:
                # change the model at the switch and go on from the same point
                branch.events.append({"name": fired.name, **new_values})
                new_tangent = self._switch(problem, fired)
            self._record(branch, new_values, on_accept)
            base, tangent, values, s = problem.save(), new_tangent, new_values, s + ds
            progress(f"step {step:4d}  s={s:.4f}  ds={ds:.3g}  its={problem.iterations}  "
                     + "  ".join(f"{k}={values[k]:.6g}" for k in progress_keys if k in values))
            # the step cap grows with the load, so unbounded loads (locking) are reached in few steps
            cap = p.ds_max * min(1e3, max(1.0, abs(float(base[il][0])) / self.load_scale))
            ds = min(cap, ds * min(2.0, max(0.5, p.target_iterations / its)))
        else:
            raise ContinuationError(f"max_steps = {p.max_steps} reached before the end point")
        branch.wall_time_s = time.perf_counter() - t0
        return branch

    def _step(self, problem, base, tangent, ds, branch, step, values, progress_keys):
        """Predictor-corrector from ``base``; a failed step is halved and retried.

        Returns:
            (the step taken, the tangent at the new point)
        """
        while not self._solve_at(problem, base, tangent, ds):
            branch.failed_steps += 1
            ds *= 0.5
            if ds < self.params.ds_min:
                problem.restore(base)
                raise ContinuationError(
                    f"step {step}: Newton failed ({problem.failure}) even at "
                    f"ds < ds_min = {self.params.ds_min:g}; last converged point: "
                    + ", ".join(f"{k}={values[k]:.6g}" for k in progress_keys if k in values))
        branch.newton_iterations += problem.iterations
        return ds, self._tangent(problem)

    def _switch(self, problem, switch) -> list[np.ndarray]:
        """Apply ``switch`` at the current state, converge the new model there, return its tangent."""
        switch.action()
        if not problem.solve():
            raise ContinuationError(f"no converged state after '{switch.name}' ({problem.failure})")
        progress(f"event: {switch.name}")
        return self._oriented(problem, self._tangent(problem), switch)

    @staticmethod
    def _record(branch, values, on_accept) -> None:
        branch.rows.append(values)
        if on_accept:
            on_accept(values)

    def _locate(self, problem, base, tangent, ds, f_now, f0, f1) -> float:
        """Root in (0, ds) of ``f_now`` along the hyperplanes from ``base``; states end at the root."""

        from scipy.optimize import brentq  # lazily: scipy.optimize costs ~0.4 s to import

        def f(sigma):
            if sigma <= 0:
                return f0
            if sigma >= ds:
                return f1
            if not self._solve_at(problem, base, tangent, sigma):
                raise ContinuationError(f"Newton failed inside an accepted step (sigma={sigma:g})")
            return f_now()

        sigma = brentq(f, 0.0, ds, xtol=self.params.event_tol, rtol=4 * np.finfo(float).eps)
        if not self._solve_at(problem, base, tangent, sigma):
            raise ContinuationError(f"Newton failed at a located event (sigma={sigma:g})")
        return sigma

    def _locate_fold(self, problem, base, tangent, ds, s, observe, f1) -> LimitPoint:
        """The point in (0, ds) where the tangent's load component vanishes."""
        il = self._index(problem)[1]
        f0 = float(tangent[il][0])
        sigma = self._locate(problem, base, tangent, ds,
                             lambda: float(self._tangent(problem)[il][0]), f0, f1)
        values = observe()
        values["s"] = s + sigma
        return LimitPoint(kind="max" if f0 > 0 else "min", s=s + sigma, values=values)
