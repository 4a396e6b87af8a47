"""Seconds PETSc itself spent factorising and solving, from its event log.

Logging is begun once (``PETSc.Log.begin``: a clock per event, no output) so that every
run can split its Newton time into the direct solver's part and the rest.
"""

from __future__ import annotations

from petsc4py import PETSc

#: PETSc events of each part (MUMPS and PETSc's own factorisations log the same ones)
EVENTS = {"factorisation": ("MatLUFactorSym", "MatLUFactorNum", "MatCholFctrSym", "MatCholFctrNum"),
          "linear_solve": ("MatSolve",)}

_events: dict | None = None


def seconds() -> dict[str, float]:
    """The cumulative seconds of each part of :data:`EVENTS` on this rank."""
    global _events
    if _events is None:
        PETSc.Log.begin()
        _events = {part: [PETSc.Log.Event(name) for name in names] for part, names in EVENTS.items()}
    return {part: sum(event.getPerfInfo()["time"] for event in events) for part, events in _events.items()}
