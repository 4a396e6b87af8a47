r"""The signed gap of a node against a straight segment, and its exact derivatives.

.. math:: g = \frac{(b - a) \times (p - a)}{|b - a|},

positive on the segment's free side (to the left of b - a). The penalty self-contact
(:mod:`bcfem.contact.self_contact`) needs g and its gradient and Hessian in the six coordinates
(p, a, b); :func:`gap_derivatives_batch` gives them for every pair at once.
"""

from __future__ import annotations

import numpy as np

ROTATION = np.array([[0.0, -1.0], [1.0, 0.0]])  # d -> d_perp = (-d_z, d_r)


def gap(p, a, b):
    """Signed distance of p from the line of segment (a, b), > 0 on its free side
    (to the left of b - a), and the parameter of p's projection (0 at a, 1 at b).
    All arguments (n, 2)."""
    d, v = b - a, p - a
    length2 = np.einsum("ij,ij->i", d, d)
    length = np.sqrt(length2)
    cross = d[:, 0] * v[:, 1] - d[:, 1] * v[:, 0]
    return cross / length, np.einsum("ij,ij->i", d, v) / length2


def gap_derivatives(p, a, b):
    """Gradient (6,) and Hessian (6, 6) of the gap of one node p against segment (a, b),
    in the unknowns (p, a, b)."""
    grad, hess = gap_derivatives_batch(*(np.asarray(z, dtype=float)[None] for z in (p, a, b)))
    return grad[0], hess[0]


def gap_derivatives_batch(p, a, b):
    """:func:`gap_derivatives` of n pairs at once: gradients (n, 6) and Hessians (n, 6, 6);
    p, a, b are (n, 2)."""
    d, v = b - a, p - a
    L = np.hypot(d[:, 0], d[:, 1])[:, None]
    c = (d[:, 0] * v[:, 1] - d[:, 1] * v[:, 0])[:, None]
    dperp = d @ ROTATION.T
    s = np.stack([v[:, 1], -v[:, 0]], axis=1)
    g_v = dperp / L
    g_d = s / L - c * d / L**3
    outer = np.einsum  # (n, 2) x (n, 2) -> (n, 2, 2)
    H_vd = ROTATION[None] / L[..., None] - outer("ni,nj->nij", dperp, d) / L[..., None] ** 3
    H_dd = ((-outer("ni,nj->nij", s, d) - outer("ni,nj->nij", d, s) - c[..., None] * np.eye(2)) / L[..., None] ** 3
            + 3 * c[..., None] * outer("ni,nj->nij", d, d) / L[..., None] ** 5)
    n = len(p)
    H = np.zeros((n, 4, 4))
    H[:, :2, 2:], H[:, 2:, :2], H[:, 2:, 2:] = H_vd, np.swapaxes(H_vd, 1, 2), H_dd
    eye, zero = np.eye(2), np.zeros((2, 2))
    T = np.block([[eye, -eye, zero], [zero, -eye, eye]])  # (v, d) = T (p, a, b)
    return np.concatenate([g_v, g_d], axis=1) @ T, np.einsum("ki,nkl,lj->nij", T, H, T)
