"""Pseudo-time relaxation (bcfem.path.relaxation.relax) on a one-unknown body falling to u = 1:
more viscosity for a failed step first, the line-search fallbacks only where that gives up."""

from types import SimpleNamespace

import numpy as np

from bcfem.path.relaxation import relax


class Falling:
    """Pi = k/2 (u - 1)^2 from u = 0; a viscous step solves k (u - 1) + c (u - u_prev) = 0.
    Newton at c = 0 converges within 0.1 of the equilibrium; ``cycles``: every viscous step
    fails unless the line-search fallbacks are asked for (an active set that cycles at any c)."""

    k = 1.0

    def __init__(self, viscosity, cycles: bool):
        self.u = SimpleNamespace(x=SimpleNamespace(array=np.zeros(1)))
        self.knob = SimpleNamespace(value=0.0)  # the context's run-time constant "viscosity"
        self.ctx = SimpleNamespace(u=self.u, constant=lambda name: self.knob)
        self.viscosity, self.cycles = viscosity, cycles
        self.calls = []

    def save(self):
        return [self.u.x.array.copy()]

    def restore(self, saved):
        self.u.x.array[:] = saved[0]

    def solve(self, fallbacks=True):
        c, u = self.knob.value, self.u.x.array
        self.calls.append((c, fallbacks))
        if c == 0:
            if abs(u[0] - 1) > 0.1:
                return False
            u[:] = 1.0
            return True
        new = (self.k + c * u[0]) / (self.k + c)
        if self.cycles and not fallbacks:
            return False
        u[:] = new
        return True


def viscosity_of():
    previous = SimpleNamespace(x=SimpleNamespace(array=np.zeros(1)))
    return SimpleNamespace(previous=previous,
                           increment=lambda ctx: abs(ctx.u.x.array[0] - previous.x.array[0]))


def falling(cycles: bool) -> tuple[Falling, SimpleNamespace]:
    viscosity = viscosity_of()
    return Falling(viscosity, cycles), viscosity


def test_a_failed_step_takes_more_viscosity_not_line_searches():
    problem, viscosity = falling(cycles=False)
    converged, steps, dissipated = relax(problem, viscosity, stiffness=0.1)
    assert converged and problem.u.x.array[0] == 1.0
    # the viscous work, sum of c du^2, is below the energy released (k/2: a proximal step's
    # energy falls by at least c du^2, the last Newton step's share is undissipated)
    assert 0 < dissipated < 0.5 * problem.k
    assert not [c for c, fallbacks in problem.calls if c > 0 and fallbacks]


def test_where_viscosity_alone_gives_up_the_fallbacks_are_tried_from_the_start():
    """Every step fails without line searches: c grows to its cap (the first ladder gives
    up), and the relaxation starts again from u = 0 with the fallbacks."""
    problem, viscosity = falling(cycles=True)
    converged, _, _ = relax(problem, viscosity, stiffness=1e-3)
    assert converged and problem.u.x.array[0] == 1.0
    first_with = next(i for i, (c, fallbacks) in enumerate(problem.calls) if c > 0 and fallbacks)
    # the second ladder's first step starts at the initial c again, from the saved state
    assert problem.calls[first_with][0] == 1e-3
    assert max(c for c, _ in problem.calls[:first_with]) > 1e6 * 1e-3 / 4
