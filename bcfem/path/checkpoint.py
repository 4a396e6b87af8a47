"""Checkpoints of a path, readable on any number of ranks: PETSc's binary format for the fields,
JSON for the rest.

A field is written cell by cell in the mesh's input order (dolfinx's
``topology.original_cell_index``: gmsh's order, the same on every number of ranks): the values of
each cell's dofs, one PETSc ``Vec`` of (cells x dofs per cell x block size) entries, which
``VecLoad`` reads back on any layout and a ``VecScatter`` hands to the ranks that hold the cells
now. The mesh's nodes are written the same way, so a checkpoint read on another mesh is refused
rather than misread. A state on the real element (a pressure, a load) is one number, kept in the
JSON exactly (``repr``). States on a boundary submesh are not supported (:class:`Unsupported`).

On disk, in ``<out>/checkpoint/``: each path that was checkpointed has ``<key>.json`` (its record,
rows and numbers) pointing to ``<key>-<seq>/fields.dat``. A checkpoint's fields are written
first, then its JSON replaces the last one atomically, then the fields it replaced are removed:
a run killed at any moment leaves the last complete checkpoint readable. ``latest.json`` names
the last key written, whose rows are the run's.
"""

from __future__ import annotations

import json
import shutil
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from bcfem import io
from bcfem.log import logger

FIELDS = "fields.dat"


class Unsupported(RuntimeError):
    """A state this module cannot write (on a boundary submesh)."""


class ResumeError(RuntimeError):
    """A checkpoint that does not fit this run (another mesh, parameters or code)."""


def _is_real(f) -> bool:
    return bool(f.function_space.ufl_element().is_real)


def _cells(mesh) -> tuple[np.ndarray, int]:
    """(the input index of every local cell, owned first; the number owned)."""
    tdim = mesh.topology.dim
    imap = mesh.topology.index_map(tdim)
    return np.asarray(mesh.topology.original_cell_index, dtype=np.int64), imap.size_local


def _positions(original: np.ndarray, width: int) -> np.ndarray:
    return (original[:, None] * width + np.arange(width)[None, :]).ravel().astype(PETSc.IntType)


def _per_cell(f, array: np.ndarray) -> np.ndarray:
    """``array`` (a local array of ``f``'s space) as (cells, dofs x block)."""
    space = f.function_space
    bs = space.dofmap.bs
    return array.reshape(-1, bs)[space.dofmap.list].reshape(space.dofmap.list.shape[0], -1)


def _geometry(mesh) -> np.ndarray:
    return mesh.geometry.x[mesh.geometry.dofmaps[0]].reshape(mesh.geometry.dofmaps[0].shape[0], -1)


def _write_cells(viewer, comm, original: np.ndarray, owned: int, values: np.ndarray, cells: int) -> None:
    """One Vec of (cells x width) in input order from this rank's owned cells' ``values``."""
    width = values.shape[1]
    natural = PETSc.Vec().createMPI(cells * width, comm=comm)
    local = PETSc.Vec().createWithArray(np.ascontiguousarray(values[:owned].ravel()), comm=PETSc.COMM_SELF)
    index = PETSc.IS().createGeneral(_positions(original[:owned], width), comm=PETSc.COMM_SELF)
    scatter = PETSc.Scatter().create(local, None, natural, index)
    scatter.scatter(local, natural, PETSc.InsertMode.INSERT_VALUES, PETSc.ScatterMode.FORWARD)
    natural.view(viewer)
    for obj in (scatter, index, local, natural):
        obj.destroy()


def _read_cells(viewer, comm, original: np.ndarray, width: int) -> np.ndarray:
    """The next Vec of ``viewer`` at this rank's cells (owned and ghost): (cells, width)."""
    natural = PETSc.Vec().create(comm=comm)
    natural.load(viewer)
    if natural.getSize() % width or natural.getSize() // width <= int(original.max(initial=-1)):
        size = natural.getSize()
        natural.destroy()
        raise ResumeError(f"a checkpoint field of {size} values does not fit cells of {width}")
    local = PETSc.Vec().createSeq(len(original) * width, comm=PETSc.COMM_SELF)
    index = PETSc.IS().createGeneral(_positions(original, width), comm=PETSc.COMM_SELF)
    scatter = PETSc.Scatter().create(natural, index, local, None)
    scatter.scatter(natural, local, PETSc.InsertMode.INSERT_VALUES, PETSc.ScatterMode.FORWARD)
    values = local.getArray().copy().reshape(len(original), width)
    for obj in (scatter, index, local, natural):
        obj.destroy()
    return values


def check_supported(functions) -> None:
    """Raise :class:`Unsupported` for a state this module cannot write."""
    mesh = functions[0].function_space.mesh
    for f in functions:
        if f.function_space.mesh is not mesh and not _is_real(f):
            raise Unsupported(f"the state {f.name!r} lives on a boundary submesh: checkpoints hold the body's "
                              "fields and real states only")


def size_of(functions, vectors: int) -> int:
    """About the bytes of :func:`write_fields` with ``vectors`` vectors (collective)."""
    mesh = functions[0].function_space.mesh
    cells = mesh.topology.index_map(mesh.topology.dim).size_global
    widths = sum(f.function_space.dofmap.list.shape[1] * f.function_space.dofmap.bs
                 for f in functions if not _is_real(f))
    return 8 * cells * (mesh.geometry.dofmaps[0].shape[1] * 3 + vectors * widths)


def write_fields(path: Path, functions, vectors: list[list[np.ndarray]], comm) -> list[list[float]]:
    """Write the mesh's nodes and each of ``vectors`` (local arrays in the spaces of
    ``functions``: the states, a tangent) into ``path`` (collective); returns the real states'
    values of each vector (kept in the JSON)."""
    check_supported(functions)
    mesh = functions[0].function_space.mesh
    original, owned = _cells(mesh)
    cells = mesh.topology.index_map(mesh.topology.dim).size_global
    reals: list[list[float]] = []
    if comm.rank == 0:
        path.parent.mkdir(parents=True, exist_ok=True)
    comm.barrier()
    viewer = PETSc.Viewer().createBinary(str(path), mode=PETSc.Viewer.Mode.WRITE, comm=comm)
    try:
        _write_cells(viewer, comm, original, owned, _geometry(mesh), cells)
        for vector in vectors:
            values = []
            for f, array in zip(functions, vector):
                if _is_real(f):
                    imap = f.function_space.dofmap.index_map
                    values.append(comm.allreduce(float(array[: imap.size_local].sum())))
                else:
                    _write_cells(viewer, comm, original, owned, _per_cell(f, array), cells)
            reals.append(values)
    finally:
        viewer.destroy()
    return reals


def read_fields(path: Path, functions, reals: list[list[float]], comm) -> list[list[np.ndarray]]:
    """The vectors :func:`write_fields` wrote, as local arrays of ``functions``' spaces on this
    run's mesh and ranks (collective). Raises :class:`ResumeError` if the mesh differs."""
    mesh = functions[0].function_space.mesh
    original, _ = _cells(mesh)
    viewer = PETSc.Viewer().createBinary(str(path), mode=PETSc.Viewer.Mode.READ, comm=comm)
    try:
        nodes = _geometry(mesh)
        stored = _read_cells(viewer, comm, original, nodes.shape[1])
        scale = max(1.0, float(comm.allreduce(np.abs(nodes).max(initial=0.0), op=MPI.MAX)))
        mismatch = comm.allreduce(float(np.abs(stored - nodes).max(initial=0.0)), op=MPI.MAX)
        if mismatch > 1e-10 * scale:
            raise ResumeError(f"the checkpoint was written on another mesh (nodes differ by {mismatch:.3g})")
        vectors = []
        for values in reals:
            vector, real = [], iter(values)
            for f in functions:
                array = np.zeros_like(f.x.array)
                if _is_real(f):
                    array[:] = next(real)
                else:
                    space = f.function_space
                    per_cell = _read_cells(viewer, comm, original, space.dofmap.list.shape[1] * space.dofmap.bs)
                    bs = space.dofmap.bs
                    array.reshape(-1, bs)[space.dofmap.list] = per_cell.reshape(len(original), -1, bs)
                vector.append(array)
            vectors.append(vector)
    finally:
        viewer.destroy()
    return vectors


@dataclass
class Saved:
    """A checkpoint read back: its record (JSON) and its vectors (local arrays)."""

    record: dict
    vectors: list[list[np.ndarray]]


class Checkpoints:
    """A run's checkpoints in ``directory`` (collective calls; rank 0 writes the JSON).

    Args:
        directory: where they go (``<out>/checkpoint``).
        comm: the run's communicator.
        every: seconds between two checkpoints of a path (0: at every chance).
        resume: read the checkpoints there, and jump each path to its own, until the run
            passes the last one written; otherwise remove them.
        identity: what the run is (scene and parameters): a checkpoint of another is refused.
    """

    def __init__(self, directory: Path, comm, every: float, resume: bool, identity: dict):
        self.directory, self.comm, self.every = Path(directory), comm, float(every)
        self.identity = _canonical(identity)
        self._last = time.monotonic()
        self._keys: dict[str, int] = {}
        #: the key of the last checkpoint on disk when the run was resumed (None: a fresh run)
        self.latest_key: str | None = None
        if resume:
            latest = _read(self.directory / "latest.json") if comm.rank == 0 else None
            latest = comm.bcast(latest)
            if latest is not None:
                stored = _canonical(latest.get("identity") or {})
                if stored != self.identity:
                    differ = sorted(k for k in {**self.identity, **stored} if self.identity.get(k) != stored.get(k))
                    raise ResumeError(f"--resume: the checkpoint in {self.directory} is of another run "
                                      f"(it differs in {', '.join(differ)})")
                self.latest_key = latest["key"]
        elif comm.rank == 0 and self.directory.exists():
            shutil.rmtree(self.directory)
        self.resuming = self.latest_key is not None
        #: why this run writes no checkpoints (states they cannot hold), or None
        self.unsupported: str | None = None

    def passed(self) -> None:
        """The run is past its last checkpoint: no path jumps any more."""
        self.resuming = False

    def key(self, stage: str) -> str:
        """The next path's key in ``stage`` (its order among the stage's paths, on every entry):
        the same in a resumed run, which takes the same paths."""
        count = self._keys.get(stage, 0)
        self._keys[stage] = count + 1
        return f"{stage}-{count}"

    def due(self) -> bool:
        """Whether a checkpoint is due (the same on every rank); never once states were found that
        checkpoints cannot hold."""
        return self.unsupported is None and bool(self.comm.bcast(time.monotonic() - self._last >= self.every))

    def write(self, key: str, functions, vectors, record: dict) -> None:
        """Write the checkpoint ``key``: ``vectors`` in the spaces of ``functions`` and ``record``
        (JSON: the rows, the path's record). One that might not fit the free space is not begun
        (:class:`~bcfem.io.DiskFull`); a write that fails leaves the last checkpoint as it was."""
        try:
            check_supported(functions)
        except Unsupported as err:
            self.unsupported = str(err)
            logger.warning(f"warning: no checkpoints: {err}; this run cannot be resumed")
            return
        previous = _read(self.directory / f"{key}.json") if self.comm.rank == 0 else None
        previous = self.comm.bcast(previous)
        seq = (previous or {}).get("seq", -1) + 1
        folder = self.directory / f"{key}-{seq}"
        need = size_of(functions, len(vectors))
        if self.comm.rank == 0:
            self.directory.mkdir(parents=True, exist_ok=True)
        free = self.comm.bcast(shutil.disk_usage(self.directory).free if self.comm.rank == 0 else None)
        if free < 2 * need + io.VTX_MARGIN:
            raise io.DiskFull(f"no space left on the device of {self.directory} ({free // 1024} kB free; a "
                              f"checkpoint needs about {need // 1024} kB)")
        try:
            with io.space_checked(folder):
                reals = write_fields(folder / FIELDS, functions, vectors, self.comm)
        except BaseException:
            if self.comm.rank == 0:
                shutil.rmtree(folder, ignore_errors=True)
            raise
        full = {**record, "key": key, "seq": seq, "reals": reals, "identity": self.identity}

        def commit() -> None:
            if self.comm.rank != 0:
                return
            io.write_json(self.directory / f"{key}.json", full, MPI.COMM_SELF, exact=True)
            io.write_json(self.directory / "latest.json", {"key": key, "identity": self.identity}, MPI.COMM_SELF)
            if previous is not None:
                shutil.rmtree(self.directory / f"{key}-{previous['seq']}", ignore_errors=True)

        io.collectively(self.comm, commit)
        self._last = time.monotonic()

    def read(self, key: str, functions) -> Saved | None:
        """The checkpoint ``key`` of a resumed run (None if it has none)."""
        if not self.resuming:
            return None
        record = _read(self.directory / f"{key}.json") if self.comm.rank == 0 else None
        record = self.comm.bcast(record)
        if record is None:
            return None
        folder = self.directory / f"{key}-{record['seq']}"
        vectors = read_fields(folder / FIELDS, functions, record["reals"], self.comm)
        return Saved(record, vectors)

    def remove(self) -> None:
        """Remove the checkpoints (a run that finished needs none)."""
        if self.comm.rank == 0 and self.directory.exists():
            shutil.rmtree(self.directory, ignore_errors=True)


def _canonical(data: dict) -> dict:
    """``data`` as its JSON reads back (non-finite floats as text), to compare."""
    return json.loads(json.dumps(io.strict(data), default=str))


def _read(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


class StageCheckpoints:
    """The checkpoints of one stage's paths, as a path sees them (the problem's
    ``checkpoints``): the run's rows go into each one, and a resumed path hands the rows back.

    Args:
        checkpoints: the run's.
        stage: the stage's name.
        rows: the run's rows (the list itself, which a resumed path refills).
        resumed: called with the rows on disk once the run is past its last checkpoint (it writes
            again from there).
    """

    def __init__(self, checkpoints: Checkpoints, stage: str, rows: list, resumed):
        self.checkpoints, self.stage, self.rows, self.resumed = checkpoints, stage, rows, resumed

    def key(self) -> str:
        return self.checkpoints.key(self.stage)

    def due(self) -> bool:
        return self.checkpoints.due()

    def read(self, key: str, functions) -> Saved | None:
        return self.checkpoints.read(key, functions)

    def write(self, key: str, functions, vectors, record: dict) -> None:
        self.checkpoints.write(key, functions, vectors, {**record, "rows": list(self.rows)})

    def jump(self, saved: Saved) -> None:
        """The run's rows up to the checkpoint's last one, which the path records again."""
        self.rows[:] = saved.record["rows"][:-1]

    def landed(self, saved: Saved, row: dict | None = None, expected: dict | None = None,
               written: list | None = None) -> None:
        """Check what the resumed path recorded again against its checkpoint: the run's rows,
        and the path's own ``row`` against ``expected``. Once past the run's last checkpoint the
        rows on disk are ``written`` (default: the run's rows) and the run writes again."""
        stored = saved.record["rows"]
        if len(self.rows) != len(stored):
            raise ResumeError(f"the resumed path recorded {len(self.rows)} rows where its checkpoint has {len(stored)}")
        for mine, theirs in ([(self.rows[-1], stored[-1])] if stored else []) + \
                ([(row, expected)] if row is not None else []):
            differ = different(mine, theirs)
            if differ:
                raise ResumeError(f"the checkpoint {saved.record['key']} does not reproduce its last row ({differ})")
        if saved.record["key"] == self.checkpoints.latest_key:
            self.checkpoints.passed()
            self.resumed(self.rows if written is None else written)


class Kept(Protocol):
    """An observer of a path whose state a checkpoint keeps (a stability count's record)."""

    def checkpoint(self, problem) -> tuple[dict, list[list[np.ndarray]]]:
        """(its record as JSON data, vectors in the spaces of ``problem.states``)."""
        ...

    def resume(self, problem, record: dict, vectors: list[list[np.ndarray]]) -> None:
        """Back to what :meth:`checkpoint` returned."""
        ...


def different(row: dict, stored: dict, rtol: float = 1e-8, atol: float = 1e-9) -> str | None:
    """The first column where ``row`` and ``stored`` differ beyond round-off, in words (None: none)."""
    for name in sorted(set(row) | set(stored)):
        a, b = row.get(name), stored.get(name)
        if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
            if not (np.isclose(a, b, rtol=rtol, atol=atol) or (np.isnan(a) and np.isnan(b))):
                return f"{name}: {a!r} against {b!r}"
        elif a != b:
            return f"{name}: {a!r} against {b!r}"
    return None
