"""The picture of a three-dimensional blister: the deformed membrane, coloured by its major
principal tension (or another of :data:`MEASURES`), rendered off screen by pyvista (VTK's EGL
window; no display needed) and framed in a matplotlib figure like every other PNG of a run."""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from bcfem.path.terminations import Described
from bcfem.run.scene import BranchScene
from bcfem.run.stages import Ended, Stage

if TYPE_CHECKING:
    from bcfem.scenes.blister_3d.release import ReleaseRate
    from bcfem.scenes.blister_3d.stability import VolumeStability


def gather_surface(u, fields, comm):
    """The membrane's cells, current points and the columns of ``fields`` (the 'measures'
    lambda_1, lambda_2, N2 and the 'tensions' N1, N2, N_eq: :data:`MEASURES`) of every rank, on
    rank 0 (None elsewhere); collective."""
    from dolfinx import plot

    topology, cell_types, points = plot.vtk_mesh(u.function_space)
    bs = u.function_space.dofmap.index_map_bs
    n = len(points)
    local = (topology, cell_types, points + u.x.array.reshape(-1, bs)[:n],
             np.hstack([f.x.array.reshape(-1, bs)[:n] for f in fields]))
    parts = comm.gather(local, root=0)
    return parts if comm.rank == 0 else None


#: what :func:`membrane_figure` can colour by: the columns of the 'measures' and 'tensions' fields
MEASURES = {"major stretch": 0, "minor stretch": 1, "taut minor tension (< 0: wrinkled)": 2,
            "major tension N1 / (mu t0)": 3, "equivalent tension / (mu t0)": 5}


def membrane_figure(parts, title: str, colour: str = "major tension N1 / (mu t0)"):
    """A matplotlib figure of the gathered surface (rank 0), coloured by one of :data:`MEASURES`."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import matplotlib.pyplot as plt
    import pyvista

    grids = []
    for topology, cell_types, points, values in parts:
        grid = pyvista.UnstructuredGrid(topology, cell_types, points)
        grid.point_data[colour] = values[:, MEASURES[colour]]
        grids.append(grid)
    surface = grids[0].merge(grids[1:]) if len(grids) > 1 else grids[0]
    plotter = pyvista.Plotter(off_screen=True, window_size=[1000, 700])
    plotter.add_mesh(surface, scalars=colour, cmap="viridis", show_edges=False, scalar_bar_args={"title": colour})
    plotter.view_isometric()
    plotter.set_background("white")
    image = plotter.screenshot(return_img=True)
    plotter.close()
    fig, ax = plt.subplots(figsize=(7, 5))
    ax.imshow(image)
    ax.set_axis_off()
    ax.set_title(title)
    return fig


def release_figure(points, G, cost, title: str):
    """The release rate along the outline over the cost of debonding there (an array, or a
    number), against the polar angle, with the outline drawn in the plane (rank 0)."""
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    angle = np.degrees(np.arctan2(points[:, 1], points[:, 0]))
    left.plot(angle, G / cost, ".-", ms=3)
    left.axhline(1.0, color="k", lw=0.8, ls="--")
    left.set(xlabel="polar angle of the outline's node [deg]", ylabel="G / (w + α)", title=title)
    picture = right.scatter(points[:, 0], points[:, 1], c=G / cost, s=8, cmap="viridis")
    top = int(np.argmax(G))
    right.plot(points[top, 0], points[top, 1], "r*", ms=12, label="largest G")
    right.set(aspect="equal", xlabel="X / R0", ylabel="Y / R0")
    right.legend(loc="lower right", fontsize=8)
    fig.colorbar(picture, ax=right, label="G / (w + α)")
    fig.tight_layout()
    return fig


def fronts_figure(fronts, title: str):
    """The debond front's outline at each volume of its growth, in the reference plane (rank 0)."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 5))
    colours = plt.cm.viridis(np.linspace(0, 1, len(fronts)))
    for (volume, points), colour in zip(fronts, colours, strict=True):
        closed = np.vstack([points, points[:1]])
        ax.plot(closed[:, 0], closed[:, 1], color=colour, lw=1.2, label=f"V/V0 = {volume:.3g}")
    ax.set(aspect="equal", xlabel="X / R0", ylabel="Y / R0", title=title)
    ax.legend(fontsize=7, loc="center")
    fig.tight_layout()
    return fig


@dataclass
class MembraneScene(BranchScene):
    """An arc-length scene that also draws its last state (``membrane.png``) and, with an
    adhesive edge, the release rate along the outline there (``release.png``) and the front at
    each step of its growth (``front.png``)."""

    release: ReleaseRate | None = None
    #: the drive of the stage ``front`` (the front's growth after the onset), or None
    after: Callable[[Any, Any], Ended] | None = None
    fronts: list = field(default_factory=list)  # (V/V0, the outline's points) at the onset and each growth step

    v0: float = 4.0 * math.pi / 3.0  # the volume of the normalisation V/V0
    follow: bool = False  # trace the branch off the first located bifurcation too (broken.csv)

    stages = ("branch", "stability", "broken", "front")  # type: ignore[assignment]  # BranchScene infers tuple[str]

    def __post_init__(self):
        #: what the figures and tables draw, kept by the solve: the broken branch's rows, the last
        #: state's surface, the front's release rates on the outline
        self._broken: list[dict] | None = None
        self._surface: tuple | None = None
        self._outline: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self.stability: VolumeStability | None = None

    def plan(self) -> list[Stage]:
        """``branch`` with its unstable modes counted (their problem: ``stability``), then
        ``broken``, the branch off its first bifurcation (``--follow broken``), and ``front``,
        the front's growth after the onset (an adhesive edge with front steps)."""
        branch = replace(super().plan()[0], drive=self._trace_counted)
        broken = Stage("broken", terms=lambda: self.terms, enter=self._broken_from, drive=self._follow,
                       until=branch.until, options=lambda: dict(petsc_options=self.petsc_options,
                                                                rows=self._broken_arc.rows(),
                                                                energy_scale=self.energy_scale))
        stages = [branch, broken]
        if self.after is not None:
            stages.append(Stage("front", terms=lambda: self.terms, enter=self._onset, drive=self.after,
                                until=Described("the front in equilibrium at each of --front-steps volumes up to "
                                                "--v-max"), options=dict))
        return stages

    def solve(self, run) -> None:
        try:
            super().solve(run)
        finally:  # the converged part is drawn too
            self._surface = gather_surface(self.fields[0], (self.fields[1], self.fields[3]), self.ctx.mesh.comm)
            self._outline = self.release.gather() if self.release else None

    def _trace_counted(self, problem, run) -> Ended:
        """The branch, with the unstable modes under volume control counted at every accepted
        point and its bifurcations located
        (:class:`bcfem.scenes.blister_3d.stability.VolumeStability`)."""
        from bcfem.path.continuation import ContinuationError
        from bcfem.run.trace import trace
        from bcfem.scenes.blister_3d.stability import VolumeStability

        stability = self.stability = VolumeStability(run.problem("stability", self.ctx, self.terms, self.bcs),
                                                     self.ctx, self.v0)
        self.kept = (stability,)

        def on_accept(values):
            stability.on_accept(values)
            run.on_accept(values)

        try:
            branch, _ = trace(self, on_accept, run, arc=self._arc, problem=problem)
        except ContinuationError as err:
            self._report(run, err.branch)
            raise
        finally:
            run.results.update(stability.summary())
        self._report(run, branch)
        return Ended(f"the end condition holds at point {len(branch.rows)}")

    def _broken_from(self, run) -> str | None:
        """Why the broken branch is not followed, or None (its arc-length made here)."""
        if not self.follow:
            return "not asked for (--follow broken follows it)"
        if self.stability is None or not self.stability.modes:
            return "no bifurcation located on the branch"
        self._broken_arc = self.arc_length()
        return None

    def _onset(self, run) -> str | None:
        """Why the front does not grow, or None."""
        return None if run.results.get("delamination_onset") and run.rows else "no delamination onset on the branch"

    def _follow(self, problem, run) -> Ended:
        """The branch off the first bifurcation, from the switch to the end (``broken.csv``;
        ``broken_branch`` in summary.json)."""
        from bcfem.path.continuation import ContinuationError
        from bcfem.scenes.blister_3d.stability import follow_broken

        stability = self.stability
        assert stability is not None, "entered after the branch"

        def observe():
            return {**self.observe(), **stability.offsets()}

        def on_accept(values):
            values["unstable_modes"] = stability.count()

        error = None
        try:
            broken = follow_broken(self._broken_arc, problem, stability, observe, self.end, on_accept, self.guard,
                                   progress_keys=("V_over_V0", "P", "centroid_x", "centroid_y"))
        except ContinuationError as err:
            broken, error = err.branch, str(err)
        self._broken = broken.rows
        last = broken.rows[-1] if broken.rows else {}
        run.results["broken_branch"] = {
            "from_V_over_V0": stability.bifurcations[0]["V_over_V0"], "points": len(broken.rows),
            "error": error, "limit_points": [{**lp.values, "kind": lp.kind} for lp in broken.limit_points],
            **{key: last[key] for key in ("V_over_V0", "P", "centroid_x", "centroid_y", "unstable_modes")
               if key in last}}
        return Ended(error or f"the end condition holds at point {len(broken.rows)}")

    def tables(self, rows, summary) -> dict[str, list[dict]]:
        return {"broken.csv": self._broken} if self._broken else {}

    def figures(self, rows, summary) -> dict:
        figures = super().figures(rows, summary)
        if self._surface:  # the last state solved: the broken branch's, if followed
            broken = self._broken
            last, which = (broken[-1], " (broken branch)") if broken else (rows[-1], "")
            figures["membrane.png"] = membrane_figure(
                self._surface, f"{self.name}{which}: V/V0 = {last['V_over_V0']:.3g}, P = {last['P']:.4g}")
        if self._outline:
            last = rows[-1]
            points, G, cost = self._outline
            figures["release.png"] = release_figure(
                points, G, cost, f"V/V0 = {last['V_over_V0']:.4g}, P = {last['P']:.4g}")
        if len(self.fronts) > 1:
            figures["front.png"] = fronts_figure(self.fronts, f"{self.name}: the debond front as it grows")
        return figures
