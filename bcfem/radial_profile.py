r"""Radial profiles of an interface energy, :math:`f(R)`, read from a flag's text (no dolfinx here).

A flag that takes a profile takes a number (uniform) or one of

* ``step:R_s:inner:outer[:width]``: ``inner`` below the radius R_s, ``outer`` beyond;
* ``ramp:R_a:R_b:inner:outer[:width]``: ``inner`` below R_a, linear to ``outer`` at R_b;
* ``table:FILE[:width]``: rows ``R value`` (whitespace or commas, ``#`` comments), R strictly
  increasing; linear between rows, the end values beyond them.

The sharp profile :math:`\bar f` (steps, linear pieces) is averaged over a window of width
:math:`w` (default :data:`WIDTH`) with the positive kernel of the quintic smoothstep,

.. math:: f = \bar f * h_w,\qquad h_w(x) = \tfrac{30}{w}\,t^2(1-t)^2,\quad t = x/w + 1/2\in[0, 1],

so that a jump J at :math:`\rho` becomes :math:`J\,H_w(R-\rho)`, :math:`H_w = 10t^3-15t^4+6t^5`
(C2), and a kink of slope change S becomes :math:`S\,K_w(R-\rho)`, :math:`K_w = \int H_w`
(C3); outside the windows :math:`|R-\rho| < w/2` the profile is the sharp one, and inside it
stays between the neighbouring values (a positive kernel of unit mass). Why: the profile
enters an energy that Gauss quadrature integrates on a mesh the profile moves across (a
moving debond front); a jump or a kink there puts an O(1) error into the energy's
derivative, a resolved C2 step an error that falls as (h/w)^4.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

#: default width of the window a step or a kink is smoothed over, in R0
WIDTH = 0.05
FORMS = ("step:R_s:inner:outer[:width]", "ramp:R_a:R_b:inner:outer[:width]", "table:FILE[:width]")
#: the largest radius a profile may name, in R0 (every input is bounded)
RADIUS_MAX = 1e3


@dataclass(frozen=True)
class RadialProfile:
    """f(R) = base + sum_k jump_k H_w(R - rho_k) + sum_k slope_k K_w(R - rho_k).

    Attributes:
        text: the flag's text it was read from.
        base: the value at small R (below every window).
        steps: (rho, jump) of each smoothed step.
        kinks: (rho, slope change) of each rounded kink.
        width: w, the smoothing window, > 0.
        values: the values the text names (the profile stays within their range).
    """

    text: str
    base: float
    steps: tuple = ()
    kinks: tuple = ()
    width: float = WIDTH
    values: tuple = ()

    def __str__(self) -> str:
        return self.text

    @property
    def scale(self) -> float:
        """max |f|, from the named values (0: the profile vanishes)."""
        return max(abs(v) for v in self.values)

    @property
    def windows(self) -> list[tuple[float, float]]:
        """The intervals (rho - w/2, rho + w/2) where the profile differs from the sharp one."""
        return [(rho - self.width / 2, rho + self.width / 2) for rho, _ in (*self.steps, *self.kinks)]

    def __call__(self, R):
        """f at radii R (numpy)."""
        return self._evaluate(np.asarray(R, dtype=float), np.clip, np.maximum)

    def ufl(self, R):
        """f at a UFL radius R."""
        import ufl

        def clip(t, low, high):
            return ufl.max_value(low, ufl.min_value(t, high))

        return self._evaluate(R, clip, ufl.max_value)

    def shape(self, R):
        """f/scale at a UFL radius R: the factor of a term whose run-time constant is the scale."""
        return self.ufl(R) / self.scale

    def _evaluate(self, R, clip, maximum):
        w = self.width
        f = self.base
        for rho, jump in self.steps:
            t = clip((R - rho) / w + 0.5, 0.0, 1.0)
            f = f + jump * t**3 * (10 - 15 * t + 6 * t**2)
        for rho, slope in self.kinks:
            s = (R - rho) / w + 0.5
            t = clip(s, 0.0, 1.0)
            f = f + slope * w * (t**4 * (2.5 - 3 * t + t**2) + maximum(s - 1, 0.0))
        return f

    def area_integral(self, a: float, b: float) -> float:
        """The integral of f over the annulus a < R < b per pi: int_a^b f(R) 2R dR (exact: f is a
        polynomial of degree <= 6 between the windows' ends, 4 Gauss points a piece)."""
        cuts = sorted({a, b, *(c for window in self.windows for c in window if a < c < b)})
        x, weights = np.polynomial.legendre.leggauss(4)
        total = 0.0
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            R = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x
            total += 0.5 * (hi - lo) * float(np.sum(weights * self(R) * 2 * R))
        return total


def parse(text: str) -> float | RadialProfile:
    """A number, or the profile a text names (:data:`FORMS`); ``ValueError`` in one line
    otherwise. Radii must be in [0, RADIUS_MAX] and increasing, the width in (0, 1]."""
    try:
        number = float(text)
    except ValueError:
        number = None
    if number is not None:
        if not math.isfinite(number):
            raise ValueError(f"expected a finite number or a profile {' | '.join(FORMS)} (got {text!r})")
        return number
    kind, _, rest = text.partition(":")
    if kind not in ("step", "ramp", "table"):
        raise ValueError(f"expected a number or a profile {' | '.join(FORMS)} (got {text!r})")
    if kind == "table":
        name, width = _width_suffix(rest)
        return _table(text, Path(name), width)
    fields = rest.split(":")
    arity = 3 if kind == "step" else 4
    form = FORMS[0 if kind == "step" else 1]
    if len(fields) not in (arity, arity + 1):
        raise ValueError(f"a {kind} is {form} (got {text!r})")
    numbers = [_finite(f, text) for f in fields]
    width = numbers[arity] if len(numbers) > arity else WIDTH
    _check_width(width, text)
    if kind == "step":
        rho, inner, outer = numbers[:3]
        _check_radii([rho], text)
        return RadialProfile(text, inner, steps=((rho, outer - inner),) if outer != inner else (), width=width,
                             values=(inner, outer))
    a, b, inner, outer = numbers[:4]
    _check_radii([a, b], text)
    slope = (outer - inner) / (b - a)
    kinks = ((a, slope), (b, -slope)) if slope != 0 else ()
    return RadialProfile(text, inner, kinks=kinks, width=width, values=(inner, outer))


def read_rows(path: Path, columns: str, what: str = "table") -> list[list[float]]:
    """The rows of finite numbers in the text file ``path`` (whitespace or commas, ``#``
    comments), each with the fields named in ``columns`` (``'R value'``); ValueError naming the
    file and line otherwise."""
    try:
        lines = Path(path).read_text().splitlines()
    except OSError as err:
        raise ValueError(f"cannot read the {what} {str(path)!r} ({err.strerror})") from None
    rows = []
    for number, line in enumerate(lines, 1):
        fields = line.split("#", 1)[0].replace(",", " ").split()
        if not fields:
            continue
        if len(fields) != len(columns.split()):
            raise ValueError(f"{path}:{number}: a row is {columns!r} (got {len(fields)} fields)")
        rows.append([_finite(f, f"{path}:{number}") for f in fields])
    if not rows:
        raise ValueError(f"the {what} {str(path)!r} has no rows ({columns})")
    return rows


def _table(text: str, path: Path, width: float) -> RadialProfile:
    rows = read_rows(path, "R value")
    radii, values = (list(c) for c in zip(*rows))
    _check_radii(radii, text)
    slopes = [0.0, *((v1 - v0) / (r1 - r0) for r0, r1, v0, v1 in zip(radii, radii[1:], values, values[1:])), 0.0]
    kinks = tuple((r, s1 - s0) for r, s0, s1 in zip(radii, slopes, slopes[1:]) if s1 != s0)
    return RadialProfile(text, values[0], kinks=kinks, width=width, values=tuple(values))


def _width_suffix(rest: str) -> tuple[str, float]:
    """FILE[:width]: a last field that is a number is the width."""
    name, _, tail = rest.rpartition(":")
    try:
        width = float(tail) if name else None
    except ValueError:
        width = None
    if width is None:
        return rest, WIDTH
    _check_width(width, rest)
    return name, width


def _finite(field: str, where: str) -> float:
    try:
        value = float(field)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ValueError(f"expected a finite number, got {field!r} (in {where!r})")
    return value


def _check_width(width: float, text: str) -> None:
    if not 0 < width <= 1:
        raise ValueError(f"the smoothing width must be in (0, 1] R0 (got {width:g} in {text!r})")


def _check_radii(radii: list[float], text: str) -> None:
    if not all(0 <= r <= RADIUS_MAX for r in radii):
        raise ValueError(f"radii must be in [0, {RADIUS_MAX:g}] R0 (got {radii} in {text!r})")
    if any(r1 <= r0 for r0, r1 in zip(radii, radii[1:])):
        raise ValueError(f"radii must increase (got {radii} in {text!r})")


def scale_of(value) -> float:
    """The run-time constant of a term: a number itself, or a profile's scale max |f|."""
    return value.scale if isinstance(value, RadialProfile) else value


def shape_of(value):
    """None for a number (a uniform term), the profile for a profile of nonzero scale."""
    return value if isinstance(value, RadialProfile) and value.scale > 0 else None


def check_resolved(value, element: float, flag: str, where: str) -> None:
    """``ValueError`` unless a profile's windows span 2 elements of size ``element`` (``where``:
    which elements, in the flags' words). At w = 2h the 5-point Gauss rule of a graded mesh
    (h, growth 1.25 or 1.5) moves a front held in a step's window by < 2% of an element (the
    release rate's error is < 1% of the step's jump in force); a sharp step would move it by
    an element or more, wherever the jump falls between Gauss points."""
    if isinstance(value, RadialProfile) and value.windows and value.width < 2 * element - 1e-12:
        raise ValueError(f"{flag}'s smoothing width {value.width:g} must be >= 2 elements {where} "
                         f"({2 * element:g} R0)")


@runtime_checkable
class Valued(Protocol):
    """A parameter that is not a number but names some (a profile, blister-3d's stripes and maps)."""

    @property
    def values(self) -> tuple: ...


def checked_values(value) -> tuple:
    """The numbers a bound must admit: the value, or the values a profile (or another
    :class:`Valued` pattern) names."""
    return value.values if isinstance(value, Valued) else (value,)
