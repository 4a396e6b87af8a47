"""SIGINT and SIGTERM end a run with a status on disk, never as a failed Newton solve.

A signal sets a flag. On one rank, outside a PETSc solve, the handler also raises
:class:`Interrupted` at once. Inside a solve a raise would be swallowed by PETSc as a failed
callback, and under MPI it could leave another rank waiting in a collective; there the flag
is what counts: a residual assembled after the signal is NaN, so the solve in progress ends
at its next evaluation, and :func:`check` (collective, after every SNES solve) raises
:class:`Interrupted` on every rank at once. The exit code is 128 + the signal's number
(130 for SIGINT, 143 for SIGTERM), as a shell reports a process killed by it.
"""

from __future__ import annotations

import functools
import signal
from contextlib import contextmanager
from typing import Any

from mpi4py import MPI

_received = 0  # the first signal's number (0: none)
_installed = False
_raise_at_once = False
_deferred = 0  # depth of the regions where the handler must not raise
_compiles_deferred = False  # dolfinx's form compiles wrapped in deferred()


class Interrupted(BaseException):
    """The run was stopped by a signal. A BaseException, like KeyboardInterrupt, so that an
    ``except Exception`` (a sweep recording a failed point) does not take it for a failure."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum
        #: the interrupted solve's record (``bcfem.run.runner.Run``), once the solve had begun
        self.run: Any = None

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


def install(comm) -> None:
    """Handle SIGINT and SIGTERM for a command on ``comm`` (the world)."""
    from petsc4py import PETSc  # noqa: F401  PETSc's initialisation handles SIGTERM: ours come after

    global _installed, _raise_at_once
    _installed, _raise_at_once = True, comm.size == 1
    reinstall()
    _defer_compiles()


def _defer_compiles() -> None:
    """Form compiles run :func:`deferred`. FFCx removes a failed compile's lock (its ``.c`` file
    in the cache, whose ``.so`` others wait for) on an ``Exception`` only: :class:`Interrupted`
    raised mid-compile would leave it, and every later compile of that form would time out."""
    from dolfinx import jit

    global _compiles_deferred
    if _compiles_deferred:
        return
    _compiles_deferred = True
    compile_form = jit.ffcx_jit

    @functools.wraps(compile_form)
    def ffcx_jit(*args, **kwargs):
        with deferred():
            return compile_form(*args, **kwargs)

    jit.ffcx_jit = ffcx_jit


def reinstall() -> None:
    """Handle the signals again after a library set them behind Python's back (gmsh's
    initialize sets SIGTERM to its default, which would end the process with no status)."""
    if _installed:
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, _handle)


def _handle(signum, frame) -> None:
    global _received
    if _received:  # a second signal: the stop of the first is under way
        return
    _received = signum
    if _raise_at_once and not _deferred:
        raise Interrupted(signum)


def requested() -> bool:
    """Whether this rank has received a signal (local, no communication)."""
    return bool(_received)


def received(comm) -> int:
    """The signal any rank of ``comm`` has received, else 0 (collective)."""
    return comm.allreduce(_received, op=MPI.MAX)


def check(comm) -> None:
    """Raise :class:`Interrupted` on every rank of ``comm`` if any has received a signal
    (collective)."""
    signum = received(comm)
    if signum:
        raise Interrupted(signum)


@contextmanager
def deferred():
    """No raise from the handler inside (a PETSc solve, writing the results): the flag alone
    records the signal."""
    global _deferred
    _deferred += 1
    try:
        yield
    finally:
        _deferred -= 1
