"""The crater's cycle on a 3-D quarter of its specimen equals the axisymmetric scene's, where
nothing breaks the symmetry: the same terms on Solid3D, the error shrinking with the mesh."""

from mpi4py import MPI

import numpy as np
import pytest

from bcfem.geometry.crater_sector import CraterSector
from bcfem.scenes import crater
from bcfem.scenes.crater_sector import cycle

PRELOAD = 0.02


@pytest.mark.slow
def test_quarter_equals_the_axisymmetric_crater():
    axi_rows, _ = crater.solve(crater.Params(preload=PRELOAD, surface_energy=0.0, self_contact=0.0), MPI.COMM_WORLD)
    axi_load = next(r for r in axi_rows if r["stage"] == "load" and r["eps"] == PRELOAD)
    axi_end = axi_rows[-1]  # unloaded to zero platen force (eps ~ 1e-4)
    errors = []
    for wall, far in ((0.25, 0.6), (0.15, 0.4)):
        rows = cycle(PRELOAD, sector=CraterSector(size_wall=wall, size_far=far))
        loaded = next(r for r in rows if r["stage"] == "load" and np.isclose(r["eps"], PRELOAD))
        unload = [r for r in rows if r["stage"] == "unload"]
        p_end = np.interp(axi_end["eps"], [r["eps"] for r in unload][::-1], [r["p_over_pa"] for r in unload][::-1])
        errors.append([abs(loaded["V_over_V0"] - axi_load["V_over_V0"]),
                       abs(loaded["A_over_A0"] - axi_load["A_over_A0"]),
                       abs(p_end - axi_end["p_over_pa"])])
    print("errors (V, A, p), coarse and fine:", errors)
    coarse, fine = np.array(errors)
    assert np.all(fine < coarse)
    assert fine[0] < 1e-4 and fine[1] < 2e-4 and fine[2] < 1e-5
