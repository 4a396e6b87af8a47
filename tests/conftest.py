"""Shared test set-up. ``bcfem`` is imported first: it loads MPI ahead of dolfinx."""

import bcfem  # noqa: F401
