"""What a problem holds: its terms checked against the contract, and the multipliers they declare."""

from __future__ import annotations

from bcfem.physics.protocols import DiscreteTerm, Term


def checked_terms(terms) -> list:
    """``terms`` as a list, each a :class:`~bcfem.physics.protocols.Term` or a
    :class:`~bcfem.physics.protocols.DiscreteTerm`.

    Raises:
        TypeError: naming the first that is neither, and the fix.
    """
    terms = list(terms)
    for term in terms:
        if not isinstance(term, (Term, DiscreteTerm)):
            raise TypeError(f"{type(term).__name__} is not an energy term: inherit bcfem.Term (its energy(ctx), "
                            "name and multipliers) or bcfem.DiscreteTerm")
    return terms


def declared_multipliers(terms, names: list[str], rows: dict) -> tuple[str, ...]:
    """The multiplier states the terms declare (``multipliers``), in the order of ``names``;
    each must be a state."""
    declared = {n for t in terms for n in t.multipliers}
    missing = declared.difference(names)
    if missing:
        raise ValueError(f"terms declare the multipliers {sorted(missing)}, which no term's energy created")
    return tuple(n for n in names if n in declared and n not in rows)
