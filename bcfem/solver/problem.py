"""The problem builder: collect states, sum energies, derive blocks, own the SNES.

No physics lives here. The residual of each state is the derivative of the
total energy (the Lagrangian) in that state, unless a caller supplies a
replacement row, as arc-length continuation does for its load parameter.
"""

from __future__ import annotations

from contextlib import contextmanager
from time import perf_counter
from typing import Any

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import NonlinearProblem, assign

from bcfem import interrupt, jit
from bcfem.log import logger
from bcfem.mpi import global_sum
from bcfem.physics.protocols import DiscreteTerm, total_energy
from bcfem.solver import fieldsplit, memory, options, petsc_events, pivots
from bcfem.solver.algebra import ConvergedAlgebra
from bcfem.solver.assembly import Assembly
from bcfem.solver.fieldsplit import FieldSplit
from bcfem.solver.newton_cycles import RepeatedIterates
from bcfem.solver.reduced_lu import ReducedLU
from bcfem.solver.terms import checked_terms, declared_multipliers

#: the parts of :attr:`Problem.timings`
TIMED = ("assembly", "discrete_terms", "factorisation", "linear_solve", "newton", "stability")


class Problem(ConvergedAlgebra):
    """A blocked nonlinear problem over all states of a context.

    Args:
        ctx: the context; its states are collected after the energies are built. States
            on another mesh (a field on a boundary submesh) are assembled through the
            context's entity maps.
        terms: :class:`~bcfem.physics.protocols.Term` s, whose energies are summed, and
            :class:`~bcfem.physics.protocols.DiscreteTerm` s (e.g. self-contact), which add their
            residual and tangent to the assembled system.
        bcs: Dirichlet conditions on any state (also on a state on a submesh).
        prefix: PETSc options prefix, e.g. ``bcfem_blister_rigid_``.
        petsc_options: scene defaults, layered over bcfem's (the user's win).
        rows: replacement residuals, keyed by state name: a UFL form, or a callable
            that takes the (scaled) Lagrangian and returns one.
        jit_options: passed to dolfinx (e.g. a cache directory).
        energy_scale: the energy is divided by this before differentiation, so that
            residuals are O(1) and absolute tolerances mean the same for every
            parameter set (e.g. a strong surface tension).
        line_search_fallbacks: SNES line searches to retry a failed solve with, in turn,
            from the same initial state (e.g. ``("bt",)``: full Newton steps can cycle
            between two contact active sets). Ignored when the user sets
            ``snes_linesearch_type``: the user's choice wins.
        stability_count: how :func:`bcfem.stability.inertia.unstable_modes` counts:
            ``inertia``, MUMPS's LDLᵀ; ``spectrum``, the lowest eigenvalues of the Schur
            complement on the multipliers (:mod:`bcfem.stability.spectrum`), preconditioned
            by the field split (needs ``pc_type fieldsplit``): no factorisation.
    """

    def __init__(self, ctx, terms, bcs, prefix: str, petsc_options: dict | None = None,
                 rows: dict | None = None, jit_options: dict | None = None, energy_scale: float = 1.0,
                 line_search_fallbacks: tuple[str, ...] = (), stability_count: str = "inertia"):
        if stability_count not in ("inertia", "spectrum"):
            raise ValueError(f"stability_count must be 'inertia' or 'spectrum' (got {stability_count!r})")
        self.ctx = ctx
        self.terms = checked_terms(terms)
        self.discrete = [t for t in self.terms if isinstance(t, DiscreteTerm)]
        self.lagrangian = total_energy(ctx, self.terms)
        self._energy: fem.Form | None = None
        rows = rows or {}
        # a Constant, so that a new scale does not mean a new compiled form
        inverse_scale = fem.Constant(ctx.mesh, 1.0 / energy_scale)
        self.inverse_scale = inverse_scale
        self.bcs = list(bcs)
        # the states the terms use (a state left from another stage, e.g. the pressure of
        # chambers since merged, would be an empty row)
        used = {id(c) for c in ufl.algorithms.extract_coefficients(self.lagrangian)}
        self.names = [n for n, s in ctx.states.items() if id(s) in used or n in rows or s is ctx.u]
        self.states = [ctx.states[n] for n in self.names]
        #: the Lagrange-multiplier states the terms declare, in state order; a state whose
        #: row is replaced (an arc-length load) is no multiplier of this problem
        self.multipliers = declared_multipliers(self.terms, self.names, rows)
        #: the tangent is symmetric: it is the Hessian of the Lagrangian (no row replaced, and
        #: every discrete term declares ``symmetric_tangent``), so LDL^T may factorise it
        self.symmetric_tangent = not rows and all(t.symmetric_tangent for t in self.discrete)
        scaled = inverse_scale * self.lagrangian
        residuals = [(rows[n] if isinstance(rows[n], ufl.Form) else rows[n](scaled)) if n in rows else
                     ufl.derivative(scaled, s, ufl.TestFunction(s.function_space))
                     for n, s in zip(self.names, self.states)]
        self.prefix = prefix
        self.options = options.merge(prefix, petsc_options or {})
        if stability_count == "spectrum" and self.options.get("pc_type") != fieldsplit.TYPE:
            raise ValueError(f"{prefix}: the stability count by the spectrum is preconditioned by the field split: "
                             f"give -{prefix}pc_type fieldsplit (or count by inertia)")
        #: whether MUMPS's memory estimate was compared with the ranks' memory (:mod:`.memory`)
        self.memory_checked = False
        #: the stage's checkpoints, which its paths write and resume from (set by the run that
        #: built the problem: :class:`bcfem.path.checkpoint.StageCheckpoints`); None: none
        self.checkpoints: Any = None
        with options.untouched():
            self._nlp = NonlinearProblem(residuals, self.states, bcs=bcs, kind="mpi",
                                         petsc_options_prefix=prefix, petsc_options=self.options,
                                         jit_options=jit_options, entity_maps=ctx.entity_maps or None)
        self.snes: PETSc.SNES = self._nlp.solver
        #: the user's field split (``pc_type fieldsplit``), its splits from the states' spaces
        self.field_split = FieldSplit(self) if self.options.get("pc_type") == fieldsplit.TYPE else None
        if self.field_split is not None:
            self.field_split.configure(self.snes.getKSP().getPC())
        self.stability_count = stability_count
        self.line_search_fallbacks = () if options.user_set(prefix, "snes_linesearch_type") \
            else tuple(line_search_fallbacks)
        self.iterations = 0
        #: Newton solves (each :meth:`solve` call) and their iterations, fallbacks included
        self.newton_solves = 0
        self.newton_iterations = 0
        self.reason: int = 0
        #: how often cp's critical-point exit had to be finished by Newton steps
        self.critical_point_exits = 0
        #: why the last converged state was rejected by a term (None: it was not)
        self.inadmissible: str | None = None
        #: converged states rejected by a term so far, and the last reason
        self.rejections = 0
        self.last_rejection: str | None = None
        #: Newton steps shortened by :meth:`bound_steps`
        self.bounded_steps = 0
        #: null pivots of the tangent at the first converged state (0: regular; :mod:`.pivots`)
        self.null_pivots: int | None = None
        self._tangent_ksp = None
        self._bounds: tuple[PETSc.Vec, ...] = ()
        self._owned: list = []
        self._kept: dict = {}
        for term in self.discrete:
            term.bind(self)
        #: seconds spent within Newton solves in: form assembly, discrete terms, the direct
        #: solver's factorisations and solves, the rest of Newton (line search, active sets);
        #: and in :meth:`timed` work (stability)
        self.timings = dict.fromkeys(TIMED, 0.0)
        self._timing_outside = 0
        #: Newton solves that did not converge (each is a cut-back or a retry)
        self.failed_solves = 0
        self._first_norm: float | None = None  # the residual norm at the start of a solve (divergence test)
        #: the SNES's residual and Jacobian callbacks
        self.assembly = Assembly(self, residuals)
        #: ends a solve whose iterates cycle (it would fail at snes_max_it)
        self.cycles = RepeatedIterates(self.snes, self.comm)

    def _guard_divergence(self, f: PETSc.Vec) -> None:
        """PETSc's divergence test, which vinewtonrsls does not apply: a residual grown past
        ``snes_divergence_tolerance`` (-3, PETSC_UNLIMITED: off) times the solve's first is reported as NaN, so the
        solve stops (DIVERGED_FNORM_NAN) or the line search backs off, rather than iterating
        to ``snes_max_it`` on a diverging path."""
        if interrupt.received(self.comm):  # every rank ends the solve here; check() then stops it
            f.set(np.nan)
            return
        norm = f.norm()
        if self._first_norm is None:
            self._first_norm = norm
            return
        divtol = self.snes.getDivergenceTolerance()
        if divtol > 0 and norm > divtol * max(self._first_norm, np.finfo(float).tiny):
            f.set(np.nan)

    @contextmanager
    def timed(self, key: str):
        """Count the time of the enclosed work (assembly included, the form compiler's not) under
        ``key``."""
        clock = jit.Clock()
        self._timing_outside += 1
        try:
            yield
        finally:
            self._timing_outside -= 1
            self.timings[key] = self.timings.get(key, 0.0) + clock.seconds()

    def bound_steps(self) -> None:
        """Shorten every Newton step to what the discrete terms with a ``step_bound(x, y)``
        allow (e.g. a wall that must not pass through itself), before the line search.
        Off by default: it changes the path wherever a full step would have been taken."""
        bounded = [t for t in self.discrete if t.bounds_steps()]
        if not bounded:
            return

        def precheck(x, y):
            # one t on every rank, whatever part of x and y each term sees
            t = self.comm.allreduce(min(term.step_bound(x, y) for term in bounded), op=MPI.MIN)
            if t < 1.0:
                self.bounded_steps += 1
                y.scale(t)

        self.snes.setLineSearchPreCheck(precheck)

    def allow_new_nonzeros(self) -> None:
        """Let a discrete term add entries outside the forms' sparsity pattern."""
        self._nlp.A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)

    def save(self) -> list[np.ndarray]:
        """A copy of every state's local array (for restore on failure)."""
        return [s.x.array.copy() for s in self.states]

    def restore(self, saved: list[np.ndarray]) -> None:
        for s, a in zip(self.states, saved):
            s.x.array[:] = a

    def solve(self, fallbacks: bool = True) -> bool:
        """Newton from the current states, retried from them with each of the
        ``line_search_fallbacks`` while it fails (unless ``fallbacks`` is False: a
        continuation may rather cut its step first, since a line search can also land on
        another branch). On failure the states are restored.

        Returns:
            True when SNES converged (reason > 0) to a finite state.
        """
        self.newton_solves += 1
        saved = self.save()
        ok = self._newton()
        line_search = self.snes.getLineSearch()
        default = line_search.getType()
        for fallback in self.line_search_fallbacks if fallbacks else ():
            if ok:
                break
            self.restore(saved)
            line_search.setType(fallback)
            try:
                ok = self._newton()
            finally:
                line_search.setType(default)
        if not ok:
            self.restore(saved)
            self.failed_solves += 1
        return ok

    def _check_memory(self) -> None:
        """Before the first factorisation, MUMPS's estimate against the ranks' memory (once: the
        sparsity stays along a path; :func:`.memory.check`)."""
        if self.memory_checked:
            return
        self.memory_checked = True
        if self.options.get("pc_type") not in ("lu", "cholesky") or \
                self.options.get("pc_factor_mat_solver_type") != "mumps":
            return  # no MUMPS factorisation (an iterative solver, another direct one)
        A, _ = self.jacobian()
        factor = "cholesky" if self.symmetric_tangent else "lu"
        with self.timed("factorisation"):
            warning = memory.check(A, self.prefix, factor, self._mumps_options, self.comm)
        if warning:
            logger.warning(f"{self.prefix}: {warning}")

    def _newton(self) -> bool:
        x = self._nlp.x
        assign(self.states, x)
        self._snes_solve(x)
        iterations = self.iterations
        if self._critical_point_exit():
            # cp left x where it stopped: finish from there with full Newton steps
            self.critical_point_exits += 1
            line_search = self.snes.getLineSearch()
            chosen = line_search.getType()
            line_search.setType("basic")
            try:
                self._snes_solve(x)
            finally:
                line_search.setType(chosen)
            iterations += self.iterations
        self.iterations = iterations
        self.newton_iterations += iterations
        ok = self.reason > 0 and np.isfinite(x.norm()) and not self._critical_point_exit()
        # vinewtonrsls tests convergence on the reduced norm it reports, so only other VI
        # types need the norm recomputed
        if ok and self.iterations == 0 and self._bounds and self.snes.getType() != "vinewtonrsls":
            self._check_vi_start(x)
        self.inadmissible = None
        if ok:
            x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
            assign(x, self.states)
            # an equilibrium can still be unphysical (a wall through itself, an inverted
            # solid): the terms that know their geometry may veto it, and the solve fails
            # like any other
            self.inadmissible = next((message for term in self.discrete
                                      for message in [term.inadmissible()] if message), None) or \
                next((message for term in self.terms if not isinstance(term, DiscreteTerm)
                      for message in [term.inadmissible(self.ctx)] if message), None)
            ok = self.inadmissible is None
            self._check_pivots()
            if not ok:
                self.rejections += 1
                self.last_rejection = self.inadmissible
        if not ok:
            short = memory.shortage(self.snes.getKSP().getPC())
            if short is not None:  # no smaller step helps: the run ends here
                raise memory.OutOfMemory(f"{self.prefix}: {short}")
            # a failed factorisation (e.g. of a NaN Jacobian) would otherwise stick to the PC
            self.snes.getKSP().getPC().reset()
        return ok

    def _check_pivots(self) -> None:
        """Count the tangent's null pivots once, at the first state converged by a Newton step (its
        tangent assembled on the way; :mod:`.pivots`)."""
        if self.null_pivots is not None or self.iterations == 0:
            return
        if not pivots.direct(self.snes):
            self.null_pivots = 0  # no factorisation to spare
            return
        with self.timed("stability"):
            self.null_pivots = pivots.null_pivots(self.snes.getJacobian()[0], self.prefix + "pivots_")
        if self.null_pivots:
            logger.warning(pivots.warning(self.prefix, self.null_pivots))

    @property
    def failure(self) -> str:
        """Why the last solve failed, for messages."""
        if self.inadmissible:
            return f"converged to an inadmissible state: {self.inadmissible}"
        if self.cycles.period:
            return f"SNES reason {self.reason} (the Newton iterates repeat with period {self.cycles.period})"
        return f"SNES reason {self.reason}"

    def _snes_solve(self, x: PETSc.Vec) -> None:
        self._first_norm = None
        for term in self.discrete:
            term.begin_solve()
        self._check_memory()  # the discrete terms' tangents are set up by now
        t0 = perf_counter()
        assembled = self.timings["assembly"] + self.timings["discrete_terms"]
        solver = petsc_events.seconds()
        try:
            # MUMPS reads its options at each analysis: they must be in the database then
            with interrupt.deferred(), options.inserted(self.prefix, self._mumps_options):
                self.snes.solve(None, x)
            self.reason = int(self.snes.getConvergedReason())
        except PETSc.Error:
            self.reason = -100  # e.g. a NaN pivot from an inverted iterate
        assembled = self.timings["assembly"] + self.timings["discrete_terms"] - assembled
        for part, seconds in petsc_events.seconds().items():
            self.timings[part] += seconds - solver[part]
            assembled += seconds - solver[part]
        self.timings["newton"] += perf_counter() - t0 - assembled
        self.iterations = self.snes.getIterationNumber()
        interrupt.check(self.comm)  # a signal is no failed solve: every rank stops here

    def _critical_point_exit(self) -> bool:
        """Whether the solve ended at an exit of PETSc's cp line search that is no convergence.

        cp reports CONVERGED_FNORM_ABS when dot(F, Y) ~ 0 for the Newton step Y, and returns
        with the state and its norm unchanged. With an indefinite tangent (past a limit point)
        dot(F, Y) also vanishes where F does not, so that exit is convergence only when the
        norm itself meets ``snes_atol``."""
        return (self.reason == PETSc.SNES.ConvergedReason.CONVERGED_FNORM_ABS
                and self.snes.getFunctionNorm() >= self.snes.getTolerances()[1])

    def _check_vi_start(self, x: PETSc.Vec) -> None:
        """Convergence in 0 iterations means the start already met ``snes_atol``. Check that
        on the residual reduced to the unknowns not held at a bound: some SNESVI types
        (``vinewtonssls`` on these bounds) report a zero norm there and would accept a
        state that is no equilibrium."""
        f = x.duplicate()
        try:
            self.snes.computeFunction(x, f)
            lower, upper = (b.array for b in self._bounds)
            # PETSc's own active set (SNESVIGetActiveSetIS): within 1e-8 of a bound, pushing on it
            held = ((x.array <= lower + 1e-8) & (f.array >= 0)) | ((x.array >= upper - 1e-8) & (f.array <= 0))
            norm = np.sqrt(self.comm.allreduce(float(np.sum(f.array[~held] ** 2))))
        finally:
            f.destroy()
        atol = self.snes.getTolerances()[1]
        if norm > 10.0 * atol:
            raise RuntimeError(
                f"SNES ({self.snes.getType()}) reported convergence in 0 iterations, but the residual "
                f"off the bounds is {norm:.3e} > snes_atol = {atol:.1e}: this SNES type does not "
                f"handle these bounds; use -{self.prefix}snes_type vinewtonrsls")

    @property
    def bounds(self) -> tuple[PETSc.Vec, ...]:
        """(lower, upper) as blocked vectors once :meth:`set_bounds` was called, else ()."""
        return self._bounds

    def set_bounds(self, lower, upper) -> None:
        """Variable bounds for a variational-inequality SNES (e.g. ``vinewtonrsls``):
        one function per state for each side (use +-1e20 where unbounded)."""
        self._bounds = (self.vector_from(lower), self.vector_from(upper))
        self.snes.setVariableBounds(*self._bounds)
        if (self.snes.getType() == "vinewtonrsls" and self.options.get("ksp_type") == "preonly"
                and self.options.get("pc_type") == "lu" and not options.user_set(self.prefix, "pc_type")):
            # one symbolic analysis for the whole path, not one per Newton iteration
            pc = self.snes.getKSP().getPC()
            solver = self.options.get("pc_factor_mat_solver_type", "mumps")
            # MUMPS's LDL^T of a symmetric indefinite tangent: a fifth cheaper than its LU
            factor = "cholesky" if self.symmetric_tangent and solver == "mumps" else "lu"
            pc.setType("python")
            pc.setPythonContext(ReducedLU(self.snes, solver, self.prefix, factor))
        elif self.snes.getType() == "vinewtonrsls" and self.field_split is not None:
            # the user's Krylov method on the reduced system, its preconditioner the split of
            # the full-size one (the index sets stay valid on every active set)
            pc = self.snes.getKSP().getPC()
            pc.setType("python")
            # not the user's prefix: a reset of the KSP on a new active set re-reads the options,
            # and their pc_type would replace this PC
            pc.setOptionsPrefix(self.prefix + "reduced_")
            inner = fieldsplit.reduced_inner_ksp(self, self.field_split)
            pc.setPythonContext(ReducedLU(self.snes, "", self.prefix, inner=inner))

    @property
    def _mumps_options(self) -> dict:
        return {key: value for key, value in self.options.items() if key.startswith("mat_mumps_")}

    def energy(self) -> float:
        """The Lagrangian at the current states, summed over the ranks (collective; its form
        compiled on the first call)."""
        if self._energy is None:
            self._energy = fem.form(self.lagrangian)
        return global_sum(self._energy)

    def kept(self, key: str, make):
        """The resource ``key`` of this problem, made by ``make()`` on first use and closed
        with the problem (:meth:`own`): e.g. a factorisation kept along a path."""
        if key not in self._kept:
            self._kept[key] = self.own(make())
        return self._kept[key]

    def own(self, resource):
        """Close ``resource`` (anything with a collective ``close()``, such as a
        :class:`~bcfem.stability.modes.ModeAnalysis` of this problem's states) with this problem;
        returns it."""
        self._owned.append(resource)
        return resource

    def close(self) -> None:
        """Destroy the PETSc objects now, in the same order on every rank.

        Left to the garbage collector, their collective destruction can happen in
        a different order on different ranks and deadlock at exit.
        """
        for resource in self._owned:
            resource.close()
        self._owned, self._kept = [], {}
        if self._tangent_ksp is not None:
            self._tangent_ksp.destroy()
            self._tangent_ksp = None
        if self._nlp is not None and self.snes.getKSP().getPC().getType() == "python":
            self.snes.getKSP().getPC().getPythonContext().destroy()  # ReducedLU (set_bounds)
        self.assembly.destroy()
        if self.field_split is not None:
            self.field_split.destroy()
            self.field_split = None
        for vec in self._bounds:
            vec.destroy()
        self._bounds = ()
        if self._nlp is not None:
            del self._nlp
            self._nlp = None  # type: ignore[assignment]  # closed: the Problem is not used again

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
