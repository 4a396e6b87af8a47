"""Parameters of the crater scene, its CLI texts and its closure criteria.

Nothing here imports dolfinx, so drivers (benchmarks, sweeps) read the crater's
parameters and constants without loading the finite-element stack.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from bcfem.columns import Column, declare
from bcfem.geometry.crater import CraterGeometry
from bcfem.params import Bound, check_bounds, describe, flags_named, require
from bcfem.path.terminations import Termination

SUMMARY = "air- or liquid-filled crater pressed on a rigid plate: the suction cycle (ch. 7-8)"
DESCRIPTION = """\
A neo-Hookean specimen (nearly incompressible, Taylor-Hood u-p) with a
spherical-cap crater in its bottom face is pressed on a rigid plate with the
vent open (stage 'load'), then sealed and unloaded to zero platen force (stage
'unload'); the air obeys p V = p_a V1, a liquid keeps V = V1 (with
--cavitation p_v/p_a: until its pressure falls to p_v; it then holds p_v, its
volume free, until the vapour collapses: summary.json 'phase_changes').

Units and normalisations:
  pressures      in p_a = 101.325 kPa;  beta = mu / p_a
  lengths        in mm (experiment: specimen 25.40 x 35.13, crater diameter 12.70)
  alpha          = b / a (crater height over base radius), 1 = hemisphere
  preload eps    = -dL / L of the specimen
  V/V0, A/A0     crater volume and projected area over their values at rest
  F_tilde        = F / (p_a A0) = (1 - V1/V2) A2/A0
  platen_force   = the platen's force over p_a A0: < 0 pressing, > 0 pulling (--retract)
The wall is in frictionless contact with the plate and does not pass through
itself (penalty self-contact). surface_energy regularises creasing of the wall.
Instabilities (the tangent's inertia) and snaps (steps passed by pseudo-time
relaxation) are reported in summary.json ('stability'). A cycle that is not
'stable' has passed an instability: the same parameters can then end in another
stable state with another F_tilde, so read it as one of several equilibria;
'bcfem sweep crater --grid strain_step=0.005:0.02:4' shows their spread
(docs/results.md). With --waves N the onset of non-axisymmetric deformation is
detected (Fourier modes n = 1..N, events of kind 'waves').
PETSc prefixes: bcfem_crater_load_ and bcfem_crater_unload_."""

#: ``--path``: the load-stepped path that relaxes past instabilities, or the branch from rest
PATHS = ("stable", "fundamental")
#: ``--bottom``: the bottom face held on the plate, or in unilateral contact with it
BOTTOMS = ("held", "contact")


@dataclass(frozen=True)
class Element:
    """A displacement-pressure pair: Lagrange degrees (pressure 0: constant per cell), the
    quadrature degree of the strain energy, the cell shape and the geometry's order."""

    displacement: int
    pressure: int
    quadrature: int
    cell: str
    order: int


#: ``--element``: Taylor-Hood P2-P1 on second-order triangles, or Q1-P0 on straight-sided
#: quadrilaterals with 2 x 2 Gauss points (Abaqus's CAX4H: bilinear, hybrid with a constant
#: pressure, isoparametric, full integration)
ELEMENTS = {"p2p1": Element(2, 1, 4, "triangle", 2),
            "q1p0": Element(1, 0, 2, "quadrilateral", 1)}
#: the crater fluids (the terms are ``bcfem.physics.fluids.FLUIDS``)
FLUID_NAMES = ("air", "liquid")
#: ``--preload closure``: load to the smallest preload that closes the crater (eps_m)
PRELOAD_TO_CLOSURE = -1.0
#: ``--preload closure`` gives up closing the crater at this preload
MAX_CLOSURE_PRELOAD = 0.85
#: how far beyond its original height the platen may lift looking for zero force
MAX_LIFT = 0.1


@dataclass(frozen=True)
class Specimen:
    """What a crater model is built from (:class:`bcfem.scenes.crater.model.Crater`): the
    geometry, the material, the elements, the bottom face, the path and the checks it carries.
    Each scene's parameters give their own (``Params.model_inputs()``); a model reads nothing else.

    Attributes:
        geometry: the dimensions and mesh sizes (:class:`~bcfem.geometry.crater.CraterGeometry`,
            or a subclass model's own).
        beta: mu / p_a.
        kappa_ratio: bulk over shear modulus.
        specimen_height: H (the platen strain's length).
        surface_energy: gamma_s / (mu a).
        layer_thickness, layer_stiffness: the reinforcing layer (0: none) and its modulus over mu.
        self_contact: the wall's self-contact penalty (0: off).
        waves: check the modes with 1..waves circumferential waves (0: off).
        element: the displacement-pressure element (``p2p1``, ...).
        bottom: the bottom face outside the crater: ``held`` or ``contact``.
        path: ``stable`` (load steps, relaxed snaps) or ``fundamental`` (arc-length in w).
    """

    geometry: Any
    beta: float
    kappa_ratio: float
    specimen_height: float
    surface_energy: float = 0.0
    layer_thickness: float = 0.0
    layer_stiffness: float = 1.0
    self_contact: float = 0.0
    waves: int = 0
    element: str = "p2p1"
    bottom: str = "held"
    path: str = "stable"


@dataclass(frozen=True)
class ClosureCriteria(Termination):
    """When a crater counts as closed (volumes over V0, areas over A0); as a termination, a
    loading that ends at closure (``V_over_V0`` and ``A_over_A0`` of a row).

    Attributes:
        closed: V <= closed V0 is a closed crater (vacuum inside).
        volume: ``--preload closure`` stops at V1 <= volume V0 ...
        area: ... or once the wall lies on the plate up to within sqrt(area) a of the axis
            with at most ``trapped`` V0 left in folds (a wall that folds onto the plate,
            e.g. a thin stiff lining, traps pockets that never close).
    """

    closed: float = 1e-8
    volume: float = 1e-3
    area: float = 2.5e-3
    trapped: float = 1e-2

    def measure(self, row: dict) -> float:
        V, A = row["V_over_V0"], row["A_over_A0"]
        return max(self.volume - V, min(self.trapped - V, self.area - A))

    def __str__(self) -> str:
        return (f"closure (V <= {self.volume:g} V0, or V <= {self.trapped:g} V0 with the wall on the plate to "
                f"within sqrt({self.area:g}) a of the axis)")


CLOSURE_CRITERIA = ClosureCriteria()
#: the columns of ``branch.csv``
CYCLE_COLUMNS = declare("stage", "eps", "V_over_V0", "p_over_pa", "A_over_A0", "F_tilde",
                        Column("F_hat", "mu A0", "suction force over mu A0, F_tilde / beta"), "platen_force")
#: the fundamental path's (``--path fundamental``)
FUNDAMENTAL_COLUMNS = declare(
    *CYCLE_COLUMNS, "s", Column("unstable", "1", "the unstable axisymmetric modes at fixed platen"),
    Column("unstable_waves", "", "the unstable modes of each n-wave block, n = 1..waves"))
#: every column the scene may write
COLUMNS = FUNDAMENTAL_COLUMNS
#: the stability classes, in the order of ``stability_code``
STABILITY = ["stable", "unstable-unloading", "unstable-both"]


@dataclass(frozen=True)
class Preset:
    """A specimen (``--specimen``): its radius in mm and its solid's elements."""

    radius: float
    element: str


#: the experiment's puck, and the dissertation's FE model as its numbers pin it: a section 4a
#: wide (the crater's diameter drawn as the radius) of Abaqus's CAX4H elements, whose coarse
#: outer face does not crease (docs/results.md)
SPECIMENS = {"physical": Preset(12.70, "p2p1"), "dissertation": Preset(25.40, "q1p0")}


@dataclass(frozen=True)
class Params:
    """Parameters of ``crater``; each field's help and unit are in its metadata (``--help``)."""

    fluid: str = field(default="air", metadata=describe(
        "crater fluid: air (ideal gas, p V = p_a V1) or liquid (incompressible, V = V1)", choices=FLUID_NAMES))
    alpha: float = field(default=1.0, metadata=describe(
        "crater aspect b/a (1: a hemisphere)", "1", bound=Bound(0.05, 1)))
    beta: float = field(default=47.3 / 101.325, metadata=describe("mu / p_a", "1", bound=Bound(1e-2, 1e3)))
    preload: float = field(default=0.1, metadata=describe(
        "eps = -dL/L, or closure (the smallest eps with V1 = 0, eps_m; a crater still "
        "open at eps = 0.85 is reported as such and cycled from there)", "1",
        words={"closure": PRELOAD_TO_CLOSURE},
        bound=Bound(0, 0.9, open_high=True, also=(PRELOAD_TO_CLOSURE,), spelled=("closure",))))
    kappa_ratio: float = field(default=1e4, metadata=describe("bulk over shear modulus", "1", bound=Bound(10, 1e8)))
    size_crater: float = field(default=0.06, metadata=describe(
        "element size at the crater over a", "1", bound=Bound(3e-3, 0.5)))
    specimen: str = field(default="physical", metadata=describe(
        "the specimen: physical (the experiment's puck, radius 12.70 mm = 2a, p2p1 elements) or "
        "dissertation (the dissertation's FE model as its numbers pin it: radius 25.40 mm = 4a, q1p0 "
        "elements like its CAX4H, whatever --element says; its closure strains, optima and design maps; "
        "docs/results.md); a --specimen-radius of its own needs physical (p2p1 at 25.40 mm: "
        "--specimen-radius 25.4)",
        choices=tuple(SPECIMENS), later=True))
    specimen_radius: float = field(default=12.70, metadata=describe(
        "specimen radius Rs, in (a, 50 a] (--specimen dissertation: 25.40)", "mm", bound=Bound(1e-3, 1e4)))
    specimen_height: float = field(default=35.13, metadata=describe(
        "specimen height Hs, above the crater and at most 100 a", "mm", bound=Bound(1e-3, 1e4)))
    crater_radius: float = field(default=6.35, metadata=describe(
        "crater base radius a, < Rs", "mm", bound=Bound(1e-3, 1e4)))
    strain_step: float = field(default=0.0125, metadata=describe(
        "platen strain between checkpoints of both stages (failed steps are halved; every "
        "run passes the same checkpoints); with --path fundamental, the largest arc-length step", "1",
        bound=Bound(1e-3, 0.1)))
    surface_energy: float = field(default=0.01, metadata=describe(
        "gamma / (mu a) of the crater wall (physical PDMS: 7e-5): gives creases a length "
        "scale and acts as a surface stress; 0 is the unregularised model, whose creases are as fine as "
        "the mesh (its effect on F_tilde: docs/results.md)", "1", bound=Bound(0, 0.1)))
    layer_thickness: float = field(default=0.0, metadata=describe(
        "reinforcement layer lining the crater, alpha' = t / a, 0: none", "1",
        bound=Bound(5e-3, 0.5, open_high=True, also=(0.0,))))
    layer_stiffness: float = field(default=1.0, metadata=describe(
        "beta' = mu_layer / mu of the reinforcement", "1", bound=Bound(1e-2, 1e4)))
    self_contact: float = field(default=100.0, metadata=describe(
        "penalty of the wall's self-contact over mu/L (L: node spacing on the wall), 0: off; "
        "a state whose wall passes through itself deeper than L/4 is rejected", "1",
        bound=Bound(10, 1e4, also=(0.0,))))
    waves: int = field(default=0, metadata=describe(
        "check the non-axisymmetric modes with n = 1..waves circumferential waves after every step, "
        "0: off", bound=Bound(0, 400, integer=True)))
    path: str = field(default="stable", metadata=describe(
        "stable: load stepping that passes each instability by pseudo-time relaxation and lands on "
        "a stable state; fundamental: the equilibrium branch connected to the rest state, traced by "
        "arc-length continuation in the platen displacement through its folds and unstable "
        "stretches (no relaxation), recording folds and the unstable modes at each point; it ends "
        "at the preload, at closure, at eps = 0.85, or where it cannot go on (reported)",
        choices=PATHS))
    bottom: str = field(default="held", metadata=describe(
        "the bottom face on the plate: held (u_z = 0, sliding freely: ambient pressure holds a sealed "
        "interface down) or contact (frictionless unilateral contact, free to lift off: the "
        "dissertation's model; the suction area is then the one the sealed contact line encloses)",
        choices=BOTTOMS, later=True))
    retract: float = field(default=0.0, metadata=describe(
        "after unloading, lift the platen on to eps = -retract (past the specimen's original height; "
        "stage 'retract', --bottom contact): the suction force, p and A along the way, and pull-off "
        "where the seal opens or the platen's pull peaks; 0: no retraction", "1", bound=Bound(0, 0.5), later=True))
    cavitation: float = field(default=-math.inf, metadata=describe(
        "p_v / p_a: a liquid whose pressure falls to it on unloading cavitates and holds it, its "
        "volume free, until the vapour collapses; a crater closed on loading holds vapour from the "
        "seal (water at 20 C: 0.023); -inf: no cavitation, the liquid takes any tension and a closed "
        "crater stays closed; not used for air", "1",
        bound=Bound(-1e3, 1, open_high=True, also=(-math.inf,)), later=True))
    element: str = field(default="p2p1", metadata=describe(
        "the solid's elements: p2p1 (Taylor-Hood: quadratic displacement, linear pressure, on curved "
        "triangles) or q1p0 (bilinear displacement, a constant pressure per cell, on straight-sided "
        "quadrilaterals: the analogue of Abaqus's CAX4H, the dissertation's element)",
        choices=tuple(ELEMENTS), later=True))
    max_snaps: int = field(default=24, metadata=describe(
        "snaps (steps passed by pseudo-time relaxation) allowed per stage; a path that "
        "snaps more often fails (a deepening crease)", bound=Bound(0, 1000, integer=True), budget=True))

    #: solver budgets: they decide whether a path gets through, never where it goes, so a
    #: sweep reuses a solved point whatever its budget (and retries one that ran out)

    def __post_init__(self):
        check_bounds(self)
        require(self.specimen in SPECIMENS, f"--specimen must be one of {list(SPECIMENS)} (got {self.specimen!r})")
        if self.specimen != "physical":
            physical, preset = SPECIMENS["physical"], SPECIMENS[self.specimen]
            require(self.specimen_radius in (physical.radius, preset.radius),
                    f"--specimen {self.specimen} sets --specimen-radius to {preset.radius:.2f} mm: give one of "
                    f"them (got --specimen-radius {self.specimen_radius:g})")
            object.__setattr__(self, "specimen_radius", preset.radius)
            object.__setattr__(self, "element", preset.element)
        require(self.path in PATHS, f"--path must be one of {list(PATHS)} (got {self.path!r})")
        require(self.fluid in FLUID_NAMES, f"--fluid must be one of {list(FLUID_NAMES)} (got {self.fluid!r})")
        require(self.element in ELEMENTS, f"--element must be one of {list(ELEMENTS)} (got {self.element!r})")
        require(self.bottom in BOTTOMS, f"--bottom must be one of {list(BOTTOMS)} (got {self.bottom!r})")
        require(self.retract == 0 or self.bottom == "contact",
                f"--retract needs --bottom contact: a bottom face held on the plate cannot separate "
                f"(got {self.bottom})")
        require(self.retract == 0 or self.path == "stable", "--retract follows the stable path (--path stable)")
        cavitates = self.cavitation != -math.inf and self.fluid == "liquid"
        require(not cavitates or (self.path == "stable" and self.retract == 0),
                "--cavitation is followed on the stable path's unloading only (--path stable, --retract 0)")
        a = self.crater_radius
        require(a < self.specimen_radius,
                f"--crater-radius must be < --specimen-radius = {self.specimen_radius:g} mm (got {a:g})")
        depth = (self.alpha + self.layer_thickness) * a
        require(depth < self.specimen_height,
                f"--specimen-height must exceed the crater's depth b + t = {depth:g} mm (got {self.specimen_height:g})")
        require(self.specimen_radius <= 50 * a,
                f"--specimen-radius must be at most 50 crater radii (got {self.specimen_radius / a:g} a)")
        require(self.specimen_height <= 100 * a,
                f"--specimen-height must be at most 100 crater radii (got {self.specimen_height / a:g} a)")
        with flags_named(self):
            self.geometry()  # the crater inside the specimen: ValueError naming it, before any meshing

    def model_inputs(self) -> Specimen:
        """What the crater model is built from."""
        return Specimen(self.geometry(), self.beta, self.kappa_ratio, self.specimen_height, self.surface_energy,
                        self.layer_thickness, self.layer_stiffness, self.self_contact, self.waves, self.element,
                        self.bottom, self.path)

    def geometry(self) -> CraterGeometry:
        element = ELEMENTS[self.element]
        return CraterGeometry(radius=self.specimen_radius, height=self.specimen_height,
                              crater_radius=self.crater_radius, alpha=self.alpha,
                              size_crater=self.size_crater, size_far=max(0.5, self.size_crater),
                              layer_thickness=self.layer_thickness * self.crater_radius,
                              order=element.order, cell=element.cell)
