"""A run's checkpoints, as the command line and a sweep ask for them: in ``<out>/checkpoint``
for ``bcfem run`` (:func:`checkpoints_of`, checked before any meshing), in a sweep point's own
folder for every solve inside that point (:func:`checkpointed`). What they hold and how a path
resumes: :mod:`bcfem.path.checkpoint`."""

from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path

from bcfem.log import logger
from bcfem.path.checkpoint import Checkpoints

#: the checkpoints' folder in a run's directory
FOLDER = "checkpoint"


#: the checkpoints of the sweep point being solved (:func:`checkpointed`), for every solve inside it
_point: ContextVar[Checkpoints | None] = ContextVar("point_checkpoints", default=None)


@contextmanager
def checkpointed(checkpoints: Checkpoints):
    """Every :func:`solve` inside (a sweep point's, however its study solves it) writes and
    resumes from ``checkpoints``; they are the caller's to remove."""
    token = _point.set(checkpoints)
    try:
        yield checkpoints
    finally:
        _point.reset(token)


def checkpoints_of(out: Path, scene: str, parameters: dict, comm, every: float, resume: bool) -> Checkpoints:
    """The checkpoints of a run of ``scene`` into ``out`` (collective): written at most every
    ``every`` seconds; with ``resume``, read from an earlier run of the same parameters there
    (:class:`ResumeError` if they are another run's), else removed."""
    checkpoints = Checkpoints(Path(out) / FOLDER, comm, every, resume,
                              {"scene": scene, **parameters})
    if resume and not checkpoints.resuming:
        logger.info(f"--resume: no checkpoint in {out}: from the start")
    return checkpoints


def point_checkpoints() -> Checkpoints | None:
    """The checkpoints of the sweep point being solved (:func:`checkpointed`), or None."""
    return _point.get()
