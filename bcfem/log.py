"""Rank-0 logging and the continuation progress line."""

from __future__ import annotations

import logging
import sys

logger = logging.getLogger("bcfem")


def configure(comm, quiet: bool = False) -> None:
    """Send bcfem's log to stderr on rank 0 only; silence other ranks. ``quiet`` leaves the
    warnings alone (a large problem, ...)."""
    logger.handlers.clear()
    logger.propagate = False
    if comm.rank == 0:
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("%(message)s"))
        logger.addHandler(handler)
        logger.setLevel(logging.WARNING if quiet else logging.INFO)
    else:
        logger.addHandler(logging.NullHandler())
        logger.setLevel(logging.CRITICAL + 1)


def ensure(comm, quiet: bool = False) -> None:
    """:func:`configure`, unless the log already has a handler (the command line's, or a script's
    own): a script that solves a scene sees the command line's progress lines."""
    if not logger.handlers:
        configure(comm, quiet)


def progress(message: str) -> None:
    """One progress line (INFO level, so --quiet removes it)."""
    logger.info(message)
