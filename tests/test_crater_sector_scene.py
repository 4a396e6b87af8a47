"""``bcfem run crater-sector``: bad input exits 2 before meshing; the drawn drive's rows and
summary on a coarse wedge pi/8 (the plain crater holds a suction linear in the volume drawn off
while it is small, and no mode is unstable); 2 ranks equal COMM_SELF."""

from mpi4py import MPI

import pytest

from bcfem.scenes import crater_sector
from tests.helpers import refused

TINY = crater_sector.Params(drive="drawn", wedge_waves=8, drawn_max=0.01, drawn_step=0.005)


@pytest.mark.parametrize(("argv", "name"), [
    (("--wedge-waves", "0"), "--wedge-waves"),
    (("--size-wall", "0.5", "--size-far", "0.3"), "--size-far"),
    (("--drive", "drawn", "--amplitude-max", "0.001", "--amplitude-step", "0.002"), "--amplitude-step"),
    (("--layer-thickness", "0.001"), "--layer-thickness"),
])
def test_bad_input_exits_2(tmp_path, argv, name):
    assert name in refused("run", "crater-sector", *argv, out=tmp_path / "out")


@pytest.mark.mpi
def test_the_drawn_drive_on_a_tiny_wedge():
    comm = MPI.COMM_WORLD
    rows, summary = crater_sector.solve(TINY, comm)
    assert summary["status"] == "ok" and summary["onset"] is None
    assert [r["r"] for r in rows] == pytest.approx([0.005, 0.01])
    assert all(r["unstable"] == 0 and r["branch"] == "fundamental" for r in rows)
    # linear while small: twice the volume drawn off, twice the suction (to the geometry's 1 %)
    assert rows[1]["s"] / rows[0]["s"] == pytest.approx(2.0, rel=0.01)
    if comm.size > 1:
        alone, _ = crater_sector.solve(TINY, MPI.COMM_SELF)
        for row, single in zip(rows, alone):
            assert row["s"] == pytest.approx(single["s"], rel=1e-9)
