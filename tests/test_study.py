"""A study (a demo's many solves) is recorded with the runner's summary schema: its counts are
those of its solves, once for a solve on the study's communicator and summed over the ranks
for a solve on a rank's own (marker ``mpi``), and a study that raises says ``failed``."""

import json

from mpi4py import MPI

import pytest
from test_summary_schema import SCHEMA

from bcfem.run.study import Study
from bcfem.scenes import blister_rigid

SMALL = dict(cells=20, v_max=0.5)


@pytest.mark.mpi
def test_a_study_counts_its_solves_with_the_runners_schema(tmp_path):
    comm = MPI.COMM_WORLD
    out = comm.bcast(tmp_path if comm.rank == 0 else None)
    study = Study("two-blisters", comm, out, parameters={"alphas": [0.0, 1.0]})
    together = study.branch(blister_rigid.build(blister_rigid.Params(**SMALL), comm))
    rows, alone = study.solve(blister_rigid.build(blister_rigid.Params(alpha=1.0, **SMALL), MPI.COMM_SELF),
                              MPI.COMM_SELF)
    summary = study.write({"checks": {"points": len(together.rows)}})
    assert SCHEMA - {"columns"} <= set(summary), SCHEMA - set(summary)
    assert summary["status"] == "ok" and summary["scene"] == "two-blisters"
    assert summary["parameters"] == {"alphas": [0.0, 1.0]} and summary["checks"]["points"] == len(together.rows)
    # the branch once, the rank's own solve on every rank
    assert summary["steps"] == len(together.rows) + comm.size * len(rows)
    assert summary["newton_solves"] >= comm.size * alone["newton_solves"] > 0
    assert summary["newton_iterations"] >= summary["newton_solves"]
    assert any(s["stage"] == "blister-rigid: branch" and s["ended"] for s in summary["stages"])
    assert all(k.startswith("bcfem_blister_rigid_") for k in summary["petsc_options"])
    if comm.rank == 0:
        assert json.loads((out / "summary.json").read_text())["steps"] == summary["steps"]


def test_a_study_that_raises_is_written_as_failed(tmp_path):
    with pytest.raises(ZeroDivisionError):
        with Study("broken", MPI.COMM_SELF, tmp_path):
            1 / 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["error"].startswith("ZeroDivisionError")
    assert "Traceback" in summary["traceback"] and summary["steps"] == 0
