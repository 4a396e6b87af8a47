"""The lined crater's first non-axisymmetric bifurcation on the 3-D wedge pi/8, and the branch
past it (a study: about three minutes serial, marker ``study``; on 2 ranks also COMM_SELF's).

A stiff lining (t = 0.05 a, beta' = 1000) on the crater, at eps = 0 with the volume drawn off,
wrinkles in hoop. The wedge pi/8 admits n = 8, 16, ...; its first bifurcation, by the inertia of
its 3-D tangent, is the axisymmetric scene's n = 8 onset (the same specimen, its n-wave blocks,
:mod:`bcfem.stability.modes`) within 5 %. The critical mode is n = 8 on the wall, and the
bifurcated branch, followed by its amplitude, is subcritical: it turns back to a fold at a
smaller drawn volume, is stable past it, and holds less suction there than at the onset.
"""

from mpi4py import MPI

import numpy as np
import pytest

from bcfem.geometry.crater_sector import CraterSector
from bcfem.scenes.crater_sector import axisymmetric_suction_waves, drawn_stability

LINING, STIFFNESS, WAVES = 0.05, 1000.0, 8
DRAWN = [0.01, 0.02, 0.03, 0.034, 0.036, 0.037, 0.038, 0.0385, 0.039, 0.04]
AMPLITUDES = [0.002, 0.004, 0.006, 0.008, 0.01, 0.012]


def wedge(comm):
    return drawn_stability(DRAWN, layer_stiffness=STIFFNESS, amplitudes=AMPLITUDES, comm=comm,
                           sector=CraterSector(size_wall=0.1, layer_thickness=LINING, wedge_waves=WAVES))


@pytest.mark.study
@pytest.mark.mpi
def test_the_wedge_bifurcates_at_the_n_wave_onset_onto_a_subcritical_branch():
    comm = MPI.COMM_WORLD
    axi = axisymmetric_suction_waves(list(np.arange(0.034, 0.0401, 0.0005)), WAVES, LINING, STIFFNESS, 0.05,
                                     drawn=True, comm=comm)
    first = next(i for i, row in enumerate(axi) if row["waves"][WAVES] > 0)
    assert first > 0 and axi[first - 1]["n0"] == 0
    axi_onset = 0.5 * (axi[first - 1]["s"] + axi[first]["s"])

    result = wedge(comm)
    s = {row[0]: row[2] for row in result["rows"]}
    below, above = result["onset"]
    print("axisymmetric n = 8 onset s in", axi[first - 1]["s"], axi[first]["s"], "; wedge", s[below], s[above])
    assert s[above] - s[below] < 0.01 * s[below]
    assert 0.5 * (s[below] + s[above]) == pytest.approx(axi_onset, rel=0.05)

    assert result["waves"] == WAVES and all(abs(c) < 0.05 for n, c in result["mode"]["fourier"].items() if n != WAVES)
    branch = result["branch"]
    assert result["branch_failure"] is None and len(branch) == len(AMPLITUDES)
    for row in branch:
        print("branch", row["amplitude"], row["r"], row["s"], row["unstable"], row["fourier"])
    fold = min(range(len(branch)), key=lambda i: branch[i]["r"])
    assert 0 < fold < len(branch) - 1 and branch[fold]["r"] < below  # subcritical: it turns back
    assert all(row["unstable"] == 1 for row in branch[:fold - 1]) and branch[-1]["unstable"] == 0
    beyond = branch[-1]
    assert beyond["r"] > above and beyond["s"] < 0.9 * s[below]
    assert abs(beyond["fourier"][2 * WAVES]) < 0.1 * abs(beyond["fourier"][WAVES])

    if comm.size > 1:  # the same onset and branch as one process alone
        alone = wedge(MPI.COMM_SELF)
        assert alone["onset"] == result["onset"]
        for row, single in zip(branch, alone["branch"]):
            assert row["r"] == pytest.approx(single["r"], abs=1e-8)
            assert row["s"] == pytest.approx(single["s"], abs=1e-7)
            assert row["unstable"] == single["unstable"]
