r"""A sealed liquid that cavitates, shared by the scenes ``crater`` and ``crater-double``.

A liquid holds its volume, V = n (:class:`bcfem.physics.fluids.IncompressibleLiquid`), and its
pressure p is the multiplier. Where p falls below the vapour pressure p_v (over p_a) the liquid
cavitates: from there the cavity holds p_v and its volume is free
(:class:`bcfem.physics.fluids.HeldPressure`), until the volume falls back below the liquid's, n, and
the vapour collapses. A scene swaps the term at each change, which it locates by bisection in
its load (:meth:`bcfem.path.stepping.LoadPath.bisect`), and solves the state again.

While the vapour holds, the pressure state is not an unknown of the problem; it is set to p_v,
so that a scene reading it reads the held pressure, and the liquid starts from there again.
"""

from __future__ import annotations

import math

from bcfem.physics.fluids import HeldPressure

#: halvings of the load step that brackets a cavitation or a collapse
BISECTIONS = 12
#: no cavitation: the liquid takes any tension
NEVER = -math.inf


def liquid_or_vapour(fluid, cavity, amount: float, name: str, vapour: bool, vapour_pressure: float):
    """The fluid term of a cavity: the held vapour pressure once cavitated, else ``fluid``
    (a :class:`bcfem.physics.fluids.SealedFluid` class) with the amount ``amount``."""
    return HeldPressure(cavity, vapour_pressure, name) if vapour else fluid(cavity, amount, name)


def phase_change(vapour: bool, pressure: float, volume: float, amount: float,
                 vapour_pressure: float) -> str | None:
    """``cavitation`` (a liquid below p_v), ``collapse`` (the vapour's volume below the
    liquid's amount) or None (the phase stays)."""
    if vapour:
        return "collapse" if volume < amount else None
    return "cavitation" if pressure < vapour_pressure else None


def change_phase(ctx, name: str, kind: str, vapour_pressure: float) -> bool:
    """Apply the change ``kind`` to the cavity whose pressure state is ``name``; returns
    whether it now holds vapour. The state takes p_v either way: the held pressure while the
    vapour holds, the liquid's start once it has collapsed."""
    ctx.real_state(name).x.array[:] = vapour_pressure
    return kind == "cavitation"
