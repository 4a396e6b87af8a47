"""Null pivots of a tangent: a singular tangent found, not traced silently.

MUMPS' null-pivot detection (ICNTL(24) = 1) counts the pivots it would have had to divide by
(INFOG(28)). A converged Newton state whose tangent has null pivots is not isolated: a free
rigid mode (a boundary condition missing) or an unknown no energy constrains, whose value is
then the solver's choice, not the physics'. The count is a factorisation of its own, so the
problem's solver runs as it was configured.
"""

from __future__ import annotations

from petsc4py import PETSc

from bcfem.solver import options

#: MUMPS options of the count: detect null pivots rather than fail or divide by them
_OPTIONS = (("mat_mumps_icntl_24", 1),)


def null_pivots(A: PETSc.Mat, prefix: str) -> int:
    """The null pivots of an LU factorisation of ``A`` (the same on every rank; collective).
    The user's ``-<prefix>mat_mumps_*`` options apply."""
    opts = PETSc.Options()
    added = [(key, value) for key, value in _OPTIONS if not opts.hasName(prefix + key)]
    for key, value in added:
        opts[prefix + key] = value
    ksp = PETSc.KSP().create(A.getComm())
    try:
        ksp.setOptionsPrefix(prefix)
        ksp.setType("preonly")
        pc = ksp.getPC()
        pc.setType("lu")
        pc.setFactorSolverType("mumps")
        ksp.setOperators(A)
        ksp.setFromOptions()
        with options.inserted(prefix, options.users_mumps()):
            ksp.setUp()  # the factorisation; MUMPS reads its options here
        return int(pc.getFactorMatrix().getMumpsInfog(28))
    finally:
        ksp.destroy()
        for key, _ in added:
            opts.delValue(prefix + key)


def direct(snes: PETSc.SNES) -> bool:
    """Whether ``snes`` solves with MUMPS' LU or LDLᵀ: a problem that factorises anyway can spare one
    more factorisation; an iterative or a reduced (variational-inequality) solve is not counted."""
    pc = snes.getKSP().getPC()
    return pc.getType() in ("lu", "cholesky") and pc.getFactorSolverType() == "mumps"


def warning(prefix: str, count: int) -> str:
    return (f"warning: {prefix}: the tangent at the first converged state has {count} null pivot(s): a free "
            "rigid mode or an unconstrained unknown (a boundary condition missing?); the state is then the "
            "solver's choice")
