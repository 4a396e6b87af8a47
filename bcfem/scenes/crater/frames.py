"""Deformed shapes of a crater cycle: a ``Crater`` that records every state it observes,
and a function that draws one state (dissertation Figs. 7.5b, 7.10, 7.12).

``record(params)`` solves one cycle on this rank alone (``MPI.COMM_SELF``); the cycle
is the scene's own (:func:`bcfem.scenes.crater.solve` with ``model_class=Recorder``).
It returns plain arrays (:class:`Frames`), so that ranks can record cycles side by side
and send them to the rank that draws.
"""

from __future__ import annotations

from dataclasses import dataclass

from mpi4py import MPI

import numpy as np

from bcfem.geometry.crater import LAYER
from bcfem.run.runner import solve_rows
from bcfem.run.study import Study
from bcfem.scenes import crater
from bcfem.scenes.crater.model import Crater


class Recorder(Crater):
    """``Crater`` that keeps, at every observed state, its row, the displacement
    interpolated on P1 (to deform the vertex mesh) and the crater wall's current nodes."""

    def __init__(self, params, comm):
        from dolfinx import fem

        super().__init__(params, comm)
        V1 = fem.functionspace(self.mesh, ("Lagrange", 1, (2,)))
        self.u1 = fem.Function(V1)
        self.vertices = V1.tabulate_dof_coordinates()[:, :2]
        cells = V1.dofmap.list
        in_layer = np.isin(np.arange(len(cells)), self.cell_tags.find(LAYER))
        if cells.shape[1] == 4:  # quadrilaterals (vertices in tensor order 0 1 / 2 3): two triangles each
            cells = np.vstack([cells[:, [0, 1, 3]], cells[:, [0, 3, 2]]])
            in_layer = np.concatenate([in_layer, in_layer])
        self.triangles, self.in_layer = cells.copy(), in_layer
        g = self.geometry
        X = self.u.function_space.tabulate_dof_coordinates()[:, :2]
        centre = g.crater_height - g.sphere_radius
        on_wall = (np.abs(np.hypot(X[:, 0], X[:, 1] - centre) - g.sphere_radius) < 1e-6 * g.crater_radius) \
            & (X[:, 1] >= -1e-9)
        order = np.argsort(np.arctan2(X[on_wall, 1] - centre, X[on_wall, 0]))  # from the rim to the pole
        self.wall_nodes = np.flatnonzero(on_wall)[order]
        self.wall_X = X[self.wall_nodes]
        self.states: list[dict] = []

    def observe(self, stage, eps, V1=None):
        row = super().observe(stage, eps, V1)
        self.u1.interpolate(self.u)
        u = self.u.x.array.reshape(-1, 2)
        self.states.append({**{k: float(v) for k, v in row.items() if k != "stage"}, "stage": stage,
                            "u1": self.u1.x.array.reshape(-1, 2).copy(), "wall": self.wall_X + u[self.wall_nodes]})
        return row


@dataclass
class Frames:
    """What :func:`draw` needs of a recorded cycle (the mesh's vertices and triangles, the
    layer's cells, the wall at rest, the states), without the mesh: plain arrays, kept as JSON
    (:meth:`to_json`, :meth:`from_json`)."""

    vertices: np.ndarray
    triangles: np.ndarray
    in_layer: np.ndarray
    wall_X: np.ndarray
    states: list[dict]

    def to_json(self) -> dict:
        def plain(value):
            return value.tolist() if isinstance(value, np.ndarray) else value

        return {"vertices": self.vertices.tolist(), "triangles": self.triangles.tolist(),
                "in_layer": self.in_layer.tolist(), "wall_X": self.wall_X.tolist(),
                "states": [{k: plain(v) for k, v in s.items()} for s in self.states]}

    @classmethod
    def from_json(cls, data: dict) -> Frames:
        arrays = ("u1", "wall")
        return cls(np.array(data["vertices"]), np.array(data["triangles"], dtype=np.int32),
                   np.array(data["in_layer"], dtype=bool), np.array(data["wall_X"]),
                   [{k: np.array(v) if k in arrays else v for k, v in s.items()} for s in data["states"]])


def record(params: crater.Params, study: Study | None = None) -> tuple[dict, Frames]:
    """One cycle on this rank alone (counted by ``study``, if given); returns (summary, its
    frames)."""
    made = []

    def model(p, comm):
        made.append(Recorder(p, comm))
        return made[-1]

    scene = crater.build(params, MPI.COMM_SELF, model_class=model)
    _, summary = study.solve(scene, MPI.COMM_SELF) if study else solve_rows(scene, MPI.COMM_SELF)
    rec = made[-1]  # a retraced cycle's second model
    return summary, Frames(rec.vertices, rec.triangles, rec.in_layer, rec.wall_X, rec.states)


def record_point(params: crater.Params, comm, study: Study | None = None) -> dict:
    """One recorded cycle as a point of :func:`bcfem.run.sweep.run` (``comm``: the point's own
    one-rank communicator; counted by ``study``, if given): its summary and its frames."""
    summary, frames = record(params, study)
    return {"summary": summary, "frames": frames.to_json()}


def nearest(states: list[dict], stage: str, eps: float) -> dict:
    """The recorded state of ``stage`` whose platen strain is nearest ``eps``."""
    return min((s for s in states if s["stage"] == stage), key=lambda s: abs(s["eps"] - eps))


def draw(ax, recorder: Frames, state: dict, extent: float, text: str = "") -> None:
    """The deformed specimen near the crater (grey; a layer red), the crater wall (blue),
    the wall at rest (dotted) and the plate (black), in a square of side ``extent`` [mm]."""
    import matplotlib.tri as mtri
    from matplotlib.colors import ListedColormap

    xy = recorder.vertices + state["u1"]
    for cells, colour in ((~recorder.in_layer, "0.93"), (recorder.in_layer, "tab:red")):
        if cells.any():
            part = mtri.Triangulation(xy[:, 0], xy[:, 1], recorder.triangles[cells])
            ax.tripcolor(part, facecolors=np.zeros(cells.sum()), cmap=ListedColormap([colour]))
            ax.triplot(part, color="0.55", lw=0.25)
    ax.plot(recorder.wall_X[:, 0], recorder.wall_X[:, 1], ":", color="0.2", lw=0.9)
    ax.plot(state["wall"][:, 0], state["wall"][:, 1], "-", color="C0", lw=1.8)
    ax.axhline(0, color="k", lw=1.5)
    ax.set_xlim(0, extent)
    ax.set_ylim(-0.05 * extent, extent)
    ax.set_aspect("equal")
    if text:
        ax.text(0.97, 0.97, text, transform=ax.transAxes, ha="right", va="top", fontsize=7.5,
                bbox=dict(fc="white", ec="none", alpha=0.9, pad=1.5))
