r"""The crater's fundamental branch (``--path fundamental``): both stages by arc-length.

The platen displacement w is an unknown (the model's lift u + w φ e_z, φ = 1 on the top
face), so :class:`bcfem.path.continuation.ArcLength` can drive it: the branch connected to
the rest state is followed through its folds in ε = -w/H (snap-backs) and along its
unstable stretches, with no relaxation. At each accepted point the unstable modes are
counted at fixed platen (displacement control: w held, Sylvester's law), and with
``--waves`` the n-wave modes too; a change is an event, as on the stable path, and a
fold of ε is an event of kind ``fold``.

``load`` (vent open) ends at the preload, at closure (:data:`CLOSURE_CRITERIA`) or at
ε = 0.85; ``unload`` (sealed) ends where the platen force vanishes. A branch the
continuation cannot follow (a bifurcation it cannot pass, a wall that would pass
through itself) ends the run with the converged part written and the reason given.
"""

from __future__ import annotations

import math

import ufl
from dolfinx import fem

from bcfem.mpi import global_sum
from bcfem.params import ContinuationParams
from bcfem.path.continuation import ArcLength, ContinuationError
from bcfem.path.stepping import LoadPath
from bcfem.path.terminations import PLATEN_FORCE_ZERO, AnyOf, Reaches, Termination
from bcfem.physics.fluids import FLUIDS, Vacuum
from bcfem.run.stages import Ended, Stage
from bcfem.scenes.crater.model import Crater
from bcfem.scenes.crater.params import (
    CLOSURE_CRITERIA,
    FUNDAMENTAL_COLUMNS,
    MAX_CLOSURE_PRELOAD,
    PRELOAD_TO_CLOSURE,
    Params,
)
from bcfem.scenes.crater.report import Cycle, finish
from bcfem.scenes.crater.seal import seal
from bcfem.scenes.crater.stages import LINE_SEARCH_FALLBACKS, CraterScene

#: the load parameter: the platen's displacement (mm; compression < 0)
PARAMETER = "platen_displacement"


class FundamentalCycle(CraterScene):
    """The crater scene on its fundamental branch: the stages ``load`` and ``unload``, each
    traced by arc-length in the platen's displacement (:meth:`plan`)."""

    columns = FUNDAMENTAL_COLUMNS

    def __init__(self, params: Params, comm, model_class: type[Crater] = Crater):
        super().__init__(params, comm, model_class)
        self.folds: list[dict] = []

    def solve(self, run) -> None:
        try:
            super().solve(run)
        finally:
            run.results.update(self.cycle.partial(), folds=self.folds)

    def continuation(self) -> ContinuationParams:
        """Steps in the strain-like norm (lengths over H), at most ``strain_step``: longer steps
        let Newton land on a neighbouring branch within the correction bound."""
        step = self.params.strain_step
        return ContinuationParams(ds=step / 2, ds_min=step * 2.0**-16, ds_max=step, event_tol=1e-9,
                                  max_steps=20000, max_correction=0.25)

    # -- the plan -------------------------------------------------------------------------
    @property
    def problem_options(self) -> dict:
        return dict(petsc_options={"snes_type": "vinewtonrsls"}, energy_scale=self.crater.energy_scale,
                    line_search_fallbacks=LINE_SEARCH_FALLBACKS, rows=self.arc.rows())

    def setup(self, run) -> None:
        model = self.model = self.model_class(self.params.model_inputs(), self.comm)
        run.watch([model.u])
        self.cycle, self.folds = Cycle(), []
        run.results.update(retraced=None, folds=self.folds, **self.cycle.partial())
        H = self.params.specimen_height
        self.arc = ArcLength(model.ctx, PARAMETER, self.continuation(), load_scale=H, norm={"displacement": H})

    def plan(self) -> list[Stage]:
        return [Stage("load", terms=self._terms, prepare=self.crater.contact_bounds, drive=self._load,
                      until=self.loaded),
                Stage("unload", enter=self._seal, terms=lambda: self._terms(self.fluid),
                      prepare=self.crater.contact_bounds, drive=self._unload, until=PLATEN_FORCE_ZERO)]

    @property
    def loaded(self) -> Termination:
        """The load stage's end: the preload, closure, or eps = 0.85."""
        preload = self.params.preload
        end_strain = MAX_CLOSURE_PRELOAD if preload == PRELOAD_TO_CLOSURE else preload
        return AnyOf((Reaches("eps", end_strain), CLOSURE_CRITERIA))

    def _terms(self, *fluids) -> list:
        """The model's terms without the viscous one: the branch is followed, not relaxed."""
        return [t for t in self.crater.terms(*fluids) if t is not self.crater.viscosity]

    def _load(self, problem, run) -> Ended:
        self._trace(run, self.arc, problem, "load", None, end=self.loaded, direction=-1)
        self.load_end = run.rows[-1]
        return Ended(f"{'closed' if CLOSURE_CRITERIA.reached(self.load_end) else 'loaded'} at eps = "
                     f"{self.load_end['eps']:.6g}")

    def _seal(self, run) -> str | None:
        """Seal at the end of loading; a liquid crater that closed is not unloaded (the reason)."""
        model, load_end, cycle = self.crater, self.load_end, self.cycle
        cycle.V1, cycle.preload = load_end["V"], load_end["eps"]
        # the end is located to event_tol: within round-off of 0
        cycle.closes = CLOSURE_CRITERIA.measure(load_end) >= -1e-8
        sealing = cycle.sealing = seal(model, cycle.V1, cycle.closes, self.params.fluid, cavitates=False)
        cycle.zero_force = cycle.preload
        if sealing.stays_closed:
            cycle.final = sealing.final_closed(model, cycle.preload)
            cycle.final.update(s=load_end["s"], platen_force=load_end["platen_force"], unstable=load_end["unstable"])
            cycle.final_unstable = load_end["unstable"]
            return "a closed liquid crater stays closed: F = 0 (eq. 8.8)"
        self.fluid = Vacuum(model.cavity) if sealing.closed else FLUIDS[self.params.fluid](model.cavity, cycle.V1)
        return None

    def _unload(self, problem, run) -> Ended:
        model, H, cycle = self.crater, self.params.specimen_height, self.cycle
        if cycle.sealed.closed:  # the suction of a closed crater jumps from 0 to p_a: ramp it at fixed platen
            self.arc.hold(problem, -cycle.preload * H)
            ramp = model.ctx.constant("vacuum_load")
            sealing = LoadPath(problem, lambda s: setattr(ramp, "value", s), "seal", check_stability=False,
                               load_name="vacuum_ramp")
            sealing.start()
            sealing.advance(0.0, 1.0, 0.25)
        self._trace(run, self.arc, problem, "unload", cycle.sealed.sealed_volume, end=PLATEN_FORCE_ZERO,
                    direction=1)
        cycle.final = run.drop_last()
        cycle.zero_force, cycle.final_unstable = cycle.final["eps"], cycle.final["unstable"]
        return Ended(f"zero platen force at eps = {cycle.zero_force:.6g}")

    def finish(self, run) -> None:
        cycle = self.cycle
        finish(run, self.params, self.crater, cycle)
        if not cycle.sealed.stays_closed:
            run.results["eps_m"] = cycle.preload if self.params.preload == PRELOAD_TO_CLOSURE and cycle.closes else None

    def _trace(self, run, arc, problem, stage: str, V1, end, direction: int) -> None:
        """Follow the branch from the current state (its platen held) until ``end`` turns >= 0,
        recording every accepted point in ``run`` with its unstable modes."""
        model, H, events = self.crater, self.params.specimen_height, self.cycle.events
        w = model.platen_state
        arc.hold(problem, -model.platen_strain() * H)
        if not problem.solve():
            raise ContinuationError(f"{stage}: no converged state at the start of the branch ({problem.failure})")
        assert w is not None, "the fundamental path's platen displacement is a state"
        unit = fem.Function(w.function_space)
        unit.x.array[:] = 1.0
        force = fem.form(ufl.derivative(problem.lagrangian, w, unit))  # compression < 0
        A0 = math.pi * model.geometry.crater_radius**2

        def observe() -> dict:
            eps = model.platen_strain()
            return {**model.observe(stage, eps, V1), "platen_force": global_sum(force) / A0}

        stability = LoadPath(problem, model.set_platen, stage, events=events, held=(PARAMETER,), load_name="eps",
                             waves=model.wave_check(problem, problem.terms))
        stability.start()

        def accept(values: dict) -> None:
            stability.inspect(values["eps"])
            values.update(unstable=stability.unstable, unstable_waves=" ".join(map(str, stability.unstable_waves)))
            run.record(values)

        arc.jumps = arc.unlocated = 0
        try:
            branch = arc.trace(problem, observe, end, ("eps", "V_over_V0", "A_over_A0", "unstable"),
                               on_accept=accept, direction=direction)
        except ContinuationError as error:
            self._report(error.branch, arc, stage, events, self.folds, run)
            raise ContinuationError(f"{stage}: the branch cannot be followed past eps = "
                                    f"{model.platen_strain():.6g}: {error}") from None
        self._report(branch, arc, stage, events, self.folds, run)

    @staticmethod
    def _report(branch, arc, stage: str, events: list, folds: list, run) -> None:
        """The branch's folds (as events too) and its continuation counts, into ``run``."""
        for point in branch.limit_points:
            kind = "min" if point.kind == "max" else "max"  # of eps = -w/H
            folds.append({"stage": stage, "s": point.s, "eps": point.values["eps"], "kind": f"eps_{kind}",
                          "V_over_V0": point.values["V_over_V0"], "A_over_A0": point.values["A_over_A0"],
                          "platen_force": point.values["platen_force"]})
            events.append({"stage": stage, "eps": point.values["eps"], "kind": "fold", "unstable": None,
                           "detail": f"the branch turns back in eps (a {kind}imum): a snap-back"})
        run.results.setdefault("continuation", {})[stage] = {
            "points": len(branch.rows), "newton_iterations": branch.newton_iterations,
            "failed_steps": branch.failed_steps, "jumps_rejected": arc.jumps,
            "events_located_to_a_step": arc.unlocated, "wall_time_s": branch.wall_time_s}
