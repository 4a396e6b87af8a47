"""Results on disk: one directory per run, written by rank 0, atomically.

CSV, JSON and PNG files are written to a temporary name and renamed, so a
reader never sees half a file. The VTX (ADIOS2) field file is written
collectively into a temporary directory that is renamed at close.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import tempfile
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _atomic_write(path: Path, write) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; results are for sharing
    try:
        with os.fdopen(fd, "w", newline="") as f:
            write(f)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def write_csv(path, rows: list[dict], comm, columns: list[str] | None = None) -> None:
    """Write ``rows`` (dicts) as CSV on rank 0; columns default to the first row's keys."""
    if comm.rank != 0:
        return
    columns = columns or (list(rows[0]) if rows else [])

    def write(f):
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for row in rows:
            w.writerow({k: (repr(float(v)) if isinstance(v, float) else v) for k, v in row.items()})

    _atomic_write(Path(path), write)


def read_csv(path) -> list[dict]:
    """Read a bcfem CSV back, converting numeric fields to float."""
    def convert(v):
        try:
            return float(v)
        except ValueError:
            return v

    with open(path, newline="") as f:
        return [{k: convert(v) for k, v in row.items()} for row in csv.DictReader(f)]


def write_json(path, data: dict, comm) -> None:
    """Write ``data`` as indented JSON on rank 0."""
    if comm.rank != 0:
        return
    _atomic_write(Path(path), lambda f: json.dump(data, f, indent=2, default=_jsonable))


def _jsonable(obj):
    if hasattr(obj, "item"):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj)}")


def save_figure(fig, path, comm) -> None:
    """Save a matplotlib figure atomically (rank 0)."""
    if comm.rank != 0:
        return
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    fig.savefig(tmp, dpi=150, bbox_inches="tight")
    os.replace(tmp, path)


class FieldWriter:
    """VTX (ADIOS2) output of fields along the branch, for ParaView.

    Writes into ``<name>.tmp.bp`` and renames it to ``<name>.bp`` on close.
    """

    def __init__(self, comm, path, functions):
        from dolfinx.io import VTXWriter

        self.comm = comm
        self.path = Path(path)
        self.tmp = self.path.with_name(self.path.stem + ".tmp.bp")
        if comm.rank == 0 and self.tmp.exists():
            shutil.rmtree(self.tmp)
        comm.barrier()
        self.writer = VTXWriter(comm, str(self.tmp), functions, engine="BP4")

    def write(self, t: float) -> None:
        self.writer.write(t)

    def close(self) -> None:
        self.writer.close()
        self.comm.barrier()
        if self.comm.rank == 0:
            if self.path.exists():
                shutil.rmtree(self.path)
            os.replace(self.tmp, self.path)
        self.comm.barrier()
