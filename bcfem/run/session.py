"""Reuse of a compiled arc-length problem by parameter points that differ only in Constants.

Composing a model compiles its forms and building its problem creates the PETSc objects;
points of a sweep or a fit that differ only in run-time constants (``fem.Constant``, such
as a surface tension or an adhesion energy) would repeat that work at every point. A
:class:`Session` keeps one composed model with its problem and traces it again for each
point; :class:`Sessions` keeps the session of the last structure key, so a caller that
walks points in order reuses it without knowing where the structure changes.
"""

from __future__ import annotations

import atexit
from collections.abc import Callable, Hashable

from mpi4py import MPI

from bcfem.path.continuation import ArcLength, Branch, ContinuationError
from bcfem.run.trace import branch_of, trace
from bcfem.solver.problem import Problem


class Session:
    """A composed model and, from its first trace on, its arc-length problem.

    Args:
        model: what a scene's states, terms and observables come from; it has a ``ctx``,
            and every scene traced here is built on that context.
    """

    def __init__(self, model):
        self.model = model
        self.arc: ArcLength | None = None
        self.problem: Problem | None = None

    @property
    def comm(self):
        return self.model.ctx.mesh.comm

    def trace(self, scene) -> Branch:
        """Trace ``scene`` from its start, as :func:`bcfem.run.runner.trace` traces a new one.

        The scene holds the point's constants and states (its builder set and reset them).
        The first trace builds the problem; a later one only takes the scene's step control
        and scales, which are Python values and a Constant. A scene with a backward part
        (``begin``) is traced on a problem of its own.

        Raises:
            ContinuationError: as a new trace would; the session stays usable.
        """
        if scene.ctx is not self.model.ctx:
            raise ValueError("the scene is not built on this session's model")
        if scene.begin is not None:
            return branch_of(scene)
        if self.problem is None or self.arc is None:
            self.arc = ArcLength(scene.ctx, scene.load, scene.continuation, scene.load_scale)
            self.problem = Problem(scene.ctx, scene.terms, scene.bcs, scene.prefix, scene.petsc_options,
                                   rows={**scene.rows, **self.arc.rows()}, energy_scale=scene.load_scale)
        else:
            self.arc.params = scene.continuation
            self.arc.load_scale = float(scene.load_scale)
            self.problem.inverse_scale.value = 1.0 / scene.load_scale
        try:
            return trace(scene, arc=self.arc, problem=self.problem)[0]
        except ContinuationError:
            raise  # a failed path leaves nothing behind that the next start does not reset
        except BaseException:
            self.close()  # a problem in an unknown state is built again by the next trace
            raise

    def close(self) -> None:
        """Destroy the problem's PETSc objects now (the model stays, for a later trace)."""
        if self.problem is not None:
            self.problem.close()
        self.problem = self.arc = None


class Sessions:
    """The session of the last structure key on a communicator like the caller's.

    Sweep workers and fits walk points whose structure seldom changes, so one session is
    kept; a new key (or a communicator of other ranks) closes it before composing the next.
    The problem's PETSc objects are destroyed by :meth:`close`, on leaving a ``with`` block,
    on a new key, or at interpreter exit (before PETSc and MPI finalise), never by the
    garbage collector, so ranks cannot destroy collective objects in different orders.
    """

    def __init__(self):
        self._key: Hashable = None
        self._session: Session | None = None
        atexit.register(self.close)

    @property
    def current(self) -> Session | None:
        """The session kept, if any."""
        return self._session

    def get(self, key: Hashable, comm, compose: Callable[[], object]) -> Session:
        """The session of ``key`` on ``comm`` (ranks and order), composing it if needed.

        Args:
            key: equal keys mean that one composed model serves both parameter sets.
            compose: builds the model on ``comm``.
        """
        if self._session is not None and (key != self._key or MPI.Comm.Compare(self._session.comm, comm)
                                          not in (MPI.IDENT, MPI.CONGRUENT)):
            self.close()
        if self._session is None:
            self._session, self._key = Session(compose()), key
        return self._session

    def close(self) -> None:
        if self._session is not None:
            self._session.close()
        self._session = self._key = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
