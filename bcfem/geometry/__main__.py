"""``python -m bcfem.geometry SHAPE [--field value ...] -o mesh.msh``: write a mesh and a PNG preview."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mpi4py import MPI

import bcfem  # noqa: F401  (MPI before dolfinx)
from bcfem.geometry import crater, double_crater, substrate


@dataclasses.dataclass(frozen=True)
class Shape:
    """A geometry the command line can build: its dataclass, mesher and preview."""

    geometry: type
    create_mesh: Callable[..., Any]
    help: str
    labels: tuple[str, str]
    zooms: Callable[[Any], list] | None = None  # geometry -> close-ups, each (r_min, r_max, z_min, z_max)


SHAPES = {
    "crater": Shape(crater.CraterGeometry, crater.create_mesh,
                    "cylindrical specimen with a spherical-cap crater (mm)", ("r [mm]", "z [mm]")),
    "double-crater": Shape(double_crater.DoubleCraterGeometry, double_crater.create_mesh,
                           "cylindrical crater with a spherical protuberance from its roof (mm)",
                           ("r [mm]", "z [mm]"), zooms=lambda g: [gap_window(g), crater_window(g)]),
    "substrate": Shape(substrate.SubstrateGeometry, substrate.create_mesh,
                       "soft substrate graded towards the contact line (units of R0)", ("R", "Z"),
                       zooms=lambda g: [contact_window(g, g.contact_radius),
                                        contact_window(g, 50 * g.element_size(0.0))]),
}


def gap_window(geometry):
    """A close-up of the gap between the sidewall and the protuberance, at their closest."""
    g, half = geometry, 0.15 * geometry.crater_height
    middle = 0.5 * (g.r0 + g.protuberance_radius_at(g.contact_height))
    return (middle - half, middle + half, g.contact_height - half, g.contact_height + half)


def crater_window(geometry):
    """The crater, its protuberance and the rims."""
    g = geometry
    return (0.0, 1.25 * g.r0, 0.0, 1.25 * g.crater_height)


def contact_window(geometry, half_width):
    """A close-up of the substrate under its contact point (R0, 0)."""
    r0, depth = geometry.contact_radius, min(half_width, geometry.height)
    return (r0 - half_width, r0 + half_width, -depth, 0.05 * depth)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bcfem.geometry")
    sub = parser.add_subparsers(dest="shape", required=True)
    for name, shape in SHAPES.items():
        command = sub.add_parser(name, help=shape.help)
        for f in dataclasses.fields(shape.geometry):
            # a None default (derived from other fields) takes a float
            kind = float if f.default is None else type(f.default)
            command.add_argument("--" + f.name.replace("_", "-"), type=kind, default=f.default)
        command.add_argument("-o", "--output", type=Path, required=True,
                             help="the .msh file; a .png preview beside it")
    args = parser.parse_args(argv)
    shape = SHAPES[args.shape]
    values = {f.name: getattr(args, f.name) for f in dataclasses.fields(shape.geometry)}
    try:
        geometry = shape.geometry(**values)
    except ValueError as err:
        parser.exit(2, f"python -m bcfem.geometry {args.shape}: error: {err}\n")
    comm = MPI.COMM_WORLD
    args.output.parent.mkdir(parents=True, exist_ok=True)
    data = shape.create_mesh(geometry, comm, msh_file=args.output if comm.rank == 0 else None)
    zooms = shape.zooms(geometry) if shape.zooms else []
    preview(data, args.output.with_suffix(".png"), comm, shape.labels, zooms)
    if comm.rank == 0:
        print(f"wrote {args.output} and {args.output.with_suffix('.png')} "
              f"({data.mesh.topology.index_map(2).size_global} cells)")
    return 0


def preview(data, path, comm, labels=("r", "z"), zooms=()) -> None:
    """The mesh (vertices only) coloured by region, on rank 0, and a panel for each close-up window."""
    import numpy as np
    from matplotlib.collections import PolyCollection

    from bcfem import io
    from bcfem.plots import pyplot

    msh = data.mesh
    cells = msh.geometry.dofmaps[0][:, :3]
    xy = msh.geometry.x[:, :2]
    tags = np.zeros(len(cells))
    tags[data.cell_tags.indices] = data.cell_tags.values
    gathered = comm.gather((xy[cells], tags), root=0)
    if comm.rank != 0:
        return
    triangles = np.concatenate([t for t, _ in gathered])
    colours = np.where(np.concatenate([r for _, r in gathered]) == 2, "#f4c27a", "#cfe0f3")
    plt = pyplot()
    shape = np.ptp(triangles[..., 1]) / np.ptp(triangles[..., 0])
    panels = 1 + len(zooms)
    fig, axes = plt.subplots(1, panels, figsize=(4 * panels, min(8.0, max(3.0, 4 * shape))), squeeze=False)
    for ax, window in zip(axes[0], [None, *zooms]):
        # a thin layer at true scale would be a line: stretch it and leave its
        # edges, a smear at that scale, to the close-ups (which stay true)
        true_scale = bool(window) or 0.2 < shape < 5
        ax.add_collection(PolyCollection(list(triangles), facecolors=colours, edgecolors="k",
                                         linewidths=0.15 if true_scale else 0))
        ax.autoscale_view()
        if window:
            ax.set_xlim(*window[:2])
            ax.set_ylim(*window[2:])
        ax.set_aspect("equal" if true_scale else "auto")
        ax.set_title(f"{len(triangles)} cells" if window is None else "close-up", fontsize=9)
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
    fig.tight_layout()
    io.save_figure(fig, path, comm)


if __name__ == "__main__":
    sys.exit(main())
