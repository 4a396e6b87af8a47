r"""Pseudo-arc-length continuation in a load parameter, with located folds and events.

The load parameter :math:`\lambda` (a real-space state, e.g. the
cavity pressure) gets the arc-length equation as its residual row,

.. math:: \Big\langle \sum_i t_i\cdot(x_i - x_{a,i}) + t_\lambda(\lambda - \lambda_a) \Big\rangle = 0,

a hyperplane through the predictor :math:`x_a = x_k + \sigma t_k` orthogonal
to the unit tangent :math:`t_k`. The states :math:`x_i` of the norm are
declared (by default the displacement alone), each part divided by its scale
squared (``load_scale`` for λ; omitted above), and
:math:`\langle\cdot\rangle` is the mean over the reference body that the
kinematics supply (:math:`\frac{1}{A}\int\cdot\,dA` for a membrane,
:math:`\frac{1}{V}\int\cdot\,dV` for a solid), so the step is mesh
independent. The row is one more real-space row in the blocked system, so
Newton, step control and retries are ours and the linear algebra is PETSc's
(MUMPS). The tangent at a converged point solves
:math:`[F_x; t_{k-1}^T]\,\tau = e_\lambda`; its λ-component changes sign at a
limit point, which is then located by a bracketed root finder
(:mod:`bcfem.path.roots`) on the arc length, to ``event_tol``.

Every step is checked: an unconverged or non-finite Newton solve is never
accepted; the step is halved and retried down to ``ds_min``, then
:class:`ContinuationError` names where it stopped.
"""

from __future__ import annotations

import math
import operator
import time
from collections.abc import Callable, Mapping
from functools import reduce
from typing import Any

import numpy as np
import ufl
from dolfinx import fem

from bcfem.log import progress
from bcfem.mpi import global_sum
from bcfem.params import ContinuationParams
from bcfem.path.branch import Branch, ContinuationError, LimitPoint, Switch
from bcfem.path.locate import locate, locate_fold

# the records of a branch live in bcfem.path.branch; they are importable from here too
__all__ = ["ArcLength", "Branch", "ContinuationError", "LimitPoint", "Mean", "Switch"]


#: the mean of a density over the reference body, as a form: (1/|B|) int_B density dB
Mean = Callable[[ufl.core.expr.Expr], ufl.Form]


class ArcLength:
    """Pseudo-arc-length continuation in the load parameter ``parameter``.

    Build the problem with ``rows=arc.rows()`` so the parameter's residual is
    the arc-length equation, then call :meth:`trace`.

    The arc length is measured in the norm

    ``||x||^2 = mean(sum_i |x_i / scale_i|^2) + (lambda / load_scale)^2``

    over the states ``x_i`` named in ``norm``. States left out (multipliers, a
    debond radius, a mixed pressure) follow the path but do not measure it.

    Args:
        ctx: the model context (must already hold the parameter and the norm's states).
        parameter: name of the real-space state that acts as the load.
        params: step control.
        load_scale: typical size of the load, so that steps stay balanced when
            the load is large (e.g. a strong surface tension).
        norm: the states that measure the arc length, each with its typical size
            (default: ``{"displacement": 1.0}``). Must not contain ``parameter``.
        mean: the mean over the reference body of a density, as a form; it must be
            linear in the density. Default: ``ctx.kin.mean`` (the reference-area mean
            of a membrane, the reference-volume mean of a solid).

    Example (a solid whose load is a platen displacement, a real-space state)::

        arc = ArcLength(ctx, "platen_displacement", ContinuationParams(ds=0.01), load_scale=0.1)
        problem = Problem(ctx, terms, bcs, "bcfem_crater_", rows=arc.rows())
        arc.start(problem, 0.0)  # from a shaped guess in the displacement
        branch = arc.trace(problem, observe, end)
    """

    def __init__(self, ctx, parameter: str = "pressure", params: ContinuationParams = ContinuationParams(),
                 load_scale: float = 1.0, *, norm: Mapping[str, float] | None = None, mean: Mean | None = None):
        if not load_scale > 0:
            raise ValueError(f"load_scale must be > 0 (got {load_scale})")
        norm = {"displacement": 1.0} if norm is None else dict(norm)
        if mean is None and ctx.kin is None:
            raise ValueError("ctx has no kinematics, so no mean(density): pass mean=")
        mean = mean if mean is not None else ctx.kin.mean
        if not norm or parameter in norm:
            raise ValueError(f"norm must name at least one state other than {parameter!r} (got {sorted(norm)})")
        unknown = sorted(set(norm) - set(ctx.states))
        if unknown:
            raise ValueError(f"norm names states the context does not hold: {unknown} "
                             f"(it holds {sorted(ctx.states)})")
        if not all(scale > 0 for scale in norm.values()):
            raise ValueError(f"the norm's scales must be > 0 (got {norm})")
        self.ctx = ctx
        self.params = params
        self.load_scale = float(load_scale)
        self.parameter = parameter
        #: corrected points rejected as jumps to another branch (``max_correction``)
        self.jumps = 0
        #: events (folds, switches, the end) located only to within their step
        self.unlocated = 0
        self.norm = {name: float(scale) for name, scale in norm.items()}
        lam = ctx.real_state(parameter)
        fields = {name: ctx.states[name] for name in self.norm}
        self._tangent_parts = {n: fem.Function(f.function_space, name=f"tangent_{n}") for n, f in fields.items()}
        self._anchor_parts = {n: fem.Function(f.function_space, name=f"anchor_{n}") for n, f in fields.items()}
        self._work = {n: fem.Function(f.function_space) for n, f in fields.items()}
        self.t_lam = fem.Constant(ctx.mesh, 0.0)
        self.lam_anchor = fem.Constant(ctx.mesh, 0.0)
        q = ufl.TestFunction(lam.function_space)
        # the tangent parts hold t_i / scale_i^2, so the row is <t, x - x_a> in the scaled product
        along = [ufl.inner(self._tangent_parts[n], fields[n] - self._anchor_parts[n]) for n in fields]
        self._row = mean((reduce(operator.add, along) + self.t_lam * (lam - self.lam_anchor)) * q)
        # a state on a boundary submesh (a membrane's lift) needs the context's entity maps
        self._norm2 = fem.form(mean(reduce(operator.add, [ufl.inner(w, w) for w in self._work.values()])),
                               entity_maps=ctx.entity_maps or None)

    def rows(self) -> dict:
        return {self.parameter: self._row}

    # -- vector helpers on lists of local arrays ------------------------------------------
    def _index(self, problem) -> tuple[dict[str, int], int]:
        """The positions in ``problem.states`` of the norm's states and of the parameter."""
        return {n: problem.names.index(n) for n in self.norm}, problem.names.index(self.parameter)

    def _length(self, problem, vec: list[np.ndarray]) -> float:
        parts, il = self._index(problem)
        for name, i in parts.items():
            self._work[name].x.array[:] = vec[i] / self.norm[name]
        return math.sqrt(global_sum(self._norm2) + (float(vec[il][0]) / self.load_scale) ** 2)

    def _set_hyperplane(self, problem, tangent, anchor) -> None:
        parts, il = self._index(problem)
        for name, i in parts.items():
            self._tangent_parts[name].x.array[:] = tangent[i] / self.norm[name] ** 2
            self._anchor_parts[name].x.array[:] = anchor[i]
        self.t_lam.value = np.asarray(float(tangent[il][0]) / self.load_scale**2)
        self.lam_anchor.value = np.asarray(float(anchor[il][0]))

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
        norm = self._length(problem, tangent)  # global: not finite on every rank alike
        if not math.isfinite(norm) or norm == 0:
            raise ContinuationError("the tangent is not finite: the Jacobian is singular at a converged point")
        return [t / norm for t in tangent]

    def _oriented(self, problem, tangent, switch) -> list[np.ndarray]:
        """Turn ``tangent`` so that the switch's growing state grows."""
        if switch.grows is None:
            return tangent
        component = float(tangent[problem.names.index(switch.grows)][0])
        return [-t for t in tangent] if component < 0 else tangent

    def _solve_at(self, problem, base, tangent, sigma) -> bool:
        """Correct the predictor ``base + sigma tangent`` onto the branch; False if Newton
        fails or lands farther than ``max_correction`` sigma from the predictor (a jump)."""
        anchor = [b + sigma * t for b, t in zip(base, tangent)]
        self._set_hyperplane(problem, tangent, anchor)
        problem.restore(anchor)  # the predictor is the initial guess
        if not problem.solve():
            return False
        if math.isfinite(self.params.max_correction):
            distance = self._length(problem, [x - a for x, a in zip(problem.save(), anchor)])
            if distance > self.params.max_correction * abs(sigma):
                self.jumps += 1
                problem.restore(anchor)
                return False
        return True

    # -- the path -------------------------------------------------------------------------
    def start(self, problem, value: float) -> None:
        """Converge the first point near the guess in the states, with load guess ``value``.

        The row fixes the projection of the norm's states on the guess itself
        (displacement control along the guessed shape), so the load is an
        unknown from the start: this is better posed than a fixed load, which a
        guess of the wrong amplitude, or an unstable or stress-free state, can
        defeat.
        """
        parts, _ = self._index(problem)
        problem.state(self.parameter).x.array[:] = value
        guess = problem.save()
        direction = [np.zeros_like(g) for g in guess]
        for i in parts.values():
            direction[i][:] = guess[i]
        norm = self._length(problem, direction)
        if norm == 0:
            raise ContinuationError(f"the start guess is zero in the norm's states {sorted(self.norm)}; "
                                    "give a shaped guess")
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

    def hold(self, problem, value: float) -> None:
        """Make the parameter's row ``lambda = value``: the load is then given (a converged
        state is on the branch at that load), e.g. to start a trace from a known state or
        to solve at a checkpoint. The next :meth:`trace` starts along the load's tangent."""
        parts, il = self._index(problem)
        zero = [np.zeros_like(s.x.array) for s in problem.states]
        self._set_hyperplane(problem, zero, zero)
        self.t_lam.value = np.asarray(1.0 / self.load_scale**2)
        self.lam_anchor.value = np.asarray(float(value))
        problem.state(self.parameter).x.array[:] = value

    def restart_row(self, problem) -> None:
        """Put back the row of :meth:`start`, so a second trace from the start point
        orients its first tangent the same way as the first trace did."""
        self._set_hyperplane(problem, *self._start_row)

    def trace(self, problem, observe, end, progress_keys=(), on_accept=None, guard=None,
              switches=(), direction: int = 1, kept=()) -> Branch:
        """Follow the branch; see :meth:`_trace`. A :class:`ContinuationError` carries
        the converged part of the branch as ``error.branch``. ``direction=-1`` starts
        against the start's tangent (e.g. towards smaller volumes)."""
        self._partial = Branch()
        self._direction = direction
        t0 = time.perf_counter()
        try:
            return self._trace(problem, observe, end, progress_keys, on_accept, guard, switches, kept)
        except ContinuationError as error:
            error.branch = self._partial
            error.branch.wall_time_s = time.perf_counter() - t0
            raise

    def _trace(self, problem, observe: Callable[[], dict], end: Callable[[dict], float],
              progress_keys: tuple[str, ...] = (), on_accept: Callable[[dict], None] | None = None,
              guard: Callable[[dict], str | None] | None = None, switches=(), kept=()) -> Branch:
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
            kept: the observers in ``on_accept`` whose state a checkpoint keeps
                (:class:`bcfem.path.checkpoint.Kept`).

        With the problem's checkpoints (a run's), the trace writes a checkpoint after accepted
        points (:meth:`_resume` goes on from one in a resumed run).
        """
        p = self.params
        t0 = time.perf_counter()
        branch = self._partial
        pending = list(switches)
        keeper: Any = getattr(problem, "checkpoints", None)  # a stand-in problem may have none
        key = keeper.key() if keeper is not None else None
        saved = keeper.read(key, problem.states) if keeper is not None else None
        if saved is not None:  # a resumed run: on from this trace's last checkpoint
            base, tangent, values, s, ds, first = self._resume(problem, saved, branch, pending, kept)
            keeper.jump(saved)
            self._record(branch, values, on_accept)  # its row again, and the callers' counts
            keeper.landed(saved, values, saved.record["values"], branch.rows)
        else:
            s, ds, first = 0.0, p.ds, 1
            values = {**observe(), "s": s}
            base = problem.save()
            tangent = [self._direction * t for t in self._tangent(problem)]
            if end(values) >= 0:
                raise ContinuationError("the branch starts beyond its end point")
            for switch in [sw for sw in pending if sw.function(values) >= 0]:
                # already past the switch at the start: change the model there
                pending.remove(switch)
                branch.events.append({"name": switch.name, **values})
                tangent = self._switch(problem, switch)
                base, values = problem.save(), {**observe(), "s": s}
            self._record(branch, values, on_accept)
        il = self._index(problem)[1]
        for step in range(first, p.max_steps + 1):
            ds, new_tangent = self._step(problem, base, tangent, ds, branch, step, values, progress_keys)
            its = max(problem.iterations, 1)
            new_values = {**observe(), "s": s + ds}
            accepted = problem.save()
            fired = next((sw for sw in pending if sw.function(values) < 0 <= sw.function(new_values)), None)
            if fired:
                # end the step at the switch (the old model holds up to there) ...
                sigma = locate(self, problem, base, tangent, ds, lambda: fired.function(observe()),
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
                sigma = locate(self, problem, base, tangent, ds,
                                     lambda: end(observe()), end(values), end(new_values))
                last = {**observe(), "s": s + sigma}
                last_state, last_tangent = problem.save(), self._tangent(problem)
                if np.sign(last_tangent[il][0]) != np.sign(tangent[il][0]):
                    branch.limit_points.append(locate_fold(self,
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
                branch.limit_points.append(locate_fold(self,
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
            if keeper is not None and keeper.due():
                record = {"s": s, "ds": ds, "step": step, "values": values, "fired": [sw.name for sw in switches
                                                                                      if sw not in pending],
                          "limit_points": [vars(lp) for lp in branch.limit_points], "events": branch.events,
                          "branch_rows": branch.rows, "failed_steps": branch.failed_steps,
                          "newton_iterations": branch.newton_iterations, "jumps": self.jumps,
                          "unlocated": self.unlocated, "kept": []}
                vectors = [base, tangent]
                for observer in kept:
                    entry, more = observer.checkpoint(problem)
                    record["kept"].append({"record": entry, "vectors": len(more)})
                    vectors += more
                keeper.write(key, problem.states, vectors, record)
        else:
            raise ContinuationError(f"max_steps = {p.max_steps} reached before the end point")
        branch.wall_time_s = time.perf_counter() - t0
        return branch

    def _resume(self, problem, saved, branch, pending, kept):
        """Back to a checkpoint of :meth:`_trace`: the states, the branch's record, the switches
        that fired (their actions again, in order) and the kept observers' states. Returns
        (base, tangent, values, s, ds, the next step)."""
        record, vectors = saved.record, saved.vectors
        for switch in [sw for sw in list(pending) if sw.name in record["fired"]]:
            pending.remove(switch)
            switch.action()
        problem.restore(vectors[0])
        branch.rows[:] = record["branch_rows"][:-1]
        branch.limit_points[:] = [LimitPoint(**lp) for lp in record["limit_points"]]
        branch.events[:] = record["events"]
        branch.failed_steps, branch.newton_iterations = record["failed_steps"], record["newton_iterations"]
        self.jumps, self.unlocated = record["jumps"], record["unlocated"]
        rest = vectors[2:]
        for observer, entry in zip(kept, record["kept"]):
            observer.resume(problem, entry["record"], rest[: entry["vectors"]])
            rest = rest[entry["vectors"]:]
        return (problem.save(), vectors[1], dict(record["values"]), record["s"], record["ds"],
                record["step"] + 1)

    def _step(self, problem, base, tangent, ds, branch, step, values, progress_keys):
        """Predictor-corrector from ``base``; a failed step is halved and retried.

        Returns:
            (the step taken, the tangent at the new point)
        """
        while True:
            failure = None
            if self._solve_at(problem, base, tangent, ds):
                try:
                    new_tangent = self._tangent(problem)
                    break
                except ContinuationError as err:  # a singular point: step past it, or short of it
                    failure = str(err)
                    problem.restore(base)
            branch.failed_steps += 1
            ds *= 0.5
            if ds < self.params.ds_min:
                problem.restore(base)
                raise ContinuationError(
                    f"step {step}: Newton failed ({failure or problem.failure}) even at "
                    f"ds < ds_min = {self.params.ds_min:g}; last converged point: "
                    + ", ".join(f"{k}={values[k]:.6g}" for k in progress_keys if k in values))
        branch.newton_iterations += problem.iterations
        return ds, new_tangent

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
