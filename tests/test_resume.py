"""Checkpoints and ``--resume``: a run killed at any accepted step goes on from its last
checkpoint, on the same or another number of ranks, and writes the rows and results an
uninterrupted run writes. Faults are injected: SIGKILL of the process or of one rank at
seeded accepted steps, a checkpoint cut half-written, another run's checkpoint."""

import json
import os
import random
import shutil
import subprocess
import time

from mpi4py import MPI

import numpy as np
import pytest
from helpers import BIN, bcfem, killed, rows_on_disk

from bcfem.path.checkpoint import ResumeError, read_fields, write_fields

#: results that depend on the run, not on the physics
RUN_KEYS = {"wall_time_s", "time_split_s", "jit", "versions", "resumed_from", "files", "newton_solves",
            "newton_iterations", "failed_solves", "ranks", "petsc_options", "peak_rss_mb"}
QUIET = ["--no-plots", "--quiet", "--checkpoint-every", "0"]


def assert_same(mine, theirs, where=""):
    """Equal up to round-off (another number of ranks sums in another order)."""
    if isinstance(theirs, dict):
        assert isinstance(mine, dict) and mine.keys() == theirs.keys(), where
        for key in theirs:
            assert_same(mine[key], theirs[key], f"{where}.{key}")
    elif isinstance(theirs, list):
        assert isinstance(mine, list) and len(mine) == len(theirs), where
        for i, (a, b) in enumerate(zip(mine, theirs)):
            assert_same(a, b, f"{where}[{i}]")
    elif isinstance(theirs, float) and not isinstance(theirs, bool):
        assert mine == pytest.approx(theirs, rel=1e-7, abs=1e-9, nan_ok=True), where
    else:
        assert mine == theirs, where


def results(out) -> dict:
    summary = json.loads((out / "summary.json").read_text())
    return {k: v for k, v in summary.items() if k not in RUN_KEYS}


def resumed(args, out, ranks: int = 1) -> dict:
    done = bcfem(*args, *QUIET, "--out", out, "--resume", ranks=ranks)
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "ok" and summary["resumed_from"], summary.get("error")
    assert not (out / "checkpoint").exists() and not list(out.glob(".*"))
    return summary


def uninterrupted(args, tmp_path_factory, ranks: int = 1):
    out = tmp_path_factory.mktemp("resume") / "uninterrupted"
    done = bcfem(*args, *QUIET, "--out", out, ranks=ranks)
    assert done.returncode == 0, done.stderr
    return out


# -- the fields, on any number of ranks ---------------------------------------------------------
def fields(comm, cell_type="triangle"):
    import basix
    from dolfinx import fem, mesh

    domain = mesh.create_unit_square(comm, 6, 5, cell_type=getattr(mesh.CellType, cell_type))
    u = fem.Function(fem.functionspace(domain, ("Lagrange", 2, (2,))), name="displacement")
    p = fem.Function(fem.functionspace(domain, ("DG", 0)), name="pressure")
    r = fem.Function(fem.functionspace(domain, basix.ufl.real_element(domain.basix_cell(), value_shape=(),
                                                                       dtype=np.float64)), name="load")
    u.interpolate(lambda x: np.vstack([np.sin(3 * x[0]) * x[1], x[0] ** 2 + x[1]]))
    p.interpolate(lambda x: x[0] + 7 * x[1])
    r.x.array[:] = 3.25
    return [u, p, r]


@pytest.mark.parametrize("cell_type", ["triangle", "quadrilateral"])
def test_fields_read_back_exactly_and_not_on_another_mesh(tmp_path, cell_type):
    functions = fields(MPI.COMM_SELF, cell_type)
    arrays = [f.x.array.copy() for f in functions]
    reals = write_fields(tmp_path / "f.dat", functions, [arrays, [2 * a for a in arrays]], MPI.COMM_SELF)
    assert reals == [[3.25], [6.5]]
    for f in functions:
        f.x.array[:] = 0.0
    back = read_fields(tmp_path / "f.dat", functions, reals, MPI.COMM_SELF)
    for a, b, c in zip(back[0], back[1], arrays):
        assert np.array_equal(a, c) and np.array_equal(b, 2 * c)
    functions[0].function_space.mesh.geometry.x[:, 0] *= 1.5  # another mesh of as many cells
    with pytest.raises(ResumeError, match="another mesh"):
        read_fields(tmp_path / "f.dat", functions, reals, MPI.COMM_SELF)


@pytest.mark.mpi
def test_fields_written_on_two_ranks_read_back_on_one(tmp_path_factory):
    comm = MPI.COMM_WORLD
    folder = comm.bcast(str(tmp_path_factory.mktemp("fields")) if comm.rank == 0 else None)
    path = __import__("pathlib").Path(folder) / "f.dat"
    functions = fields(comm)
    reals = write_fields(path, functions, [[f.x.array for f in functions]], comm)
    comm.barrier()
    if comm.rank == 0:  # one rank's mesh: the cells in the input's order, dofs numbered otherwise
        serial = fields(MPI.COMM_SELF)
        expected = [f.x.array.copy() for f in serial]
        back = read_fields(path, serial, reals, MPI.COMM_SELF)
        for a, b in zip(back[0], expected):
            assert np.allclose(a, b, rtol=0, atol=1e-15)
    comm.barrier()


# -- bad input ----------------------------------------------------------------------------------
def test_another_runs_checkpoint_is_refused_before_any_meshing(tmp_path):
    out = tmp_path / "run"
    (out / "checkpoint").mkdir(parents=True)
    (out / "checkpoint" / "latest.json").write_text(json.dumps(
        {"key": "load-0", "identity": {"scene": "crater", "preload": 0.3}}))
    done = bcfem("run", "crater", "--preload", "0.2", "--out", out, "--resume", "--quiet")
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "of another run" in done.stderr and "preload" in done.stderr
    assert not (out / "summary.json").exists() and (out / "checkpoint" / "latest.json").exists()
    negative = bcfem("run", "crater", "--out", tmp_path / "other", "--checkpoint-every", "-1")
    assert negative.returncode == 2 and "--checkpoint-every" in negative.stderr
    assert not (tmp_path / "other").exists()


def test_resume_without_a_checkpoint_runs_from_the_start(tmp_path):
    out = tmp_path / "tiny"
    args = ["run", "blister-rigid", "--cells", "20", "--v-max", "0.5"]
    done = bcfem(*args, "--out", out, "--resume", "--quiet")
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "ok" and summary["resumed_from"] is None and "checkpoint" not in summary["files"]


# -- killed and resumed ---------------------------------------------------------------------------
CLOSURE = ["run", "crater", "--preload", "closure"]


@pytest.fixture(scope="module")
def closure(tmp_path_factory):
    return uninterrupted(CLOSURE, tmp_path_factory)


@pytest.mark.slow
def test_a_closure_killed_at_seeded_steps_resumes_to_the_same_results(tmp_path, closure):
    """Killed in the load stage and, resumed, killed again in the unload stage (at accepted steps
    drawn from a seeded schedule); a checkpoint cut half-written on the way is passed over."""
    rows = rows_on_disk(closure)
    loading = sum(row["stage"] == "load" for row in rows)
    draw = random.Random(52)
    first, second = draw.randint(8, loading - 7), draw.randint(loading + 5, len(rows) - 3)
    total = len(rows)
    out = tmp_path / "run"
    assert first <= killed([*CLOSURE, *QUIET], out, first) < total
    # what a write cut by the kill leaves: the next folder of the last key, half of its file
    latest = json.loads((out / "checkpoint" / "latest.json").read_text())["key"]
    seq = json.loads((out / "checkpoint" / f"{latest}.json").read_text())["seq"]
    whole = (out / "checkpoint" / f"{latest}-{seq}" / "fields.dat").read_bytes()
    cut = out / "checkpoint" / f"{latest}-{seq + 1}"
    cut.mkdir(exist_ok=True)  # the kill may have come before the folder replaced was removed
    (cut / "fields.dat").write_bytes(whole[: len(whole) // 2])
    cmd = [str(BIN / "bcfem"), *CLOSURE, *QUIET, "--out", str(out), "--resume"]
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    process = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    while len(rows_on_disk(out)) < second and process.poll() is None:
        time.sleep(0.01)
    assert process.poll() is None, "the resumed run ended before its second kill"
    process.kill()
    process.wait(timeout=60)
    summary = resumed(CLOSURE, out)
    assert summary["resumed_from"].startswith("unload")
    assert rows_on_disk(out) == rows_on_disk(closure)
    assert results(out) == results(closure)
    assert {p.name for p in out.glob("fields*.bp")} == {"fields.bp", "fields.part1.bp", "fields.part2.bp"}


@pytest.mark.slow
@pytest.mark.parametrize("scene", [
    ["run", "crater", "--preload", "0.3"],
    ["run", "blister-3d"],
    ["run", "crater-cell", "--filling", "0.0490873852", "--preload", "0.0125", "--strain-step", "0.001",
     "--size-wall", "0.6", "--size-rim", "0.2", "--size-far", "1.2"],
], ids=["crater", "blister-3d", "crater-cell"])
def test_a_run_killed_on_two_ranks_resumes_on_one(tmp_path, tmp_path_factory, scene):
    """A rank killed after the 10th accepted step; resumed on one rank from the two ranks'
    checkpoint, the rows and results are the uninterrupted run's to round-off."""
    reference = uninterrupted(scene, tmp_path_factory)
    out = tmp_path / "run"
    assert killed([*scene, *QUIET], out, 10, ranks=2, rank=1) >= 10
    resumed(scene, out)
    assert_same(rows_on_disk(out), rows_on_disk(reference))
    assert_same(results(out), results(reference))


def test_a_checkpoint_that_does_not_fit_the_disk_ends_the_run_with_one_line(tmp_path, monkeypatch, capsys):
    """With less free space than a checkpoint needs, the run ends with a full-disk status before
    the checkpoint is begun; the last one stays."""
    from bcfem import cli
    from bcfem.path import checkpoint

    monkeypatch.setattr(checkpoint, "size_of", lambda functions, vectors: shutil.disk_usage(tmp_path).free)
    out = tmp_path / "run"
    code = cli.main(["run", "crater", "--preload", "0.05", *QUIET, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1 and len(err.strip().splitlines()) == 1 and "a checkpoint needs about" in err, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["steps"] == len(rows_on_disk(out)) >= 1
    assert not list(out.rglob("*tmp*")) and not list(out.glob(".*"))


@pytest.mark.slow
def test_a_killed_sweep_resumes_its_point_from_the_points_checkpoint(tmp_path):
    """A sweep killed inside its second point: the rerun reuses the first point and goes on with
    the second from its checkpoint (the point's record says so); the map is the uninterrupted one."""
    sweep = ["sweep", "crater", "--grid", "preload=0.1,0.3", "--quiet", "--checkpoint-every", "0"]
    reference = tmp_path / "reference"
    assert bcfem(*sweep, "--out", reference).returncode == 0
    out = tmp_path / "sweep"
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    process = subprocess.Popen([str(BIN / "bcfem"), *sweep, "--out", str(out)], stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL, env=env)
    deadline = time.monotonic() + 300
    while not list(out.glob("points/preload=0.3_*.checkpoint/load-0-15")):
        assert process.poll() is None and time.monotonic() < deadline, "the sweep ended before it was killed"
        time.sleep(0.01)
    process.kill()
    process.wait(timeout=60)
    assert bcfem(*sweep, "--out", out).returncode == 0
    assert (out / "sweep.csv").read_text() == (reference / "sweep.csv").read_text()
    record = json.loads(next(out.glob("points/preload=0.3_*.json")).read_text())
    assert record["resumed_from"] == "load-0" and not list(out.glob("points/*.checkpoint"))
