"""A command's output directory: checked and locked before any meshing, and cleared of the
files of an earlier run that this run does not write again.

The lock is ``.bcfem.lock``, created exclusively by rank 0 with its pid, host and command, and
removed at the end. A lock left by a process that is gone from this host (killed) is taken over,
with that run's temporary files; a live one refuses the run. A killed run that wrote no summary
gets one, ``status: killed`` with the rows it kept on disk (:func:`record_killed`; also by
``bcfem status DIR``). Only the files an earlier run's ``summary.json`` lists as its own are ever
removed, so a user's files are never touched.
"""

from __future__ import annotations

import json
import os
import shutil
import socket
from pathlib import Path

from mpi4py import MPI

LOCK = ".bcfem.lock"


class OutDirError(ValueError):
    """The directory cannot take this run's results (bad input: exit 2)."""


def lock(out: Path, comm, command: str = "") -> bool:
    """Create ``out`` and take its lock (collective), noting ``command`` in it; raises
    :class:`OutDirError` before anything is written if ``out`` is no directory or another run
    holds it. Returns whether ``out`` was created (for :func:`unlock`)."""
    outcome: bool | str | None = None
    if comm.rank == 0:
        try:
            outcome = _lock(Path(out), command)
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
    owner = _owner(out / LOCK)
    if owner is not None and {k: owner[k] for k in ("pid", "host")} == _me():
        (out / LOCK).unlink(missing_ok=True)
    if created and not any(out.iterdir()):
        out.rmdir()


def _me() -> dict:
    return {"pid": os.getpid(), "host": socket.gethostname()}


def _lock(out: Path, command: str = "") -> bool:
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
            record_killed(out, owner, lock)
            lock.unlink(missing_ok=True)  # a killed run's lock
            continue
        except OSError as err:
            raise OutDirError(f"--out {out}: cannot write there ({err.strerror})") from None
        with os.fdopen(fd, "w") as f:
            json.dump({**_me(), "command": command}, f)
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
    """The pid, host and command in a lock file; None if it is unreadable (e.g. being written)."""
    try:
        owner = json.loads(lock.read_text())
        return {"pid": int(owner["pid"]), "host": str(owner["host"]), "command": str(owner.get("command", ""))}
    except (OSError, ValueError, KeyError, TypeError):
        return None


def record_killed(out: Path, owner: dict | None, lock: Path) -> dict | None:
    """Write the summary of the run that held ``lock`` and was killed before it wrote its own
    (its ``summary.json`` missing or older than the lock): ``status: killed``, its command and
    the rows it kept in ``branch.csv``. Returns that summary, or None if the run had finished."""
    from bcfem import io

    summary, rows = out / "summary.json", out / "branch.csv"
    try:
        if summary.exists() and summary.stat().st_mtime >= lock.stat().st_mtime:
            return None  # it finished, and was stopped only before removing its lock
    except OSError:
        pass
    kept = [_keep_fields(tmp) for tmp in out.glob(f".*.{owner['pid']}.tmp.bp")] if owner else []
    steps = 0
    if rows.exists():
        with open(rows, newline="") as f:
            steps = max(sum(1 for line in f if line.strip()) - 1, 0)
    who = f"pid {owner['pid']} on {owner['host']}" if owner else "a run"
    command = (owner or {}).get("command", "")
    words = command.split()
    record = {"scene": words[1] if len(words) > 1 else None, "status": "killed",
              "error": f"{who} ended without writing its summary (killed: SIGKILL, the out-of-memory killer or "
                       f"a lost node); its {steps} accepted rows are in branch.csv",
              "command": command, "steps": steps,
              "files": sorted({"summary.json", *(["branch.csv"] if rows.exists() else []), *kept})}
    io.write_json(summary, record, MPI.COMM_SELF)  # the lock, and so this file, is rank 0's
    return record


def _keep_fields(tmp: Path) -> str:
    """A killed run's VTX directory (``.<name>.<pid>.tmp.bp``) under its own name: ADIOS2's BP4
    engine writes each step's index as the step ends, so it holds every accepted step."""
    name = tmp.name.removeprefix(".").split(".")[0] + ".bp"
    target = tmp.with_name(name)
    if target.is_dir() and not target.is_symlink():
        shutil.rmtree(target)
    os.replace(tmp, target)
    return name


def keep_fields_part(out: Path) -> None:
    """Before a resumed run writes ``fields.bp`` (its steps from its checkpoint on), keep the
    killed run's as the next ``fields.part<k>.bp`` (rank 0; the VTX time is the row's index);
    every part is the run's file."""
    from bcfem import io

    parts = sorted(out.glob("fields.part*.bp"))
    for part in parts:
        io.note_written(part)
    if (out / "fields.bp").is_dir():
        part = out / f"fields.part{len(parts) + 1}.bp"
        os.replace(out / "fields.bp", part)
        io.note_written(part)


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
    return not _zombie(owner["pid"])


def _zombie(pid: int) -> bool:
    """Whether ``pid`` has ended and waits to be reaped (a container's first process may never
    reap a killed run's orphans): it holds no file any more."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[-1].split()[:1] in (["Z"], ["X"])


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


def status(out: Path) -> tuple[str, int]:
    """What ``out`` holds (rank 0): (one line, exit code 0; 1 for a run that failed, was killed
    or interrupted; 2 for no run there). A killed run's summary is written on the way
    (:func:`record_killed`)."""
    out = Path(out)
    lock = out / LOCK
    if lock.exists():
        owner = _owner(lock)
        if owner is None or _alive(owner):
            pid = owner["pid"] if owner else "unknown"
            return f"{out}: running (pid {pid}{'' if owner is None else ' on ' + owner['host']})", 0
        killed = record_killed(out, owner, lock)
        lock.unlink(missing_ok=True)
        _clear_leftovers(out)
        if killed is not None:
            return f"{out}: killed: {killed['error']}", 1
    try:
        summary = json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        return f"{out}: no bcfem run here", 2
    line = f"{out}: {summary.get('scene')} {summary.get('status')}, {summary.get('steps', 0)} rows"
    if summary.get("error"):
        line += f": {summary['error']}"
    return line, 0 if summary.get("status") == "ok" else 1
