r"""The cell's suction cycle as two declared stages, as the crater scene's.

``load`` (vents open): the platen compresses the cell to the preload through fixed
checkpoints, the lateral strains free. ``unload`` (each crater sealed at p_a with its volume
V1 there): the platen retracts to zero force, located by Brent's method, and on to eps = 0.
F = (p_a - p) A2 per crater at zero platen force (eq. 7.3), F_tilde = F/(p_a A0).
Steps Newton cannot reach are passed by pseudo-time relaxation, and the tangent's inertia
is checked after every step (:class:`bcfem.path.stepping.LoadPath`).
"""

from __future__ import annotations

from bcfem.log import progress
from bcfem.path.stepping import LoadPath, SteppingError
from bcfem.path.terminations import PLATEN_FORCE_ZERO, Reaches
from bcfem.run.stages import Ended, Stage, StagedScene
from bcfem.scenes.crater.params import MAX_LIFT
from bcfem.scenes.crater.report import classify
from bcfem.scenes.crater.stages import LINE_SEARCH_FALLBACKS
from bcfem.scenes.crater_cell.model import CellModel
from bcfem.scenes.crater_cell.params import COLUMNS, Params
from bcfem.solver.fieldsplit import SCHUR_GAMG, SPLIT_ABOVE


class CellCycle(StagedScene):
    """The scene ``crater-cell``: its model driven through the stages ``load`` and ``unload``
    (:meth:`plan`; :class:`bcfem.run.stages.StagedScene` runs them)."""

    params: Params
    name = "crater-cell"
    stages = ("load", "unload")
    columns = COLUMNS

    def __init__(self, params: Params, comm):
        self.params, self.comm = params, comm
        self.model: CellModel | None = None
        self.events: list[dict] = []
        self.fluids: list = []
        #: the rows at the preload and at zero platen force, and the strain there
        self.preloaded: dict = {}
        self.final: dict = {}
        self.zero = 0.0

    @property
    def cell(self) -> CellModel:
        """The model, once built."""
        if self.model is None:
            raise RuntimeError("the cell's model is built by setup()")
        return self.model

    @property
    def split(self) -> bool:
        """Whether the Newton step is the field split's (``--solver``; auto: by the dofs)."""
        params = self.params
        if params.solver != "auto":
            return params.solver == "split"
        space = self.cell.u.function_space
        return params.stability == "spectrum" or space.dofmap.index_map.size_global * 3 > SPLIT_ABOVE

    @property
    def problem_options(self) -> dict:
        return dict(petsc_options={"snes_type": "vinewtonrsls", **(SCHUR_GAMG if self.split else {})},
                    energy_scale=self.cell.energy_scale, line_search_fallbacks=LINE_SEARCH_FALLBACKS,
                    stability_count="spectrum" if self.params.stability == "spectrum" else "inertia")

    def setup(self, run) -> None:
        model = self.model = CellModel(self.params, self.comm)
        run.watch([model.u])
        cell = model.cell
        self.events = []
        run.results.update(spacing=cell.spacing, cell_extent=list(cell.extent), craters_in_cell=cell.craters)

    def solve(self, run) -> None:
        try:
            super().solve(run)
        finally:
            run.results["instabilities"] = self.events

    def plan(self) -> list[Stage]:
        model = self.cell
        return [
            Stage("load", terms=model.terms, prepare=self._prepare, drive=self._load,
                  until=Reaches("eps", self.params.preload)),
            Stage("unload", enter=self._seal, terms=lambda: model.terms(*self.fluids), prepare=self._prepare,
                  drive=self._unload, until=PLATEN_FORCE_ZERO),
        ]

    def _path(self, problem, stage: str) -> LoadPath:
        params = self.params
        return LoadPath(problem, self.cell.set_platen, stage, self.cell.viscosity,
                        params.beta / params.crater_radius**2, events=self.events, max_snaps=params.max_snaps,
                        load_name="eps", check_stability=params.stability != "none")

    def _prepare(self, problem) -> None:
        self.cell.contact_bounds(problem)
        self.cell.measure_force(problem)

    def _record(self, run, stage: str):
        return lambda eps: run.record(self.cell.observe(stage, eps))

    def _load(self, problem, run) -> Ended:
        params = self.params
        path = self._path(problem, "load")
        self._record(run, "load")(0.0)
        path.start()
        path.through(0.0, params.preload, params.strain_step, self._record(run, "load"))
        self.preloaded = run.rows[-1]
        return Ended(f"preloaded at eps = {params.preload:g}")

    def _seal(self, run) -> None:
        """Each crater sealed at p_a with its volume V1 at the preload."""
        self.fluids = self.cell.seal()

    def _unload(self, problem, run) -> Ended:
        params, model = self.params, self.cell
        path = self._path(problem, "unload")
        path.start()
        last = path.mark(params.preload)

        def accept(eps):
            if model.platen_force() >= 0:
                return True
            self._record(run, "unload")(eps)
            last.update(path.mark(eps))
            return False

        reached = path.through(params.preload, -MAX_LIFT, params.strain_step, accept)
        if model.platen_force() < 0:
            raise SteppingError(f"unload: the platen still presses at eps = {reached:.4g}", reached)
        self.zero = path.root(last, reached, model.platen_force, xtol=1e-10 * params.preload)
        self.final = model.observe("unload", self.zero)
        run.record(self.final)
        progress(f"unload: zero platen force at eps = {self.zero:.6g}, F_tilde = {self.final['F_tilde']:.6g}")
        if self.zero > 0:  # on to the specimen's original height: the platen pulls
            path.through(self.zero, 0.0, params.strain_step, self._record(run, "unload"))
        return Ended(f"zero platen force at eps = {self.zero:.6g}" + (", then on to eps = 0" if self.zero > 0 else ""))

    def finish(self, run) -> None:
        final, preloaded = self.final, self.preloaded
        run.results.update({
            "F_tilde": final["F_tilde"], "F_tilde_area": final["F_tilde_area"], "p2_over_pa": final["p_over_pa"],
            "V1_over_V0": preloaded["V_over_V0"], "V2_over_V0": final["V_over_V0"],
            "A2_over_A0": final["A_over_A0"], "eps_at_zero_force": self.zero, "preload": self.params.preload,
            "lateral_strain_at_preload": [preloaded[k] for k in ("lateral_strain_x", "lateral_strain_y")],
            "platen_force_at_preload": preloaded["platen_force"],
            # the craters of a hexagonal cell are one crater of the lattice twice: equal pressures
            "pressure_spread": max(r["pressure_spread"] for r in run.rows),
            "wall_on_plate": max(r["wall_on_plate"] for r in run.rows),
            "stability": classify(self.events) if self.params.stability != "none" else "not checked",
            "linear_solver": "split" if self.split else "direct"})

    def figures(self, rows, summary) -> dict:
        from bcfem.scenes.crater_cell.report import plot

        return {"cycle.png": plot(rows, summary)}
