"""Parameters of ``crater-sector`` and its CLI texts (no dolfinx here).

Lengths in mm and pressures in p_a, as the crater scene; the specimen is the experiment's
(R = 12.70 mm, H = 35.13 mm, a = 6.35 mm, :class:`bcfem.geometry.crater_sector.CraterSector`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from bcfem.columns import Column, declare
from bcfem.geometry.crater_sector import CraterSector
from bcfem.params import Bound, check_bounds, describe, require

SUMMARY = "one crater on a 3-D wedge pi/m of its specimen: the cycle, or its wrinkling past the first onset"
DESCRIPTION = """\
The isolated hemispherical crater of the crater scene (neo-Hookean, nearly
incompressible, on quadratic tetrahedra; the same specimen) on the wedge
0 <= theta <= pi/m of its specimen, with mirror faces at theta = 0 and pi/m
(m = 2: the quarter). The wedge admits the modes cos(k m theta), k = 0, 1, ...:
the non-axisymmetric ones the axisymmetric scene's --waves check only detects
can be followed past their onset here. The face theta = pi/m is held by a
multiplier field for m >= 3.

--drive cycle: vented loading to the preload, sealed with air at p_a, unloaded
to eps = 0 (no plate contact: the run stops if the wall reaches the plate).
--drive drawn: at eps = 0, the crater's volume drawn off, V = (1 - r) V0, its
suction s = 1 - p a multiplier; the wall in frictionless contact with the
plate. The unstable modes are counted after every step by the inertia of the
3-D tangent, the first onset is bisected, and past it the bifurcated branch is
followed by its wave's amplitude (the wall's cos n theta content c_n of
u.X/|X|, over a), from the critical mode (inverse iteration), to
--amplitude-max (0: stop at the onset).

Units and normalisations:
  pressures      in p_a = 101.325 kPa;  beta = mu / p_a
  r              the fraction of the crater's volume drawn off
  s              = 1 - p, the suction the crater holds (over p_a)
  V/V0, A/A0     the crater's volume and projected opening over their values at rest
  F_tilde        = (1 - p) A2/A0, the suction force over p_a A0
  c_0, c_m, c_2m the wall's cos n theta content of u.X/|X| over a
  unstable       unstable modes (volume control, contact held), multipliers subtracted
PETSc prefixes: bcfem_crater_sector_load_, _unload_ (cycle); bcfem_crater_sector_drawn_ (its
critical mode: _drawn_critical_mode_) and bcfem_crater_sector_wave_ (drawn)."""

DRIVES = ("cycle", "drawn")


def columns(drive: str) -> tuple[Column, ...]:
    """The columns of ``branch.csv`` for ``drive``."""
    if drive == "cycle":
        return declare("stage", "eps", "p_over_pa", "V_over_V0", "A_over_A0", "F_tilde")
    return declare("stage", Column("branch", "", "fundamental, or n=<waves> (the bifurcated branch)"),
                   Column("r", "1", "the fraction of the crater's volume drawn off"),
                   Column("s", "p_a", "the suction 1 - p"), "A_over_A0", "F_tilde",
                   Column("unstable", "1", "the unstable modes"),
                   *(Column(f"c_{k}", "1", f"the wall's Fourier coefficient of order {k} (m = --wedge-waves)")
                     for k in ("0", "m", "2m")))


@dataclass(frozen=True)
class Params:
    """Parameters of ``crater-sector``; each field's help and unit are in its metadata (``--help``)."""

    drive: str = field(default="cycle", metadata=describe("the path", "", DRIVES))
    wedge_waves: int = field(default=2, metadata=describe(
        "m: the wedge is 0 <= theta <= pi/m and admits the modes cos(k m theta) (1: the half, 2: the quarter)",
        bound=Bound(1, 32, integer=True)))
    preload: float = field(default=0.02, metadata=describe(
        "eps = -dL/L at sealing (--drive cycle)", bound=Bound(0, 0.9, open_low=True, open_high=True)))
    steps: int = field(default=4, metadata=describe(
        "platen steps of each stage (--drive cycle)", bound=Bound(1, 200, integer=True)))
    beta: float = field(default=47.3 / 101.325, metadata=describe("mu / p_a", bound=Bound(1e-2, 1e3)))
    kappa_ratio: float = field(default=1e4, metadata=describe("bulk over shear modulus", bound=Bound(10, 1e8)))
    layer_thickness: float = field(default=0.0, metadata=describe(
        "a lining of the crater, alpha' = t / a, 0: none", bound=Bound(5e-3, 0.5, open_high=True, also=(0.0,))))
    layer_stiffness: float = field(default=1.0, metadata=describe(
        "beta' = mu_lining / mu (--drive drawn)", bound=Bound(1e-2, 1e4)))
    size_wall: float = field(default=0.25, metadata=describe(
        "element size on the crater's wall over a", bound=Bound(0.05, 1)))
    size_far: float = field(default=0.6, metadata=describe(
        "element size far from the wall over a, at least --size-wall", bound=Bound(0.05, 5)))
    drawn_max: float = field(default=0.04, metadata=describe(
        "the largest fraction r of the volume drawn off (--drive drawn)", bound=Bound(0, 0.5, open_low=True)))
    drawn_step: float = field(default=0.005, metadata=describe(
        "r between steps (--drive drawn; failed steps are halved)", bound=Bound(1e-4, 0.1)))
    bisections: int = field(default=6, metadata=describe(
        "halvings of the step that brackets the first onset", bound=Bound(0, 30, integer=True)))
    amplitude_max: float = field(default=0.012, metadata=describe(
        "the wave's amplitude c_n to follow the bifurcated branch to, over a, 0: stop at the onset "
        "(--drive drawn)", bound=Bound(1e-4, 0.2, also=(0.0,))))
    amplitude_step: float = field(default=0.002, metadata=describe(
        "c_n between steps on the bifurcated branch (failed steps are halved); well above the fundamental "
        "branch's own c_n near the onset (the mesh's imperfection, ~3e-4 a at size 0.1), or the first "
        "step may land on the fundamental branch", bound=Bound(5e-4, 0.05)))

    def __post_init__(self):
        check_bounds(self)
        require(self.drive in DRIVES, f"--drive must be one of {list(DRIVES)} (got {self.drive!r})")
        require(self.size_wall <= self.size_far,
                f"--size-far must be at least --size-wall = {self.size_wall:g} (got {self.size_far:g})")
        require(self.drawn_step <= self.drawn_max,
                f"--drawn-step must be at most --drawn-max = {self.drawn_max:g} (got {self.drawn_step:g})")
        require(self.amplitude_max == 0 or self.amplitude_step <= self.amplitude_max,
                f"--amplitude-step must be at most --amplitude-max = {self.amplitude_max:g} "
                f"(got {self.amplitude_step:g})")

    def geometry(self) -> CraterSector:
        return CraterSector(size_wall=self.size_wall, size_far=self.size_far, layer_thickness=self.layer_thickness,
                            wedge_waves=self.wedge_waves)

    def drawn(self) -> list[float]:
        """The fractions r of the drawn path."""
        count = max(1, round(self.drawn_max / self.drawn_step))
        return [self.drawn_max * (k + 1) / count for k in range(count)]

    def amplitudes(self) -> list[float]:
        """The wave's amplitudes on the bifurcated branch (none: stop at the onset)."""
        if self.amplitude_max == 0:
            return []
        count = max(1, round(self.amplitude_max / self.amplitude_step))
        return [self.amplitude_max * (k + 1) / count for k in range(count)]
