"""Parameters of the crater scene, its CLI texts and its closure criteria.

Nothing here imports dolfinx, so drivers (benchmarks, sweeps) read the crater's
parameters and constants without loading the finite-element stack.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from bcfem.geometry.crater import CraterGeometry
from bcfem.params import require

SUMMARY = "air- or liquid-filled crater pressed on a rigid plate: the suction cycle (ch. 7-8)"
DESCRIPTION = """\
A neo-Hookean specimen (nearly incompressible, Taylor-Hood u-p) with a
spherical-cap crater in its bottom face is pressed on a rigid plate with the
vent open (stage 'load'), then sealed and unloaded to zero platen force (stage
'unload'); the air obeys p V = p_a V1, a liquid keeps V = V1.

Units and normalisations:
  pressures      in p_a = 101.325 kPa;  beta = mu / p_a
  lengths        in mm (experiment: specimen 25.40 x 35.13, crater diameter 12.70)
  alpha          = b / a (crater height over base radius), 1 = hemisphere
  preload eps    = -dL / L of the specimen
  V/V0, A/A0     crater volume and projected area over their values at rest
  F_tilde        = F / (p_a A0) = (1 - V1/V2) A2/A0
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
#: the crater fluids (the terms are ``bcfem.fluids.FLUIDS``)
FLUID_NAMES = ("air", "liquid")
#: ``--preload closure``: load to the smallest preload that closes the crater (eps_m)
PRELOAD_TO_CLOSURE = -1.0
#: ``--preload closure`` gives up closing the crater at this preload
MAX_CLOSURE_PRELOAD = 0.85
#: how far beyond its original height the platen may lift looking for zero force
MAX_LIFT = 0.1


@dataclass(frozen=True)
class ClosureCriteria:
    """When a crater counts as closed (volumes over V0, areas over A0).

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


CLOSURE_CRITERIA = ClosureCriteria()
#: the columns of ``branch.csv``
COLUMNS = ["stage", "eps", "V_over_V0", "p_over_pa", "A_over_A0", "F_tilde", "F_hat"]
#: the stability classes, in the order of ``stability_code``
STABILITY = ["stable", "unstable-unloading", "unstable-both"]


def _help(text: str, unit: str = "", choices=None, words=None) -> dict:
    return {"help": text, "unit": unit, **({"choices": choices} if choices else {}),
            **({"words": words} if words else {})}


@dataclass(frozen=True)
class Params:
    """Parameters of ``crater``; each field's help and unit are in its metadata (``--help``)."""

    fluid: str = field(default="air", metadata=_help(
        "crater fluid: air (ideal gas, p V = p_a V1) or liquid (incompressible, V = V1)", choices=FLUID_NAMES))
    alpha: float = field(default=1.0, metadata=_help("crater aspect b/a, in (0, 1]", "1"))
    beta: float = field(default=47.3 / 101.325, metadata=_help("mu / p_a, > 0", "1"))
    preload: float = field(default=0.1, metadata=_help(
        "eps = -dL/L, in [0, 0.9), or closure (the smallest eps with V1 = 0, eps_m; a crater still "
        "open at eps = 0.85 is reported as such and cycled from there)", "1",
        words={"closure": PRELOAD_TO_CLOSURE}))
    kappa_ratio: float = field(default=1e4, metadata=_help("bulk over shear modulus, in [10, 1e8]", "1"))
    size_crater: float = field(default=0.06, metadata=_help("element size at the crater over a, > 0", "1"))
    specimen_radius: float = field(default=12.70, metadata=_help("specimen radius Rs, > crater radius", "mm"))
    specimen_height: float = field(default=35.13, metadata=_help("specimen height Hs, > 0", "mm"))
    crater_radius: float = field(default=6.35, metadata=_help("crater base radius a, < Rs", "mm"))
    strain_step: float = field(default=0.0125, metadata=_help(
        "platen strain between checkpoints of both stages, in (0, 0.1] (failed steps are halved; every "
        "run passes the same checkpoints); with --path fundamental, the largest arc-length step", "1"))
    surface_energy: float = field(default=0.01, metadata=_help(
        "gamma / (mu a) of the crater wall, in [0, 0.1] (physical PDMS: 7e-5): gives creases a length "
        "scale and acts as a surface stress; 0 is the unregularised model, whose creases are as fine as "
        "the mesh (its effect on F_tilde: docs/results.md)", "1"))
    layer_thickness: float = field(default=0.0, metadata=_help(
        "reinforcement layer lining the crater, alpha' = t / a, 0 (none) or in (0, 0.5)", "1"))
    layer_stiffness: float = field(default=1.0, metadata=_help(
        "beta' = mu_layer / mu of the reinforcement, > 0", "1"))
    self_contact: float = field(default=100.0, metadata=_help(
        "penalty of the wall's self-contact over mu/L (L: node spacing on the wall), 0 (off) or in "
        "[10, 1e4]; a state whose wall passes through itself deeper than L/4 is rejected", "1"))
    waves: int = field(default=0, metadata=_help(
        "check the non-axisymmetric modes with n = 1..waves circumferential waves after every step, "
        "0 (off) to 400"))
    path: str = field(default="stable", metadata=_help(
        "stable: load stepping that passes each instability by pseudo-time relaxation and lands on "
        "a stable state; fundamental: the equilibrium branch connected to the rest state, traced by "
        "arc-length continuation in the platen displacement through its folds and unstable "
        "stretches (no relaxation), recording folds and the unstable modes at each point; it ends "
        "at the preload, at closure, at eps = 0.85, or where it cannot go on (reported)",
        choices=PATHS))
    max_snaps: int = field(default=24, metadata=_help(
        "snaps (steps passed by pseudo-time relaxation) allowed per stage, 0 to 1000; a path that "
        "snaps more often fails (a deepening crease)"))

    #: solver budgets: they decide whether a path gets through, never where it goes, so a
    #: sweep reuses a solved point whatever its budget (and retries one that ran out)
    BUDGETS = ("max_snaps",)

    def __post_init__(self):
        require(self.path in PATHS, f"path must be one of {list(PATHS)} (got {self.path!r})")
        require(self.fluid in FLUID_NAMES, f"fluid must be one of {list(FLUID_NAMES)} (got {self.fluid!r})")
        require(self.beta > 0 and math.isfinite(self.beta), f"beta must be > 0 (got {self.beta})")
        require(self.preload == PRELOAD_TO_CLOSURE or 0 <= self.preload < 0.9,
                f"preload must be in [0, 0.9) or 'closure' (got {self.preload})")
        require(10 <= self.kappa_ratio <= 1e8, f"kappa-ratio must be in [10, 1e8] (got {self.kappa_ratio})")
        require(0 <= self.surface_energy <= 0.1, f"surface-energy must be in [0, 0.1] (got {self.surface_energy})")
        require(self.layer_thickness == 0 or 0 < self.layer_thickness < 0.5,
                f"layer-thickness (t/a) must be 0 or in (0, 0.5) (got {self.layer_thickness})")
        require(self.layer_stiffness > 0 and math.isfinite(self.layer_stiffness),
                f"layer-stiffness (mu_layer/mu) must be > 0 (got {self.layer_stiffness})")
        require(self.self_contact == 0 or 10 <= self.self_contact <= 1e4,
                f"self-contact must be 0 (off) or in [10, 1e4] (got {self.self_contact})")
        require(self.waves == int(self.waves) and 0 <= self.waves <= 400,
                f"waves must be an integer in [0, 400] (got {self.waves})")
        require(self.max_snaps == int(self.max_snaps) and 0 <= self.max_snaps <= 1000,
                f"max-snaps must be an integer in [0, 1000] (got {self.max_snaps})")
        require(0 < self.strain_step <= 0.1, f"strain-step must be in (0, 0.1] (got {self.strain_step})")
        self.geometry()  # validates alpha, radii and sizes before any meshing

    def geometry(self) -> CraterGeometry:
        return CraterGeometry(radius=self.specimen_radius, height=self.specimen_height,
                              crater_radius=self.crater_radius, alpha=self.alpha,
                              size_crater=self.size_crater, size_far=max(0.5, self.size_crater),
                              layer_thickness=self.layer_thickness * self.crater_radius)
