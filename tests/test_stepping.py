"""LoadPath bookkeeping: a trial path from a mark leaves no trace once rewound."""

import numpy as np

from bcfem.stepping import LoadPath


class Quadratic:
    """A stand-in for Problem: the state follows the load exactly (u = load)."""

    def __init__(self):
        self.u = np.zeros(3)
        self.load = 0.0

    def save(self):
        return [self.u.copy()]

    def restore(self, saved):
        self.u[:] = saved[0]

    def solve(self):
        self.u[:] = self.load
        return True


def test_rewind_restores_state_load_snaps_and_events():
    problem = Quadratic()
    path = LoadPath(problem, lambda v: setattr(problem, "load", v), "load", check_stability=False)
    path.start()
    path.advance(0.0, 0.5, 0.1)
    mark = path.mark(0.5)
    # a trial path: it moves on, snaps twice and reports an event
    path.advance(0.5, 0.8, 0.1)
    path.snaps += 2
    path.events.append({"stage": "load", "eps": 0.7, "kind": "snap", "unstable": None, "detail": "trial"})
    assert path.rewind(mark) == 0.5
    assert problem.load == 0.5 and np.all(problem.u == 0.5)
    assert path.snaps == 0 and path.events == []
    # the next path starts from the mark, and a failed step would restore the mark's state
    assert path.advance(0.5, 0.6, 0.1) == 0.6 and np.all(problem.u == 0.6)
