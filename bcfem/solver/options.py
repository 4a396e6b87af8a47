"""PETSc options: bcfem defaults, merged with what the user set.

Precedence, lowest first: bcfem defaults < scene defaults < the user's
options (``PETSC_OPTIONS`` or command-line ``-key value`` pairs). A user option
applies when given with the solver's prefix (``-bcfem_blister_rigid_snes_rtol``)
or without a prefix (``-snes_rtol``); the prefixed one wins.
"""

from __future__ import annotations

from contextlib import contextmanager

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
    opts = PETSc.Options()
    user = opts.getAll()
    for key, value in user.items():
        if key.startswith(_USER_FAMILIES):
            merged[key] = value
            opts.getString(key)  # read here: PETSc would report it unused at exit
    for key, value in user.items():
        if key.startswith(prefix):
            merged[key[len(prefix):]] = value
    return merged


def user_set(prefix: str, key: str) -> bool:
    """Whether the user set ``key`` (with or without ``prefix``)."""
    opts = PETSc.Options()
    return opts.hasName(key) or opts.hasName(prefix + key)


@contextmanager
def untouched():
    """Put PETSc's options database back as it was on entry.

    dolfinx's ``NonlinearProblem`` writes its options under its prefix and leaves
    them there (a later ``setFromOptions`` would re-apply them), and its clean-up
    deletes the *unprefixed* keys of the same names: the user's ``-snes_max_it``
    would vanish after the first problem, and every later stage would run on
    bcfem's defaults.
    """
    opts = PETSc.Options()
    before = opts.getAll()
    try:
        yield
    finally:
        after = opts.getAll()
        for key in after.keys() - before.keys():
            opts.delValue(key)
        for key, value in before.items():
            if after.get(key) != value:
                opts.setValue(key, value)
                opts.getString(key)  # it was read before: PETSc must not report it unused


@contextmanager
def inserted(prefix: str, values: dict):
    """``values`` in PETSc's database under ``prefix`` inside (those not there already), for a
    solver that reads them late: MUMPS reads its ``mat_mumps_*`` options at each analysis, long
    after the problem's options were set from the database and taken out again."""
    opts = PETSc.Options()
    added = [key for key in values if not opts.hasName(prefix + key)]
    for key in added:
        opts[prefix + key] = values[key]
    try:
        yield
    finally:
        for key in added:
            opts.delValue(prefix + key)


def users_mumps() -> dict:
    """The user's unprefixed ``mat_mumps_*`` options (``-mat_mumps_icntl_14 50``): they apply to
    every MUMPS factorisation, the stability counts' too (under their own prefixes a user's
    prefixed option still wins)."""
    return {key: value for key, value in PETSc.Options().getAll().items() if key.startswith("mat_mumps_")}
