"""Parameters of the droplet-soft scene and its CLI texts (no dolfinx).

Everything is normalised by the shear modulus μ and the reference contact radius R0:
tensions γ/(μ R0), lengths over R0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from bcfem.columns import Column, declare
from bcfem.geometry.substrate import SubstrateGeometry
from bcfem.params import Bound, check_bounds, check_meshable, describe, flags_named, require

SUMMARY = "liquid drop on a soft substrate: the wetting ridge, linear and neo-Hookean (ch. 5)"
DESCRIPTION = """\
A drop of contact radius R0 sits on a soft substrate, a layer of thickness h on a
rigid base (--thickness h/R0) or a block L R0 wide and deep standing in for a
half-space (--thickness 0, --width L). The contact line is pinned to the material
point R0 of the top surface.

--model linear: small-strain elasticity (mixed u-p, any nu in (-1, 0.5]), the
linearised solid surface tension (gamma_ls on the wetted part, gamma_s on the dry
part) and the drop's loads at Young's angle cos(theta) = (gamma_s - gamma_ls)/gamma_l:
a ring load gamma_l sin(theta) up at R0, the Laplace pressure 2 gamma_l sin(theta)/R0
down on R < R0 and an inward pull at R0, gamma_l cos(theta) (--contact-force liquid,
eq. 5.22) or that pull net of the solid's surface-tension jump, zero (balanced).
One linear solve.

--model neo-hookean: the nearly incompressible neo-Hookean solid (Taylor-Hood),
finite-strain surface energies and the drop as a spherical cap of fixed volume (the
Young cap on R0), its angle and Laplace pressure unknowns. All three tensions are
ramped together from 0 (load = tension / target) to the targets: from the linear
regime to the elastocapillary cusp, where Neumann's triangle holds.
--control neumann (the dissertation's iteration, sec. 5.4.2): after the ramp the drop's
volume is changed (bracket and root, in stage load) until the liquid pulls along the
resultant of the solid tensions at the tip, measured with the chords to R0 -/+ delta
(neumann_misfit: the part of gamma_l v + gamma_ls tau_ls + gamma_s tau_s normal to v, over
gamma_l, = 0); the volume and the angle phi_l are outputs. The angle it selects depends on
the mesh (Table 5.1's EG: 54.6 deg, refine 1: 79.4 deg), and a misfit that jumps through
zero (two tip states) ends the run as failed.

Units: tensions gamma/(mu R0); lengths, displacements over R0; c = mu R0/((1-nu) gamma_s).
Writes profile.csv (the top surface against R/R0), branch.csv (the load path),
summary.json (ridge_height = u_z(R0)/R0, ridge_height_normalised = mu u_z/((1-nu) gamma_l),
cusp_angle_deg, neumann_angles_deg, ...) and profile.png.
PETSc prefixes: bcfem_droplet_soft_solve_ (linear) and bcfem_droplet_soft_load_."""

MODELS = ("linear", "neo-hookean")
CONTACT_FORCES = ("liquid", "balanced")
CONTROLS = ("volume", "neumann")
#: the columns of ``branch.csv``
COLUMNS = declare(
    Column("load", "1", "the tensions' fraction of their targets"),
    Column("gamma_l", "mu R0", "the liquid's tension at this load"),
    Column("ridge_height", "1", "the wetting ridge's height u_z(R0) / R0"),
    Column("ridge_height_normalised", "1", "mu u_z(R0) / ((1 - nu) gamma_l)"),
    Column("tip_r", "1", "the ridge tip's radius over R0"), Column("tip_z", "1", "the ridge tip's height over R0"),
    Column("cap_angle_deg", "deg", "the drop's cap angle at the contact line"),
    Column("cusp_angle_deg", "deg", "the solid's wedge at the tip (chords extrapolated to the tip)"),
    Column("liquid_angle_deg", "deg", "the liquid's wedge at the tip"),
    Column("vapour_angle_deg", "deg", "the vapour's wedge at the tip"),
    Column("cusp_angle_chord_deg", "deg", "the solid's wedge between the chords to R0 -/+ delta"),
    Column("neumann_residual", "1", "|the three tensions' sum along their wedges| over the largest tension"),
    Column("neumann_misfit", "1", "the tensions' sum normal to the liquid's side, over gamma_l (0: Neumann)"),
    Column("drop_volume", "R0^3", "the drop's volume (nan for the linear model)"),
    Column("laplace_pressure", "gamma_l / R0", "the drop's pressure over gamma_l / R0"),
    Column("newton_iterations", "1", "Newton iterations of the step"))


@dataclass(frozen=True)
class Params:
    """Parameters of ``droplet-soft``; each field's help is in its metadata (``--help``)."""

    model: str = field(default="linear", metadata=describe(
        "linear (small strain, any nu) or neo-hookean (finite strain, nearly incompressible)", "",
        MODELS))
    gamma_s: float = field(default=0.1, metadata=describe(
        "gamma_s/(mu R0), the dry solid's tension", bound=Bound(0, 1e3)))
    gamma_l: float = field(default=0.1, metadata=describe(
        "gamma_l/(mu R0), the liquid's tension", bound=Bound(0, 1e3, open_low=True)))
    gamma_ls: float = field(default=0.1, metadata=describe(
        "gamma_ls/(mu R0), the wetted solid's tension, |gamma_s - gamma_ls| <= gamma_l (Young)", bound=Bound(0, 1e3)))
    cap_angle: float = field(default=0.0, metadata=describe(
        "the drop's angle at rest, setting its volume (and the linear loads' angle); "
        "0 for Young's angle from the tensions", "deg", bound=Bound(1, 179, also=(0.0,))))
    nu: float = field(default=0.5, metadata=describe(
        "Poisson ratio of the linear model", bound=Bound(-1, 0.5, open_low=True)))
    thickness: float = field(default=0.0, metadata=describe(
        "h/R0 of a layer on a rigid base; 0 for a half-space stand-in (a block width x width)",
        bound=Bound(1e-3, 1e3, also=(0.0,))))
    width: float = field(default=40.0, metadata=describe(
        "L: the block's radius (and a half-space's depth) over R0", bound=Bound(1, 1e3, open_low=True)))
    size_contact: float = field(default=2e-3, metadata=describe(
        "element size at the contact line over R0", bound=Bound(1e-4, 0.1)))
    growth: float = field(default=1.3, metadata=describe(
        "size ratio of neighbouring elements", bound=Bound(1, 2, open_low=True)))
    refine: int = field(default=0, metadata=describe(
        "halve every element size this often", bound=Bound(0, 6, integer=True)))
    degree: int = field(default=2, metadata=describe(
        "displacement degree (pressure: degree - 1)", bound=Bound(2, 3, integer=True)))
    contact_force: str = field(default="liquid", metadata=describe(
        "linear model's tangential line force: liquid (gamma_l cos theta, eq. 5.22) or balanced (0)", "",
        CONTACT_FORCES))
    kappa: float = field(default=1e4, metadata=describe("neo-Hookean bulk over shear modulus", bound=Bound(10, 1e8)))
    load_step: float = field(default=0.05, metadata=describe(
        "neo-Hookean: first step of the tension ramp (load from 0 to 1)", bound=Bound(1e-4, 1)))
    control: str = field(default="volume", metadata=describe(
        "neo-Hookean: what holds the drop: volume (the cap of --cap-angle on R0, fixed) or neumann "
        "(the dissertation's: the drop's angle phi_l such that the liquid pulls along the resultant "
        "of the two solid tensions at the tip, the volume an output)", "", CONTROLS))

    def __post_init__(self):
        check_bounds(self)
        require(self.model in MODELS, f"--model must be one of {list(MODELS)} (got {self.model!r})")
        require(abs(self.gamma_s - self.gamma_ls) <= self.gamma_l,
                f"--gamma-s, --gamma-ls, --gamma-l: need |gamma_s - gamma_ls| <= gamma_l for a Young angle "
                f"(got {self.gamma_s}, {self.gamma_ls}, {self.gamma_l})")
        if self.model == "neo-hookean":
            require(self.gamma_l <= self.gamma_s + self.gamma_ls,
                    f"--gamma-l must be <= --gamma-s + --gamma-ls for Neumann's triangle (got {self.gamma_l}, "
                    f"{self.gamma_s}, {self.gamma_ls})")
        require(self.control in CONTROLS, f"--control must be one of {list(CONTROLS)} (got {self.control!r})")
        require(self.control == "volume" or self.model == "neo-hookean",
                "--control neumann needs --model neo-hookean (the linear model's loads are fixed)")
        require(self.contact_force in CONTACT_FORCES,
                f"--contact-force must be one of {list(CONTACT_FORCES)} (got {self.contact_force!r})")
        with flags_named(self):
            geometry = self.geometry()  # the sizes, before any meshing
        check_meshable(geometry.estimated_cells(), "--size-contact, --growth, --refine, --width and --thickness")

    @property
    def young_angle(self) -> float:
        """θ_Y from cos θ = (γs - γls)/γl (radians)."""
        return math.acos(max(-1.0, min(1.0, (self.gamma_s - self.gamma_ls) / self.gamma_l)))

    @property
    def rest_angle(self) -> float:
        """The drop's angle at rest (radians): ``cap_angle`` or Young's."""
        return math.radians(self.cap_angle) if self.cap_angle else self.young_angle

    @property
    def c(self) -> float:
        """c = μ R0/((1-ν) γs) of the linear theory (inf for γs = 0)."""
        return math.inf if self.gamma_s == 0 else 1.0 / ((1.0 - self.nu) * self.gamma_s)

    def geometry(self) -> SubstrateGeometry:
        return SubstrateGeometry(contact_radius=1.0, size_factor=self.width,
                                 thickness=self.thickness or None, size_contact=self.size_contact,
                                 growth=self.growth, refine=int(self.refine))
