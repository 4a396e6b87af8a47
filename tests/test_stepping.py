"""LoadPath bookkeeping: a trial path from a mark leaves no trace once rewound."""

import numpy as np
import pytest

from bcfem.path.stepping import LoadPath, SteppingError


class Quadratic:
    """A stand-in for Problem: the state follows the load exactly (u = load)."""

    iterations = 1
    rejections = 0  # converged states a term vetoed (Problem's count)

    def __init__(self):
        self.timings = {"stability": 0.0}
        self.u = np.zeros(3)
        self.load = 0.0

    def save(self):
        return [self.u.copy()]

    def restore(self, saved):
        self.u[:] = saved[0]

    def solve(self, fallbacks=True):
        self.u[:] = self.load
        return True

    def energy(self):
        return 0.5 * float(self.u @ self.u)


def test_rewind_restores_state_load_snaps_and_events():
    problem = Quadratic()
    path = LoadPath(problem, lambda v: setattr(problem, "load", v), "load", check_stability=False)
    path.start()
    path.advance(0.0, 0.5, 0.1)
    mark = path.mark(0.5)
    # a trial path: it moves on, snaps twice and reports an event
    path.advance(0.5, 0.8, 0.1)
    path.snaps += 2
    path.events.append({"stage": "load", "load": 0.7, "kind": "snap", "unstable": None, "detail": "trial"})
    assert path.rewind(mark) == 0.5
    assert problem.load == 0.5 and np.all(problem.u == 0.5)
    assert path.snaps == 0 and path.events == []
    # the next path starts from the mark, and a failed step would restore the mark's state
    assert path.advance(0.5, 0.6, 0.1) == 0.6 and np.all(problem.u == 0.6)


def test_waves_events_and_their_rewind(monkeypatch):
    """A waves check reports each change of the set of unstable n, and whether some n has
    more unstable modes than the axisymmetric count; rewinding restores the set."""
    import bcfem.path.stepping as stepping

    problem = Quadratic()
    monkeypatch.setattr(stepping, "unstable_modes", lambda p, multipliers, held=(): int(p.load >= 0.3 - 1e-12))

    def waves():
        return {1: int(problem.load >= 0.3 - 1e-12), 2: 2 * int(problem.load >= 0.5 - 1e-12), 3: 0}

    path = LoadPath(problem, lambda v: setattr(problem, "load", v), "load", waves=waves)
    path.start()
    path.advance(0.0, 0.4, 0.1)
    mark = path.mark(0.4)
    path.advance(0.4, 0.7, 0.1)
    found = [(e["load"], e["waves"], e["breaks_symmetry"]) for e in path.events if e["kind"] == "waves"]
    assert [(w, b) for _, w, b in found] == [([1], False), ([1, 2], True)]  # n = 1 copies the axisymmetric mode
    assert 0.3 <= found[0][0] <= 0.4 and 0.5 <= found[1][0] <= 0.7
    assert "n = 1 -> 1-2" in path.events[-1]["detail"]
    path.rewind(mark)
    assert path.unstable_waves == (1,) and path.unstable == 1 and len(path.events) == 2


def test_a_failed_relaxation_is_not_repeated_from_the_same_state(monkeypatch):
    """Relaxation goes to a full first step beyond the last accepted state whatever the cut, so
    once it failed from that state it would fail again: further cuts only retry Newton."""
    import bcfem.path.stepping as stepping

    class Wall(Quadratic):
        failure = "SNES reason -5"  # iteration limit

        def solve(self, fallbacks=True):  # no equilibrium beyond 0.25
            if self.load > 0.25 + 1e-12:
                return False
            return super().solve()

    calls = []
    monkeypatch.setattr(stepping, "relax", lambda *args: calls.append(args) or (False, 1, 0.0))
    problem = Wall()
    path = LoadPath(problem, lambda v: setattr(problem, "load", v), "load", viscosity=object(),
                    check_stability=False)
    path.start()
    with pytest.raises(SteppingError) as failure:
        path.advance(0.0, 1.0, 0.1)
    assert failure.value.reached == pytest.approx(0.25)
    assert "(SNES reason -5)" in str(failure.value)
    assert len(calls) == 1


def test_line_search_fallbacks_only_once_cutting_has_not_helped():
    """A line search can land on another branch where a cut step stays on this one, so the
    problem's fallbacks are asked for only below first_step / 2**cuts_before_relax."""

    class Recording(Quadratic):
        failure = "SNES reason -5"

        def __init__(self):
            super().__init__()
            self.asked = []

        def solve(self, fallbacks=True):
            self.asked.append((self.load, fallbacks))
            return self.load <= 0.1 + 1e-12 and super().solve()

    problem = Recording()
    path = LoadPath(problem, lambda v: setattr(problem, "load", v), "load", check_stability=False)
    path.start()
    with pytest.raises(SteppingError):
        path.advance(0.0, 1.0, 0.1)
    first_step = 0.1
    for load, fallbacks in problem.asked[1:]:  # after the accepted step to 0.1
        step = load - 0.1
        assert fallbacks == (step < first_step * 0.5**path.cuts_before_relax - 1e-15), (step, fallbacks)
    assert any(f for _, f in problem.asked) and not all(f for _, f in problem.asked)


def test_the_error_says_when_converged_states_were_rejected():
    """Beyond 0.25 Newton converges, but a term vetoes every state (a wall through itself):
    the stepper cuts back, then fails, and says that and why rather than only the last
    SNES reason."""

    class Vetoed(Quadratic):
        failure = "converged to an inadmissible state: through itself"
        rejections, last_rejection = 0, None

        def solve(self, fallbacks=True):
            if self.load > 0.25 + 1e-12:
                self.rejections += 1
                self.last_rejection = "through itself"
                return False
            return super().solve()

    problem = Vetoed()
    path = LoadPath(problem, lambda v: setattr(problem, "load", v), "load", check_stability=False)
    path.start()
    with pytest.raises(SteppingError) as failure:
        path.advance(0.0, 1.0, 0.1)
    assert failure.value.reached == pytest.approx(0.25)
    assert f"; {problem.rejections} converged states on the way were rejected, the last as: through itself" \
        in str(failure.value)
    assert problem.rejections > 10  # every cut was tried


def test_through_passes_the_same_checkpoints_whatever_the_end():
    """Two paths to different ends, and one that starts between checkpoints, pass the
    checkpoints k * step; the path ends exactly at its end; an accept that returns True
    stops it there."""
    def visited(start, end, step, stop=None):
        problem = Quadratic()
        problem.u[:] = problem.load = start
        path = LoadPath(problem, lambda v: setattr(problem, "load", v), "load", check_stability=False)
        path.start()
        seen = []

        def accept(value):
            seen.append(value)
            return stop is not None and value >= stop - 1e-12

        return path.through(start, end, step, accept), seen

    end, seen = visited(0.0, 0.3, 0.1)
    assert end == pytest.approx(0.3) and seen == pytest.approx([0.1, 0.2, 0.3])
    end, seen = visited(0.0, 0.25, 0.1)
    assert end == pytest.approx(0.25) and seen == pytest.approx([0.1, 0.2, 0.25])
    end, seen = visited(0.15, 0.35, 0.1)
    assert seen == pytest.approx([0.2, 0.3, 0.35])
    end, seen = visited(0.3, -0.05, 0.1)  # backwards, past zero
    assert seen == pytest.approx([0.2, 0.1, 0.0, -0.05])
    end, seen = visited(0.0, 1.0, 0.1, stop=0.4)
    assert end == pytest.approx(0.4) and seen[-1] == pytest.approx(0.4)


def test_bisect_locates_an_event_of_the_state_and_ends_past_it():
    """u = load; the event 'u >= 0.237' is bracketed by the checkpoints 0.2 and 0.3 and
    bisected 20 times: the located load is within 0.1 * 2**-20 above the event, the state
    is the one found past it, and trial states below the event leave no trace."""
    problem = Quadratic()
    path = LoadPath(problem, lambda v: setattr(problem, "load", v), "load", check_stability=False)
    path.start()
    path.advance(0.0, 0.2, 0.2)
    before = path.mark(0.2)
    path.advance(0.2, 0.3, 0.1)
    trials = []

    def passed(load):
        trials.append(load)
        return problem.u[0] >= 0.237

    located = path.bisect(before, 0.3, passed, bisections=20)
    assert 0.237 <= located <= 0.237 + 0.1 * 2**-20
    assert np.all(problem.u == located) and problem.load == located and len(trials) == 20


def test_root_locates_a_zero_of_the_state_from_a_mark():
    """u = load, f = u^2 - 0.05 between the mark at 0.3 and 0.2: the root sqrt(0.05) is found
    to xtol, every evaluation starting from the mark, and the path ends at the root."""
    problem = Quadratic()
    starts = []

    def set_load(value):
        problem.load = value

    path = LoadPath(problem, set_load, "load", check_stability=False)
    path.start()
    path.advance(0.0, 0.3, 0.3)
    mark = path.mark(0.3)
    path.advance(0.3, 0.2, 0.1)

    def f():
        return problem.u[0] ** 2 - 0.05

    original = path.rewind

    def rewind(m):
        starts.append(m["value"])
        return original(m)

    path.rewind = rewind
    root = path.root(mark, 0.2, f, xtol=1e-12)
    assert root == pytest.approx(np.sqrt(0.05), abs=1e-11)
    assert np.all(problem.u == root) and set(starts) == {0.3}


class Fold(Quadratic):
    """Unloading past a snap: branch A (u = load + 1) ends below load 0.25, branch B
    (u = load) above 0.28; a solve stays on the branch of the state it starts from."""

    failure = "SNES reason -5"

    def solve(self, fallbacks=True):
        on_a = self.u[0] > 0.9
        if (on_a and self.load < 0.25) or (not on_a and self.load > 0.28):
            return False
        self.u[:] = self.load + (1.0 if on_a else 0.0)
        return True


def test_root_past_a_snap_continues_on_the_branch_fallen_onto(monkeypatch):
    """f = 0.23 - u vanishes at 0.23 on branch B, which the path fell onto by a relaxation
    between the mark (0.3, branch A) and 0.2: each evaluation follows A from the mark while
    A lasts and B from 0.2 below it, without relaxing again, and the path ends on B."""
    import bcfem.path.stepping as stepping

    relaxations = []

    def relax(problem, viscosity, stiffness):
        relaxations.append(problem.load)
        problem.u[:] = problem.load  # falls onto B
        return True, 1, 0.01

    monkeypatch.setattr(stepping, "relax", relax)
    problem = Fold()
    problem.load, problem.u[:] = 0.4, 1.4
    path = LoadPath(problem, lambda v: setattr(problem, "load", v), "unload", viscosity=object(),
                    check_stability=False)
    path.start()
    path.advance(0.4, 0.3, 0.1)
    mark = path.mark(0.3)
    path.advance(0.3, 0.2, 0.1)
    assert path.snaps == 1 and len(relaxations) == 1 and problem.u[0] == 0.2
    # the snap reports the relaxation's dissipated energy over the energy it landed on
    snap = next(e for e in path.events if e["kind"] == "snap")
    assert snap["dissipated_fraction"] == pytest.approx(0.01 / problem.energy())
    branches = []

    def f():
        branches.append(round(problem.u[0] - problem.load))  # 1 on A, 0 on B
        return 0.23 - problem.u[0]

    root = path.root(mark, 0.2, f, xtol=1e-12)
    assert root == pytest.approx(0.23, abs=1e-11)
    assert problem.u[0] == root and path.snaps == 1 and len(relaxations) == 1
    assert set(branches) == {0, 1}  # A above 0.25 (B reaches to 0.28)


class Recording(Quadratic):
    """Records the state each solve starts from, and takes ``its`` Newton iterations."""

    def __init__(self, its=1):
        super().__init__()
        self.starts, self.iterations = [], its

    def solve(self, fallbacks=True):
        self.starts.append(self.u[0])
        return super().solve(fallbacks)


@pytest.mark.parametrize("predict", [False, True])
def test_the_secant_predictor_starts_newton_on_the_line_through_the_last_two_states(predict):
    problem = Recording()
    path = LoadPath(problem, lambda v: setattr(problem, "load", v), "load", check_stability=False,
                    predict=predict)
    path.start()
    path.advance(0.0, 0.3, 0.1)  # steps 0.1, 0.15 (grown by 1.5), then 0.05 to the end
    # without: each solve starts from the last state; with: on the secant, exact here (u = load)
    # from the second step on (the first has only the start state)
    expected = [0.0, 0.25, 0.3] if predict else [0.0, 0.1, 0.25]
    assert problem.starts == pytest.approx(expected, abs=1e-15)
    # a rewind forgets the secant: the next step starts from the mark
    mark = path.mark(0.3)
    path.rewind(mark)
    path.advance(0.3, 0.4, 0.1)
    assert problem.starts[-1] == pytest.approx(0.3, abs=1e-15)


@pytest.mark.parametrize("its, growth", [(3, 1.5), (8, 1.0), (16, 0.5)])
def test_adapted_steps_follow_newtons_iterations(its, growth):
    problem = Recording(its)
    loads = []
    path = LoadPath(problem, lambda v: (setattr(problem, "load", v), loads.append(v)), "load",
                    check_stability=False, adapt_steps=True)
    path.start()
    path.advance(0.0, 1.0, 0.1, lambda v: len(loads) >= 3)
    steps = np.diff([0.0, *loads[:3]])
    assert steps[1:] == pytest.approx(0.1 * growth ** np.arange(1, 3), rel=1e-12)
