"""gmsh models to distributed dolfinx meshes: the one place gmsh is run.

gmsh builds the model on rank 0 alone (one thread, no terminal output), and
dolfinx distributes it over the communicator. A failure on rank 0 is raised on
every rank, so that no rank waits for a mesh that never comes.
"""

from __future__ import annotations

from collections.abc import Callable


def distribute(build_model: Callable[[], None], comm, msh_file=None, gdim: int = 2):
    """Run ``build_model()`` (it adds entities and physical groups to the current gmsh
    model) on rank 0 and distribute the mesh over ``comm``.

    Args:
        build_model: builds and meshes the model.
        comm: the communicator of the mesh.
        msh_file: if given, rank 0 also writes the gmsh model there.
        gdim: the geometric dimension of the mesh.

    Returns:
        dolfinx.io.gmsh.MeshData: mesh, cell_tags, facet_tags, ridge_tags, ...
    """
    import gmsh
    from dolfinx.io import gmsh as gmshio

    from bcfem import interrupt
    error = None
    if comm.rank == 0:
        gmsh.initialize(interruptible=False)
        interrupt.reinstall()  # gmsh resets SIGTERM to its default: a run would end with no status
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        try:
            build_model()
            if msh_file is not None:
                gmsh.write(str(msh_file))
        except Exception as err:  # reported on every rank below
            error = f"{type(err).__name__}: {err}"
            gmsh.finalize()
    error = comm.bcast(error, root=0)
    if error is not None:
        raise RuntimeError(f"gmsh could not build the mesh: {error}")
    data = gmshio.model_to_mesh(gmsh.model if comm.rank == 0 else None, comm, 0, gdim=gdim)
    if comm.rank == 0:
        gmsh.finalize()
    return data


def graded_tetrahedra(surfaces: list[int], size_near: float, size_far: float, near: float, far: float,
                      curves: tuple[int, ...] | list[int] = (), size_curves: float | None = None) -> None:
    """Mesh the current gmsh model with quadratic tetrahedra of size ``size_near`` within ``near`` of
    the ``surfaces``, growing linearly to ``size_far`` at ``far`` from them and beyond; with
    ``curves``, of size ``size_curves`` within ``near`` of those, growing at the same rate (rank 0)."""
    import gmsh

    field = gmsh.model.mesh.field

    def threshold(kind: str, tags, size: float) -> int:
        distance = field.add("Distance")
        field.setNumbers(distance, kind, list(tags))
        graded = field.add("Threshold")
        field.setNumber(graded, "InField", distance)
        field.setNumber(graded, "SizeMin", size)
        field.setNumber(graded, "SizeMax", size_far)
        field.setNumber(graded, "DistMin", near)
        # the same growth per length as the surfaces' field
        field.setNumber(graded, "DistMax", near + (far - near) * (size_far - size) / (size_far - size_near)
                        if size_far > size_near else far)
        return graded

    fields = [threshold("SurfacesList", surfaces, size_near)]
    if curves:
        fields.append(threshold("CurvesList", curves, size_near if size_curves is None else size_curves))
    smallest = field.add("Min")
    field.setNumbers(smallest, "FieldsList", fields)
    field.setAsBackgroundMesh(smallest)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
