"""Shared test set-up. ``bcfem`` is imported first: it loads MPI ahead of dolfinx.

Under ``mpirun`` tests marked ``serial`` are skipped: they compare with serial runs
of their own or spawn ``mpirun`` themselves. After every test the garbage is collected
on every rank at the same point, so that the meshes and PETSc objects of finished tests
free their communicators: left to the collector's own schedule they pile up until MPICH
runs out of communicator context ids (MPI_ERR_OTHER, exit 15, after about a hundred tests).
"""

import gc

from mpi4py import MPI

import cores
import pytest

import bcfem  # noqa: F401


def pytest_collection_modifyitems(config, items):
    if MPI.COMM_WORLD.size == 1:
        return
    skip = pytest.mark.skip(reason="serial only (runs on one rank)")
    for item in items:
        if "serial" in item.keywords:
            item.add_marker(skip)


@pytest.fixture(autouse=True)
def _hold_a_core():
    """Under tools/test-halves.sh: this half's core while the test runs (see tests/cores.py)."""
    cores.take_own()
    yield
    cores.release()


@pytest.fixture(autouse=True)
def _collect_garbage():
    yield
    if MPI.COMM_WORLD.size > 1:
        gc.collect()
