"""The double-chamber crater's model (issue #24): the crater model on the double geometry.

* one sealed cavity before the sidewall meets the protuberance: Boyle's law holds to solver
  tolerance along a compression, the same on 1 and 2 ranks (marker ``mpi``);
* bad geometry is refused before meshing, naming the parameter.
"""

import functools

from mpi4py import MPI

import pytest

from bcfem.fluids import IdealGas
from bcfem.mpi import global_sum, real_value
from bcfem.problem import Problem
from bcfem.scenes.crater_double.params import Params

COARSE = dict(size_wall=0.04, size_contact=0.01)
STRAINS = (0.005, 0.01, 0.015)  # before the protuberance reaches the plate (about 0.02)


def sealed_compression(comm) -> list[tuple[float, float]]:
    """(p / p_a, V / V_rest) at each of STRAINS, the cavity sealed at p_a at rest."""
    from bcfem.scenes.crater_double.model import DoubleCrater
    from bcfem.stepping import LoadPath

    model = DoubleCrater(Params(**COARSE), comm)
    rest = global_sum(model.volume)
    model.ctx.real_state("fluid_pressure").x.array[:] = 1.0
    terms = model.terms(IdealGas(model.cavity, rest))
    with Problem(model.ctx, terms, model.bcs, f"bcfem_test_double_{comm.size}_", {"snes_type": "vinewtonrsls"},
                 energy_scale=model.energy_scale, line_search_fallbacks=("bt", "cp")) as problem:
        model.contact_bounds(problem)
        path = LoadPath(problem, model.set_platen, "load", model.viscosity, 1.0, load_name="eps")
        path.start()
        states = []

        def accept(eps):
            if any(abs(eps - e) < 1e-12 for e in STRAINS):
                states.append((real_value(model.ctx.states["fluid_pressure"]), global_sum(model.volume) / rest))
            return False

        path.through(0.0, STRAINS[-1], STRAINS[0], accept)
    return states


@functools.cache
def serial():
    return sealed_compression(MPI.COMM_SELF)


@pytest.mark.mpi
def test_one_sealed_cavity_obeys_boyle_before_the_split():
    states = sealed_compression(MPI.COMM_WORLD)
    print("(p/p_a, V/V_rest):", states)
    assert len(states) == len(STRAINS)
    volumes = [v for _, v in states]
    assert all(b < a for a, b in zip([1.0, *volumes], volumes))  # the cavity shrinks ...
    for p, v in states:
        assert p * v == pytest.approx(1.0, abs=1e-10)  # ... and its gas keeps p V = p_a V_rest
    if MPI.COMM_WORLD.size > 1:
        assert [x for s in states for x in s] == pytest.approx([x for s in serial() for x in s], rel=1e-8)


@pytest.mark.parametrize("kwargs, word", [({"gap": 0.0}, "gap"), ({"protuberance_radius": 0.6}, "protuberance"),
                                          ({"gap": 0.5, "protuberance_radius": 0.2}, "protuberance_radius")])
def test_bad_geometry_is_refused_naming_the_parameter(kwargs, word):
    with pytest.raises(ValueError, match=word):
        Params(**kwargs)


@pytest.mark.mpi
def test_the_sidewall_on_the_protuberance_is_the_split():
    """At rest there is one chamber; a sidewall pushed just through the protuberance at its
    equator splits it there: (Z_w, Z_b) within an element of the equator's height."""
    import numpy as np

    from bcfem.scenes.crater_double.model import DoubleCrater

    model = DoubleCrater(Params(**COARSE), MPI.COMM_WORLD)
    g = model.geometry
    zc, h = g.centre_height, COARSE["size_contact"]
    width = g.r0 - g.R0
    with Problem(model.ctx, model.terms(), model.bcs, f"bcfem_test_split_{MPI.COMM_WORLD.size}_"):
        assert model.sidewall_contact() is None
        # the sidewall moved 1.05 times the gap inwards around the equator; the ball stays
        model.u.interpolate(lambda x: np.vstack([-1.05 * width * np.clip((x[0] - g.R0) / width, 0, 1)
                                                 * np.exp(-(((x[1] - zc) / 0.1) ** 2)), 0 * x[0]]))
        Zw, Zb = model.sidewall_contact()
    assert abs(Zw - zc) <= h and abs(Zb - zc) <= 2 * h
