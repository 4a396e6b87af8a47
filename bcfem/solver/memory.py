"""A factorisation that would not fit in memory stops the run with a message, not the kernel.

MUMPS estimates its memory in its analysis, before it allocates the factors (INFOG(16): the
most one process needs, INFOG(17): all of them, in MB). Before a problem's first factorisation
:func:`check` runs that analysis alone (a probe capped at 1 MB by ICNTL(23), which MUMPS refuses
to factorise with INFOG(1) = -19 once it has estimated) and compares the estimate with what each
rank may still use: the node's available memory over the ranks on it, a cgroup's headroom,
``ulimit -v``'s headroom. A factorisation past it is an :class:`OutOfMemory` (the run ends,
exit 1) before anything is allocated; past half of it, a warning. A factorisation that still
fails for memory (INFOG(1) -9, -13, -19) is one too (:func:`shortage`).

ICNTL(23) is not set for the real factorisation: MUMPS then reserves its whole value up front
(address space, not resident memory), which ``ulimit -v`` counts.
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
#: dolfinx's forms, Python); past half of it a warning
SHARE = 0.8
WARN = 0.5


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


def shortage(pc: PETSc.PC) -> str | None:
    """Why ``pc``'s factorisation failed for memory (collective: every rank gets rank 0's
    answer), or None if it did not."""
    factor = factor_of(pc)
    code = factor.getMumpsInfog(1) if factor is not None else 0
    message = None
    if factor is not None and code in SHORT:
        why = {-9: "its working array was too small", -13: "an allocation failed",
               -19: "that is more than ICNTL(23) allows"}[code]
        message = (f"out of memory: the factorisation needs about {factor.getMumpsInfog(16)} MB on its largest rank "
                   f"({factor.getMumpsInfog(17)} MB in all, MUMPS's estimate) and {why} "
                   f"(MUMPS INFOG(1) = {code}); {ADVICE}")
    return pc.comm.tompi4py().bcast(message)


ADVICE = "use fewer unknowns, more ranks or nodes, or an iterative solver (-pc_type fieldsplit)"


def estimate_mb(A: PETSc.Mat, prefix: str, factor: str, options: dict) -> tuple[int, int]:
    """MUMPS's estimate for factorising ``A`` (``factor``: lu or cholesky) with the problem's
    MUMPS ``options``: (MB on the largest rank, MB in all), from its analysis alone (collective)."""
    from bcfem.solver.options import inserted

    probe = prefix + "memory_probe_"
    ksp = PETSc.KSP().create(A.getComm())
    try:
        ksp.setOptionsPrefix(probe)
        ksp.setType("preonly")
        pc = ksp.getPC()
        pc.setType(factor)
        pc.setFactorSolverType("mumps")
        ksp.setOperators(A)
        with inserted(probe, {**options, "mat_mumps_icntl_23": 1}):  # estimate, then refuse
            ksp.setFromOptions()
            ksp.setUp()
        F = pc.getFactorMatrix()
        return int(F.getMumpsInfog(16)), int(F.getMumpsInfog(17))
    finally:
        ksp.destroy()


def check(A: PETSc.Mat, prefix: str, factor: str, options: dict, comm) -> str | None:
    """Raise :class:`OutOfMemory` if MUMPS's estimate for ``A`` exceeds what the ranks may use
    (:data:`SHARE` of :func:`available_mb`); return a warning past :data:`WARN` of it, else None
    (collective)."""
    per_rank, total = estimate_mb(A, prefix, factor, options)
    available = available_mb(comm)
    line = (f"the factorisation needs about {per_rank} MB on its largest rank ({total} MB in all, MUMPS's estimate) "
            f"and each rank has about {available} MB left")
    if per_rank > SHARE * available:
        raise OutOfMemory(f"out of memory: {line}; {ADVICE}")
    if per_rank > WARN * available:
        return f"warning: {line}: close to the limit"
    return None
