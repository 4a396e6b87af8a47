"""The contact edge inside an element (:mod:`bcfem.contact.plate_edge`): closed-form Hertz and
flat-punch gaps sampled on P2 node layouts, the gather over ranks, and the crater's F~ at
eps = 0.2 over meshes (``convergence``)."""

from __future__ import annotations

import dataclasses
import math

from mpi4py import MPI

import numpy as np
import pytest

from bcfem.contact.plate_edge import edge_radius, plate_edge


def hertz_gap(r, c, R=1.0):
    """Gap outside a Hertz contact of radius c (sphere of radius R on a half-space, Johnson
    eq. 3.42): g = r²/2R - c²/R + [(2c² - r²) asin(c/r) + c sqrt(r² - c²)] / (πR), 0 inside."""
    r = np.asarray(r, dtype=float)
    g = np.zeros_like(r)
    o = r > c
    ro = r[o]
    g[o] = ro**2 / (2 * R) - c**2 / R + ((2 * c**2 - ro**2) * np.arcsin(c / ro) + c * np.sqrt(ro**2 - c**2)) / (
        np.pi * R)
    return g


def punch_gap(r, c, depth=1.0):
    """Gap outside a flat punch of radius c pressed to ``depth``: δ (1 - 2/π asin(c/r)); it grows
    as (r - c)^(1/2), the edge is the punch's corner."""
    r = np.asarray(r, dtype=float)
    return np.where(r > c, depth * (1 - 2 / np.pi * np.arcsin(np.minimum(c / r, 1.0))), 0.0)


def layout(c, h, fraction, below=4, above=5):
    """P2 nodes (spacing h/2) along the plate, the edge c at ``fraction`` of the node interval
    past the last node in contact; reference positions along a quarter circle of radius 3
    (the wall is curved before it is pressed flat)."""
    r = c - fraction * h / 2 + h / 2 * np.arange(-below, above + 1)
    theta = (r - r[0]) / 3.0
    X = np.column_stack([3.0 * np.sin(theta), 3.0 * (1 - np.cos(theta))])
    return r, X


@pytest.mark.parametrize("h", [0.2, 0.1, 0.05])
def test_hertz_edge_inside_the_element(h):
    """|r_edge - c| <= 0.1 h³/c² wherever c lies between two nodes (measured: 0.04-0.06 h³/c²,
    the quadratic in g^(2/3) through three nodes misses the next term of the expansion); the
    midpoint of the nodes, the former rule, is off by up to h/4."""
    c = 1.0
    worst = 0.0
    for fraction in np.linspace(0.0, 0.98, 50):
        r, X = layout(c, h, fraction)
        # in the reference the nodes are equally spaced along the arc, as are their radii now
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(X, axis=0).T))])
        np.testing.assert_allclose(np.diff(s), np.diff(r) / 3.0 * 3.0, rtol=1e-3)
        x = np.column_stack([r, hertz_gap(r, c)])
        worst = max(worst, abs(plate_edge(MPI.COMM_SELF, X, x, 1e-14) - c))
    assert worst <= 0.1 * h**3 / c**2


def test_hertz_edge_on_the_pressed_wall_order():
    """Nodes given in any order and radii decreasing along the wall (the crater's wall rolls
    onto the plate from its rim inward): the same edge."""
    c, h = 1.0, 0.1
    r, X = layout(c, h, 0.37)
    x = np.column_stack([2 * c - r, hertz_gap(r, c)])  # mirror: the contact is at r > 1
    order = np.random.default_rng(1).permutation(len(r))
    edge = plate_edge(MPI.COMM_SELF, X[order], x[order], 1e-14)
    assert abs(edge - c) <= 0.1 * h**3


@pytest.mark.parametrize("gap", [punch_gap, lambda r, c: np.maximum(r - c, 0.0)], ids=["punch", "linear"])
def test_corner_edge_is_the_corner_node(gap):
    """A flat punch's edge (gap ~ (r - c)^(1/2)) and a wall leaving the plate at an angle (the
    crater's rim, gap ~ r - c) extrapolate below the corner node: the edge is that node, exactly."""
    c, h = 1.0, 0.1
    r, X = layout(c, h, 0.0)
    x = np.column_stack([r, gap(r, c)])
    assert plate_edge(MPI.COMM_SELF, X, x, 1e-14) == pytest.approx(c, abs=1e-14)


def test_no_contact_full_contact_and_one_node_off():
    r = np.linspace(1.0, 2.0, 5)
    X = np.column_stack([r, r - 1])  # the reference height orders the nodes
    assert plate_edge(MPI.COMM_SELF, X, np.column_stack([r, np.full(5, 0.1)]), 1e-9) == 0.0
    assert plate_edge(MPI.COMM_SELF, X, np.column_stack([r, np.zeros(5)]), 1e-9) == 2.0
    # one node off the plate: nothing to extrapolate, the midpoint
    gap = np.array([0, 0, 0, 0, 0.1])
    assert plate_edge(MPI.COMM_SELF, X, np.column_stack([r, gap]), 1e-9) == pytest.approx(1.875)
    # a gap that does not grow away from the edge: the midpoint
    gap = np.array([0, 0, 0.2, 0.1, 0.05])
    assert edge_radius(X[1:], np.column_stack([r, gap])[1:], 1e-9) == pytest.approx(1.375)


@pytest.mark.mpi
def test_plate_edge_over_ranks():
    """Nodes dealt out over the ranks, some on two ranks (ghosts): the serial edge on every rank."""
    comm = MPI.COMM_WORLD
    c, h = 1.0, 0.05
    r, X = layout(c, h, 0.61, below=10, above=10)
    x = np.column_stack([r, hertz_gap(r, c)])
    serial = plate_edge(MPI.COMM_SELF, X, x, 1e-14)
    mine = (np.arange(len(r)) % comm.size == comm.rank) | (np.arange(len(r)) % 3 == 0)
    edge = plate_edge(comm, X[mine], x[mine], 1e-14)
    assert edge == serial
    assert abs(edge - c) <= 0.1 * h**3
    assert comm.allgather(edge) == [edge] * comm.size


@pytest.mark.serial
@pytest.mark.convergence
def test_crater_F_converges_at_eps_02():
    """F~ at eps = 0.2 converges monotonically (differences of one sign, shrinking) on meshes
    refined everywhere (far-field size 4 size_crater); only the rim node is on the plate
    at the end, so A2 is the rim's radius whatever the rule between nodes. About 20 s.
    (On the scene's meshes, whose far field stays at 0.5 a, F~ scatters by 1e-4.)"""
    from bcfem.geometry.crater import create_mesh
    from bcfem.scenes import crater
    from bcfem.scenes.crater.model import Crater
    from bcfem.scenes.crater.params import Params

    on_plate = []

    class Refined(Crater):
        @staticmethod
        def create_mesh(geometry, comm):
            return create_mesh(dataclasses.replace(geometry, size_far=4 * geometry.size_crater), comm)

        def observe(self, stage, eps, V1=None):
            X, zdofs, _ = self._wall
            on_plate.append(int(np.sum(X[:, 1] + self.u.x.array[zdofs] <= 1e-6 * self.geometry.crater_radius)))
            return super().observe(stage, eps, V1)

    F = []
    for size in (0.16, 0.12, 0.09, 0.06):
        on_plate.clear()
        _, summary = crater.solve(Params(preload=0.2, size_crater=size), MPI.COMM_SELF, Refined)
        assert on_plate[-1] == 1
        F.append(summary["F_tilde"])
    d = np.diff(F)
    assert np.all(d > 0) and np.all(np.abs(d[1:]) < np.abs(d[:-1])), F
    assert math.isclose(F[-1], 0.07885, rel_tol=1e-4)
