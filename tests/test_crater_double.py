"""The double-chamber crater's model: the crater model on the double geometry.

* one sealed cavity before the sidewall meets the protuberance: Boyle's law holds to solver
  tolerance along a compression, on a frictionless and a sticking plate, the same on 1 and
  2 ranks (marker ``mpi``);
* the split: none at rest, at the equator for a sidewall pushed through it;
* bad geometry is refused before meshing, naming the parameter.
"""

import functools

from mpi4py import MPI

import pytest

from bcfem.mpi import global_sum, real_value
from bcfem.physics.fluids import IdealGas
from bcfem.scenes.crater_double.params import Params
from bcfem.solver.problem import Problem

COARSE = dict(size_wall=0.04, size_contact=0.01)
STRAINS = (0.005, 0.01, 0.015)  # before the protuberance reaches the plate (about 0.02)


def sealed_compression(comm, plate: str, bottom: str = "held",
                       strains=STRAINS) -> tuple[list[tuple[float, float]], float]:
    """(p / p_a, V / V_rest) at each of ``strains``, the cavity sealed at p_a at rest, and the
    largest radial slip of the bottom face at the end."""
    import numpy as np
    from dolfinx import fem

    from bcfem.geometry.double_crater import BOTTOM
    from bcfem.path.stepping import LoadPath
    from bcfem.scenes.crater_double.model import SEALED_BOTTOM, DoubleCrater

    model = DoubleCrater(Params(**COARSE, plate=plate, bottom=bottom).model_inputs(), comm)
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
            if any(abs(eps - e) < 1e-12 for e in strains):
                states.append((real_value(model.ctx.states["fluid_pressure"]), global_sum(model.volume) / rest))
            return False

        path.through(0.0, strains[-1], strains[0], accept)
    V = model.u.function_space
    face = fem.locate_dofs_topological(V, 1, np.concatenate([model.facet_tags.find(BOTTOM),
                                                             model.facet_tags.find(SEALED_BOTTOM)]))
    slip = np.abs(model.u.x.array.reshape(-1, 2)[face, 0]).max(initial=0.0)
    return states, comm.allreduce(float(slip), op=MPI.MAX)


@functools.cache
def serial(plate, bottom="held", strains=STRAINS):
    return sealed_compression(MPI.COMM_SELF, plate, bottom, strains)


@pytest.mark.mpi
@pytest.mark.parametrize("plate", ["frictionless", "sticking"])
def test_one_sealed_cavity_obeys_boyle_before_the_split(plate):
    """Boyle's law to solver tolerance; the bottom face slides on a frictionless plate and
    stays put on a sticking one; 2 ranks give the serial numbers."""
    states, slip = sealed_compression(MPI.COMM_WORLD, plate)
    print(plate, "(p/p_a, V/V_rest):", states, "bottom slip:", slip)
    assert len(states) == len(STRAINS)
    volumes = [v for _, v in states]
    assert all(b < a for a, b in zip([1.0, *volumes], volumes))  # the cavity shrinks ...
    for p, v in states:
        assert p * v == pytest.approx(1.0, abs=1e-10)  # ... and its gas keeps p V = p_a V_rest
    if plate == "sticking":
        assert slip == 0.0
    else:
        assert slip > 1e-3  # the specimen spreads: about eps/2 of its radius at the rim
    if MPI.COMM_WORLD.size > 1:
        reference, reference_slip = serial(plate)
        assert [x for s in states for x in s] == pytest.approx([x for s in reference for x in s], rel=1e-8)
        assert slip == pytest.approx(reference_slip, rel=1e-8, abs=1e-14)


@pytest.mark.study
@pytest.mark.parametrize("plate", ["frictionless", "sticking"])
def test_a_bottom_face_in_contact_keeps_boyle_and_its_slip(plate):
    """With the bottom face in contact (the gap under a lifted rim part of the cavity), the
    sealed gas keeps p V = p_a V_rest to solver tolerance, the sticking face does not slip and
    the frictionless one spreads as held."""
    states, slip = sealed_compression(MPI.COMM_WORLD, plate, "contact")
    print(plate, "(p/p_a, V/V_rest):", states, "bottom slip:", slip)
    assert len(states) == len(STRAINS)
    for p, v in states:
        assert p * v == pytest.approx(1.0, abs=1e-10)
    assert slip == 0.0 if plate == "sticking" else slip > 1e-3


@pytest.mark.mpi
@pytest.mark.study
def test_a_bottom_face_in_contact_keeps_boyle_on_one_and_two_ranks():
    """The first step of the frictionless contact compression (the whole one, and the sticking
    plate: ``make study``): p V = p_a V_rest to solver tolerance, the face slides, and
    2 ranks give the serial numbers."""
    states, slip = sealed_compression(MPI.COMM_WORLD, "frictionless", "contact", STRAINS[:1])
    (p, v), = states
    assert p * v == pytest.approx(1.0, abs=1e-10) and v < 1 and slip > 0
    if MPI.COMM_WORLD.size > 1:
        reference, reference_slip = serial("frictionless", "contact", STRAINS[:1])
        assert [x for s in states for x in s] == pytest.approx([x for s in reference for x in s], rel=1e-8)
        assert slip == pytest.approx(reference_slip, rel=1e-8, abs=1e-14)


@pytest.mark.parametrize("kwargs, word", [({"gap": 0.0}, "gap"), ({"protuberance_radius": 0.6}, "protuberance"),
                                          ({"gap": 0.5, "protuberance_radius": 0.2}, "--protuberance-radius"),
                                          ({"plate": "glued"}, "plate")])
def test_bad_geometry_is_refused_naming_the_parameter(kwargs, word):
    with pytest.raises(ValueError, match=word):
        Params(**kwargs)


@pytest.mark.mpi
def test_the_sidewall_on_the_protuberance_is_the_split():
    """At rest there is one chamber; a sidewall pushed just through the protuberance at its
    equator splits it there: (Z_w, Z_b) within an element of the equator's height."""
    import numpy as np

    from bcfem.scenes.crater_double.model import DoubleCrater

    model = DoubleCrater(Params(**COARSE).model_inputs(), MPI.COMM_WORLD)
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


@pytest.mark.parametrize("top", ["sliding", "bonded"])
def test_a_bonded_top_face_does_not_slip_on_the_platen(top):
    """Pressed by 2 %, the top face spreads on a sliding platen (incompressible: by about
    eps/2 of its radius at the rim) and stays put where it is bonded to the backing."""
    import numpy as np
    from dolfinx import fem

    from bcfem.geometry.double_crater import TOP
    from bcfem.path.stepping import LoadPath
    from bcfem.scenes.crater_double.model import DoubleCrater

    model = DoubleCrater(Params(size_wall=0.08, size_contact=0.02, top=top).model_inputs(), MPI.COMM_SELF)
    with Problem(model.ctx, model.terms(), model.bcs, f"bcfem_test_top_{top}_", {"snes_type": "vinewtonrsls"},
                 energy_scale=model.energy_scale) as problem:
        model.contact_bounds(problem)
        path = LoadPath(problem, model.set_platen, "load", model.viscosity, 1.0, load_name="eps")
        path.start()
        assert path.through(0.0, 0.02, 0.02) == 0.02
    V = model.u.function_space
    dofs = fem.locate_dofs_topological(V, 1, model.facet_tags.find(TOP))
    slip = np.abs(model.u.x.array.reshape(-1, 2)[dofs, 0]).max()
    rim = model.geometry.specimen_radius
    if top == "bonded":
        assert slip == 0.0
    else:
        assert 0.2 * 0.01 * rim < slip < 2 * 0.01 * rim
