"""A factorisation that would not fit in memory stops the run with a message, not the kernel.

MUMPS estimates its memory in the analysis, before it allocates the factors (INFOG(16): the
most any process needs, INFOG(17): all of them, in MB), and refuses to go past ICNTL(23) MB per
process with INFOG(1) = -19. bcfem sets ICNTL(23) to what each rank may still use (the node's
available memory shared by the ranks on it, a cgroup's limit, ``ulimit -v``), unless the user set
it; a factorisation refused for memory (-19, or -9/-13 for an allocation that failed) is then a
:class:`OutOfMemory`, which ends the run (exit 1) instead of being cut into smaller steps.
"""

from __future__ import annotations

import os
import resource
from pathlib import Path

from mpi4py import MPI
from petsc4py import PETSc

#: MUMPS's INFOG(1) for a factorisation that ran out of memory: the working array too small
#: (-9), an allocation failed (-13), more than ICNTL(23) allows (-19)
SHORT = (-9, -13, -19)
#: of the memory a rank may use, this share is left to MUMPS (the rest: PETSc's matrices,
#: dolfinx's forms, Python)
SHARE = 0.8


class OutOfMemory(RuntimeError):
    """A factorisation needs more memory than the ranks have."""


def _meminfo(key: str) -> float | None:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith(key + ":"):
                return float(line.split()[1]) / 1024  # kB -> MB
    except OSError:
        pass
    return None


def _cgroup_headroom() -> float | None:
    """MB left under the cgroup (v2) memory limit of this process, if it has one."""
    try:
        limit = Path("/sys/fs/cgroup/memory.max").read_text().strip()
        if limit == "max":
            return None
        used = float(Path("/sys/fs/cgroup/memory.current").read_text())
        return (float(limit) - used) / 2**20
    except (OSError, ValueError):
        return None


def _address_space_headroom() -> float | None:
    """MB left under ``ulimit -v`` (RLIMIT_AS) for this process, if it is limited."""
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY:
        return None
    try:
        status = Path(f"/proc/{os.getpid()}/status").read_text()
        size = next(float(line.split()[1]) for line in status.splitlines() if line.startswith("VmSize:"))
    except (OSError, StopIteration, ValueError):
        return None
    return (soft / 1024 - size) / 1024


def available_mb(comm) -> int:
    """The memory each rank of ``comm`` may still use, in MB (collective): the node's available
    memory over the ranks on the node, bounded by a cgroup's and ``ulimit -v``'s headroom; the
    least over the ranks."""
    node = comm.Split_type(MPI.COMM_TYPE_SHARED)
    try:
        ranks_here = node.size
    finally:
        node.Free()
    limits = [value for value in ((_meminfo("MemAvailable") or 0.0) / ranks_here, _cgroup_headroom(),
                                  _address_space_headroom()) if value is not None]
    return max(int(comm.allreduce(min(limits), op=MPI.MIN)), 1)


def factor_of(pc: PETSc.PC) -> PETSc.Mat | None:
    """The MUMPS factor of ``pc`` (a direct PC, or bcfem's reduced LU around one), else None."""
    from bcfem.solver.reduced_lu import ReducedLU

    if pc.getType() == "python":
        context = pc.getPythonContext()
        return factor_of(context.ksp.getPC()) if isinstance(context, ReducedLU) else None
    if pc.getType() in ("lu", "cholesky") and pc.getFactorSolverType() == "mumps":
        try:
            return pc.getFactorMatrix()
        except PETSc.Error:
            return None
    return None


def shortage(pc: PETSc.PC, limit_mb: int | None) -> str | None:
    """Why ``pc``'s factorisation failed for memory (collective: every rank gets rank 0's
    answer), or None if it did not."""
    factor = factor_of(pc)
    message = None
    code = factor.getMumpsInfog(1) if factor is not None else 0
    if factor is not None and code in SHORT:
        per_rank, total = factor.getMumpsInfog(16), factor.getMumpsInfog(17)
        why = (f"more than the {limit_mb} MB each rank may use (ICNTL(23))" if code == -19 and limit_mb else
               "and an allocation failed: the rank had less (ulimit -v, a cgroup or the node's memory)")
        message = (f"out of memory: the factorisation needs about {per_rank} MB on its largest rank ({total} MB "
                   f"in all, MUMPS's estimate), {why}; use fewer unknowns, more ranks or nodes, or an "
                   f"iterative solver (-pc_type fieldsplit); MUMPS INFOG(1) = {code}")
    return pc.comm.tompi4py().bcast(message)
