"""Parameters of ``crater-cell`` and its CLI texts (no dolfinx here).

Lengths in mm and pressures in p_a, as the crater scene, so that a sparse lattice is
comparable with ``bcfem run crater``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from bcfem.columns import Column, declare
from bcfem.geometry.crater_cell import CELLS, LATTICES, MIN_LIGAMENT, CraterCell, close_packing
from bcfem.params import Bound, check_bounds, check_meshable, describe, flags_named, require

SUMMARY = "a lattice of craters pressed on a rigid plate: the suction cycle of one mirror cell in 3-D"
DESCRIPTION = """\
A square or hexagonal lattice of spherical-cap craters in the bottom face of a
neo-Hookean specimen (nearly incompressible, Taylor-Hood u-p on quadratic
tetrahedra) is pressed on a rigid plate with the vents open (stage 'load'),
sealed at the preload and unloaded to zero platen force, then on to eps = 0
(stage 'unload'); the air obeys p V = p_a V1, a liquid keeps V = V1. The
computed body is the lattice's smallest rectangular mirror cell (a quarter of
the square prism around one crater; for the hexagonal lattice the rectangle
d/2 x sqrt(3) d/2 with quarter craters at two corners), or with --cell eighth
the square prism's eighth 0 <= y <= x <= d/2 (the diagonal face a mirror held
by a multiplier field: half the mesh, and e_x = e_y). Its side faces stay
planes and move with the lateral macroscopic strains e_x, e_y (global unknowns
whose conjugates, the mean lateral tractions, vanish): the array spreads as a
whole under the platen. The plate and the platen are frictionless; the bottom
face is held on the plate. Mirror symmetry excludes every response that breaks
it (the n-wave modes with odd n, a crater's sideways tilt, an array that shears);
the inertia of the tangent is checked after every step (summary.json 'stability').

Units and normalisations:
  pressures      in p_a = 101.325 kPa;  beta = mu / p_a
  lengths        in mm; a the crater base radius, d the lattice spacing
  filling F      = pi a^2 / (cell area per crater): d^2 (square), sqrt(3) d^2 / 2 (hexagonal)
  V/V0, A/A0     a crater's volume and projected opening over their values at rest (A0 = pi a^2);
                 A is -int_wall (cof F N)_z dA, the area the rim encloses on the plate
  F_tilde        = (1 - p) A2/A0, the suction force per crater over p_a A0
  F_tilde_area   = F_tilde x F, the suction force per unit (reference) area of the array over p_a
  lateral_strain_x, _y   the cell's lateral macroscopic strains
  platen_force   the platen's force per crater over p_a A0 (< 0 pressing)
  wall_on_plate  how many of the walls' nodes above the rim lie on the plate
The walls are in frictionless contact with the plate (bounds of the VI solver);
wall_on_plate counts their nodes above the rim that lie on it, and A2 is then the
area the contact line encloses (the wall's part off the plate).
PETSc prefixes: bcfem_crater_cell_load_ and bcfem_crater_cell_unload_."""

FLUID_NAMES = ("air", "liquid")
SOLVERS = ("auto", "direct", "split")
STABILITY = ("inertia", "spectrum", "none")
#: the columns of ``branch.csv``
COLUMNS = declare(
    "stage", "eps", "p_over_pa", "V_over_V0", "A_over_A0", "F_tilde",
    Column("F_tilde_area", "p_a", "the suction per unit reference area of the array, F_tilde x filling"),
    Column("lateral_strain_x", "1", "the cell's lateral macroscopic strain e_x"),
    Column("lateral_strain_y", "1", "the cell's lateral macroscopic strain e_y"),
    "platen_force", Column("wall_on_plate", "1", "the walls' nodes above the rim that lie on the plate"))


@dataclass(frozen=True)
class Params:
    """Parameters of ``crater-cell``; each field's help and unit are in its metadata (``--help``)."""

    lattice: str = field(default="square", metadata=describe("the craters' lattice", "", LATTICES))
    cell: str = field(default="quarter", metadata=describe(
        "the mirror cell: a quarter of the lattice's rectangle, or the square lattice's eighth "
        "(which also excludes the modes that break the diagonal mirror)", "", CELLS))
    filling: float = field(default=0.1, metadata=describe(
        "area filling factor F = pi a^2 / (cell area per crater), below close packing (pi/4 = 0.785 "
        "square, pi/(2 sqrt 3) = 0.907 hexagonal) by a ligament of 0.05 a", bound=Bound(0, 0.91, open_low=True)))
    fluid: str = field(default="air", metadata=describe(
        "crater fluid: air (ideal gas, p V = p_a V1) or liquid (incompressible, V = V1, any tension)",
        "", FLUID_NAMES))
    preload: float = field(default=0.1, metadata=describe(
        "eps = -dL/L at sealing", bound=Bound(0, 0.9, open_low=True, open_high=True)))
    alpha: float = field(default=1.0, metadata=describe(
        "crater aspect b/a (1: a hemisphere)", bound=Bound(0.05, 1)))
    beta: float = field(default=47.3 / 101.325, metadata=describe("mu / p_a", bound=Bound(1e-2, 1e3)))
    kappa_ratio: float = field(default=1e4, metadata=describe("bulk over shear modulus", bound=Bound(10, 1e8)))
    crater_radius: float = field(default=6.35, metadata=describe("crater base radius a", "mm",
                                                                 bound=Bound(1e-3, 1e4)))
    specimen_height: float = field(default=35.13, metadata=describe(
        "specimen height H, above the crater and at most 100 a", "mm", bound=Bound(1e-3, 1e4)))
    size_wall: float = field(default=0.3, metadata=describe(
        "element size on the crater walls over a", bound=Bound(0.05, 1)))
    size_rim: float = field(default=0.1, metadata=describe(
        "element size at the craters' rims over a, at most --size-wall", bound=Bound(0.01, 1)))
    size_far: float = field(default=0.8, metadata=describe(
        "element size far from the walls over a, at least --size-wall", bound=Bound(0.05, 5)))
    surface_energy: float = field(default=0.0, metadata=describe(
        "gamma / (mu a) of the crater walls, 0: none", bound=Bound(0, 0.1)))
    strain_step: float = field(default=0.0125, metadata=describe(
        "platen strain between checkpoints of both stages (failed steps are halved)", bound=Bound(1e-3, 0.1)))
    solver: str = field(default="auto", metadata=describe(
        "the Newton step's linear solver: direct (MUMPS's LDL^T), split (FGMRES with a "
        "displacement-pressure Schur split, GAMG on the displacement), auto (split above 40000 "
        "displacement dofs or with --stability spectrum, direct below)", "", SOLVERS))
    stability: str = field(default="inertia", metadata=describe(
        "inertia: count the tangent's negative eigenvalues after every step by a MUMPS LDL^T "
        "factorisation (whatever the solver); spectrum: by the lowest eigenvalues of its Schur "
        "complement on the pressures, preconditioned by the split (no factorisation; needs the "
        "split); none: skip it (summary.json then says 'not checked')", "", STABILITY))
    max_snaps: int = field(default=24, metadata=describe(
        "snaps (steps passed by pseudo-time relaxation) allowed per stage", "",
        bound=Bound(0, 1000, integer=True), budget=True))


    def __post_init__(self):
        check_bounds(self)
        for name, choices in (("lattice", LATTICES), ("fluid", FLUID_NAMES), ("cell", CELLS),
                              ("stability", STABILITY), ("solver", SOLVERS)):
            require(getattr(self, name) in choices,
                    f"--{name} must be one of {list(choices)} (got {getattr(self, name)!r})")
        require(self.size_rim <= self.size_wall,
                f"--size-rim must be at most --size-wall = {self.size_wall:g} (got {self.size_rim:g})")
        require(self.size_wall <= self.size_far,
                f"--size-far must be at least --size-wall = {self.size_wall:g} (got {self.size_far:g})")
        require(self.specimen_height <= 100 * self.crater_radius,
                f"--specimen-height must be at most 100 crater radii "
                f"(got {self.specimen_height / self.crater_radius:g} a)")
        require(self.stability != "spectrum" or self.solver != "direct",
                "--stability spectrum needs --solver split or auto (its preconditioner; got --solver direct)")
        require(self.cell == "quarter" or self.lattice == "square",
                f"--cell eighth is the square lattice's (got --lattice {self.lattice})")
        densest = close_packing(self.lattice)
        require(self.filling < densest * (1 - MIN_LIGAMENT) ** 2,
                f"--filling must be below {densest * (1 - MIN_LIGAMENT) ** 2:.4g} for a {self.lattice} lattice "
                f"(close packing pi a^2 / cell area = {densest:.4g}, less a ligament of {MIN_LIGAMENT:g} a "
                f"between rims; got {self.filling:g}: the crater would be as wide as the cell)")
        depth = self.alpha * self.crater_radius
        require(depth < self.specimen_height,
                f"--specimen-height must exceed the crater's depth b = {depth:g} mm (got {self.specimen_height:g})")
        with flags_named(self):
            cell = self.geometry()
        check_meshable(cell.estimated_cells(), "--size-wall, --size-rim, --size-far and --filling")

    def geometry(self) -> CraterCell:
        return CraterCell(lattice=self.lattice, filling=self.filling, crater_radius=self.crater_radius,
                          alpha=self.alpha, height=self.specimen_height, size_wall=self.size_wall,
                          size_rim=self.size_rim, size_far=self.size_far, cell=self.cell)
