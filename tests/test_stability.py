"""Loss of stability from the tangent's inertia, on a case whose answer is known exactly:
an inflated neo-Hookean membrane is stable under volume control everywhere, and under
pressure control up to the pressure maximum only (a dead load past a limit point)."""

import math

from mpi4py import MPI

import pytest

from bcfem.energies import MembraneStrain
from bcfem.problem import Problem
from bcfem.protocols import find_term
from bcfem.scenes import blister_rigid
from bcfem.stability import unstable_modes
from bcfem.volume_control import VolumeControl

pytestmark = pytest.mark.mpi
FOLD = 0.667656  # V/V0 of the neo-Hookean pressure maximum (tests/test_blister_rigid.py, P2/200)


class DeadPressure:
    """-P V with P a fixed number: pressure control."""

    def __init__(self, pressure):
        self.pressure = pressure

    def energy(self, ctx):
        kin = ctx.kin
        return kin.integral(-ctx.constant("dead_pressure", self.pressure) * kin.volume_density)


@pytest.mark.parametrize("v_over_v0, unstable_under_pressure", [(0.55, 0), (0.66, 0), (0.675, 1), (0.9, 1)])
def test_inertia_finds_the_pressure_maximum(v_over_v0, unstable_under_pressure):
    params = blister_rigid.Params(material="neo-hookean", cells=60)
    scene = blister_rigid.build(params, MPI.COMM_WORLD)
    scene.start()
    volume = Problem(scene.ctx, scene.terms, scene.bcs, scene.prefix, scene.petsc_options)
    VolumeControl.membrane(scene.ctx).solve_to(volume, v_over_v0 * 4 * math.pi / 3)
    # the pressure is the multiplier of the volume constraint: PressureVolume says so
    assert volume.multipliers == ("pressure",)
    assert unstable_modes(volume) == unstable_modes(volume, ["pressure"]) == 0  # volume control: always stable
    pressure = scene.ctx.states["pressure"].x.array[0]
    strain = find_term(scene.terms, MembraneStrain)
    dead = Problem(scene.ctx, [strain, DeadPressure(pressure)], scene.bcs, "dead_", scene.petsc_options)
    # the same state is an equilibrium of the pressure-controlled problem (same u-residual);
    # its unused "pressure" unknown only adds a null pivot, not a negative one, and no term
    # declares it a multiplier
    assert dead.multipliers == ()
    assert unstable_modes(dead) == unstable_under_pressure
    dead.close()
    volume.close()
