"""Parameters: the range of every numeric input (:class:`Bound`), and the solver's and the
continuation's own parameters as frozen, validated dataclasses."""

from __future__ import annotations

import dataclasses
import math
import re
from contextlib import contextmanager
from dataclasses import dataclass

from bcfem.radial_profile import RadialProfile, checked_values


def require(condition: bool, message: str) -> None:
    """Raise ``ValueError(message)`` unless ``condition``; messages name the parameter and range."""
    if not condition:
        raise ValueError(message)


def flag(name: str) -> str:
    """The command-line flag of a parameter (``size_crater`` -> ``--size-crater``)."""
    return "--" + name.replace("_", "-")


def _number(x: float) -> str:
    """1e4, 0.5, 1e-4: as a range is written by hand."""
    if math.isfinite(x) and x != 0 and not 1e-3 <= abs(x) < 1e4:
        mantissa, exponent = f"{x:.6e}".split("e")
        return f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"
    return format(x, ".6g")


@dataclass(frozen=True)
class Bound:
    """The legal values of a numeric parameter: the interval from ``low`` to ``high`` (each end
    closed unless ``open_low``/``open_high``), only whole numbers if ``integer``, and the
    values of ``also`` besides (an off switch such as 0, or the number a word such as ``closure``
    stands for, spelled as ``spelled`` says).
    Both ends are finite: no input is unbounded, so none can ask for an endless mesh or path.
    """

    low: float
    high: float
    open_low: bool = False
    open_high: bool = False
    integer: bool = False
    also: tuple = ()
    spelled: tuple = ()

    def __post_init__(self):
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low < self.high):
            raise ValueError(f"a bound needs finite low < high (got {self.low}, {self.high})")

    def admits(self, value) -> bool:
        if isinstance(value, bool) or not isinstance(value, int | float):
            return False
        if value in self.also:
            return True
        if not math.isfinite(value) or (self.integer and value != int(value)):
            return False
        above = value > self.low if self.open_low else value >= self.low
        below = value < self.high if self.open_high else value <= self.high
        return above and below

    def __str__(self) -> str:
        interval = (f"{'(' if self.open_low else '['}{_number(self.low)}, "
                    f"{_number(self.high)}{')' if self.open_high else ']'}")
        text = f"an integer in {interval}" if self.integer else f"in {interval}"
        named = list(self.spelled) or [_number(v) for v in self.also]
        return " or ".join([*named, text])


def bound_of(cls, name: str) -> Bound | None:
    """The bound of a field of a parameter class: its metadata's ``bound`` (None: unbounded)."""
    f = next(f for f in dataclasses.fields(cls) if f.name == name)
    return f.metadata.get("bound")


def check_bounds(params) -> None:
    """Raise ``ValueError`` naming the flag and its range for the first field of ``params`` out of
    its bound (every scene's ``Params.__post_init__`` calls it first)."""
    for f in dataclasses.fields(params):
        bound = bound_of(type(params), f.name)
        value = getattr(params, f.name)
        if bound is None or all(bound.admits(v) for v in checked_values(value)):
            continue
        if isinstance(value, RadialProfile):
            raise ValueError(f"every value of {flag(f.name)} must be {bound} (got {value})")
        raise ValueError(f"{flag(f.name)} must be {bound} (got {value!r})")


@dataclass(frozen=True)
class ContinuationParams:
    """Pseudo-arc-length step control.

    The arc length is measured in a mesh-independent norm, the mean over the
    reference body of the squared states that measure it plus the squared load,
    each over its typical size (:class:`bcfem.path.continuation.ArcLength`), so the
    same steps work on every mesh.

    Attributes:
        ds: first step.
        ds_min: smallest step before the continuation gives up.
        ds_max: largest step while ``|load| <= load_scale``; beyond, it grows with ``|load|/load_scale``.
        target_iterations: Newton iterations per step that the step control aims at.
        max_steps: hard limit on accepted steps.
        event_tol: tolerance, in arc length, to which limit points and end points are located.
        max_correction: a corrected point farther than this times the step from its predictor
            is rejected like a failed solve (the step is halved): Newton jumped to another
            branch. A smooth branch corrects by O(ds^2) and a kink (a contact's active set)
            by ds sin(angle), so 1 passes both; inf: no check.
    """

    ds: float = 0.05
    ds_min: float = 1e-7
    ds_max: float = 0.5
    target_iterations: int = 4
    max_steps: int = 2000
    event_tol: float = 1e-11
    max_correction: float = math.inf

    def __post_init__(self):
        require(0 < self.ds_min <= self.ds <= self.ds_max and math.isfinite(self.ds_max),
                f"need 0 < ds_min <= ds <= ds_max < inf (got {self.ds_min}, {self.ds}, {self.ds_max})")
        require(self.target_iterations >= 1, f"target_iterations must be >= 1 (got {self.target_iterations})")
        require(self.max_steps >= 1, f"max_steps must be >= 1 (got {self.max_steps})")
        require(self.event_tol > 0, f"event_tol must be > 0 (got {self.event_tol})")
        require(self.max_correction > 0, f"max_correction must be > 0 (got {self.max_correction})")


def describe(text: str, unit: str = "", choices=None, words=None, bound: Bound | None = None,
             budget: bool = False, later: bool = False) -> dict:
    """A parameter field's metadata: its help and unit, and its choices, named values
    (``{"closure": -1.0}``) or bound, as the CLI and :func:`check_bounds` read them. For a
    sweep's point digest (:func:`bcfem.run.sweep.point_key`): ``budget``, a solver budget (it
    decides whether a point gets through, not its result: left out); ``later``, added after
    the stored maps were solved (left out at its default, so that their points stay valid)."""
    return {"help": text, "unit": unit, **({"choices": choices} if choices else {}),
            **({"words": words} if words else {}), **({"bound": bound} if bound else {}),
            **({"budget": True} if budget else {}), **({"later": True} if later else {})}


@contextmanager
def flags_named(params):
    """Re-raise a ``ValueError`` from within (a geometry's check, which speaks Python names) with
    every field name of ``params`` that has an underscore written as its flag (``size_contact`` ->
    ``--size-contact``; a one-word name reads as a word of the sentence)."""
    try:
        yield
    except ValueError as err:
        names = sorted((f.name for f in dataclasses.fields(params) if "_" in f.name), key=len, reverse=True)
        pattern = re.compile(r"(?<![\w-])(" + "|".join(map(re.escape, names)) + r")\b")
        raise ValueError(pattern.sub(lambda m: flag(m.group(1)), str(err))) from None


#: the most cells a mesh may have: what gmsh meshes in about a minute on one core (a thin
#: graded layer of 160 000 triangles takes 90 s); the solve of such a mesh takes far longer
MESHABLE_CELLS = 2e5


def check_meshable(cells: float, flags: str) -> None:
    """Refuse a mesh estimated at more than :data:`MESHABLE_CELLS`, naming the ``flags`` that
    size it."""
    require(cells <= MESHABLE_CELLS, f"{flags} would make a mesh of about {cells:.2g} cells, more than "
            f"{MESHABLE_CELLS:.0e} (a minute of meshing on one core): coarsen it")
