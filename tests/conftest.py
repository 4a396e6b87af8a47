"""Shared test set-up. ``bcfem`` is imported first: it loads MPI ahead of dolfinx.

Under ``mpirun`` tests marked ``serial`` are skipped: they compare with serial runs
of their own or spawn ``mpirun`` themselves.
"""

from mpi4py import MPI

import pytest

import bcfem  # noqa: F401


def pytest_collection_modifyitems(config, items):
    if MPI.COMM_WORLD.size == 1:
        return
    skip = pytest.mark.skip(reason="serial only (runs on one rank)")
    for item in items:
        if "serial" in item.keywords:
            item.add_marker(skip)
