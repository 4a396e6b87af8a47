"""``python -m bcfem.geometry crater --alpha 0.7 -o crater.msh``: write a mesh and a PNG preview."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import bcfem  # noqa: F401  (MPI before dolfinx)
from mpi4py import MPI

from bcfem.geometry.crater import CraterGeometry, create_mesh


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bcfem.geometry")
    sub = parser.add_subparsers(dest="shape", required=True)
    crater = sub.add_parser("crater", help="cylindrical specimen with a spherical-cap crater (mm)")
    for f in dataclasses.fields(CraterGeometry):
        crater.add_argument("--" + f.name.replace("_", "-"), type=type(f.default), default=f.default)
    crater.add_argument("-o", "--output", type=Path, required=True, help="the .msh file; a .png preview beside it")
    args = parser.parse_args(argv)
    values = {f.name: getattr(args, f.name) for f in dataclasses.fields(CraterGeometry)}
    try:
        geometry = CraterGeometry(**values)
    except ValueError as err:
        parser.exit(2, f"python -m bcfem.geometry crater: error: {err}\n")
    comm = MPI.COMM_WORLD
    args.output.parent.mkdir(parents=True, exist_ok=True)
    data = create_mesh(geometry, comm, msh_file=args.output if comm.rank == 0 else None)
    preview(data, args.output.with_suffix(".png"), comm)
    if comm.rank == 0:
        print(f"wrote {args.output} and {args.output.with_suffix('.png')} "
              f"({data.mesh.topology.index_map(2).size_global} cells)")
    return 0


def preview(data, path, comm) -> None:
    """The mesh (vertices only) coloured by region, on rank 0."""
    import numpy as np

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
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(4, 8))
    for triangles, region in gathered:
        for tri, tag in zip(triangles, region):
            ax.fill(tri[:, 0], tri[:, 1], facecolor="#f4c27a" if tag == 2 else "#cfe0f3",
                    edgecolor="k", linewidth=0.15)
    ax.set_aspect("equal")
    ax.set_xlabel("r [mm]")
    ax.set_ylabel("z [mm]")
    io.save_figure(fig, path, comm)


if __name__ == "__main__":
    sys.exit(main())
