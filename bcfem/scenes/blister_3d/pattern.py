r"""Adhesion that varies over the substrate, Δγ(x, y), for ``blister-3d --edge adhesive``
(the dissertation's eq. 10.1), and its wetting term.

``--delta-gamma`` takes a number or a pattern (values over μ_f t0, lengths over R0):

* ``stripes:PERIOD:LOW:HIGH``: Δγ = (LOW + HIGH)/2 − (HIGH − LOW)/2 cos(2π x/PERIOD), stripes
  along y, LOW on the centre line x = 0;
* a radial profile of the distance from the centroid, as ``blister-rigid --adhesion`` and
  ``blister-soft --delta-gamma`` take it (:mod:`bcfem.radial_profile`: ``step:R_s:inner:outer``,
  a disc; ``ramp:...``; ``table:FILE``), so that a circle meets the axisymmetric scenes.

Δγ belongs to the substrate: the liquid wets the substrate inside the front at the cost
γ_ls − Δγ(x) per area (:class:`PatternedWetting`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bcfem.radial_profile import RadialProfile
from bcfem.radial_profile import parse as parse_profile


@dataclass(frozen=True)
class Pattern:
    """Stripes of Δγ (the module's docstring).

    Attributes:
        text: the flag's text.
        period: the stripes' period.
        values: (LOW, HIGH).
    """

    text: str
    period: float
    values: tuple

    def __str__(self) -> str:
        return self.text

    def _blend(self, x, cos):
        low, high = self.values
        return 0.5 * (low + high) - 0.5 * (high - low) * cos(2 * math.pi * x / self.period)

    def expression(self, x, y):
        """Δγ at the point (x, y), a UFL expression."""
        import ufl  # here: the parameters read patterns without the finite-element stack

        return self._blend(x, ufl.cos)

    def at(self, points: np.ndarray) -> np.ndarray:
        """Δγ at the rows (x, y) of ``points``."""
        return self._blend(points[:, 0], np.cos)


def parse(text: str) -> float | Pattern | RadialProfile:
    """A number, stripes or a radial profile (ValueError naming the forms)."""
    if not text.startswith("stripes"):
        return parse_profile(text)
    fields = text.split(":")[1:]
    form = "stripes:PERIOD:LOW:HIGH"
    try:
        numbers = [float(f) for f in fields]
    except ValueError:
        raise ValueError(f"{form} takes numbers (got {text!r})") from None
    if len(numbers) != 3 or not all(map(math.isfinite, numbers)) or numbers[0] <= 0:
        raise ValueError(f"expected {form} with a finite PERIOD > 0 (got {text!r})")
    return Pattern(text, numbers[0], tuple(numbers[1:]))


def varies(value) -> bool:
    """Whether Δγ is a pattern or a profile (not a number)."""
    return isinstance(value, Pattern | RadialProfile)


def values_of(value) -> tuple:
    """The Δγ values a number, stripes or a profile takes (their range bounds the cost)."""
    return value.values if varies(value) else (value,)


def expression(value, x, y):
    """Δγ at (x, y), a UFL expression."""
    if isinstance(value, Pattern):
        return value.expression(x, y)
    import ufl

    return value.ufl(ufl.sqrt(x * x + y * y))


def at(value, points: np.ndarray) -> np.ndarray:
    """Δγ at the rows (x, y) of ``points``."""
    if isinstance(value, Pattern):
        return value.at(points)
    return value(np.hypot(points[:, 0], points[:, 1]))


@dataclass(frozen=True)
class PatternedWetting:
    r"""The wetted substrate's energy with a patterned adhesion,
    :math:`\int_\Omega \gamma_{ls} - \Delta\gamma(X)\, dA`, over the debonded region Ω of
    the reference plane (the mesh, which grows with the front). The film is clamped, unmoved,
    on the front, so Ω is the wetted substrate and this is ``WettedSubstrate``'s energy: it does
    not depend on the displacement, and its coordinate derivative is the cost at the front.
    (Written on the current positions, ∫ (γ_ls − Δγ(x)) n_z dA, it is the same in exact
    arithmetic, but where the membrane overhangs the front, quadrature of a varying Δγ over the
    fold leaves a node-to-node noise in the release rate.) γ_ls is the run-time constant
    ``gamma_ls``.

    Attributes:
        gamma_ls: γ_ls over μ_f t0.
        delta_gamma: a :class:`Pattern` or a :class:`bcfem.radial_profile.RadialProfile`.
    """

    gamma_ls: float
    delta_gamma: object
    name = "patterned_wetting"
    multipliers = ()

    def energy(self, ctx):
        kin = ctx.kin
        X = kin.x - kin.u  # the reference point: the substrate's under the clamped front
        return kin.integral(ctx.constant("gamma_ls", self.gamma_ls) - expression(self.delta_gamma, X[0], X[1]))
