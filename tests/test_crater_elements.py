"""The crater on Q1-P0 quadrilaterals (``--element q1p0``, the analogue of Abaqus's CAX4H)
against Taylor-Hood P2-P1 triangles, the default."""

from mpi4py import MPI

import pytest
from helpers import refused

from bcfem.scenes import crater

#: vented loading to a small preload, no wall-plate contact yet, no surface energy
SMALL = dict(preload=0.05, strain_step=0.025, surface_energy=0.0)


def test_q1p0_crater_converges_to_the_p2p1_crater_at_second_order():
    """The crater's volume at the end of vented loading, V1, is an integral of the wall's
    displacement (and of the straight-sided wall's chords): both errors are O(h^2) for bilinear
    elements, so halving h cuts Q1-P0's distance from P2-P1 (whose own error is O(h^3), below
    1e-6 here) at least threefold. The suction force, a difference of nearly equal volumes,
    agrees within 1 %."""
    reference = crater.solve(crater.Params(size_crater=0.12, **SMALL), MPI.COMM_WORLD)[1]
    errors = []
    for h in (0.12, 0.06):
        summary = crater.solve(crater.Params(element="q1p0", size_crater=h, **SMALL), MPI.COMM_WORLD)[1]
        errors.append(abs(summary["V1_over_V0"] - reference["V1_over_V0"]))
        assert summary["F_tilde"] == pytest.approx(reference["F_tilde"], rel=1e-2)
        assert summary["fluid_law_residual"] == pytest.approx(0.0, abs=1e-10)
    assert errors[1] < errors[0] / 3, errors


@pytest.mark.mpi
def test_q1p0_crater_on_two_ranks_equals_serial():
    """The same cycle with self-contact and the n-wave check, on this rank alone and on all
    ranks (the wall's P1 segments, the DG0 pressure and the quadrilaterals distributed)."""
    params = crater.Params(element="q1p0", preload=0.08, strain_step=0.02, waves=3, size_crater=0.12)
    serial = crater.solve(params, MPI.COMM_SELF)[1]
    parallel = crater.solve(params, MPI.COMM_WORLD)[1]
    for key in ("F_tilde", "V1_over_V0", "V2_over_V0", "p2_over_pa", "A2_over_A0", "eps_at_zero_force"):
        assert parallel[key] == pytest.approx(serial[key], rel=1e-8), key
    assert parallel["instabilities"] == serial["instabilities"]
    assert serial["symmetry_breaking"] == {} and serial["stability"] == "stable"


@pytest.mark.parametrize("value", ["p3p2", "Q1P0", "cax4h"])
def test_an_unknown_element_exits_2_before_meshing(tmp_path, value):
    assert "element" in refused("run", "crater", "--element", value, out=tmp_path / "bad")
