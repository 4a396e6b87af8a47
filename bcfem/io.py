"""Results on disk: one directory per run, written by rank 0, atomically.

CSV, JSON and PNG files are written to a temporary name of their own and renamed, so a
reader never sees half a file. The VTX (ADIOS2) field file is written
collectively into a temporary directory that is renamed at close. :func:`recording`
collects the paths written, for a run's list of its files.

JSON is strict (no ``Infinity`` or ``NaN``, which strict parsers reject): a non-finite
float is written as ``"inf"`` or ``"-inf"`` (read back as floats by :func:`read_json`),
and NaN as ``null``.
"""

from __future__ import annotations

import csv
import errno
import json
import math
import os
import shutil
import tempfile
from collections.abc import Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TextIO

_recorders: list[list[Path]] = []
#: what a VTX step may write besides its arrays (ADIOS2's index and metadata), and what its
#: close still writes
VTX_MARGIN = 64 * 1024


class DiskFull(RuntimeError):
    """No space left on the device a run writes to: one line naming where."""


def disk_full(path: Path) -> DiskFull:
    where = next((p for p in (path, *path.parents) if p.exists()), Path("."))
    free = shutil.disk_usage(where).free
    return DiskFull(f"no space left on the device of {where} ({free // 1024} kB free) writing {path.name}")


@contextmanager
def space_checked(path: Path):
    """OSError ENOSPC or EDQUOT inside as :class:`DiskFull`."""
    try:
        yield
    except OSError as err:
        if err.errno in (errno.ENOSPC, errno.EDQUOT):
            raise disk_full(path) from None
        raise


def collectively(comm, write) -> None:
    """``write()`` on every rank (it writes on rank 0); a :class:`DiskFull` there is raised on
    every rank, so that no rank waits in a collective the others left."""
    message = None
    try:
        write()
    except DiskFull as err:
        message = str(err)
    message = comm.bcast(message)
    if message is not None:
        raise DiskFull(message)


@contextmanager
def recording():
    """The paths written (by this rank) inside, as a list filled in as they are written."""
    written: list[Path] = []
    _recorders.append(written)
    try:
        yield written
    finally:
        _recorders.remove(written)


def note_written(path: Path) -> None:
    for written in _recorders:
        written.append(path)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _atomic_write(path: Path, write) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with space_checked(path):
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; results are for sharing
        try:
            with os.fdopen(fd, "w", newline="") as f:
                write(f)
            os.replace(tmp, path)
        except BaseException:
            os.unlink(tmp)
            raise
    note_written(path)


def write_csv(path, rows: list[dict], comm, columns: Sequence[str] | None = None) -> None:
    """Write ``rows`` (dicts) as CSV on rank 0; columns default to the first row's keys."""
    if comm.rank != 0:
        return
    columns = columns or (list(rows[0]) if rows else [])

    def write(f):
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for row in rows:
            w.writerow(_cells(row))

    _atomic_write(Path(path), write)


def _cells(row: dict) -> dict:
    """A row as the CSV writes it: floats to their shortest exact text."""
    return {k: (repr(float(v)) if isinstance(v, float) else v) for k, v in row.items()}


class RowJournal:
    """A run's accepted rows on disk as they are accepted (rank 0): each row appended to the CSV
    at ``path`` and flushed, so a killed run keeps every row up to its last accepted one. The
    finished run writes the same table again atomically (:func:`write_csv`).

    A row replaced or a path started again rewrites the file (:meth:`rewrite`)."""

    def __init__(self, path, columns: Sequence[str] | None, comm):
        self.path, self.columns, self.comm = Path(path), list(columns or []), comm
        self._file: TextIO | None = None
        self._writer: csv.DictWriter | None = None

    def rewrite(self, rows: list[dict]) -> None:
        """The file holds ``rows`` alone (a header first; collective)."""
        collectively(self.comm, lambda: self._rewrite(rows))

    def append(self, row: dict) -> None:
        """``row`` added at the end of the file (collective). On a full disk the file keeps its
        complete rows (the part of this one that was written is cut off) and every rank
        raises :class:`DiskFull`."""
        collectively(self.comm, lambda: self._append(row))

    def _rewrite(self, rows: list[dict]) -> None:
        if self.comm.rank != 0:
            return
        self.close()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with space_checked(self.path):
            self._file = file = open(self.path, "w", newline="")
            self._writer = writer = csv.DictWriter(file, fieldnames=self.columns, extrasaction="ignore")
            writer.writeheader()
            for row in rows:
                writer.writerow(_cells(row))
            file.flush()

    def _append(self, row: dict) -> None:
        if self.comm.rank != 0:
            return
        if not self.columns:  # the first row's keys, as write_csv takes them
            self.columns = list(row)
        if self._file is None or self._writer is None:
            self._rewrite([])
        assert self._file is not None and self._writer is not None
        end = self._file.tell()
        try:
            with space_checked(self.path):
                self._writer.writerow(_cells(row))
                self._file.flush()
        except DiskFull:
            try:
                self._file.close()  # a part still buffered fails again: dropped with the file
            except OSError:
                pass
            self._file = None
            os.truncate(self.path, end)  # no half row on disk
            raise

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None


def read_csv(path) -> list[dict]:
    """Read a bcfem CSV back, converting numeric fields to float."""
    def convert(v):
        try:
            return float(v)
        except ValueError:
            return v

    with open(path, newline="") as f:
        return [{k: convert(v) for k, v in row.items()} for row in csv.DictReader(f)]


def write_json(path, data: dict, comm, exact: bool = False) -> None:
    """Write ``data`` as indented, strict JSON on rank 0 (see the module's note); ``exact``:
    as Python reads it back, NaN and infinities included (a file only bcfem reads)."""
    if comm.rank != 0:
        return
    text = json.dumps(data, indent=1, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o)) if exact else \
        json.dumps(strict(data), indent=2, allow_nan=False)  # a regression fails here, loudly
    _atomic_write(Path(path), lambda f: f.write(text))


def strict(obj):
    """``obj`` with non-finite floats as ``"inf"``, ``"-inf"`` or None, numpy scalars and
    arrays as Python's, and paths as strings."""
    if isinstance(obj, dict):
        return {k: strict(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [strict(v) for v in obj]
    if isinstance(obj, Path):
        return str(obj)
    if hasattr(obj, "tolist"):  # numpy
        return strict(obj.tolist())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None if math.isnan(obj) else ("inf" if obj > 0 else "-inf")
    return obj


def read_json(path):
    """Read a bcfem JSON file back: ``"inf"`` and ``"-inf"`` as floats again."""
    return _floats(json.loads(Path(path).read_text()))


def _floats(obj):
    if isinstance(obj, dict):
        return {k: _floats(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_floats(v) for v in obj]
    if obj in ("inf", "-inf"):
        return float(obj)
    return obj


def save_figure(fig, path, comm) -> None:
    """Save a matplotlib figure atomically (rank 0)."""
    if comm.rank != 0:
        return
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        with space_checked(path):
            fig.savefig(tmp, dpi=150, bbox_inches="tight")
            os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    note_written(path)


class FieldWriter:
    """VTX (ADIOS2) output of fields along the branch, for ParaView.

    Writes into ``.<name>.<rank 0's pid>.tmp.bp`` (one run's own) and renames it to
    ``<name>.bp`` on close.
    """

    def __init__(self, comm, path, functions):
        from dolfinx.io import VTXWriter

        self.comm = comm
        self.path = Path(path)
        pid = comm.bcast(os.getpid() if comm.rank == 0 else None)
        self.tmp = self.path.with_name(f".{self.path.stem}.{pid}.tmp.bp")
        if comm.rank == 0 and self.tmp.exists():
            shutil.rmtree(self.tmp)
        comm.barrier()
        self.writer = VTXWriter(comm, str(self.tmp), functions, engine="BP4")
        self.closed = False
        #: this rank's bytes of a step: the arrays and the mesh (geometry and topology, about
        #: twice the geometry's), which VTX writes at every step
        mesh = functions[0].function_space.mesh
        self._step_bytes = sum(f.x.array.nbytes for f in functions) + 3 * mesh.geometry.x.nbytes

    def write(self, t: float) -> None:
        """One step (collective). A step that might not fit the free space is not begun (ADIOS2
        cannot recover from a failed write): the writer is closed with the steps written so far
        (ADIOS2's margin, :data:`VTX_MARGIN`, is kept for that), and every rank raises
        :class:`DiskFull`."""
        need = self.comm.allreduce(self._step_bytes)
        free = self.comm.bcast(shutil.disk_usage(self.tmp.parent).free if self.comm.rank == 0 else None)
        if free < 2 * need + VTX_MARGIN:
            self.close()
            raise DiskFull(f"no space left on the device of {self.path.parent} ({free // 1024} kB free; a field step "
                           f"needs about {need // 1024} kB)")
        self.writer.write(t)

    def close(self) -> None:
        if self.closed:
            return
        self.closed = True
        self.writer.close()
        self.comm.barrier()
        if self.comm.rank == 0:
            if self.path.exists():
                shutil.rmtree(self.path)
            os.replace(self.tmp, self.path)
            note_written(self.path)
        self.comm.barrier()
