"""Load stepping under displacement control, for paths with contact and snaps.

Arc-length continuation (:mod:`bcfem.path.continuation`) traces smooth branches
through folds. A contact problem's branch is not smooth: the active set
changes and the body can lose stability to a crease or a sliding rim, after
which it falls to another state. This stepper moves a load parameter towards
a target in adaptive steps:

* a converged step is accepted and the next one grows;
* a failed step is halved and retried from the last accepted state;
* once the step has been halved to ``2**-cuts_before_relax`` of the first one
  (failures in a row, or Newton creeping towards a point it cannot pass), the
  load moves a full first step on by pseudo-time relaxation
  (:func:`bcfem.path.relaxation.relax`), which lets the body move downhill at the
  new load until Newton converges on an equilibrium; this is reported as a ``snap`` event;
* :meth:`LoadPath.through` passes fixed checkpoints (k times a step), so runs to
  different targets share their states on the way; :meth:`LoadPath.bisect` locates
  where a predicate of the state turns true, and :meth:`LoadPath.root` where a
  function of the state vanishes, each from a :meth:`LoadPath.mark`;
* after each accepted step the inertia of the tangent is checked
  (:func:`bcfem.stability.inertia.unstable_modes`); a change in the number of
  unstable modes is reported as an event, and so is a change in the set of
  unstable non-axisymmetric wave numbers when a ``waves`` check is given
  (:class:`bcfem.stability.modes.ModeAnalysis`).

Nothing unconverged is ever accepted; when every retry fails the stepper
raises with the last accepted value.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from bcfem import jit
from bcfem.log import progress
from bcfem.path.relaxation import relax
from bcfem.path.roots import bracketed_root
from bcfem.physics.viscosity import Viscosity
from bcfem.stability.inertia import unstable_modes

if TYPE_CHECKING:
    from bcfem.solver.problem import Problem


class SteppingError(RuntimeError):
    """No converged state beyond ``reached``."""

    def __init__(self, message: str, reached: float):
        super().__init__(message)
        self.reached = reached


@dataclass
class LoadPath:
    """Adaptive stepping of one load parameter of ``problem``.

    Attributes:
        problem: the Problem (its states are restored after a failed step).
        set_load: sets the load parameter (e.g. a platen displacement).
        stage: a label for events and messages.
        load_name: the load's name in events (e.g. ``eps``, a platen strain).
        viscosity: the problem's Viscosity term (None: no relaxation).
        relax_stiffness: initial viscosity c of a relaxation.
        multipliers: names of multiplier states, for the stability count (None: the ones
            the problem's terms declare).
        cuts: halvings before giving up; cuts_before_relax: before relaxing.
        max_snaps: relaxations allowed along the path (a crease that keeps deepening
            would otherwise snap again at every step).
        check_stability: count unstable modes after each accepted step.
        waves: None, or a callable giving {n: unstable modes with n waves} at the current
            state (checked with the axisymmetric count).
        held: states held fixed in the stability count (an arc-length load parameter).
        predict: start Newton from the secant through the last two accepted states.
        adapt_steps: size the next step by this one's Newton iterations (:meth:`_growth`)
            rather than growing it by 1.5 always.
        Both change where a path that loses stability lands, so they are off by default.
    """

    problem: Problem
    set_load: Callable[[float], None]
    stage: str
    viscosity: Viscosity | None = None
    relax_stiffness: float = 1.0
    multipliers: list | None = None
    cuts: int = 12
    cuts_before_relax: int = 3
    check_stability: bool = True
    max_snaps: int = 6
    events: list = field(default_factory=list)
    waves: Callable[[], dict] | None = None
    load_name: str = "load"
    unstable: int = 0
    unstable_waves: tuple = ()
    snaps: int = 0
    bracket: tuple | None = None
    predict: bool = False
    adapt_steps: bool = False
    held: tuple = ()
    _previous: tuple | None = field(default=None, init=False, repr=False)
    _saved: list = field(default_factory=list, init=False, repr=False)

    def solve_at(self, value: float, fallbacks: bool) -> bool:
        self.set_load(value)
        return self.problem.solve(fallbacks=fallbacks)

    @staticmethod
    def _growth(iterations: int) -> float:
        """The next step over this one, from Newton's iterations for this one: grow while it
        converges fast, hold and then shrink as it slows (a step that takes most of
        ``snes_max_it`` is close to one that fails, and a failure costs them all)."""
        return 1.5 if iterations <= 6 else 1.0 if iterations <= 10 else 0.5

    def _predict(self, current: float, trial: float) -> None:
        """From the last accepted state at ``current``, step along the secant through the one
        before it towards ``trial`` (states only: the load is set by the solve). Nothing to
        extrapolate after a start, a rewind or a snap."""
        previous = self._previous
        self.problem.restore(self._saved)
        if not self.predict or previous is None or previous[0] == current:
            return
        ratio = (trial - current) / (current - previous[0])
        if not 0 < ratio <= 2:  # only on along the way the path came, and not far
            return
        self.problem.restore([now + ratio * (now - before) for now, before in zip(self._saved, previous[1])])

    def advance(self, start: float, target: float, step: float,
                on_accept: Callable[[float], bool | None] | None = None) -> float:
        """Step from ``start`` to ``target`` (either direction); ``on_accept(value)`` may
        return True to stop early. Returns the last accepted value."""
        direction = 1.0 if target >= start else -1.0
        current, step = start, abs(step)
        first = step
        smallest = step * 0.5**self.cuts
        relax_failed_from = None
        rejections = self.problem.rejections
        while (target - current) * direction > 0:
            trial = current + direction * min(step, abs(target - current))
            # the problem's line-search fallbacks only once cutting the step has not helped:
            # where a cut step converges, a line search may instead land on another branch
            stuck = step < first * 0.5**self.cuts_before_relax
            self._predict(current, trial)
            ok = self.solve_at(trial, fallbacks=stuck)
            if not ok:
                self.problem.restore(self._saved)
            snapped = False
            # a relaxation that failed from this state would fail again: it goes to the same load
            if not ok and stuck and self.viscosity is not None \
                    and relax_failed_from != current:
                # Newton creeps towards a point it cannot pass (a snap): relax at a load a
                # full first step on, past it
                trial = current + direction * min(first, abs(target - current))
                self.set_load(trial)
                converged, steps, dissipated = relax(self.problem, self.viscosity, self.relax_stiffness)
                if converged:
                    ok = snapped = True
                    self.snaps += 1
                    if self.snaps > self.max_snaps:
                        raise SteppingError(f"{self.stage}: more than {self.max_snaps} snaps (the path keeps "
                                            f"losing stability, e.g. a deepening crease) at {trial:.5g}", current)
                    stored = max(abs(self.problem.energy()), 1e-300)
                    self.events.append({"stage": self.stage, self.load_name: trial, "kind": "snap", "unstable": None,
                                        "detail": f"passed by pseudo-time relaxation ({steps} steps), which "
                                                  f"dissipated {dissipated / stored:.2%} of the stored energy",
                                        "dissipated_fraction": dissipated / stored})
                else:
                    self.problem.restore(self._saved)
                    relax_failed_from = current
            if not ok:
                step *= 0.5
                if step < smallest:
                    self.set_load(current)
                    rejected = self.problem.rejections - rejections
                    raise SteppingError(
                        f"{self.stage}: no converged state beyond {current:.5g} towards {target:.5g} "
                        f"after {self.cuts} cut-backs and relaxation ({self.problem.failure})"
                        + (f"; {rejected} converged states on the way were rejected, the last as: "
                           f"{self.problem.last_rejection}" if rejected else ""), current)
                continue
            self._previous = None if snapped else (current, self._saved)
            current = trial
            self._saved = self.problem.save()
            if not snapped:
                step *= self._growth(self.problem.iterations) if self.adapt_steps else 1.5
            self.inspect(current)
            progress(f"{self.stage} {current:.5f}  its={self.problem.iterations}  unstable={self.unstable}"
                     f"  snaps={self.snaps}" + ("  (snap)" if snapped else ""))
            if on_accept is not None and on_accept(current):
                break
        return current

    def through(self, start: float, end: float, step: float,
                on_accept: Callable[[float], bool | None] | None = None) -> float:
        """Advance from ``start`` to ``end`` through the checkpoints k * step, so that every run
        passes the same load states whatever its end (sweep points share one path). Stops
        early when ``on_accept`` returns True; returns the last accepted value."""
        sign = 1.0 if end >= start else -1.0
        k = math.floor(start / step + 1e-9) + 1 if sign > 0 else math.ceil(start / step - 1e-9) - 1
        current, stopped = start, False

        def accept(value):
            nonlocal stopped
            stopped = bool(on_accept(value)) if on_accept else False
            return stopped

        keeper: Any = getattr(self.problem, "checkpoints", None)  # a stand-in problem may have none
        key = keeper.key() if keeper is not None else None
        saved = keeper.read(key, self.problem.states) if keeper is not None else None
        if saved is not None:  # a resumed run: on from this path's last checkpoint
            current, k = self._resume(saved.record, saved.vectors[0])
            keeper.jump(saved)
            accept(current)  # its row again (checked against the stored one) and the caller's marks
            keeper.landed(saved)
        while (end - current) * sign > 1e-12 and not stopped:
            checkpoint = k * step
            target = checkpoint if (end - checkpoint) * sign > 1e-12 else end
            current = self.advance(current, target, abs(target - current), accept)
            k += int(sign)
            if keeper is not None and not stopped and abs(current - target) <= 1e-12 * max(1.0, abs(target)) \
                    and keeper.due():
                keeper.write(key, self.problem.states, [self._saved], self._record(current, k))
        return current

    def _record(self, value: float, k: int) -> dict:
        """What a checkpoint keeps of the path at load ``value`` besides its states: enough to
        go on as :meth:`through` would from there (``k``: the next checkpoint's index)."""
        return {"stage": self.stage, "value": value, "k": k, "snaps": self.snaps, "unstable": self.unstable,
                "waves": list(self.unstable_waves), "events": [dict(e) for e in self.events]}

    def _resume(self, record: dict, states: list) -> tuple[float, int]:
        """Back to a checkpoint's state and record (:meth:`_record`); returns (its load, k)."""
        self.problem.restore(states)
        self._saved, self._previous = self.problem.save(), None
        self.set_load(record["value"])
        self.snaps, self.unstable = record["snaps"], record["unstable"]
        self.unstable_waves = tuple(record["waves"])
        self.events[:] = record["events"]
        return record["value"], record["k"]

    def bisect(self, before: dict, after: float, passed: Callable[[float], bool], bisections: int,
               end_before: bool = False) -> float:
        """Where ``passed`` (a predicate of the state at a load) turns true, between the
        :meth:`mark` ``before`` (not passed) and the current state at load ``after`` (passed):
        ``bisections`` halvings of the bracket, or fewer if Newton cannot reach a midpoint (the
        event is then a snap inside the bracket). Each trial starts from the last state before
        the event; the path ends at the first state found past it, whose load is returned (with
        ``end_before``: at the last state found before it). ``bracket`` keeps the final
        (before, after) loads."""
        past = self.mark(after)
        for _ in range(bisections):
            low = self.rewind(before)
            middle = 0.5 * (low + after)
            try:
                self.advance(low, middle, middle - low)
            except SteppingError:
                break
            if passed(middle):
                after, past = middle, self.mark(middle)
            else:
                before = self.mark(middle)
        self.rewind(before if end_before else past)
        self.bracket = (before["value"], after)
        return before["value"] if end_before else after

    def root(self, before: dict, after: float, function: Callable[[], float], xtol: float) -> float:
        """The load between the :meth:`mark` ``before`` and the current state at ``after`` where
        ``function`` (of the current state) vanishes, to ``xtol``
        (:func:`bcfem.path.roots.bracketed_root`). Every evaluation goes from ``before`` as the path
        came, so there is no hysteresis between evaluations. Where that branch ends (a fold
        between ``before`` and the load), the evaluation continues from the state at ``after``,
        the branch the path went on to, rather than passing the fold by a relaxation again
        at every evaluation; only where neither reaches does it relax. The path ends at the
        root's state."""
        landed = self.mark(after)

        def at(load):
            if not (self._reach(before, load) or self._reach(landed, load)):
                start = self.rewind(before)
                self.advance(start, load, abs(load - start))
            return function()

        load = bracketed_root(at, after, before["value"], xtol=xtol)
        at(load)
        return load

    def _reach(self, mark: dict, load: float) -> bool:
        """Whether the path goes from ``mark`` to ``load`` on its branch: the steps of
        :meth:`advance` up to where it would relax instead; it ends there if so."""
        start = self.rewind(mark)
        viscosity, cuts = self.viscosity, self.cuts
        self.viscosity, self.cuts = None, min(self.cuts, self.cuts_before_relax + 1)
        try:
            self.advance(start, load, abs(load - start))
            return True
        except SteppingError:
            return False
        finally:
            self.viscosity, self.cuts = viscosity, cuts

    def mark(self, value: float) -> dict:
        """The accepted state at load ``value`` with the path's record (snaps, events,
        stability), to come back to with :meth:`rewind`."""
        return {"value": value, "state": self.problem.save(), "snaps": self.snaps,
                "events": len(self.events), "unstable": self.unstable, "waves": self.unstable_waves}

    def rewind(self, mark: dict) -> float:
        """Back to a :meth:`mark`: the state, the load and the record, so that trial paths
        from it (a bisection, a root search) neither count their snaps twice nor report
        events the final path did not pass. Returns the mark's load."""
        self.problem.restore(mark["state"])
        self._saved, self._previous = self.problem.save(), None
        self.set_load(mark["value"])
        self.snaps, self.unstable, self.unstable_waves = mark["snaps"], mark["unstable"], mark["waves"]
        del self.events[mark["events"]:]
        return mark["value"]

    def start(self) -> None:
        """Take the current state as the first accepted one."""
        self._saved, self._previous = self.problem.save(), None
        if self.check_stability:
            self.unstable = unstable_modes(self.problem, self.multipliers, held=self.held)
            if self.waves is not None:
                self.unstable_waves = _unstable_waves(self.waves())

    def inspect(self, value: float) -> None:
        """Count the unstable modes at the current state (load ``value``); a change is an event."""
        if not self.check_stability:
            return
        unstable = unstable_modes(self.problem, self.multipliers, held=self.held)
        if unstable != self.unstable:
            self.events.append({"stage": self.stage, self.load_name: value, "kind": "stability", "unstable": unstable,
                                "detail": f"unstable axisymmetric modes {self.unstable} -> {unstable}"})
            self.unstable = unstable
        if self.waves is None:
            return
        clock = jit.Clock()
        counts = self.waves()
        self.problem.timings["stability"] += clock.seconds()
        waves = _unstable_waves(counts)
        if waves != self.unstable_waves:
            # more unstable directions with n waves than axisymmetric ones: the loss of stability
            # is not (only) an axisymmetric mode's, so symmetry breaks
            most = max(counts.values(), default=0)
            self.events.append({"stage": self.stage, self.load_name: value, "kind": "waves", "unstable": most,
                                "waves": list(waves), "breaks_symmetry": most > self.unstable,
                                "detail": f"unstable wave numbers n = {_ranges(self.unstable_waves)} -> "
                                          f"{_ranges(waves)} (at most {most} modes per n, {self.unstable} "
                                          f"axisymmetric)"})
            self.unstable_waves = waves


def _unstable_waves(counts: dict) -> tuple:
    return tuple(sorted(n for n, c in counts.items() if c > 0))


def _ranges(waves) -> str:
    """(2, 3, 4, 7) -> '2-4, 7'; () -> 'none'."""
    parts, start = [], None
    for i, n in enumerate(waves):
        if start is None:
            start = n
        if i + 1 == len(waves) or waves[i + 1] != n + 1:
            parts.append(f"{start}" if start == n else f"{start}-{n}")
            start = None
    return ", ".join(parts) or "none"
