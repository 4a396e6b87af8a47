"""What a scene's rows hold: each column of ``branch.csv`` declared once, with its unit and
meaning, as a PyBaMM model declares its variables. A scene lists its columns
(:func:`declare`); the CSV's columns, the ``--help`` epilog and ``summary.json``'s
``columns`` follow from that list, and a column measured by several scenes (the cavity's
volume, the pressure, the platen force) is declared here once (:data:`SHARED`).

Nothing here imports dolfinx: ``--help`` reads it before any meshing. The values are the
scenes' observables (:mod:`bcfem.physics.observables`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass


@dataclass(frozen=True)
class Column:
    """A column of ``branch.csv``.

    Attributes:
        name: the column's header.
        unit: what it is measured in (``1``: a pure number or a ratio whose reference the
            meaning names; ``deg``; a normalisation such as ``mu_f t0 / R0``).
        meaning: what it is, in a line.
    """

    name: str
    unit: str
    meaning: str

    def line(self) -> str:
        unit = f" [{self.unit}]" if self.unit not in ("", "1") else ""
        return f"{self.name}{unit}: {self.meaning}"


#: the columns several scenes share (each scene's normalisation is in its description)
SHARED = {c.name: c for c in (
    Column("s", "1", "arc length along the branch (the continuation's own measure)"),
    Column("stage", "", "the stage the row belongs to"),
    Column("eps", "1", "platen strain -dL/L (compression > 0)"),
    Column("V_over_V0", "1", "the cavity's volume over its reference V0"),
    Column("P", "mu_f t0 / R0", "pressure difference dp R0 / (mu_f t0)"),
    Column("aspect", "1", "the apex height over R0"),
    Column("energy", "pi R0^2 mu_f t0", "free energy Pi / (pi R0^2 mu_f t0)"),
    Column("contact_angle_deg", "deg", "the membrane's angle with the substrate at its edge, pi - phi0"),
    Column("R1_over_R0", "1", "the debond radius over R0 (1 while the edge holds)"),
    Column("r1_over_R0", "1", "the edge's current radius over R0"),
    Column("I1_minus_3_max", "1", "the largest I1 - 3 over the membrane (Gent locks at Jm)"),
    Column("p_over_pa", "1", "the cavity's pressure over the ambient p_a"),
    Column("A_over_A0", "1", "the suction area over the crater's base area A0 = pi a^2"),
    Column("F_tilde", "p_a A0", "suction force F / (p_a A0) = (1 - p) A / A0 (eq. 7.13)"),
    Column("platen_force", "p_a A0", "the platen's force over p_a A0 (< 0 pressing)"),
)}


def declare(*columns: str | Column) -> tuple[Column, ...]:
    """A scene's columns in order: a shared one by name (:data:`SHARED`), or its own.

    Raises:
        KeyError: a name that is not shared.
        ValueError: a name declared twice.
    """
    out = tuple(SHARED[c] if isinstance(c, str) else c for c in columns)
    names = [c.name for c in out]
    if len(set(names)) != len(names):
        raise ValueError(f"a column declared twice: {sorted(n for n in names if names.count(n) > 1)}")
    return out


def union(*lists: Sequence[Column]) -> tuple[Column, ...]:
    """Every column of ``lists`` once, in order of first appearance (a scene's columns over its
    options, for ``--help``)."""
    seen: dict[str, Column] = {}
    for column in (c for columns in lists for c in columns):
        seen.setdefault(column.name, column)
    return tuple(seen.values())


def names(columns: Iterable[Column | str] | None) -> list[str] | None:
    """The columns' headers (None: every key of the rows)."""
    if columns is None:
        return None
    return [c.name if isinstance(c, Column) else c for c in columns]


def help_text(columns: Sequence[Column]) -> str:
    """The columns with their units and meanings, one per line (the ``--help`` epilog)."""
    return ("columns of branch.csv (some only with an option; summary.json's 'columns' lists a run's own):\n"
            + "\n".join(f"  {c.line()}" for c in columns))


def record(columns: Sequence[Column | str] | None) -> list[dict] | None:
    """The columns as ``summary.json`` records them (a column given by name alone: its name)."""
    if columns is None:
        return None
    return [{"name": c.name, "unit": c.unit, "meaning": c.meaning} if isinstance(c, Column) else {"name": c}
            for c in columns]
