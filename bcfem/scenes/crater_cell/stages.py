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
from bcfem.scenes.crater.report import classify
from bcfem.scenes.crater.stages import LINE_SEARCH_FALLBACKS
from bcfem.scenes.crater_cell.model import CellModel
from bcfem.scenes.crater_cell.params import COLUMNS, Params

#: how far beyond its original height the platen may lift looking for zero force
MAX_LIFT = 0.1


class CellCycle:
    """The scene ``crater-cell`` (:mod:`bcfem.run.runner` solves it)."""

    name = "crater-cell"
    stages = ("load", "unload")
    columns = COLUMNS

    def __init__(self, params: Params, comm):
        self.params, self.comm = params, comm
        self.model: CellModel | None = None

    def _path(self, problem, stage: str, events: list) -> LoadPath:
        params = self.params
        return LoadPath(problem, self.model.set_platen, stage, self.model.viscosity,
                        params.beta / params.crater_radius**2, events=events, max_snaps=params.max_snaps,
                        load_name="eps")

    def solve(self, run) -> None:
        params = self.params
        model = self.model = CellModel(params, self.comm)
        run.watch([model.u])
        events: list[dict] = []
        cell = model.cell
        run.results.update(instabilities=events, spacing=cell.spacing, cell_extent=list(cell.extent),
                           craters_in_cell=cell.craters)
        kwargs = dict(petsc_options={"snes_type": "vinewtonrsls"}, energy_scale=model.energy_scale,
                      line_search_fallbacks=LINE_SEARCH_FALLBACKS)
        step = params.strain_step

        def record(stage):
            return lambda eps: run.record(model.observe(stage, eps))

        with run.stage("load", model.ctx, model.terms(), model.bcs, **kwargs) as loading:
            model.contact_bounds(loading)
            model.measure_force(loading)
            path = self._path(loading, "load", events)
            record("load")(0.0)
            path.start()
            path.through(0.0, params.preload, step, record("load"))
        preloaded = run.rows[-1]
        V1 = preloaded["V_over_V0"]
        fluids = model.seal()
        with run.stage("unload", model.ctx, model.terms(*fluids), model.bcs, **kwargs) as unloading:
            model.contact_bounds(unloading)
            model.measure_force(unloading)
            path = self._path(unloading, "unload", events)
            path.start()
            last = path.mark(params.preload)

            def accept(eps):
                if model.platen_force() >= 0:
                    return True
                record("unload")(eps)
                last.update(path.mark(eps))
                return False

            reached = path.through(params.preload, -MAX_LIFT, step, accept)
            if model.platen_force() < 0:
                raise SteppingError(f"unload: the platen still presses at eps = {reached:.4g}", reached)
            zero = path.root(last, reached, model.platen_force, xtol=1e-10 * params.preload)
            final = model.observe("unload", zero)
            run.record(final)
            progress(f"unload: zero platen force at eps = {zero:.6g}, F_tilde = {final['F_tilde']:.6g}")
            if zero > 0:  # on to the specimen's original height: the platen pulls
                path.through(zero, 0.0, step, record("unload"))
        run.results.update({
            "F_tilde": final["F_tilde"], "F_tilde_area": final["F_tilde_area"], "p2_over_pa": final["p_over_pa"],
            "V1_over_V0": V1, "V2_over_V0": final["V_over_V0"], "A2_over_A0": final["A_over_A0"],
            "eps_at_zero_force": zero, "preload": params.preload,
            "lateral_strain_at_preload": [preloaded[k] for k in ("lateral_strain_x", "lateral_strain_y")],
            "platen_force_at_preload": preloaded["platen_force"],
            # the craters of a hexagonal cell are one crater of the lattice twice: equal pressures
            "pressure_spread": max(r["pressure_spread"] for r in run.rows),
            "wall_on_plate": max(r["wall_on_plate"] for r in run.rows),
            "stability": classify(events)})

    def figures(self, rows, summary) -> dict:
        from bcfem.scenes.crater_cell.report import plot

        return {"cycle.png": plot(rows, summary)}
