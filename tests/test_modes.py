"""Fourier-mode stability of axisymmetric states (bcfem.stability.modes) against closed forms:
Euler buckling of a column (n = 1) and Biot's surface instability (n large)."""

import math

from mpi4py import MPI

import numpy as np
import pytest
from mode_block import Block

from bcfem.mpi import PointEvaluator

pytestmark = pytest.mark.mpi




def critical(unstable, low, high, bisections=16):
    """The load where ``unstable(load)`` (monotone) switches on, by bisection."""
    assert not unstable(low) and unstable(high)
    for _ in range(bisections):
        mid = 0.5 * (low + high)
        low, high = (low, mid) if unstable(mid) else (mid, high)
    return 0.5 * (low + high)


def euler_ratio(slenderness: float, comm=MPI.COMM_WORLD) -> float:
    """Critical strain of a cylinder (radius 1, frictionless ends, free to slide) over the
    Euler strain of a column with guided ends, pi^2 EI / (E A L^2) = pi^2 / (4 L^2)."""
    L = slenderness
    block = Block(0.0, 1.0, L, (2, int(2 * L)),
                  [(0, lambda x: np.isclose(x[0], 0)), (1, lambda x: np.isclose(x[1], 0)),
                   (1, lambda x: np.isclose(x[1], L))], comm=comm)

    def unstable(eps):
        s = 1 - eps
        block.solve(lambda x: np.vstack([(s**-0.5 - 1) * x[0], (s - 1) * x[1]]), [0.0, 0.0, -eps * L])
        return block.modes.unstable(1) > 0

    euler = math.pi**2 / (4 * L**2)
    return critical(unstable, 0.9 * euler, 1.1 * euler) / euler


def test_euler_buckling_is_the_first_mode():
    """n = 1 with a sideways-moving axis: the guided-ends Euler strain, with a correction
    O((R/L)^2) (shear, finite strain) that shrinks as the column gets slender."""
    short, slender = euler_ratio(10.0), euler_ratio(20.0)
    assert abs(short - 1) < 3e-3 and abs(slender - 1) < 1e-3
    assert abs(short - 1) / abs(slender - 1) > 3  # ~4: the (R/L)^2 correction


def biot_stretch() -> float:
    """Neo-Hookean plane-strain surface instability: lambda^2 solves x^3 + x^2 + 3x - 1 = 0."""
    roots = np.roots([1.0, 1.0, 3.0, -1.0])
    return math.sqrt(float(next(r.real for r in roots if abs(r.imag) < 1e-12)))


def surface_wrinkling(cells: int, radius: float = 1000.0, depth: float = 1.0, wavenumber: float = 20.0) -> float:
    """Hoop stretch of the free surface when a thin ring (plane strain in z) compressed in
    the hoop direction first wrinkles with wavenumber k = n / R on its surface."""
    inner = radius - depth
    height = depth / cells
    block = Block(inner, radius, height, (cells, 1),
                  [(0, lambda x: np.isclose(x[0], inner)),
                   (1, lambda x: np.isclose(x[1], 0) | np.isclose(x[1], height))], kappa=1e5)
    n = round(wavenumber * radius)
    surface = PointEvaluator(block.mesh, [radius, 0.0]).expression(block.u[0])

    def unstable(stretch):
        # the incompressible plane-strain state as the first guess: r^2 - r_in^2 = R^2 - R_in^2
        block.solve(lambda x: np.vstack([np.sqrt(stretch**2 * inner**2 + x[0]**2 - inner**2) - x[0], 0 * x[0]]),
                    [(stretch - 1) * inner, 0.0])
        return block.modes.unstable(n) > 0

    # compression: unstable below the critical stretch
    stretch = -critical(lambda s: unstable(-s), -0.65, -0.45)
    unstable(stretch)
    return 1 + surface() / radius


def test_surface_wrinkling_matches_biot_and_converges():
    """A high mode (n = 20000, k = 20 / depth) of a thin curved ring: Biot's plane-strain
    wrinkling stretch 0.5437, approached at a rate > 2 in the element size."""
    stretches = [surface_wrinkling(cells) for cells in (12, 25, 50)]
    changes = [abs(stretches[1] - stretches[0]), abs(stretches[2] - stretches[1])]
    assert changes[0] / changes[1] > 4
    assert stretches[-1] == pytest.approx(biot_stretch(), rel=2e-4)


def test_rest_state_is_stable():
    block = Block(0.0, 1.0, 2.0, (4, 8), [(0, lambda x: np.isclose(x[0], 0)), (1, lambda x: np.isclose(x[1], 0))])
    block.solve(lambda x: 0 * x[:2], [0.0, 0.0])
    assert block.modes.scan(range(1, 6)) == {n: 0 for n in range(1, 6)}
    with pytest.raises(ValueError, match="wave number"):
        block.modes.unstable(0)
    with pytest.raises(ValueError, match="wave numbers"):
        block.modes.scan([1, 2.5])


def test_ranks_agree():
    """The same bisection on all ranks and on one (the inertia is global)."""
    assert euler_ratio(10.0) == pytest.approx(euler_ratio(10.0, MPI.COMM_SELF), rel=1e-5)
