"""Parameters of the double-chamber crater and its CLI texts (no dolfinx here).

Lengths are in units of the crater height H, pressures in p_a (beta = mu / p_a); the
defaults are the dissertation's design (section 9.3): r0 = 0.52 H, R0 = 0.5 H, s = 0.03 H,
mu = p_a, a preload of 0.14.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import ClassVar

from bcfem.columns import Column, declare
from bcfem.geometry.double_crater import (
    CRATER_RADIUS,
    GAP,
    PROTUBERANCE_RADIUS,
    SPECIMEN_HEIGHT,
    SPECIMEN_RADIUS,
    DoubleCraterGeometry,
)
from bcfem.params import Bound, check_bounds, describe, flags_named, require
from bcfem.scenes.crater.params import Specimen

SUMMARY = "double-chamber crater (a protuberance splits the cavity by contact): the suction cycle (ch. 9)"
DESCRIPTION = """\
A neo-Hookean specimen (nearly incompressible, Taylor-Hood u-p) with a
cylindrical crater in its bottom face, from whose roof a spherical protuberance
hangs, is pressed on a rigid plate to the preload (stage 'load') and unloaded
to eps = 0 (stage 'unload', as the dissertation's Step 2). The rows' column
'chambers' says whether the cavity is one chamber or split in two.

The crater is sealed at rest (--seal rest: the dissertation's chambers start at
p_a with no vent) or vented while loading and sealed at the preload (--seal
preload, chapter 7). One cavity holds the fluid until the sidewall touches the
protuberance; the cavity then splits into C1 (on the plate) and C2 (under the
roof), each sealed with its own fluid: p_i V_i = const (air), V_i = const
(liquid). A liquid chamber cavitates where its pressure falls to
--cavitation, and holds that pressure until its vapour collapses (events
'cavitation' and 'collapse'). With --contact separable the chambers merge,
their fluid pooled, where the contact opens; --contact bonded keeps the
touching points together (the dissertation's non-separable contact). Splits,
merges and phase changes are located by bisection in eps and reported. With
--protuberance-radius 0 the crater is a plain cylinder, one chamber throughout.
With --waves N the modes with n = 1..N circumferential waves are checked after
every step (events of kind 'waves'; 'symmetry_breaking' in summary.json).

Units and normalisations:
  lengths        over the crater height H; pressures over p_a; beta = mu / p_a
  preload eps    = -dL / L of the specimen
  V_c1, V_c2     chamber volumes over the cavity's volume at rest V0
  sidewall_gap   least distance from the sidewall to the protuberance, over H
  vapour         how many chambers hold a cavitated liquid
  F_tilde        = (p_a - p_c1) A_c1 / (p_a A0), A0 = pi r0^2: the net fluid force on
                   the specimen (C2 is enclosed by the specimen and pulls on nothing
                   outside it); A_c1 is the plate's area wetted by C1
PETSc prefixes: bcfem_crater_double_load_ and bcfem_crater_double_unload_."""

#: the bottom face's contact with the plate
PLATES = ("frictionless", "sticking")
#: ``--bottom``: the bottom face held on the plate, or in unilateral contact with it
BOTTOMS = ("held", "contact")
#: the top face on the platen: free to slide, or bonded to a rigid backing
TOPS = ("sliding", "bonded")
#: the specimen's outer face: free (one crater), the mirror face of an array's cell (it moves with
#: a free lateral strain), or on rollers (a laterally confined array)
CELLS = ("isolated", "array", "array-confined")
FLUID_NAMES = ("air", "liquid")
SEALS = ("rest", "preload")
CONTACTS = ("separable", "bonded")
#: ``--chambers``: bcfem's exact split at contact, or the dissertation's membrane from eps = 0
CHAMBERS = ("split", "membrane")
#: ``auto`` for the membrane's nodes and switch strain: found on a first (probe) run
AUTO = -1.0
#: the columns of ``branch.csv`` ("vapour": how many chambers hold a cavitated liquid)
COLUMNS = declare(
    "stage", "eps", Column("chambers", "1", "one cavity (1), or the chambers C1 and C2 (2)"),
    Column("vapour", "1", "the chambers that hold vapour (a cavitated liquid)"),
    Column("p_c1_over_pa", "1", "the pressure of C1 (on the plate) over p_a; one cavity: its pressure"),
    Column("p_c2_over_pa", "1", "the pressure of C2 (under the roof) over p_a; one cavity: its pressure"),
    Column("V_c1", "1", "the volume of C1 over the cavity's volume at rest V0"),
    Column("V_c2", "1", "the volume of C2 over V0 (0 while one cavity)"),
    Column("A_c1_over_A0", "1", "C1's wetted area on the plate over pi r0^2"),
    Column("F_tilde", "p_a A0", "suction force (1 - p_c1) A_c1 / A0"),
    Column("sidewall_gap", "H", "the least distance from the sidewall to the protuberance (empty without one)"),
    Column("fluid_law_residual", "1", "the chambers' largest equation-of-state residual (empty while vented)"),
    Column("lateral_strain", "1", "the cell's lateral strain (an array's cell; empty for an isolated specimen)"))


@dataclass(frozen=True)
class DoubleSpecimen(Specimen):
    """The crater model's record with the double chamber's own: ``cell`` (isolated or a cell of
    an array), ``plate`` (frictionless or sticking) and ``top`` (sliding or bonded)."""

    cell: str = "isolated"
    plate: str = "frictionless"
    top: str = "sliding"


@dataclass(frozen=True)
class Params:
    """Parameters of ``crater-double``; each field's help and unit are in its metadata (``--help``)."""

    preload: float = field(default=0.14, metadata=describe(
        "eps = -dL/L at the end of loading", bound=Bound(0, 0.9, open_low=True, open_high=True)))
    fluid: str = field(default="air", metadata=describe(
        "air (ideal gas, p V = const in each chamber) or liquid (incompressible, V = const)", "", FLUID_NAMES))
    cavitation: float = field(default=0.023, metadata=describe(
        "p_v / p_a: a liquid chamber whose pressure falls to it cavitates and holds "
        "it, its volume free, until the vapour collapses (0.023: water's vapour pressure at 20 C; "
        "-inf: no cavitation); not used for air",
        bound=Bound(-1e3, 1, open_high=True, also=(-math.inf,))))
    seal: str = field(default="rest", metadata=describe(
        "when the crater is sealed: at rest (the dissertation) or at the preload (vented loading)", "", SEALS))
    contact: str = field(default="separable", metadata=describe(
        "sidewall-protuberance contact: separable (the chambers merge where it opens) or bonded "
        "(the first touching points stay together, frictionless, as the dissertation's)", "", CONTACTS))
    plate: str = field(default="sticking", metadata=describe(
        "the bottom face on the plate: frictionless (slides) or sticking (no slip); the crater's "
        "walls on the plate slide either way", "", PLATES))
    bottom: str = field(default="held", metadata=describe(
        "the bottom face on the plate: held (u_z = 0: ambient pressure holds a sealed interface down) or "
        "contact (unilateral, free to lift off, the dissertation's model: the gap under a lifted rim "
        "joins C1, whose wetted area is then the one the sealed contact line encloses); with --plate "
        "sticking the face keeps its radius, on the plate and where it lifts", "", BOTTOMS, later=True))
    chambers: str = field(default="split", metadata=describe(
        "split: one cavity until the sidewall touches the protuberance, then two (exact); membrane: the "
        "dissertation's model (sec. 9.2), two chambers from eps = 0 divided by a virtual membrane between "
        "a sidewall node and a protuberance node, the gas exchanged by eq. 9.1 at --exchange-before "
        "until --switch-strain and at --exchange-after from there and in unloading (air sealed at rest)",
        "", CHAMBERS, later=True))
    exchange_before: float = field(default=0.01, metadata=describe(
        "C_V of eq. 9.1, (p_c1 - p_c2) A = C_V dm/dt, while loading below --switch-strain (--chambers "
        "membrane); normalised: pressures over p_a, gas masses m = p V over p_a H^3, A = H^2, t the "
        "step's pseudo-time eps/preload (loading) or (preload - eps)/preload (unloading); small: "
        "connected, 0: one cavity, inf: no exchange", bound=Bound(0, 1e12, also=(math.inf,)), later=True))
    exchange_after: float = field(default=1e4, metadata=describe(
        "C_V of eq. 9.1 from --switch-strain on and in unloading (--chambers membrane); large: "
        "disconnected, inf: no exchange", bound=Bound(0, 1e12, also=(math.inf,)), later=True))
    switch_strain: float = field(default=AUTO, metadata=describe(
        "eps_a, where C_V switches (--chambers membrane); auto: found on a first run with the exact "
        "split, where the membrane's nodes first touch or come closest while loading to the preload",
        words={"auto": AUTO}, bound=Bound(0, 0.9, open_high=True, also=(AUTO,), spelled=("auto",)), later=True))
    membrane_sidewall: float = field(default=AUTO, metadata=describe(
        "Z_w / H of the membrane's sidewall node (Node-2, snapped to a mesh vertex); auto: with "
        "--membrane-protuberance auto, the pair of vertices that first touch or come closest on the "
        "first run (the dissertation's closest nodes at eps_a)",
        words={"auto": AUTO}, bound=Bound(0, 1, open_low=True, open_high=True, also=(AUTO,), spelled=("auto",)),
        later=True))
    membrane_protuberance: float = field(default=AUTO, metadata=describe(
        "Z_b / H of the membrane's protuberance node (Node-1, snapped to a mesh vertex); auto: see "
        "--membrane-sidewall", words={"auto": AUTO},
        bound=Bound(0, 1, open_low=True, open_high=True, also=(AUTO,), spelled=("auto",)), later=True))
    membrane_stiffness: float = field(default=1e-6, metadata=describe(
        "mu_m t / (mu H): the membrane's modulus times its thickness (a ring membrane, Saint "
        "Venant-Kirchhoff, Poisson's ratio 0); 0: a massless, stiffness-free divider",
        bound=Bound(0, 1), later=True))
    top: str = field(default="sliding", metadata=describe(
        "the top face on the platen: sliding (frictionless) or bonded (no slip: a specimen on a rigid "
        "backing)", "", TOPS))
    cell: str = field(default="isolated", metadata=describe(
        "the specimen's outer face: isolated (free); array (the axisymmetric cell of an array of "
        "craters at spacing 2 x specimen-radius: the face, a mirror of the lattice, stays a cylinder "
        "whose radius moves with a free lateral strain, zero mean lateral traction; with --plate "
        "sticking or --top bonded the faces' radii are held, so the strain is 0, rollers); or "
        "array-confined (the face on rollers: an array held laterally)", "", CELLS))
    crater_radius: float = field(default=CRATER_RADIUS, metadata=describe("r0 / H, > R0 / H", bound=Bound(0.05, 10)))
    protuberance_radius: float = field(default=PROTUBERANCE_RADIUS, metadata=describe(
        "R0 / H, in ((1 - s/H) / 2, r0/H): the ball reaches the roof and leaves a gap to the "
        "sidewall; 0: no protuberance (a plain cylindrical crater, one chamber)",
        bound=Bound(0.01, 10, also=(0.0,))))
    gap: float = field(default=GAP, metadata=describe(
        "s / H, the protuberance above the plate", bound=Bound(1e-3, 1, open_high=True)))
    specimen_radius: float = field(default=SPECIMEN_RADIUS, metadata=describe(
        "specimen radius over r0", bound=Bound(1, 50, open_low=True)))
    specimen_height: float = field(default=SPECIMEN_HEIGHT, metadata=describe(
        "specimen height over H", bound=Bound(1, 100, open_low=True)))
    beta: float = field(default=1.0, metadata=describe("mu / p_a", bound=Bound(1e-2, 1e3)))
    kappa_ratio: float = field(default=1e4, metadata=describe("bulk over shear modulus", bound=Bound(10, 1e8)))
    size_wall: float = field(default=0.02, metadata=describe(
        "element size on the walls over H", bound=Bound(5e-3, 0.25)))
    size_contact: float = field(default=0.005, metadata=describe(
        "element size where the sidewall meets the protuberance and at the rims over H, "
        "at most --size-wall", bound=Bound(1e-3, 0.25)))
    surface_energy: float = field(default=0.01, metadata=describe(
        "gamma / (mu r0) of the walls: gives the roof's fold onto the protuberance a "
        "length scale", bound=Bound(0, 0.1)))
    self_contact: float = field(default=100.0, metadata=describe(
        "penalty of the walls' self-contact over mu/L (L: node spacing on the wall); the chambers "
        "split by it", bound=Bound(10, 1e4)))
    strain_step: float = field(default=0.01, metadata=describe(
        "platen strain between checkpoints (failed steps are halved)", bound=Bound(1e-3, 0.1)))
    max_snaps: int = field(default=24, metadata=describe(
        "snaps (steps passed by pseudo-time relaxation) allowed per stage", "",
        bound=Bound(0, 1000, integer=True), budget=True))
    waves: int = field(default=0, metadata=describe(
        "check the non-axisymmetric modes with n = 1..waves circumferential waves after every step, "
        "0: off", "", bound=Bound(0, 400, integer=True)))

    #: the membrane model's own parameters
    MEMBRANE: ClassVar[tuple] = ("exchange_before", "exchange_after", "switch_strain", "membrane_sidewall",
                                 "membrane_protuberance", "membrane_stiffness")

    def __post_init__(self):
        check_bounds(self)
        for name, choices in (("fluid", FLUID_NAMES), ("seal", SEALS), ("contact", CONTACTS),
                              ("plate", PLATES), ("bottom", BOTTOMS), ("top", TOPS), ("cell", CELLS)):
            require(getattr(self, name) in choices, f"--{name} must be one of {list(choices)} "
                    f"(got {getattr(self, name)!r})")
        require(self.chambers in CHAMBERS, f"--chambers must be one of {list(CHAMBERS)} (got {self.chambers!r})")
        if self.chambers == "split":
            changed = [f.name for f in fields(self) if f.name in self.MEMBRANE and getattr(self, f.name) != f.default]
            require(not changed, f"--{changed[0].replace('_', '-') if changed else ''} needs --chambers membrane")
        else:
            require(self.fluid == "air" and self.seal == "rest" and self.protuberance_radius > 0,
                    "--chambers membrane models air sealed at rest with a protuberance "
                    "(--fluid air, --seal rest, --protuberance-radius > 0)")
            require((self.membrane_sidewall == AUTO) == (self.membrane_protuberance == AUTO),
                    "--membrane-sidewall and --membrane-protuberance are given together or both auto")
        require(self.size_contact <= self.size_wall,
                f"--size-contact must be at most --size-wall = {self.size_wall:g} (got {self.size_contact:g})")
        with flags_named(self):
            self.geometry()  # a protuberance that does not fit, R0 >= r0: ValueError naming it

    def model_inputs(self) -> DoubleSpecimen:
        """What the double crater's model is built from: no lining, Taylor-Hood elements, the
        stable path."""
        return DoubleSpecimen(self.geometry(), self.beta, self.kappa_ratio, self.specimen_height,
                              self.surface_energy, self_contact=self.self_contact, waves=self.waves,
                              bottom=self.bottom, cell=self.cell, plate=self.plate, top=self.top)

    def geometry(self) -> DoubleCraterGeometry:
        return DoubleCraterGeometry(crater_height=1.0, crater_radius=self.crater_radius,
                                    protuberance_radius=self.protuberance_radius, gap=self.gap,
                                    radius=self.specimen_radius * self.crater_radius,
                                    height=self.specimen_height, size_wall=self.size_wall,
                                    size_contact=self.size_contact, size_corner=self.size_contact,
                                    size_far=max(0.25, self.size_wall))
