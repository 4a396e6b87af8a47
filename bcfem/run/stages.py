"""A scene's stages as data, and the loop that runs them.

A :class:`Stage` says what a stage changes and what drives it: what happens on entering it
(``enter``: seal a cavity, switch a fluid), the terms its problem holds, what is set on the
problem once built (``prepare``: contact bounds, a force to measure), and the path that drives
it to its end (``drive``: load steps to a preload, a retraction to zero force). A
:class:`StagedScene` builds its model, declares its stages, and :meth:`StagedScene.solve`
runs them in order, each as one problem under the prefix ``bcfem_<scene>_<stage>_``, as
PyBaMM's ``Simulation`` runs the steps of an ``Experiment``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from bcfem.run.scene import Scene


@dataclass(frozen=True)
class Stage:
    """One stage of a scene.

    Attributes:
        name: the stage's name (its PETSc prefix ``bcfem_<scene>_<name>_``).
        terms: the stage's energy terms, built when it is entered (after ``enter``).
        drive: follows the stage's path on its problem, recording rows into the run; it
            ends the stage (returns) where the stage's end condition holds, or returns True
            to enter the stage again with its terms built anew (a fluid that changes phase).
        ends: what ends the stage, in words (the scene's help and docs).
        enter: what happens on entering the stage, before its terms are built; returning
            False skips the stage (nothing left to do, e.g. a crater that stays closed).
        prepare: what is set on the stage's problem before it is driven.
        petsc_options: the stage's PETSc defaults (the user's options still win).
    """

    name: str
    terms: Callable[[], list]
    drive: Callable[[Any, Any], bool | None]
    ends: str
    enter: Callable[[], bool | None] | None = None
    prepare: Callable[[Any], None] | None = None
    petsc_options: dict = field(default_factory=dict)


class StagedScene(Scene):
    """A scene whose solve is its stages in order. A subclass sets ``name``, ``columns``,
    ``stages`` (the names it plans) and ``params``, builds its model in :meth:`setup` and returns its stages
    from :meth:`plan`; ``model.ctx``, ``model.bcs`` and :attr:`problem_options` are shared by
    every stage. :attr:`extra_terms` (a research script's) join the terms of every stage they
    belong to (:meth:`bcfem.physics.protocols.Term.belongs_to`)."""

    model: Any = None
    extra_terms: tuple = ()

    @property
    def problem_options(self) -> dict:
        """Keyword arguments of every stage's :class:`~bcfem.solver.problem.Problem`."""
        return {}

    def setup(self, run) -> None:
        """Build the model (mesh, states) and record what the run reports before any stage."""
        raise NotImplementedError

    def plan(self) -> list[Stage]:
        """The stages, in order (called once the model is built)."""
        raise NotImplementedError

    def finish(self, run) -> None:
        """Summary entries once every stage has ended."""

    def solve(self, run) -> None:
        self.setup(run)
        stages = self.plan()
        undeclared = [s.name for s in stages if s.name not in self.stages]
        if undeclared:
            raise ValueError(f"scene {self.name!r} plans the undeclared stages {undeclared}")
        for stage in stages:
            if stage.enter is not None and stage.enter() is False:
                continue
            again = True
            while again:
                options = {**self.problem_options}
                petsc = {**options.pop("petsc_options", {}), **stage.petsc_options}
                terms = [*stage.terms(), *(t for t in self.extra_terms if t.belongs_to(stage.name))]
                with run.stage(stage.name, self.model.ctx, terms, self.model.bcs, petsc, **options) as problem:
                    if stage.prepare is not None:
                        stage.prepare(problem)
                    again = bool(stage.drive(problem, run))
        self.finish(run)

