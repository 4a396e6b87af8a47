"""Faults lose nothing: a run killed outright (SIGKILL: the out-of-memory killer, a lost node, a
job's wall-time limit) keeps every row it accepted, and ``bcfem status`` (or the next run in its
directory) records it as ``killed``."""

import json
import os
import signal
import subprocess
import time

from mpi4py import MPI

import pytest
from helpers import BIN, bcfem
from test_run_contract import rank_pids

from bcfem import io

pytestmark = pytest.mark.serial
#: a crater cycle of about 35 accepted states, killed after its 10th
CYCLE = ["run", "crater", "--preload", "0.3", "--no-plots", "--quiet"]
KILLED_AFTER = 10


def rows_on_disk(out) -> list[dict]:
    return io.read_csv(out / "branch.csv") if (out / "branch.csv").exists() else []


def killed(out, ranks: int = 1, rank: int | None = None) -> int:
    """Run ``bcfem CYCLE --out out`` and SIGKILL it (or one of its ranks) once ``branch.csv``
    holds KILLED_AFTER rows; returns the rows on disk then."""
    cmd = [str(BIN / "bcfem"), *CYCLE, "--out", str(out)]
    if ranks > 1:
        cmd = [str(BIN / "mpirun"), "-n", str(ranks), *cmd]
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    process = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    deadline = time.monotonic() + 300
    while len(rows_on_disk(out)) < KILLED_AFTER:
        assert process.poll() is None and time.monotonic() < deadline, "the run ended before it was killed"
        time.sleep(0.02)
    if rank is None:
        process.kill()
    else:
        os.kill(rank_pids(process.pid)[rank], signal.SIGKILL)
    process.wait(timeout=120)
    return len(rows_on_disk(out))


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
    kept = killed(out, ranks, rank)
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
