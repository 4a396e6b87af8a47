"""Parameters of ``blister-3d`` and its CLI texts (no dolfinx here).

Lengths are in units of the outline's equivalent radius R0 = sqrt(area / pi), pressures in
mu_f t0 / R0 and volumes in V0 = 4/3 pi R0^3, as ``blister-rigid``: a circle reproduces it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from bcfem.columns import Column, declare
from bcfem.geometry.outline import KINDS, Outline, read_vertices
from bcfem.params import Bound, ContinuationParams, check_bounds, check_meshable, describe, require
from bcfem.physics.materials import MATERIALS, Gent, NeoHookean
from bcfem.radial_profile import RadialProfile, check_resolved
from bcfem.scenes.blister_3d.pattern import Map, Pattern, values_of, varies
from bcfem.scenes.blister_3d.pattern import parse as parse_pattern

SUMMARY = "membrane blister of any outline on a rigid substrate, in 3-D (ch. 10 outlook)"
DESCRIPTION = """\
An inflated incompressible hyperelastic membrane (neo-Hookean or Gent) whose
initial delamination is a circle, an ellipse, a rectangle or a polygon, clamped
along that outline on a rigid substrate and filled with a liquid whose
interface with the membrane has tension gamma_l. The membrane is a flat
reference mesh of the outline with a three-component displacement (F is 3x2,
the thickness stretch 1/sqrt(det C)); the free energy is U_f - dp V + gamma_l A
as for blister-rigid, the pressure a global unknown traced by arc-length
continuation through its limit points.

Units and normalisations (all inputs and outputs are dimensionless):
  lengths        by R0 = sqrt(A / pi), A the outline's area
  P              = dp R0 / (mu_f t0)
  alpha          = gamma_l / (mu_f t0)
  V/V0           with V0 = 4/3 pi R0^3
  aspect         = the apex height max z over R0
  energy         = Pi / (pi R0^2 mu_f t0)
  N2_min         the least minor principal tension (membrane's plus gamma_l), over mu_f t0
  wrinkled_fraction  the area fraction where the taut membrane's minor tension is < 0

With --edge adhesive the film beyond the outline is bonded to the substrate;
debonding costs alpha + gamma_ls - dgamma per area (dgamma a number, stripes, a
radial profile or a map over the plane: --delta-gamma). The outline is held until the energy release
rate G somewhere on it reaches that cost (delamination_onset in summary.json,
with where: front_x, front_y); then, at --front-steps volumes up to --v-max, the
front moves until G <= cost where it stays and G = cost where it moved (Griffith,
no healing). Rows add G_max, G_mean, G_min and excess_* = G - cost over the
outline (mu_f t0), R_front = sqrt(A_debonded / pi), front_R_min, front_R_max
(the front's distances from the centroid) and front_residual; DIR/release.png
is G / cost along the outline, DIR/front.png the front at each volume.

With --wrinkles relaxed the membrane cannot carry compression (tension-field
theory): where it would, it wrinkles along its major principal direction and
contracts freely across it. The VTX file holds 'measures' (lambda_1, lambda_2,
N2), 'tensions' (the taut membrane's principal tensions N1, N2 and its
equivalent tension sqrt(N1^2 - N1 N2 + N2^2), over mu_f t0, surface tension
included) and 'tension_direction' (the unit major principal direction, the
wrinkles' crests where N2 < 0).
After every point the bordered tangent's inertia gives unstable_modes (under
volume control); a rise is located (summary.json 'bifurcations', with the
mirror its critical mode breaks; exact on --mesh mirrored).
Outputs: DIR/branch.csv, DIR/summary.json, DIR/pv.png, DIR/membrane.png (the last
state rendered, coloured by the major tension N1), DIR/fields.bp (VTX: the
displacement on the reference outline; warp by it in ParaView)."""
_MEMBRANE = declare(
    "V_over_V0", "P", Column("aspect", "1", "the apex height max z over R0"), "energy",
    Column("stretch_max", "1", "the largest principal stretch"), "I1_minus_3_max",
    Column("N2_min", "mu_f t0", "the least minor principal tension (the membrane's plus gamma_l)"),
    Column("wrinkled_fraction", "1", "the area fraction where the taut membrane's minor tension is < 0"),
    Column("unstable_modes", "1", "the tangent's unstable modes under volume control"))
_FRONT = declare(
    *(Column(f"G_{k}", "mu_f t0", f"the energy release rate along the outline: its {k}imum" if k != "mean" else
             "the energy release rate along the outline: its mean") for k in ("max", "mean", "min")),
    *(Column(f"excess_{k}", "mu_f t0", f"G - cost along the outline: its {k}imum" if k != "mean" else
             "G - cost along the outline: its mean") for k in ("max", "mean", "min")),
    Column("front_x", "1", "where G - cost is largest on the outline (x over R0)"),
    Column("front_y", "1", "where G - cost is largest on the outline (y over R0)"),
    Column("R_front", "1", "sqrt(A_debonded / pi) over R0"),
    Column("front_R_min", "1", "the front's least distance from the initial centroid over R0"),
    Column("front_R_max", "1", "the front's largest distance from the initial centroid over R0"),
    Column("front_residual", "1", "the moved front's equilibrium residual over the cost (growth steps)"))
CLAMPED_COLUMNS = declare(*_MEMBRANE, "s")
ADHESIVE_COLUMNS = declare(*_MEMBRANE, *_FRONT, "s")
#: every column the scene may write
COLUMNS = ADHESIVE_COLUMNS
EDGES = ("clamped", "adhesive")
WRINKLES = ("taut", "relaxed")
MESHES = ("free", "mirrored")
FOLLOW = ("none", "broken")


@dataclass(frozen=True)
class Params:
    """Parameters of ``blister-3d``; each field's help and unit are in its metadata (``--help``)."""

    outline: str = field(default="circle", metadata=describe(
        "the initial delamination's outline (a polygon's from --vertices)", "", KINDS))
    aspect: float = field(default=1.0, metadata=describe(
        "ellipse: major over minor axis; rectangle: long over short side (along x)",
        bound=Bound(1, 100)))
    vertices: str = field(default="", metadata=describe(
        "polygon outline: a text file of 'x y' rows, any scale (scaled to the area pi R0^2)", "path"))
    material: str = field(default="neo-hookean", metadata=describe(
        "strain-energy function", "", tuple(sorted(MATERIALS))))
    Jm: float = field(default=100.0, metadata=describe(
        "Gent locking limit of I1 - 3 (Gent only)", bound=Bound(1e-2, 1e6)))
    alpha: float = field(default=0.0, metadata=describe(
        "elasto-capillary number gamma_l / (mu_f t0)", bound=Bound(0, 1e4)))
    edge: str = field(default="clamped", metadata=describe(
        "edge condition: clamped on the outline, or adhesive (the outline is held until the energy "
        "release rate somewhere on it reaches the cost of debonding: the onset)", "", EDGES))
    gamma_ls: float = field(default=3.0, metadata=describe(
        "adhesive edge: gamma_ls / (mu_f t0), the liquid-substrate interface energy", bound=Bound(0, 1e4)))
    delta_gamma: float | Pattern | RadialProfile | Map = field(default=0.5, metadata={**describe(
        "adhesive edge: dgamma / (mu_f t0), the film-substrate adhesion (debonding a unit area costs "
        "alpha + gamma_ls - dgamma > 0): a number, stripes:PERIOD:LOW:HIGH (a cosine in x), or a "
        "profile of the distance from the centroid as blister-rigid's --adhesion takes it "
        "(step:R_s:inner:outer[:width], ramp:..., table:FILE[:width]), or map:FILE, rows 'x y value' "
        "on a rectangular grid (bilinear between them) that covers the outline's bounding box (a "
        "front that leaves the map stops the run); lengths over R0 from the outline's centroid",
        bound=Bound(0, 1e4)), "parse": parse_pattern})
    front_steps: int = field(default=8, metadata=describe(
        "adhesive edge: volumes from the onset to --v-max at which the front is moved to equilibrium "
        "(0: stop at the onset)", bound=Bound(0, 200, integer=True)))
    wrinkles: str = field(default="taut", metadata=describe(
        "taut: the membrane carries compression; relaxed: it wrinkles instead (tension-field "
        "theory; needs --alpha 0)", "", WRINKLES))
    mesh: str = field(default="free", metadata=describe(
        "free: gmsh's mesh of the whole outline; mirrored: its quarter x, y >= 0 meshed and reflected, so "
        "that the discrete blister keeps both mirrors and a symmetry-breaking bifurcation is counted and "
        "located exactly (circle, ellipse, rectangle)", "", MESHES))
    follow: str = field(default="none", metadata=describe(
        "broken: after the branch, trace the branch off the first located bifurcation (one arc-length step "
        "along its critical mode, to the side where its classifying moment is positive) to --v-max: "
        "DIR/broken.csv, broken_branch in summary.json (clamped edge)", "", FOLLOW))
    v_max: float = field(default=2.0, metadata=describe(
        "end of the branch, V/V0", bound=Bound(0, 100, open_low=True)))
    v_start: float = field(default=0.01, metadata=describe(
        "start of the branch, V/V0 < v-max", bound=Bound(1e-4, 100, open_high=True)))
    size: float = field(default=0.1, metadata=describe(
        "element size over R0", bound=Bound(5e-3, 0.5)))
    degree: int = field(default=2, metadata=describe(
        "Lagrange degree of the displacement", "", bound=Bound(1, 3, integer=True)))
    continuation: ContinuationParams = field(default_factory=lambda: ContinuationParams(ds_max=0.1))

    def __post_init__(self):
        check_bounds(self)
        for name, choices in (("outline", KINDS), ("material", tuple(MATERIALS)), ("edge", EDGES),
                              ("wrinkles", WRINKLES), ("mesh", MESHES), ("follow", FOLLOW)):
            require(getattr(self, name) in choices,
                    f"--{name} must be one of {sorted(choices)} (got {getattr(self, name)!r})")
        require(self.v_start < self.v_max, f"need --v-start < --v-max (got {self.v_start:g}, {self.v_max:g})")
        require(self.wrinkles == "taut" or self.alpha == 0,
                "--wrinkles relaxed needs --alpha 0 (a surface tension moves the wrinkling criterion, "
                "which the relaxed energy of the membrane alone does not hold)")
        require((self.outline == "polygon") == bool(self.vertices),
                "--vertices FILE is needed for --outline polygon, and only for it")
        require(self.mesh == "free" or self.outline in ("circle", "ellipse", "rectangle"),
                f"--mesh mirrored needs an outline symmetric about both axes: circle, ellipse or rectangle "
                f"(got --outline {self.outline})")
        require(self.follow == "none" or self.edge == "clamped",
                "--follow broken follows a clamped blister's branch (got --edge adhesive)")
        require(self.aspect == 1.0 or self.outline in ("ellipse", "rectangle"),
                f"--aspect applies to an ellipse or a rectangle (got --outline {self.outline})")
        dgamma = values_of(self.delta_gamma)
        require(not varies(self.delta_gamma) or self.edge == "adhesive",
                "--delta-gamma takes a pattern with --edge adhesive only")
        if isinstance(self.delta_gamma, RadialProfile):
            check_resolved(self.delta_gamma, self.size, "--delta-gamma", f"(--size {self.size:g})")
        if isinstance(self.delta_gamma, Map):
            box = self.geometry().corners()
            require(self.delta_gamma.covers(box),
                    f"--delta-gamma {self.delta_gamma}: the map [{self.delta_gamma.x[0]:g}, {self.delta_gamma.x[-1]:g}]"
                    f" x [{self.delta_gamma.y[0]:g}, {self.delta_gamma.y[-1]:g}] must cover the outline's bounding "
                    f"box [{box[0, 0]:.4g}, {box[2, 0]:.4g}] x [{box[0, 1]:.4g}, {box[2, 1]:.4g}] (lengths over R0 "
                    "from its centroid)")
        if self.edge == "adhesive":
            require(self.alpha + self.gamma_ls - max(dgamma) > 0,
                    f"--delta-gamma: debonding must cost energy everywhere, alpha + gamma_ls - dgamma > 0 (got "
                    f"{self.alpha:g} + {self.gamma_ls:g} - {max(dgamma):g})")
        check_meshable(self.geometry().estimated_cells(), "--size")

    def geometry(self) -> Outline:
        """The reference outline (reads and checks the polygon's file)."""
        vertices = tuple(map(tuple, read_vertices(self.vertices))) if self.vertices else ()
        return Outline(self.outline, self.aspect, vertices, self.size)

    @property
    def adhesion_cost(self) -> float:
        """w = (gamma_ls - dgamma) / (mu_f t0), per debonded projected area (a uniform dgamma)."""
        if not isinstance(self.delta_gamma, int | float):
            raise TypeError(f"--delta-gamma {self.delta_gamma} varies: no single cost of debonding")
        return self.gamma_ls - self.delta_gamma

    def material_model(self):
        if self.material == "gent":
            return Gent(mu=1.0, Jm=self.Jm)
        return NeoHookean(mu=1.0)


V0 = 4.0 * math.pi / 3.0
