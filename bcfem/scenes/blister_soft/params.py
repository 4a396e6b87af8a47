"""Parameters of the scene ``blister-soft`` and its CLI texts (no dolfinx here).

All inputs are dimensionless: lengths by the blister radius R0, energies by
mu_f t0 R0^2 (mu_f t0: the membrane's shear modulus times its thickness).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from bcfem.columns import Column, declare
from bcfem.geometry.substrate import SubstrateGeometry
from bcfem.params import Bound, ContinuationParams, check_bounds, check_meshable, describe, flags_named, require
from bcfem.physics.materials import MATERIALS
from bcfem.radial_profile import WIDTH, RadialProfile, check_resolved
from bcfem.radial_profile import parse as parse_profile

SUMMARY = "membrane blister bonded to a soft substrate, one energy (ch. 4)"
DESCRIPTION = """\
A liquid-filled blister: an incompressible hyperelastic membrane (neo-Hookean
or Gent) bonded at radius R0 to a nearly incompressible neo-Hookean substrate
(Taylor-Hood P2-P1), which the liquid indents. One free energy,
  Pi = U_f + U_s - dp V + gamma_l A_l + gamma_ls A_ls + dgamma A_s,
is minimised monolithically: the free membrane (R < R0) is a 1-D field on the
substrate's wetted top, u_f = u_s + w with w = 0 at the contact line; the
bonded membrane (R > R0) is a surface hyperelastic term on the substrate's top.
The contact-line conditions (eqs. 4.52-4.53, Neumann's triangle without the
membrane) are natural conditions of Pi. The pressure is traced by arc-length
through its limit points. With --edge adhesive the debond radius R1 (the membrane's
material point at the contact line) is a state: held at R0 until the configurational
force -dPi/dR1 turns positive (delamination onset), then dPi/dR1 = 0 (Griffith, no
healing); the mesh stays, a map of the reference configuration moves the front.
A dgamma profile (--delta-gamma step:..., ramp:..., table:...) belongs to the substrate's
material points: the bonded energy is the integral of dgamma(R) over the bonded top's
current area, and the release rate sees dgamma(R1), the value at the front.
Far field: the block 0 <= R <= L R0, -L R0 <= Z <= 0,
bottom fixed, far side on rollers (u_r = 0), axis u_r = 0.

Units and normalisations (all inputs and outputs are dimensionless):
  lengths          by R0;  energies by mu_f t0 R0^2
  P                = dp R0 / (mu_f t0)
  stiffness-ratio  = mu_s R0 / (mu_f t0)
  alpha, gamma-ls, delta-gamma = gamma_l, gamma_ls, dgamma over mu_f t0
  V/V0             with V0 = 4/3 pi R0^3
  aspect           = z_f(0) / r0 (apex height over the current contact radius)
  contact angle    = angle between the free membrane and the substrate's undeformed
                     plane at the contact line, degrees (the rigid scene's angle)
  liquid/substrate/membrane angle
                   = the wedges at the contact line between the tangents the energy
                     sees (the line force of a unit tension on each surface), degrees
  indentation      = -z_s(0) / R0;  r1_over_R0 = current contact radius / R0
  R1_over_R0       = debond radius (material) / R0; dPi_dR1 over pi mu_f t0 R0
  J_min            = the substrate's smallest volume ratio (a state with J_min <= 0
                     is refused: the substrate would invert)
  compressed_fraction
                   = the fraction of the free membrane's reference area where a principal
                     tension is negative (hoop compression where the contact line is dragged
                     inwards; the membrane has no bending stiffness and would wrinkle there)
  energy           = (Pi - gamma_ls pi R0^2 - int_R0^{L R0} dgamma(R) 2 pi R dR)/(pi R0^2 mu_f t0)
Outputs: DIR/branch.csv, DIR/summary.json, DIR/pv.png, DIR/indentation.png,
DIR/fields.bp (VTX, the substrate; the displacement is the position minus the mesh
point, which differs from the material point by the front's map when R1 > R0),
DIR/fields_lift.bp (VTX, the free membrane's lift w on the wetted top: x_f = x_s + w)."""
HELP = {
    "material": "strain-energy function of the membrane",
    "Jm": "Gent locking limit of I1-3 (Gent only)",
    "stiffness_ratio": "mu_s R0 / (mu_f t0) (large: the rigid substrate)",
    "alpha": "gamma_l/(mu_f t0), liquid-membrane interface energy",
    "gamma_ls": "gamma_ls/(mu_f t0), liquid-substrate interface energy",
    "delta_gamma": "dgamma/(mu_f t0), membrane-substrate interface energy (debonding costs alpha + gamma-ls - "
                   "dgamma per area): a number, or a profile of the substrate's material radius R/R0, "
                   "step:R_s:inner:outer[:width], ramp:R_a:R_b:inner:outer[:width] or table:FILE[:width] "
                   "(rows 'R dgamma', linear between), steps and kinks smoothed over width "
                   f"(default {WIDTH:g}, >= 2 contact elements); the front sees dgamma(R1)",
    "edge": "edge condition: bonded (R0 fixed) or adhesive (the debond radius R1 >= R0 is a state, "
            "released when -dPi/dR1 turns positive, then dPi/dR1 = 0)",
    "size_factor": "L: the substrate block is L R0 wide and deep (the adhesive edge: L >= 2.5)",
    "v_max": "end of the branch, V/V0 > v-start",
    "v_start": "start of the branch, V/V0",
    "size_contact": "element size at the contact line, in R0",
    "size_far": "largest element size, in R0 (0: L/10)",
    "growth": "size ratio of neighbouring elements",
    "size_wetted": "largest element size on the wetted top (the free membrane), in R0 (0: the grading alone)",
    "refine": "halve every element size this many times",
    "kappa_ratio": "bulk over shear modulus of the substrate",
}
COLUMNS = declare(
    "V_over_V0", "P", Column("aspect", "1", "the apex height z_f(0) over the current contact radius r0"),
    "contact_angle_deg", Column("indentation", "1", "the substrate's depression at the axis, -z_s(0) / R0"),
    "r1_over_R0",
    Column("energy", "pi R0^2 mu_f t0", "free energy less the substrate's surface energies at rest, over "
           "pi R0^2 mu_f t0"),
    Column("z_apex", "1", "the apex height z_f(0) over R0"), "R1_over_R0",
    Column("liquid_angle_deg", "deg", "the liquid's wedge at the contact line"),
    Column("substrate_angle_deg", "deg", "the substrate's wedge at the contact line"),
    Column("membrane_angle_deg", "deg", "the angle between the free and the bonded membrane at the contact line"),
    Column("J_min", "1", "the substrate's smallest volume ratio (> 0: not inverted)"),
    Column("compressed_fraction", "1", "the free membrane's area fraction with a negative principal tension"),
    "s")
EDGES = ("bonded", "adhesive")
#: half-width of the region around the contact line that the moving front translates, in R0
FRONT_PLATEAU = 0.25


@dataclass(frozen=True)
class Params:
    """Parameters of ``blister-soft`` (normalised by mu_f t0 and R0).

    Attributes:
        material: 'neo-hookean' or 'gent' (the membrane).
        Jm: Gent locking limit of I1 - 3 (ignored for neo-Hookean).
        stiffness_ratio: mu_s R0/(mu_f t0); large is the rigid substrate of ``blister-rigid``.
        alpha, gamma_ls, delta_gamma: the three interface energies over mu_f t0.
        edge: 'bonded' (the material contact point R0 is fixed on the substrate) or
            'adhesive' (the debond radius R1 is a state, :mod:`.front`).
        size_factor: L, the block's width and depth over R0.
        v_max, v_start: the branch in V/V0.
        size_contact, size_far, growth, refine: the mesh.
        kappa_ratio: bulk over shear modulus of the substrate (nearly incompressible).
        continuation: step control.
    """

    material: str = field(default="neo-hookean", metadata=describe(HELP["material"], choices=sorted(MATERIALS)))
    Jm: float = field(default=100.0, metadata=describe(HELP["Jm"], bound=Bound(1e-2, 1e6)))
    stiffness_ratio: float = field(default=1.0, metadata=describe(HELP["stiffness_ratio"], bound=Bound(1e-3, 1e6)))
    alpha: float = field(default=0.5, metadata=describe(HELP["alpha"], bound=Bound(0, 1e6)))
    gamma_ls: float = field(default=0.5, metadata=describe(HELP["gamma_ls"], bound=Bound(0, 1e6)))
    delta_gamma: float | RadialProfile = field(
        default=0.5, metadata={"parse": parse_profile, **describe(HELP["delta_gamma"], bound=Bound(0, 1e6))})
    edge: str = field(default="bonded", metadata=describe(HELP["edge"], choices=list(EDGES)))
    size_factor: float = field(default=10.0, metadata=describe(HELP["size_factor"], bound=Bound(1, 100, open_low=True)))
    v_max: float = field(default=3.0, metadata=describe(HELP["v_max"], bound=Bound(0, 1e3, open_low=True)))
    v_start: float = field(default=0.05, metadata=describe(HELP["v_start"],
                                                           bound=Bound(0, 1e3, open_low=True, open_high=True)))
    size_contact: float = field(default=0.01, metadata=describe(HELP["size_contact"], bound=Bound(1e-4, 0.5)))
    size_far: float = field(default=0.0, metadata=describe(HELP["size_far"], bound=Bound(1e-3, 100, also=(0.0,))))
    growth: float = field(default=1.25, metadata=describe(HELP["growth"], bound=Bound(1, 2, open_low=True)))
    size_wetted: float = field(default=0.05, metadata=describe(HELP["size_wetted"], bound=Bound(1e-4, 1, also=(0.0,))))
    refine: int = field(default=0, metadata=describe(HELP["refine"], bound=Bound(0, 6, integer=True)))
    kappa_ratio: float = field(default=1e4, metadata=describe(HELP["kappa_ratio"], bound=Bound(10, 1e8)))
    continuation: ContinuationParams = field(default_factory=lambda: ContinuationParams(ds=0.02, ds_max=0.05))


    def __post_init__(self):
        check_bounds(self)
        require(self.material in MATERIALS, f"--material must be one of {sorted(MATERIALS)} (got {self.material!r})")
        require(self.edge in EDGES, f"--edge must be one of {list(EDGES)} (got {self.edge!r})")
        require(self.edge != "adhesive" or self.size_factor >= 2 * (1 + FRONT_PLATEAU),
                f"--size-factor must be >= {2 * (1 + FRONT_PLATEAU):g} for the adhesive edge (got {self.size_factor})")
        check_resolved(self.delta_gamma, self.size_contact / 2**self.refine, "--delta-gamma",
                       f"at the contact line (--size-contact {self.size_contact:g}, --refine {self.refine})")
        require(self.v_start < self.v_max, f"need --v-start < --v-max (got {self.v_start}, {self.v_max})")
        with flags_named(self):
            geometry = self.geometry()  # the mesh sizes, before any meshing
        check_meshable(geometry.estimated_cells(), "--size-contact, --size-far, --growth, --refine and --size-factor")

    def geometry(self) -> SubstrateGeometry:
        return SubstrateGeometry(size_factor=self.size_factor, size_contact=self.size_contact,
                                 size_far=self.size_far or None, growth=self.growth, refine=self.refine,
                                 size_wetted=self.size_wetted or None)
