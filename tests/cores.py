"""The machine's cores, shared by the halves of ``tools/test-halves.sh``.

Each half is a pytest process that holds the lock of "its" core while a test runs. A test that
starts ``mpirun -n 2`` takes every core's lock until it ends, so the other half waits between
tests instead of running a third process beside two ranks: oversubscribed, MPICH's ranks wait
on a descheduled partner and the run takes 2-3 times as long. Locks are taken in one order, so
two halves that both want every core cannot deadlock. Outside the halves (no
``BCFEM_TEST_CORES``) nothing is locked.
"""

import fcntl
import os
from pathlib import Path

_held: dict[int, int] = {}  # core -> file descriptor holding its lock


def _layout() -> tuple[Path, int, int] | None:
    """(lock directory, this process's core, number of cores), from ``dir:core:cores``."""
    spec = os.environ.get("BCFEM_TEST_CORES")
    if not spec:
        return None
    folder, core, cores = spec.rsplit(":", 2)
    return Path(folder), int(core), int(cores)


def _take(folder: Path, core: int) -> None:
    if core not in _held:
        fd = os.open(folder / f"core{core}", os.O_RDWR | os.O_CREAT, 0o600)
        fcntl.flock(fd, fcntl.LOCK_EX)
        _held[core] = fd


def release() -> None:
    """Let go of every core this process holds (a test has ended)."""
    for fd in _held.values():
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)
    _held.clear()


def take_own() -> None:
    """Hold this half's core while a test runs."""
    if layout := _layout():
        _take(layout[0], layout[1])


def take_all() -> None:
    """Hold every core until the test ends: it is about to start several ranks. Under
    ``BCFEM_TEST_CORES_LOG`` the test's id is noted there (``tools/test-halves.sh --record``)."""
    if log := os.environ.get("BCFEM_TEST_CORES_LOG"):
        with open(log, "a") as f:
            f.write(os.environ.get("PYTEST_CURRENT_TEST", "") + "\n")
    if layout := _layout():
        folder, _, cores = layout
        if len(_held) < cores:
            release()  # then in order: whoever holds a lower core never waits on us for it
            for core in range(cores):
                _take(folder, core)
