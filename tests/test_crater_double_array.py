"""crater-double's cell of an array (``--cell array``): the outer face, a mirror of the lattice,
stays a cylinder whose radius moves with a free lateral strain e (a real state whose residual is
the mean lateral traction on the face, zero). On a frictionless plate under a sliding platen the
cell then spreads as a whole: with a crater of porosity phi (here a needle, r0 = 0.05 H, in a
cell 2.5 H wide and 10 H tall: phi = 4e-5) it is in uniaxial stress to O(phi), e = (1 - eps)^(-1/2)
- 1 for an incompressible solid (the nearly incompressible law's closed form below); 2 ranks give
the serial numbers.
"""

import functools
import math

from mpi4py import MPI

import pytest

from bcfem.mpi import global_sum
from bcfem.scenes.crater_double.params import Params
from bcfem.solver.problem import Problem
from tests.helpers import exact_nominal_stress

NEEDLE = dict(crater_radius=0.05, protuberance_radius=0, specimen_radius=50, specimen_height=10,
              plate="frictionless", cell="array", size_wall=0.04, size_contact=0.02, surface_energy=0)
EPS = 0.1


def lateral_stretch(stretch: float, kappa: float) -> float:
    """The lateral stretch l of the uncratered solid in uniaxial stress, W = (I1 - 3)/2 - ln J +
    p (J - 1) - p^2/(2 kappa): the lateral stress l - 1/l + kappa (J - 1) J / l vanishes, with
    J = stretch l^2 a quadratic's root."""
    b = kappa - 1 / stretch
    J = (b + math.sqrt(b * b + 4 * kappa)) / (2 * kappa)
    return math.sqrt(J / stretch)


def pressed(comm, eps=EPS, **kwargs) -> tuple[float, float]:
    """(lateral strain, platen force per reference area of the cell) at ``eps``, vented."""
    from bcfem.path.stepping import LoadPath
    from bcfem.scenes.crater_double.model import DoubleCrater

    model = DoubleCrater(Params(**{**NEEDLE, **kwargs}).model_inputs(), comm)
    with Problem(model.ctx, model.terms(), model.bcs, f"bcfem_test_array_{comm.size}_",
                 {"snes_type": "vinewtonrsls"}, energy_scale=model.energy_scale,
                 line_search_fallbacks=("bt", "cp")) as problem:
        model.contact_bounds(problem)
        with model.measuring(problem) as force:
            path = LoadPath(problem, model.set_platen, "load", model.viscosity, 1.0, load_name="eps")
            path.start()
            path.through(0.0, eps, eps / 2, lambda _: False)
            nominal = global_sum(force) / (math.pi * model.geometry.specimen_radius**2)
    return model.lateral_strain(), nominal


@functools.cache
def serial(**kwargs):
    return pressed(MPI.COMM_SELF, **kwargs)


@pytest.mark.mpi
def test_a_needle_crater_cell_spreads_in_uniaxial_stress():
    """e and the platen's nominal stress within O(phi) of the closed form, on the side a void
    takes (it softens the cell: a dilute void lowers Young's modulus by 1.92 phi and the lateral
    strain by 0.75 phi); on 2 ranks the serial numbers."""
    e, nominal = pressed(MPI.COMM_WORLD)
    params = Params(**NEEDLE)
    R = params.specimen_radius * params.crater_radius
    phi = params.crater_radius**2 / (R**2 * params.specimen_height)  # the cylinder's volume fraction
    s, stress = lateral_stretch(1 - EPS, params.kappa_ratio), exact_nominal_stress(1 - EPS, params.kappa_ratio)
    print("e:", e, "closed form:", s - 1, "nominal:", nominal, "closed form:", params.beta * stress)
    assert 0 < 1 - e / (s - 1) < 2 * phi
    assert 0 < 1 - nominal / (params.beta * stress) < 3 * phi
    if MPI.COMM_WORLD.size > 1:
        assert (e, nominal) == pytest.approx(serial(), rel=1e-8)


#: a wide crater in a cell 2 r0 wide and 2 H tall: the volume a confined cell loses goes into it
WIDE = dict(crater_radius=0.52, specimen_radius=2, specimen_height=2, size_wall=0.08, size_contact=0.04)


@pytest.mark.parametrize("kwargs", [dict(plate="sticking"), dict(top="bonded"), dict(cell="array-confined")])
def test_a_cell_whose_faces_are_held_does_not_spread(kwargs):
    """A sticking plate or a bonded platen holds the mirror face's radius (rollers, exact); so
    does ``array-confined`` on a frictionless plate: e = 0, and the cell pushes back harder than
    the one that spreads (nearly incompressible, it can only fill its crater)."""
    e, nominal = pressed(MPI.COMM_SELF, eps=0.005, **{**WIDE, **kwargs})
    spreading, free = serial(eps=0.005, **WIDE)
    assert e == 0.0 and spreading > 0
    assert nominal < free < 0
