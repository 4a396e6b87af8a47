r"""The crater's suction cycle as two declared stages (ch. 7-8).

``load`` (vent open): the platen compresses the specimen to the preload
ε = -ΔL/L through fixed checkpoints; the crater fluid stays at p_a, so the wall is
unloaded. With ``--preload closure`` the stage ends at the smallest preload that
closes the crater (ε_m, located by bisection).

``unload`` (sealed): the fluid is a term of its own (Boyle's law for air, a volume
constraint for a liquid, a vacuum once closed):

.. math:: L(u, p) = \int W(F, p_s)\,dV - (p - p_a)\,V(u) + p_a V_1 \ln(p/p_a),

and the platen retracts until its force vanishes (located by Brent's method). The
suction force is F = (1 - V1/V2) p_a A2 (eq. 7.3), F~ = F/(p_a A0) (eq. 7.13).

A step Newton cannot reach is taken by pseudo-time relaxation (a snap), and the
tangent's inertia is checked after every step (:class:`bcfem.path.stepping.LoadPath`).
A cycle that fails is traced once more from the start with Newton steps bounded to
keep the wall admissible and a larger default iteration limit (the user's PETSc
options still win); ``retraced`` in the summary says why the first trace failed.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem

from bcfem.log import progress
from bcfem.mpi import global_sum, real_value
from bcfem.path.stepping import LoadPath, SteppingError
from bcfem.path.terminations import PLATEN_FORCE_ZERO, Described, Reaches
from bcfem.physics.cavitation import BISECTIONS, change_phase, liquid_or_vapour, phase_change
from bcfem.physics.fluids import FLUIDS, Vacuum
from bcfem.run.stages import Ended, Stage, StagedScene
from bcfem.scenes.crater.model import Crater
from bcfem.scenes.crater.params import (
    CLOSURE_CRITERIA,
    CYCLE_COLUMNS,
    MAX_CLOSURE_PRELOAD,
    MAX_LIFT,
    PRELOAD_TO_CLOSURE,
    Params,
)
from bcfem.scenes.crater.report import Cycle, finish, plot
from bcfem.scenes.crater.seal import seal

#: full Newton steps can cycle between two contact active sets; backtracking breaks the
#: cycle, and where it stalls, cp (a line search on the energy along Newton's direction) may
LINE_SEARCH_FALLBACKS = ("bt", "cp")
#: the retrace's default Newton budget: steps bounded to keep the wall admissible converge
#: more slowly than full ones
CAREFUL = {"snes_max_it": 80}


class CraterScene(StagedScene):
    """The crater scene's two paths (:class:`CraterCycle`, and the fundamental branch's
    :class:`~bcfem.scenes.crater.fundamental.FundamentalCycle`): a :class:`Crater` model driven
    through the stages ``load`` (vent open) and ``unload`` (sealed); what the stages find is
    one record, :class:`~bcfem.scenes.crater.report.Cycle`.

    Args:
        params: the scene's parameters.
        comm: the communicator of the mesh.
        model_class: ``Crater`` or a subclass (e.g. one that records the deformed states,
            :mod:`bcfem.scenes.crater.frames`).
    """

    params: Params
    name = "crater"
    stages = ("load", "unload")

    def __init__(self, params: Params, comm, model_class: type[Crater] = Crater):
        self.params = params
        self.comm = comm
        self.model_class = model_class
        self.model: Crater | None = None
        self.cycle = Cycle()

    @property
    def crater(self) -> Crater:
        """The model, once built."""
        if self.model is None:
            raise RuntimeError("the crater's model is built by setup()")
        return self.model

    def figures(self, rows, summary) -> dict:
        return {"cycle.png": plot(rows, summary)}


class CraterCycle(CraterScene):
    """The crater's stable path: load steps, snaps passed by relaxation; ``unload`` is entered
    again when its liquid changes phase (:meth:`plan`)."""

    columns = CYCLE_COLUMNS

    def __init__(self, params: Params, comm, model_class: type[Crater] = Crater):
        super().__init__(params, comm, model_class)
        #: Newton steps bounded to keep the wall admissible (the retrace of a failed cycle)
        self.careful = False

    def solve(self, run) -> None:
        """Both stages; a failed cycle is traced once more with bounded Newton steps."""
        try:
            super().solve(run)
        except SteppingError as failure:
            if self.params.self_contact == 0:
                raise
            progress(f"{failure}: tracing the cycle again with bounded Newton steps")
            run.restart()
            self.careful = True
            try:
                super().solve(run)
            except SteppingError as again:
                raise SteppingError(f"{again} (traced again with bounded Newton steps; the first trace: "
                                    f"{failure})", again.reached) from None
            run.results["retraced"] = str(failure)
        finally:
            run.results.update(self.cycle.partial())

    # -- the plan -------------------------------------------------------------------------
    @property
    def problem_options(self) -> dict:
        return dict(petsc_options={"snes_type": "vinewtonrsls", **(CAREFUL if self.careful else {})},
                    energy_scale=self.crater.energy_scale, line_search_fallbacks=LINE_SEARCH_FALLBACKS)

    def setup(self, run) -> None:
        model = self.model = self.model_class(self.params.model_inputs(), self.comm)
        run.watch([model.u])
        self.cycle = Cycle()
        run.results.update(retraced=None, **self.cycle.partial())

    def plan(self) -> list[Stage]:
        p = self.params
        load_ends = CLOSURE_CRITERIA if p.preload == PRELOAD_TO_CLOSURE else Reaches("eps", p.preload)
        return [
            Stage("load", terms=self.crater.terms, prepare=self._prepare, drive=self._load, until=load_ends),
            Stage("unload", enter=self._seal, terms=self._sealed_terms, prepare=self._prepare, drive=self._unload_stage,
                  until=PLATEN_FORCE_ZERO if p.retract == 0 else
                  Described(f"zero platen force, then pull-off (up to eps = -{p.retract:g})")),
        ]

    def _prepare(self, problem) -> None:
        self.crater.contact_bounds(problem)
        if self.careful:
            problem.bound_steps()

    def _path(self, problem, stage: str) -> LoadPath:
        beta, a = self.params.beta, self.params.crater_radius
        model = self.crater
        return LoadPath(problem, model.set_platen, stage, model.viscosity, beta / a**2,
                        events=self.cycle.events, max_snaps=self.params.max_snaps,
                        waves=model.wave_check(problem, problem.terms), load_name="eps")

    def _load(self, problem, run) -> Ended:
        params, model, cycle = self.params, self.crater, self.cycle
        with model.measuring(problem):
            path = self._path(problem, "load")
            run.record(model.observe("load", 0.0))
            path.start()
            if params.preload == PRELOAD_TO_CLOSURE:
                cycle.preload, cycle.closes = load_to_closure(model, path, run, params.strain_step)
            else:
                cycle.preload, cycle.closes = params.preload, False
                path.through(0.0, cycle.preload, params.strain_step, lambda e: run.record(model.observe("load", e)))
            cycle.final_unstable = path.unstable
        why = "closed" if cycle.closes else "still open" if params.preload == PRELOAD_TO_CLOSURE else "preloaded"
        return Ended(f"{why} at eps = {cycle.preload:.6g}")

    def _seal(self, run) -> str | None:
        """Seal the crater at the preload; a crater that stays closed is not unloaded (the reason)."""
        params, model, cycle = self.params, self.crater, self.cycle
        cycle.V1 = run.rows[-1]["V"]
        cavitates = params.fluid == "liquid" and params.cavitation != -math.inf
        sealing = cycle.sealing = seal(model, cycle.V1, cycle.closes, params.fluid, cavitates)
        cycle.start = cycle.zero_force = cycle.preload
        if sealing.stays_closed:
            cycle.final = sealing.final_closed(model, cycle.preload)
            return "a closed liquid crater that cannot cavitate stays closed: F = 0 (eq. 8.8)"
        if sealing.closed and cavitates:  # no liquid left to hold the wall down: vapour at p_v once it lifts
            cycle.vapour = True
            cycle.phase_changes.append({
                "stage": "unload", "kind": "cavitation", "eps": cycle.preload, "bracket": 0.0,
                "p_over_pa": params.cavitation, "V_over_V0": cycle.V1 / model.geometry.crater_volume,
                "detail": "closed on loading: the cavity holds vapour at p_v from the seal"})
        return None

    def _sealed_terms(self) -> list:
        """The model with its sealed fluid in its current phase (one problem per phase)."""
        params, model, cycle = self.params, self.crater, self.cycle
        fluid = Vacuum(model.cavity) if cycle.sealed.closed else liquid_or_vapour(
            FLUIDS[params.fluid], model.cavity, cycle.V1, "fluid_pressure", cycle.vapour, params.cavitation)
        return model.terms(fluid)

    def _unload_stage(self, problem, run) -> Ended:
        """Retract to zero platen force (and on, with --retract); entered again where the liquid
        changes phase first, with the new phase's term."""
        params, model, cycle = self.params, self.crater, self.cycle
        V1_sealed = cycle.sealed.sealed_volume
        with model.measuring(problem) as platen_force:
            path = self._path(problem, "unload")
            if cycle.start != cycle.preload:  # the state at the phase change, with the new phase's term
                if not path.solve_at(cycle.start, fallbacks=True):
                    raise SteppingError(f"unload: no equilibrium after the {cycle.phase_changes[-1]['kind']} at "
                                        f"eps = {cycle.start:.6g}: {problem.failure}", cycle.start)
                run.record(model.observe("unload", cycle.start, V1_sealed))
            ended = self._unload(model, path, problem, platen_force, cycle.start, V1_sealed,
                                 cycle.sealed.closed, run, cycle.vapour)
            cycle.final_unstable = path.unstable
            if isinstance(ended, dict):
                cycle.phase_changes.append(ended)
                progress(f"unload: {ended['kind']} at eps = {ended['eps']:.6g}")
                cycle.vapour = change_phase(model.ctx, "fluid_pressure", ended["kind"], params.cavitation)
                cycle.start = ended["eps"]
                return Ended(f"{ended['kind']} at eps = {ended['eps']:.6g}", again=True)
            cycle.zero_force = ended
            cycle.final = model.observe("unload", model.strain, V1_sealed)
            why = f"zero platen force at eps = {ended:.6g}"
            if params.retract > 0:
                run.record(cycle.final)
                pull_off = self._retract(model, path, V1_sealed, run)
                why += f"; {pull_off['kind']} at eps = {pull_off['eps']:.6g}" if pull_off else \
                    f"; no pull-off up to eps = -{params.retract:g}"
                return Ended(why, {"pull_off": pull_off})
        return Ended(why)

    def finish(self, run) -> None:
        finish(run, self.params, self.crater, self.cycle,
               recorded=self.cycle.sealed.stays_closed is False and self.params.retract > 0)

    def _retract(self, model, path, V1_sealed: float, run, bisections: int = 8) -> dict | None:
        """Lift the platen from zero force on to eps = -retract, recording the rows; stop at
        pull-off: where the platen's pull peaks, or where the seal opens (no node of the bottom
        face or the wall is left on the plate: located by bisection, the last sealed state
        recorded). Returns the pull-off state, or None if neither happens up to -retract."""
        last: dict = {}
        sealed, opened = path.mark(model.strain), None

        def accept(strain) -> bool:
            nonlocal sealed, opened
            if not model.on_plate():
                opened = strain
                return True
            row = model.observe("retract", strain, V1_sealed)
            run.record(row)
            if last and row["platen_force"] < last["platen_force"]:
                last["kind"] = "the pull peaks"
                return True
            last.update(row)
            sealed = path.mark(strain)
            return False

        try:
            path.through(model.strain, -self.params.retract, self.params.strain_step, accept)
        except SteppingError as failure:  # nothing holds the specimen down any more
            if not last:
                raise
            last["kind"] = f"no equilibrium further on ({failure})"
        if opened is not None:
            strain = path.bisect(sealed, opened, lambda strain: not model.on_plate(), bisections, end_before=True)
            if strain != sealed["value"]:  # a later sealed state than the last row
                last.update(model.observe("retract", strain, V1_sealed))
                run.record(dict(last))
            last["kind"] = "the seal opens"
        if "kind" not in last:
            return None
        return {"kind": last["kind"], **{k: last[k] for k in ("eps", "platen_force", "F_tilde", "p_over_pa",
                                                             "A_over_A0")}}

    def _unload(self, model, path, unloading, platen_force, preload: float, V1_sealed: float, closed: bool,
                run, vapour: bool = False) -> float | dict:
        """Retract the platen from ``preload`` to zero force; returns the strain there, or, if
        the liquid cavitates or its vapour (``vapour``) collapses first, that event, located by
        bisection (the path then ends at the first state past it)."""
        params = self.params
        path.start()

        def changed() -> str | None:
            if V1_sealed == 0.0 or params.fluid != "liquid" or params.cavitation == -math.inf:
                return None
            p = real_value(model.ctx.states["fluid_pressure"])
            return phase_change(vapour, p, global_sum(model.volume), V1_sealed, params.cavitation)

        if closed:  # the suction of a closed crater jumps from 0 to p_a (p_a - p_v): ramp it at fixed platen
            ramp = model.ctx.constant("vacuum_load")
            sealing = LoadPath(unloading, lambda s: setattr(ramp, "value", s), "seal", path.viscosity,
                               path.relax_stiffness, path.multipliers, events=path.events,
                               max_snaps=params.max_snaps, waves=path.waves, load_name="vacuum_ramp")
            sealing.start()
            first = len(path.events)
            suction = 1.0 - params.cavitation if vapour else 1.0
            sealing.advance(0.0, suction, 0.25 * suction)
            for event in path.events[first:]:  # report the platen strain; the ramp value goes in the detail
                event.update(detail=f"{event['detail']} (vacuum ramp at {event.pop('vacuum_ramp'):.3g})",
                             eps=preload)
            path.unstable, path.unstable_waves = sealing.unstable, sealing.unstable_waves
        path.set_load(preload)
        last = path.mark(preload)

        def accept(strain):
            if global_sum(platen_force) >= 0 or changed():
                return True
            run.record(model.observe("unload", strain, V1_sealed))
            last.update(path.mark(strain))
            return False

        # past a snap the specimen can still push at eps = 0: the platen then lifts further;
        # a force below round-off counts as zero: at eps = 0 there is nothing to unload
        round_off = -1e-10 * math.pi * params.specimen_radius**2 * max(1.0, params.beta)
        if global_sum(platen_force) >= round_off:
            reached = preload
        else:
            reached = path.through(preload, -MAX_LIFT, params.strain_step, accept)
        kind = changed()
        if kind is None and global_sum(platen_force) < round_off:
            raise SteppingError(f"unload: the platen force is still compressive at eps = {reached:.4g}", reached)
        if kind is None or global_sum(platen_force) >= 0:  # zero force: does the phase change before it?
            if reached != last["value"]:
                reached = path.root(last, reached, lambda: global_sum(platen_force),
                                    xtol=1e-10 * max(preload, 1e-3))
            kind = changed()
        if kind is not None:
            eps = path.bisect(last, reached, lambda _: changed() is not None, BISECTIONS)
            return {"stage": "unload", "kind": kind, "eps": eps, "bracket": abs(path.bracket[1] - path.bracket[0]),
                    "p_over_pa": real_value(model.ctx.states["fluid_pressure"]),
                    "V_over_V0": global_sum(model.volume) / model.geometry.crater_volume}
        if reached < 0:
            path.events.append({"stage": "unload", "eps": reached, "kind": "lift", "unstable": None,
                                "detail": "zero platen force only beyond the specimen's original height"})
        run.results["plate_reaction_tilde"] = self._plate_reaction(model, unloading)
        return reached

    def _plate_reaction(self, model, problem) -> float:
        """The plate's push on the specimen over p_a A0: the residual's vertical work on the
        nodes held by the plate (w = 1 - Z/H, zero on the top face). At zero platen force it
        balances the suction, (p_a - p) A2 (a check of A2, the sealed contact line's area)."""
        H = self.params.specimen_height
        w = fem.Function(model.u.function_space)
        w.interpolate(lambda x: np.vstack([0 * x[0], 1 - x[1] / H]))
        reaction = global_sum(fem.form(ufl.derivative(problem.lagrangian, model.u, w)))
        return reaction / (math.pi * model.geometry.crater_radius**2)


def load_to_closure(model, path: LoadPath, run, strain_step: float, bisections: int = 10) -> tuple[float, bool]:
    """The load stage up to the smallest preload that closes the crater, eps_m (to a
    2^-bisections fraction of the last step, or to the bracket where a snap-through closure
    stops the bisection): load until the crater is closed (:data:`CLOSURE_CRITERIA`), then
    bisect between the last open and the first closed state. Stage 2 neglects the remnant,
    which changes F by at most V1/V2; the summary reports V1.

    Returns (eps_m, True), or (``MAX_CLOSURE_PRELOAD``, False) for a crater still open there
    (a result, e.g. a thick stiff lining that holds it open: the cycle then runs from there)."""
    closed = CLOSURE_CRITERIA.reached
    open_state = path.mark(0.0)

    def accept(eps):
        row = model.observe("load", eps)
        run.record(row)
        if closed(row):
            return True
        open_state.update(path.mark(eps))
        return False

    closed_at = path.through(0.0, MAX_CLOSURE_PRELOAD, strain_step, accept)
    if not closed(run.rows[-1]):
        return closed_at, False

    def passed(eps) -> bool:
        row = model.observe("load", eps)
        if closed(row):
            run.replace_last(row)  # the closed state kept is the first one found past eps_m
            return True
        return False

    return path.bisect(open_state, closed_at, passed, bisections), True
