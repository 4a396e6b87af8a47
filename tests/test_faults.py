"""Faults lose nothing: a run killed outright (SIGKILL: the out-of-memory killer, a lost node, a
job's wall-time limit) keeps every row it accepted, and ``bcfem status`` (or the next run in its
directory) records it as ``killed``."""

import json
import os
import subprocess

from mpi4py import MPI

import pytest
from helpers import BIN, bcfem, killed, rows_on_disk

from bcfem import io

pytestmark = pytest.mark.serial
#: a crater cycle of about 35 accepted states, killed after its 10th
CYCLE = ["run", "crater", "--preload", "0.3", "--no-plots", "--quiet"]
KILLED_AFTER = 10


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    out = tmp_path_factory.mktemp("faults") / "uninterrupted"
    done = bcfem(*CYCLE, "--out", out)
    assert done.returncode == 0, done.stderr
    return rows_on_disk(out)


@pytest.mark.slow
@pytest.mark.parametrize("ranks, rank", [(1, None), (2, 1)], ids=["process", "one-of-two-ranks"])
def test_a_killed_run_keeps_its_rows_and_is_recorded_killed(tmp_path, uninterrupted, ranks, rank):
    out = tmp_path / "killed"
    kept = killed(CYCLE, out, KILLED_AFTER, ranks, rank)
    rows = rows_on_disk(out)
    assert KILLED_AFTER <= kept < len(uninterrupted)
    for mine, theirs in zip(rows, uninterrupted):  # the accepted rows, as an uninterrupted run has them
        assert mine.keys() == theirs.keys()
        for key, value in theirs.items():
            assert mine[key] == (value if isinstance(value, str) else pytest.approx(value, rel=1e-7, abs=1e-12))
    # mpirun may pass the kill on as a signal the other rank answers: interrupted, its rows kept
    summary = json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else None
    if summary is not None and summary["status"] == "interrupted":
        assert summary["steps"] == len(rows)
        return
    status = bcfem("status", out)
    assert status.returncode == 1 and "killed" in status.stdout and f"its {len(rows)} accepted rows" in status.stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "killed" and summary["scene"] == "crater" and summary["steps"] == len(rows)
    assert not list(out.glob(".*")), "the killed run's lock and temporaries are left"
    if ranks == 1:  # its VTX steps are kept: BP4's index has one 64-byte record per step
        assert "fields.bp" in summary["files"]
        assert (os.path.getsize(out / "fields.bp" / "md.idx") - 64) // 64 >= len(rows)
    # the next run takes the directory over and finishes
    again = bcfem(*CYCLE, "--out", out)
    assert again.returncode == 0, again.stderr
    assert rows_on_disk(out) == uninterrupted and not (out / ".bcfem.lock").exists()


def test_status_reads_a_finished_run_and_an_empty_directory(tmp_path):
    out = tmp_path / "tiny"
    assert bcfem("run", "blister-rigid", "--cells", "20", "--v-max", "0.5", "--quiet", "--out", out).returncode == 0
    status = bcfem("status", out)
    assert status.returncode == 0 and "blister-rigid ok" in status.stdout
    assert bcfem("status", tmp_path / "nothing").returncode == 2


def test_the_row_journal_follows_replaced_rows_and_restarts(tmp_path):
    """Rows appended as accepted; a replaced last row and a restart rewrite the file."""
    path = tmp_path / "branch.csv"
    journal = io.RowJournal(path, ["eps", "V"], MPI.COMM_SELF)
    journal.append({"eps": 0.1, "V": 1.0})
    journal.append({"eps": 0.2, "V": 0.5, "other": "left out"})
    assert io.read_csv(path) == [{"eps": 0.1, "V": 1.0}, {"eps": 0.2, "V": 0.5}]
    journal.rewrite([{"eps": 0.1, "V": 1.0}, {"eps": 0.15, "V": 0.75}])
    journal.append({"eps": 0.3, "V": 0.25})
    assert [r["eps"] for r in io.read_csv(path)] == [0.1, 0.15, 0.3]
    journal.rewrite([])
    journal.close()
    assert io.read_csv(path) == [] and path.read_text().strip() == "eps,V"


TINY = ["run", "blister-rigid", "--material", "gent", "--Jm", "100", "--alpha", "0.5", "--v-max", "6", "--quiet"]


def assert_ended_by_a_full_disk(out, code: int, stderr: str) -> dict:
    """Exit 1 with one line naming the device; no temporary left; the rows accepted before are
    on disk, whole, and the summary (where it fit) says failed."""
    assert code == 1, stderr
    assert len(stderr.strip().splitlines()) == 1 and "no space left on the device of" in stderr, stderr
    assert "Traceback" not in stderr and not list(out.rglob("*tmp*")) and not list(out.glob(".*"))
    rows = io.read_csv(out / "branch.csv")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["error"].startswith("no space left")
    assert summary["steps"] == len(rows) and (out / "branch.csv").read_text().endswith("\n")
    return summary


@pytest.fixture
def small_filesystem(tmp_path):
    """A 300 kB tmpfs (root only: the test is skipped where mounting is not allowed)."""
    where = tmp_path / "small"
    where.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=300k", "tmpfs", str(where)], capture_output=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.decode().strip()}")
    yield where
    subprocess.run(["umount", str(where)], check=False)


def test_a_full_filesystem_ends_the_run_with_one_line(small_filesystem):
    out = small_filesystem / "run"
    done = bcfem(*TINY, "--out", out)
    summary = assert_ended_by_a_full_disk(out, done.returncode, done.stderr)
    assert 1 <= summary["steps"] and "fields.bp" in summary["files"]  # the steps that fit are kept


def test_a_write_that_fails_for_space_keeps_whole_rows(tmp_path, monkeypatch):
    """An injected ENOSPC in the middle of a row: the journal cuts the half row off and raises
    DiskFull; a CSV, JSON or PNG written atomically leaves no temporary."""
    import errno

    journal = io.RowJournal(tmp_path / "branch.csv", ["eps", "V"], MPI.COMM_SELF)
    journal.append({"eps": 0.1, "V": 1.0})

    def no_space(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    def half_a_row(row):  # what a write got out before the device filled
        journal._file.write("0.2,0.")
        journal._file.flush()
        no_space()

    monkeypatch.setattr(journal._writer, "writerow", half_a_row)
    with pytest.raises(io.DiskFull, match="no space left on the device of"):
        journal.append({"eps": 0.2, "V": 0.5})
    assert (tmp_path / "branch.csv").read_text() == "eps,V\n0.1,1.0\n"
    monkeypatch.setattr(io.os, "replace", no_space)
    with pytest.raises(io.DiskFull):
        io.write_json(tmp_path / "summary.json", {"status": "ok"}, MPI.COMM_SELF)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["branch.csv"]


def test_fields_stop_before_the_disk_is_full(tmp_path, monkeypatch, capsys):
    """With less free space than a VTX step needs, the run ends with a full-disk status before
    ADIOS2 writes the step (ADIOS2 aborts the process on a failed write)."""
    import shutil
    from collections import namedtuple

    from bcfem import cli

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(io.shutil, "disk_usage", lambda path: usage(1 << 20, 1 << 20, 16 * 1024))
    out = tmp_path / "run"
    code = cli.main([*TINY, "--out", str(out)])
    monkeypatch.setattr(io.shutil, "disk_usage", shutil.disk_usage)
    summary = assert_ended_by_a_full_disk(out, code, capsys.readouterr().err)
    assert summary["steps"] == 0


def test_a_factorisation_past_the_ranks_memory_is_refused_before_it_starts(tmp_path, monkeypatch, capsys):
    """Before its first factorisation a problem asks MUMPS's analysis for its estimate and
    compares it with what each rank may use: with 1 MB left the run ends at once, exit 1, one line
    with the estimate, no Newton step taken."""
    from bcfem import cli
    from bcfem.solver import memory

    monkeypatch.setattr(memory, "available_mb", lambda comm: 1)
    out = tmp_path / "cell"
    code = cli.main(["run", "crater-cell", "--preload", "0.0125", "--quiet", "--no-plots", "--out", str(out)])
    stderr = capsys.readouterr().err
    assert code == 1 and len(stderr.strip().splitlines()) == 1, stderr
    assert "out of memory: the factorisation needs about" in stderr and "each rank has about 1 MB left" in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["newton_iterations"] == 0


@pytest.mark.slow
def test_a_factorisation_mumps_refuses_for_memory_stops_the_run(tmp_path):
    """A factorisation that fails for memory all the same (here past the user's ICNTL(23) of
    2 MB) ends the run with MUMPS's reason instead of cutting the step."""
    out = tmp_path / "cell"
    done = bcfem("run", "crater-cell", "--preload", "0.0125", "--quiet", "--no-plots", "--out", out,
                 "-mat_mumps_icntl_23", "2")
    assert done.returncode == 1 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "more than ICNTL(23) allows (MUMPS INFOG(1) = -19)" in done.stderr
    assert json.loads((out / "summary.json").read_text())["failed_solves"] <= 1


@pytest.mark.study
def test_a_cell_past_ulimit_v_stops_before_the_kernel_kills_it(tmp_path):
    """The #53 cell (66k dofs, MUMPS about 545 MB) under ``ulimit -v`` 1.7 GB: refused before the
    factorisation (machine-dependent: the limit must sit between the process's size and its size
    plus the factors)."""
    import resource

    def limited():
        resource.setrlimit(resource.RLIMIT_AS, (17 * 10**8, 17 * 10**8))

    out = tmp_path / "cell"
    cmd = [str(BIN / "bcfem"), "run", "crater-cell", "--filling", "0.0490873852", "--preload", "0.0125",
           "--size-wall", "0.15", "--size-rim", "0.05", "--size-far", "0.4", "--quiet", "--no-plots", "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True, preexec_fn=limited, timeout=600)
    assert done.returncode == 1 and "out of memory" in done.stderr, done.stderr[-2000:]


def test_the_users_mumps_options_reach_mumps(tmp_path):
    """MUMPS reads its options at its analysis, after the problem's options left the database:
    ``-mat_mumps_icntl_4 2`` (MUMPS's diagnostics) must still reach it."""
    done = bcfem("run", "blister-rigid", "--cells", "20", "--v-max", "0.5", "--quiet", "--no-plots",
                 "--out", tmp_path / "run", "-mat_mumps_icntl_4", "2")
    assert done.returncode == 0 and "MUMPS" in done.stdout + done.stderr
