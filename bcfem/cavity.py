r"""A cavity closed by the rigid plate z = 0: its current volume.

The crater's current volume follows from its surface alone (divergence
theorem with the field z e_z, which vanishes on the plate), mapped to the
reference surface by Nanson's formula. In axisymmetry, with cof(F2) the
in-plane cofactor and r = R + u_r,

.. math:: V(u) = -\int_\Gamma z\,(\mathrm{cof}(F_2) N)_z\, 2\pi r\, dS,

with N the reference normal pointing out of the solid (into the cavity).
"""

from __future__ import annotations

import ufl


def cavity_volume_density(kin, normal):
    """Current cavity volume per unit reference boundary length (the 2πr is included:
    integrate over the cavity wall with a plain ``ds``)."""
    F2 = ufl.as_matrix([[kin.F[0, 0], kin.F[0, 1]], [kin.F[1, 0], kin.F[1, 1]]])
    cof = ufl.det(F2) * ufl.inv(F2).T
    r = kin.x[0] + kin.u[0]
    z = kin.x[1] + kin.u[1]
    return -z * ufl.dot(cof, normal)[1] * 2 * ufl.pi * r
