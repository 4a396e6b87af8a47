"""Parameters of the droplet-soft scene and its CLI texts (no dolfinx).

Everything is normalised by the shear modulus μ and the reference contact radius R0:
tensions γ/(μ R0), lengths over R0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from bcfem.geometry.substrate import SubstrateGeometry
from bcfem.params import require

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

Units: tensions gamma/(mu R0); lengths, displacements over R0; c = mu R0/((1-nu) gamma_s).
Writes profile.csv (the top surface against R/R0), branch.csv (the load path),
summary.json (ridge_height = u_z(R0)/R0, ridge_height_normalised = mu u_z/((1-nu) gamma_l),
cusp_angle_deg, neumann_angles_deg, ...) and profile.png.
PETSc prefixes: bcfem_droplet_soft_solve_ (linear) and bcfem_droplet_soft_load_."""

MODELS = ("linear", "neo-hookean")
CONTACT_FORCES = ("liquid", "balanced")
#: the columns of ``branch.csv``
COLUMNS = ["load", "gamma_l", "ridge_height", "ridge_height_normalised", "tip_r", "tip_z",
           "cap_angle_deg", "cusp_angle_deg", "liquid_angle_deg", "vapour_angle_deg", "cusp_angle_chord_deg",
           "neumann_residual",
           "laplace_pressure", "newton_iterations"]


def _help(text: str, unit: str = "1", choices=None) -> dict:
    return {"help": text, "unit": unit, **({"choices": choices} if choices else {})}


@dataclass(frozen=True)
class Params:
    """Parameters of ``droplet-soft``; each field's help is in its metadata (``--help``)."""

    model: str = field(default="linear", metadata=_help(
        "linear (small strain, any nu) or neo-hookean (finite strain, nearly incompressible)", "",
        MODELS))
    gamma_s: float = field(default=0.1, metadata=_help("gamma_s/(mu R0), the dry solid's tension, >= 0"))
    gamma_l: float = field(default=0.1, metadata=_help("gamma_l/(mu R0), the liquid's tension, > 0"))
    gamma_ls: float = field(default=0.1, metadata=_help(
        "gamma_ls/(mu R0), the wetted solid's tension, >= 0, |gamma_s - gamma_ls| <= gamma_l (Young)"))
    cap_angle: float = field(default=0.0, metadata=_help(
        "the drop's angle at rest [deg], in (0, 180), setting its volume (and the linear loads' angle); "
        "0 for Young's angle from the tensions", ""))
    nu: float = field(default=0.5, metadata=_help("Poisson ratio of the linear model, in (-1, 0.5]"))
    thickness: float = field(default=0.0, metadata=_help(
        "h/R0 of a layer on a rigid base, > 0; 0 for a half-space stand-in (a block width x width)"))
    width: float = field(default=40.0, metadata=_help(
        "L: the block's radius (and a half-space's depth) over R0, > 1"))
    size_contact: float = field(default=2e-3, metadata=_help(
        "element size at the contact line over R0, in [1e-4, 0.1]"))
    growth: float = field(default=1.3, metadata=_help("size ratio of neighbouring elements, in (1, 2]"))
    refine: int = field(default=0, metadata=_help("halve every element size this often, 0 to 6"))
    degree: int = field(default=2, metadata=_help("displacement degree, 2 or 3 (pressure: degree - 1)"))
    contact_force: str = field(default="liquid", metadata=_help(
        "linear model's tangential line force: liquid (gamma_l cos theta, eq. 5.22) or balanced (0)", "",
        CONTACT_FORCES))
    kappa: float = field(default=1e4, metadata=_help("neo-Hookean bulk over shear modulus, in [10, 1e8]"))
    load_step: float = field(default=0.05, metadata=_help(
        "neo-Hookean: first step of the tension ramp (load from 0 to 1), in (0, 1]"))

    def __post_init__(self):
        require(self.model in MODELS, f"model must be one of {list(MODELS)} (got {self.model!r})")
        for name in ("gamma_s", "gamma_ls"):
            value = getattr(self, name)
            require(value >= 0 and math.isfinite(value), f"{name.replace('_', '-')} must be >= 0 (got {value})")
        require(self.gamma_l > 0 and math.isfinite(self.gamma_l), f"gamma-l must be > 0 (got {self.gamma_l})")
        require(abs(self.gamma_s - self.gamma_ls) <= self.gamma_l,
                f"|gamma-s - gamma-ls| must be <= gamma-l for a Young angle (got {self.gamma_s}, "
                f"{self.gamma_ls}, {self.gamma_l})")
        if self.model == "neo-hookean":
            require(self.gamma_l <= self.gamma_s + self.gamma_ls,
                    f"gamma-l must be <= gamma-s + gamma-ls for Neumann's triangle (got {self.gamma_l}, "
                    f"{self.gamma_s}, {self.gamma_ls})")
        require(self.cap_angle == 0 or 0 < self.cap_angle < 180,
                f"cap-angle must be 0 (Young's) or in (0, 180) degrees (got {self.cap_angle})")
        require(-1 < self.nu <= 0.5, f"nu must be in (-1, 0.5] (got {self.nu})")
        require(self.thickness >= 0 and math.isfinite(self.thickness),
                f"thickness (h/R0) must be >= 0, 0 for a half-space (got {self.thickness})")
        require(self.width > 1 and math.isfinite(self.width), f"width must be > 1 (got {self.width})")
        require(1e-4 <= self.size_contact <= 0.1, f"size-contact must be in [1e-4, 0.1] (got {self.size_contact})")
        require(self.refine == int(self.refine) and 0 <= self.refine <= 6,
                f"refine must be an integer in [0, 6] (got {self.refine})")
        require(self.degree in (2, 3), f"degree must be 2 or 3 (got {self.degree})")
        require(self.contact_force in CONTACT_FORCES,
                f"contact-force must be one of {list(CONTACT_FORCES)} (got {self.contact_force!r})")
        require(10 <= self.kappa <= 1e8, f"kappa must be in [10, 1e8] (got {self.kappa})")
        require(0 < self.load_step <= 1, f"load-step must be in (0, 1] (got {self.load_step})")
        self.geometry()  # validates the sizes before any meshing

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
