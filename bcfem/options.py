"""PETSc options: bcfem defaults, merged with what the user set.

Precedence, lowest first: bcfem defaults < scene defaults < the user's
options (``PETSC_OPTIONS`` or command-line ``-key value`` pairs). A user option
applies when given with the solver's prefix (``-bcfem_blister_rigid_snes_rtol``)
or without a prefix (``-snes_rtol``); the prefixed one wins.
"""

from __future__ import annotations

from petsc4py import PETSc

SOLVER_DEFAULTS = {
    "snes_type": "newtonls",
    "snes_linesearch_type": "basic",
    # converged when the residual is at round-off or Newton's update is
    # 1e-12 of the state (quadratic convergence: the error is then ~1e-24)
    "snes_rtol": 1e-10,
    "snes_atol": 1e-10,
    "snes_stol": 1e-12,
    "snes_max_it": 25,
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
}

_USER_FAMILIES = ("snes_", "ksp_", "pc_", "mat_mumps_")


def insert_command_line(args: list[str]) -> None:
    """Put ``-key value`` pairs from the command line into PETSc's database.

    dolfinx initialises PETSc without ``sys.argv``, so command-line options are
    otherwise ignored.
    """
    if args:
        PETSc.Options().insertString(" ".join(args))


def merge(prefix: str, *layers: dict) -> dict:
    """Layer option dicts, then let the user's database entries win."""
    merged: dict = {}
    for layer in (SOLVER_DEFAULTS, *layers):
        merged.update(layer or {})
    user = PETSc.Options().getAll()
    for key, value in user.items():
        if key.startswith(_USER_FAMILIES):
            merged[key] = value
    for key, value in user.items():
        if key.startswith(prefix):
            merged[key[len(prefix):]] = value
    return merged


def user_set(prefix: str, key: str) -> bool:
    """Whether the user set ``key`` (with or without ``prefix``)."""
    opts = PETSc.Options()
    return opts.hasName(key) or opts.hasName(prefix + key)


def keys_under(prefix: str) -> set[str]:
    """The option names currently set under ``prefix``."""
    return {k for k in PETSc.Options().getAll() if k.startswith(prefix)}


def forget_new(prefix: str, before: set[str]) -> None:
    """Delete options under ``prefix`` that appeared since ``before``.

    NonlinearProblem writes its options into the global database and fails to
    delete them; left there, a later ``setFromOptions`` would re-apply them.
    """
    opts = PETSc.Options()
    for key in keys_under(prefix) - before:
        opts.delValue(key)
