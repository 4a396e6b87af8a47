r"""Where a wall leaves a rigid plane: its contact edge, located inside an element.

Contact with the plane is enforced at the nodes, so the nodes say only that the edge lies
between the last node in contact and the first one off. Near a smooth frictionless
contact edge the gap grows as :math:`g \simeq C (s - s_0)^{3/2}` (Hertz), so
:math:`g^{2/3}` is a smooth function of the arc length s with a simple zero at the edge
:math:`s_0`: the polynomial through :math:`g^{2/3}` of the first few nodes off the plane,
extrapolated to its zero, places the edge. An edge at a corner of the wall (a flat punch's,
where the gap grows as :math:`(s - s_0)^{1/2}` or linearly) extrapolates below the corner
node and is clamped to it. The current radius there is the quadratic through the nodes'
radii. Plain numpy; :func:`plate_edge` gathers a few nodes over a communicator.
"""

from __future__ import annotations

import math

import numpy as np

#: the exponent of the gap at a smooth frictionless contact edge
HERTZ = 1.5
#: nodes off the plane in the fit (a quadratic in g^(2/3)) and in the gathered window
OFF_NODES = 3


def edge_in_element(s: np.ndarray, gap: np.ndarray, exponent: float = HERTZ, nodes: int = OFF_NODES) -> float:
    """The edge's arc length s_0 in [s[0], s[1]].

    Args:
        s: increasing arc lengths; s[0] is the last node in contact, s[1:] are off the plane.
        gap: the gaps there (gap[0] is ignored, gap[1:] > 0).
        exponent: m in g ~ (s - s_0)^m.
        nodes: how many nodes off the plane the polynomial in g^(1/m) passes through (<= len(s) - 1).

    Returns the midpoint of [s[0], s[1]] if the gap does not grow away from the edge (no
    zero to extrapolate to) or only one node is off the plane.
    """
    n = min(nodes, len(s) - 1)
    midpoint = 0.5 * (s[0] + s[1])
    if n < 2:
        return midpoint
    x, t = s[1:n + 1] - s[1], gap[1:n + 1] ** (1.0 / exponent)
    if not np.all(np.diff(t) > 0):
        return midpoint
    coefficients = np.polyfit(x, t, n - 1)  # exact: n points, degree n - 1
    # the linear extrapolation brackets the zero of a convex or concave t(s) from one side
    linear = -t[0] * (x[1] - x[0]) / (t[1] - t[0])
    roots = np.roots(coefficients) if n > 2 else np.array([linear])
    real = roots[np.abs(roots.imag) <= 1e-12 * (s[n] - s[0])].real
    root = real[np.argmin(np.abs(real - linear))] if len(real) else linear
    return float(np.clip(s[1] + root, s[0], s[1]))


def quadratic_at(s: np.ndarray, values: np.ndarray, s0: float) -> float:
    """The quadratic through (s[i], values[i]), i = 0, 1, 2, at s0 (Lagrange form)."""
    total = 0.0
    for i in range(3):
        weight = 1.0
        for j in range(3):
            if j != i:
                weight *= (s0 - s[j]) / (s[i] - s[j])
        total += weight * values[i]
    return total


def edge_radius(X: np.ndarray, x: np.ndarray, tolerance: float) -> float:
    """The current radius of the edge of one window of wall nodes (serial).

    Args:
        X: reference positions (n, 2), ordered along the wall from the last node in
            contact (X[0]) away from the contact.
        x: current positions (n, 2); the gap is the height x[:, 1].
        tolerance: a node with x_z <= tolerance is on the plane (only X[0] may be).
    """
    if len(X) < 2:
        return float(x[0, 0])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(X, axis=0).T))])  # chords: arc to O(h^3)
    s0 = edge_in_element(s, x[:, 1])
    if len(X) < 3:
        return float(x[0, 0] + (x[1, 0] - x[0, 0]) * (s0 - s[0]) / (s[1] - s[0]))
    return quadratic_at(s, x[:, 0], s0)


def plate_edge(comm, X: np.ndarray, x: np.ndarray, tolerance: float, nodes: int = OFF_NODES,
               order: np.ndarray | None = None) -> float:
    """The current radius where one part of a wall leaves the plane z = 0 (collective).

    The part's nodes lie on the plane from their lowest reference height (or ``order``) up to
    some height (the highest node on the plane); the edge lies past it, among the nodes above. Each rank
    holds some of the nodes (ghosts may repeat); only the highest node on the plane and the
    ``nodes`` lowest nodes above it are gathered.

    Args:
        comm: the mesh's communicator (mpi4py).
        X: reference positions (n, 2) of this rank's nodes of the part.
        x: their current positions (n, 2).
        tolerance: a node with x_z <= tolerance is on the plane.
        nodes: nodes off the plane in the fit.
        order: the nodes' place along the part, increasing away from the contact (default:
            the reference height; a wall joined to a bottom face that may lift off the plane
            counts the bottom face's nodes below the wall's).

    Returns 0 if none of the part's nodes is on the plane.
    """
    on = x[:, 1] <= tolerance
    Z = X[:, 1] if order is None else order
    top = max(comm.allgather(float(Z[on].max(initial=-math.inf))))
    if not math.isfinite(top):
        return 0.0
    above = np.flatnonzero(~on & (Z > top))
    near = above[np.argsort(Z[above])[:nodes]]
    mine = np.flatnonzero(on & (Z == top))[:1]
    rows = np.hstack([X, x, Z[:, None]])[np.concatenate([mine, near])]
    gathered = np.vstack(comm.allgather(rows))
    gathered = gathered[np.argsort(gathered[:, 4], kind="stable")]
    # a node shared by ranks comes once per rank, with the same reference position
    keep = np.concatenate([[True], np.any(np.abs(np.diff(gathered[:, :2], axis=0)) > 0, axis=1)])
    window = gathered[keep][:nodes + 1]
    return edge_radius(window[:, :2], window[:, 2:4], tolerance)
