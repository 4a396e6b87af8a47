"""A command's output directory: checked and locked before any meshing, and cleared of the
files of an earlier run that this run does not write again.

The lock is ``.bcfem.lock``, created exclusively by rank 0 with its pid and host, and removed
at the end. A lock left by a process that is gone from this host (killed) is taken over, with
that run's temporary files; a live one refuses the run. Only the files an earlier run's
``summary.json`` lists as its own are ever removed, so a user's files are never touched.
"""

from __future__ import annotations

import json
import os
import shutil
import socket
from pathlib import Path

LOCK = ".bcfem.lock"


class OutDirError(ValueError):
    """The directory cannot take this run's results (bad input: exit 2)."""


def lock(out: Path, comm) -> bool:
    """Create ``out`` and take its lock (collective); raises :class:`OutDirError` before
    anything is written if ``out`` is no directory or another run holds it. Returns whether
    ``out`` was created (for :func:`unlock`)."""
    outcome: bool | str | None = None
    if comm.rank == 0:
        try:
            outcome = _lock(Path(out))
        except OutDirError as err:
            outcome = str(err)
    outcome = comm.bcast(outcome)
    if isinstance(outcome, str):
        raise OutDirError(outcome)
    return outcome


def unlock(out: Path, comm, created: bool = False) -> None:
    """Remove this run's lock, and ``out`` too if :func:`lock` created it and it stayed
    empty (a run refused as bad input leaves nothing behind)."""
    out = Path(out)
    if comm.rank != 0:
        return
    if _owner(out / LOCK) == _me():
        (out / LOCK).unlink(missing_ok=True)
    if created and not any(out.iterdir()):
        out.rmdir()


def _me() -> dict:
    return {"pid": os.getpid(), "host": socket.gethostname()}


def _lock(out: Path) -> bool:
    if out.exists() and not out.is_dir():
        raise OutDirError(f"--out {out} is not a directory")
    created = not out.exists()
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutDirError(f"--out {out}: cannot create it ({err.strerror})") from None
    lock = out / LOCK
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            owner = _owner(lock)
            if owner is None or _alive(owner):
                pid = owner["pid"] if owner else "unknown"
                where = "" if owner is None or owner["host"] == socket.gethostname() else f" on {owner['host']}"
                raise OutDirError(f"--out {out} is in use by another run (pid {pid}{where})") from None
            lock.unlink(missing_ok=True)  # a killed run's lock
            continue
        except OSError as err:
            raise OutDirError(f"--out {out}: cannot write there ({err.strerror})") from None
        with os.fdopen(fd, "w") as f:
            json.dump(_me(), f)
        _clear_leftovers(out)
        return created
    raise OutDirError(f"--out {out} is in use by another run")


def _clear_leftovers(out: Path) -> None:
    """Remove the temporary files of runs killed before they could rename them (under the
    lock no other run writes here): ``.<name>.*.tmp``, ``.<name>.*.tmp.png``, ``.fields*.tmp.bp``."""
    for path in [*out.glob(".*.tmp"), *out.glob(".*.tmp.png"), *out.glob(".fields*.tmp.bp")]:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink(missing_ok=True)


def _owner(lock: Path) -> dict | None:
    """The pid and host in a lock file; None if it is unreadable (e.g. being written)."""
    try:
        owner = json.loads(lock.read_text())
        return {"pid": int(owner["pid"]), "host": str(owner["host"])}
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _alive(owner: dict) -> bool:
    """Whether the lock's process may still run (on another host: it cannot be told)."""
    if owner["host"] != socket.gethostname():
        return True
    if owner["pid"] == os.getpid():  # a pid reused, e.g. in a container: not this run's lock
        return False
    try:
        os.kill(owner["pid"], 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's live process
        return True
    return True


def files_of_last_run(out: Path) -> list[str]:
    """The files the run before wrote in ``out``, as its ``summary.json`` lists them."""
    try:
        files = json.loads((Path(out) / "summary.json").read_text()).get("files", [])
    except (OSError, ValueError, AttributeError):
        return []
    return [f for f in files if isinstance(f, str)] if isinstance(files, list) else []


def remove_stale(out: Path, previous: list[str], current: list[str]) -> None:
    """Remove the files of ``previous`` (an earlier run's list) that are not in ``current``;
    only plain names inside ``out``."""
    out = Path(out).resolve()
    for name in set(previous) - set(current):
        path = (out / name).resolve()
        if path.parent != out or name.startswith(".") or not path.exists():
            continue
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink()
