r"""The double-chamber crater's cycle: declared stages ``load`` and ``unload``, each followed
with the chambers as they are, which change where the sidewall touches the protuberance
(split) or leaves it (merge).

Each chamber's fluid is a term of its own (:mod:`bcfem.physics.fluids`) in its volume
(:mod:`bcfem.scenes.crater_double.chambers`): with one chamber the whole cavity holds amount n (p V = n for air,
V = n for a liquid); at a split, located by bisection in eps, C1 and C2 take the amounts
p V_C1 and p V_C2 of that state; at a merge, the sum. Every topology change starts a new
problem on the same states; the rows carry the number of chambers. The platen returns to
eps = 0, as in the dissertation (its Step 2).
"""

from __future__ import annotations

import math

from bcfem.log import progress
from bcfem.mpi import global_sum, real_value
from bcfem.path.stepping import LoadPath, SteppingError
from bcfem.path.terminations import Reaches
from bcfem.physics.cavitation import change_phase, liquid_or_vapour, phase_change
from bcfem.physics.fluids import FLUIDS
from bcfem.run.stages import Ended, Stage, StagedScene
from bcfem.scenes.crater.report import classify, symmetry_breaking
from bcfem.scenes.crater.stages import LINE_SEARCH_FALLBACKS
from bcfem.scenes.crater_double.model import DoubleCrater
from bcfem.scenes.crater_double.params import COLUMNS, Params

#: halvings of the step that brackets a split or a merge
BISECTIONS = 12
#: the pressure states of one cavity, and of the chambers C1 and C2
ONE, C1, C2 = "fluid_pressure", "p_c1", "p_c2"


class DoubleCraterCycle(StagedScene):
    """The scene ``crater-double``: :class:`DoubleCrater` pressed to the preload and unloaded
    to eps = 0, planned as legs of the stages ``load`` and ``unload`` (:meth:`plan`); a leg is
    entered again with new terms wherever the chambers change."""

    params: Params
    name = "crater-double"
    stages = ("load", "unload")
    columns = COLUMNS
    #: False: the cycle ends at the preload (a probe of the loading path)
    unloads = True

    def __init__(self, params: Params, comm, model_class: type[DoubleCrater] = DoubleCrater):
        self.params, self.comm, self.model_class = params, comm, model_class
        self.model: DoubleCrater | None = None
        self.shapes: list[dict] = []
        #: the chambers as they are: their number, sealed or vented, each one's vapour (a
        #: cavitated liquid) and amount of fluid (p V for air, V for a liquid)
        self.chambers, self.sealed = 1, False
        self.vapour: list[bool] = [False]
        self.amounts: list[float] = []
        #: the cavity's volume and the crater's base area at rest
        self.V0 = self.A0 = 0.0
        self.events: list[dict] = []
        self.topology: list[dict] = []
        #: where the current leg starts and ends, and whether its start is solved first
        self._leg_at: dict = {}

    @property
    def double(self) -> DoubleCrater:
        """The model, once built."""
        if self.model is None:
            raise RuntimeError("the double crater's model is built by setup()")
        return self.model

    # -- the chambers ---------------------------------------------------------------------
    def _names(self) -> tuple[str, ...]:
        return (ONE,) if self.chambers == 1 else (C1, C2)

    def _fluids(self) -> list:
        """The sealed fluids of the chambers as they are (none while vented); a cavitated
        liquid holds the vapour pressure."""
        if not self.sealed:
            return []
        fluid, held = FLUIDS[self.params.fluid], self.params.cavitation
        cavities = [self.double.cavity] if self.chambers == 1 else self.double.chambers
        return [liquid_or_vapour(fluid, c, n, name, vapour, held)
                for c, n, name, vapour in zip(cavities, self.amounts, self._names(), self.vapour)]

    def pressures(self) -> tuple[float, float]:
        """(p_c1, p_c2) / p_a; one cavity: its pressure twice."""
        if not self.sealed:
            return 1.0, 1.0
        states = self.double.ctx.states
        p = [self.params.cavitation if vapour else real_value(states[name])
             for name, vapour in zip(self._names(), self.vapour)]
        return (p[0], p[0]) if self.chambers == 1 else (p[0], p[1])

    def volumes(self) -> tuple[float, float]:
        """(V_C1, V_C2); one cavity: (V, 0)."""
        if self.chambers == 1:
            return global_sum(self.double.volume), 0.0
        return self.double.chamber_volumes_now()

    def _amount(self, p: float, V: float) -> float:
        return p * V if self.params.fluid == "air" else V

    def _set_pressures(self, values) -> None:
        for name, p, vapour in zip(self._names(), values, self.vapour):
            if not vapour:
                self.double.ctx.real_state(name).x.array[:] = p

    def _seal(self, run) -> None:
        """Seal each chamber with its fluid at p_a (the vented loading's end)."""
        self.sealed = True
        V = self.volumes()[: self.chambers]
        self.amounts = [self._amount(1.0, v) for v in V]
        self._set_pressures([1.0] * self.chambers)

    def _split(self, eps: float) -> dict:
        model = self.double
        p = self.pressures()[0]
        touching = model.sidewall_contact()
        assert touching is not None, "a split where the walls touch"
        V1, V2 = model.split_at(touching)
        self.chambers, self.vapour = 2, self.vapour * 2
        if self.sealed:  # a cavitated liquid: each chamber keeps its share of the liquid
            share = self.amounts[0] / (V1 + V2)
            self.amounts = [share * V1, share * V2] if self.vapour[0] else [self._amount(p, V1), self._amount(p, V2)]
            self._set_pressures([p, p])
        bonded = model.bond_split() if self.params.contact == "bonded" else 0
        split = model.chamber_split
        Zw, Zb = float(split.sidewall_height.value), float(split.protuberance_height.value)
        return {"eps": eps, "p_over_pa": p, "V_c1": V1 / self.V0, "V_c2": V2 / self.V0, "Z_sidewall": Zw,
                "Z_protuberance": Zb, **({"bonded_pairs": bonded} if bonded else {})}

    def _merge(self, eps: float) -> dict:
        (p1, p2), (V1, V2) = self.pressures(), self.volumes()
        self.chambers, self.vapour = 1, [any(self.vapour)]
        if self.sealed:
            self.amounts = [sum(self.amounts)]
            self._set_pressures([(p1 * V1 + p2 * V2) / (V1 + V2)])
        return {"eps": eps, "p_c1_over_pa": p1, "p_c2_over_pa": p2, "V_c1": V1 / self.V0, "V_c2": V2 / self.V0}

    def _phase_change(self, eps: float, kind: str) -> dict:
        """A liquid chamber cavitates (its pressure reached p_v) or its vapour collapses (its
        volume fell back to the liquid's)."""
        (p1, p2), (V1, V2) = self.pressures(), self.volumes()
        chamber = next(i for i in range(self.chambers) if self._phase_changes(i))
        self.vapour[chamber] = change_phase(self.double.ctx, self._names()[chamber], kind, self.params.cavitation)
        return {"eps": eps, "chamber": ("C1", "C2")[chamber] if self.chambers == 2 else "one",
                "p_c1_over_pa": p1, "p_c2_over_pa": p2, "V_c1": V1 / self.V0, "V_c2": V2 / self.V0}

    def _phase_changes(self, i: int) -> str | None:
        """Whether chamber i cavitates (liquid below p_v) or its vapour collapses (V below the
        liquid's): ``cavitation``, ``collapse`` or None."""
        if not (self.sealed and self.params.fluid == "liquid"):
            return None
        return phase_change(self.vapour[i], self.pressures()[i], self.volumes()[i], self.amounts[i],
                            self.params.cavitation)

    def _change(self) -> str | None:
        """The change of the chambers in this state: the sidewall touches the protuberance
        (split), left it (merge, separable contact only), a liquid cavitates or its vapour
        collapses; None if they stay as they are."""
        touching = self.double.sidewall_contact() is not None
        if self.chambers == 1 and touching:
            return "split"
        if self.chambers == 2 and not touching and self.params.contact == "separable":
            return "merge"
        return next((kind for kind in map(self._phase_changes, range(self.chambers)) if kind), None)

    # -- observables ----------------------------------------------------------------------
    def observe(self, stage: str, eps: float) -> dict:
        (p1, p2), (V1, V2) = self.pressures(), self.volumes()
        A = self.double.wetted_area() / self.A0
        row = {"stage": stage, "eps": eps, "chambers": self.chambers, "vapour": sum(self.vapour),
               "p_c1_over_pa": p1, "p_c2_over_pa": p2,
               "V_c1": V1 / self.V0, "V_c2": V2 / self.V0, "A_c1_over_A0": A, "F_tilde": (1 - p1) * A,
               "sidewall_gap": self.double.sidewall_gap(), "fluid_law_residual": None,
               "lateral_strain": self.double.lateral_strain()}
        if self.sealed:  # each fluid's law: p V = n (air) or V = n (liquid); vapour: p = p_v
            laws = [0.0 if vapour else (p if self.params.fluid == "air" else 1.0) * V / n - 1
                    for p, V, n, vapour in zip((p1, p2), (V1, V2), self.amounts, self.vapour)]
            row["fluid_law_residual"] = max(abs(r) for r in laws)
        return row

    def _shape(self, label: str, eps: float) -> None:
        """Keep the walls' current nodes for the deformed-shape figure."""
        contact = self.double.wall_contact
        self.shapes.append({"label": label, "eps": eps, "x": contact._positions().copy(),
                            "segments": contact.segments})

    # -- the plan -------------------------------------------------------------------------
    @property
    def problem_options(self) -> dict:
        return dict(petsc_options={"snes_type": "vinewtonrsls"}, energy_scale=self.double.energy_scale,
                    line_search_fallbacks=LINE_SEARCH_FALLBACKS)

    def setup(self, run) -> None:
        model = self.model = self.model_class(self.params.model_inputs(), self.comm)
        run.watch([model.u])
        self.V0 = global_sum(model.volume)
        self.A0 = math.pi * model.geometry.r0**2
        self.chambers, self.sealed, self.vapour = 1, False, [False]
        self.events, self.topology = [], []
        run.results.update(instabilities=self.events, split=None, merge=None)

    def plan(self) -> list[Stage]:
        """On the plate at ambient pressure (the walls' surface energy deforms them a little),
        sealed there or vented while loading; then loaded, sealed if still vented, unloaded."""
        stages = [self.leg("load", 0.0, 0.0, settle=True), *self._loading()]
        if self.unloads:
            stages.append(self.leg("unload", self.params.preload, 0.0, enter=self._unloading))
        return stages

    def leg(self, stage: str, start: float, end: float, settle: bool = False, enter=None) -> Stage:
        """A leg of ``stage`` from ``start`` to ``end`` with the chambers as they are (``enter``:
        what happens first); at a topology change a bisection locates it, and the leg is
        entered again from there with the new terms. ``settle``: solve and record the state at
        ``start`` first."""
        def begin(run) -> None:
            if enter is not None:
                enter(run)
            self._leg_at = {"start": start, "end": end, "fresh": settle}

        return Stage(stage, enter=begin, terms=self._terms, prepare=self.double.contact_bounds,
                     drive=lambda problem, run: self._leg(problem, run, stage),
                     until=Reaches("eps", end, falling=end < start))

    def _loading(self) -> list[Stage]:
        """The loading legs (sealed first with ``--seal rest``)."""
        seal = self._seal if self.params.seal == "rest" else None
        return [self.leg("load", 0.0, self.params.preload, enter=seal)]

    def _loaded(self, run) -> None:
        """What happens at the preload, before anything else."""

    def _unloading(self, run) -> None:
        self._loaded(run)
        self._shape("preload", self.params.preload)
        if not self.sealed:
            self._seal(run)

    def _terms(self) -> list:
        return self.double.terms(*self._fluids(), *self._more_terms())

    def finish(self, run) -> None:
        if not self.unloads:
            self._loaded(run)
            self._shape("preload", self.params.preload)
            return
        self._shape("unloaded", 0.0)
        self._finish(run)

    # -- hooks of a cycle with more terms (:mod:`bcfem.scenes.crater_double.membrane`) ------
    def _more_terms(self) -> list:
        """Terms besides the model's and the chambers' fluids."""
        return []

    def _set_platen(self, eps: float) -> None:
        self.double.set_platen(eps)

    def _bond(self, eps: float) -> dict:
        """Bond the walls where they touch (a cycle whose chambers bond)."""
        raise NotImplementedError(f"{type(self).__name__} does not bond its walls")

    def _accepted(self, eps: float) -> None:
        """Called at every accepted state, after its row."""

    def _leg(self, problem, run, stage: str) -> Ended:
        """One problem's part of a leg: to its end, or to a change of the chambers, located by
        bisection (then the leg goes on from there with a new problem: ``again``)."""
        params, model = self.params, self.double
        start, end, fresh = self._leg_at["start"], self._leg_at["end"], self._leg_at["fresh"]
        path = LoadPath(problem, self._set_platen, stage, model.viscosity,
                        params.beta / model.geometry.r0**2, events=self.events,
                        max_snaps=params.max_snaps, load_name="eps",
                        waves=model.wave_check(problem, problem.terms))
        if fresh:
            if not path.solve_at(start, fallbacks=True):
                raise SteppingError(f"{stage}: no equilibrium at eps = {start:.6g} "
                                    f"({'chambers merged' if self.topology else 'at rest'}): "
                                    f"{problem.failure}", start)
            run.record(self.observe(stage, start))
            self._accepted(start)
        path.start()
        if not self.shapes:  # the walls are known to the self-contact once bound
            self._shape("rest", start)
        before = path.mark(start)

        def accept(eps):
            if self._change():
                return True
            run.record(self.observe(stage, eps))
            self._accepted(eps)
            before.update(path.mark(eps))
            return False

        reached = path.through(start, end, params.strain_step, accept)
        if not self._change():
            return Ended(f"eps = {reached:.6g}")
        eps = path.bisect(before, reached, lambda _: self._change() is not None, BISECTIONS)
        low, high = path.bracket or (eps, eps)
        bracket = abs(high - low)
        kind = self._change()
        if kind == "split":
            event = self._split(eps)
        elif kind == "merge":
            event = self._merge(eps)
        elif kind == "bond":
            event = self._bond(eps)
        else:
            assert kind is not None, "a change was located"
            event = self._phase_change(eps, kind)
        event = {"stage": stage, "kind": kind, "bracket": bracket, **event}
        if kind in ("split", "merge"):
            run.results[kind] = run.results[kind] or event
        # a split leaves the state as it is; a merge pools the fluids and a phase change
        # swaps a chamber's law, so the state is solved again
        fresh = kind not in ("split", "bond")
        self.topology.append(event)
        progress(f"{stage}: {event['kind']} at eps = {eps:.6g}")
        self._shape(event["kind"], eps)
        if not fresh:
            run.record(self.observe(stage, eps))
            self._accepted(eps)
        self._leg_at = {"start": eps, "end": end, "fresh": fresh}
        return Ended(f"{kind} at eps = {eps:.6g}", again=True)

    def _finish(self, run) -> None:
        final = run.rows[-1]
        split = run.results["split"]
        run.results.update({
            "eps_contact": split["eps"] if split else None,
            "p_c1_over_pa": final["p_c1_over_pa"], "p_c2_over_pa": final["p_c2_over_pa"],
            "V_c1": final["V_c1"], "V_c2": final["V_c2"], "F_tilde": final["F_tilde"],
            "least_sidewall_gap": min((r["sidewall_gap"] for r in run.rows if r["sidewall_gap"] is not None),
                                      default=None),
            "F_tilde_per_chamber": {"C1": final["F_tilde"], "C2": 0.0 if final["chambers"] == 2 else None},
            "chamber_events": self.topology,
            "cavitation": next((e for e in self.topology if e["kind"] == "cavitation"), None),
            "stability": classify(self.events),
            "symmetry_breaking": symmetry_breaking(self.events) if self.params.waves else None,
            "fluid_law_residual": max((r["fluid_law_residual"] for r in run.rows
                                       if r["fluid_law_residual"] is not None), default=None),
            "V0": self.V0})

    def figures(self, rows, summary) -> dict:
        from bcfem.scenes.crater_double.report import plot_cycle, plot_shapes

        return {"cycle.png": plot_cycle(rows, summary), "shapes.png": plot_shapes(self.shapes)}
