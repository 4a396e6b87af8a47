"""The run-time contract of ``bcfem run|sweep|fit``: a signal leaves ``status:
interrupted`` and what converged; ``--out`` is locked and cleared of an earlier run's files
only; every JSON file is strict; a failure, also an internal one, is a status and an exit code,
never a traceback."""

import json
import math
import os
import re
import signal
import socket
import subprocess
from pathlib import Path

from mpi4py import MPI

import numpy as np
import pytest
from helpers import BIN, bcfem, on_ranks

from bcfem import interrupt, io
from bcfem.run import sweep
from bcfem.scenes import blister_rigid, blister_studies

TINY = ["run", "blister-rigid", "--cells", "20", "--v-max", "0.5", "--quiet"]
#: a crater pressed to near closure: minutes of load steps, signalled after its first
LONG = ["run", "crater", "--preload", "0.85", "--no-plots"]


def strict(path) -> dict:
    """``path`` parsed as strict JSON (Infinity and NaN refused)."""
    def refuse(constant):
        raise ValueError(f"{path}: {constant} is no JSON")

    return json.loads(Path(path).read_text(), parse_constant=refuse)


def rows_of(out) -> int:
    return len((out / "branch.csv").read_text().splitlines()) - 1


def rank_pids(mpirun: int) -> dict[int, int]:
    """{rank: pid} of the processes mpirun started (its grandchildren, by PMI_RANK)."""
    def children(pid):
        return [int(p.name) for p in Path("/proc").iterdir() if p.name.isdigit()
                and _parent(p) == pid]

    pids = {}
    for pid in (g for c in children(mpirun) for g in children(c)):
        environ = Path(f"/proc/{pid}/environ").read_bytes().split(b"\0")
        rank = next((e.split(b"=")[1] for e in environ if e.startswith(b"PMI_RANK=")), None)
        if rank is not None:
            pids[int(rank)] = pid
    return pids


def _parent(proc: Path) -> int | None:
    try:
        return int((proc / "stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, IndexError, ValueError):
        return None


def signalled(argv, out, signum, pattern, ranks=1, meanwhile=None, rank=None) -> tuple[int, str]:
    """Run ``bcfem argv --out out``; once stderr has a line matching ``pattern`` (an accepted
    state), call ``meanwhile()``, send ``signum`` (to mpirun for ranks > 1, or to ``rank``
    alone); (exit code, stderr)."""
    cmd = on_ranks([str(BIN / "bcfem"), *argv, "--out", str(out)], ranks)
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    process = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    seen = []
    for line in process.stderr:
        seen.append(line)
        if re.search(pattern, line):
            break
    if meanwhile is not None:
        meanwhile()
    if rank is None:
        process.send_signal(signum)
    else:
        os.kill(rank_pids(process.pid)[rank], signum)
    try:
        _, rest = process.communicate(timeout=120)
    except subprocess.TimeoutExpired:  # a rank left waiting: end them all
        for pid in rank_pids(process.pid).values() if ranks > 1 else ():
            os.kill(pid, signal.SIGKILL)
        process.kill()
        raise
    return process.returncode, "".join(seen) + rest


def assert_interrupted(out, code, stderr, signum):
    assert code == 128 + signum, stderr[-2000:]
    assert "Traceback" not in stderr
    summary = strict(out / "summary.json")
    assert summary["status"] == "interrupted" and signal.Signals(signum).name in summary["error"]
    assert rows_of(out) == summary["steps"] >= 1  # what converged before the signal
    assert not [p.name for p in out.rglob("*tmp*")], "temporary files left behind"
    assert not (out / ".bcfem.lock").exists()
    return summary


@pytest.mark.serial
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_ends_a_run_with_status_interrupted(tmp_path, signum):
    """Neither signal is taken for a failed Newton solve: the run stops, writes what converged
    and exits 128 + the signal's number. While it runs, a second run into its directory is
    refused (exit 2, one line), before any meshing."""
    out = tmp_path / "run"
    refused = []

    def second_run():
        refused.append(bcfem(*TINY, "--out", out))

    code, stderr = signalled(LONG, out, signum, r"^load ", meanwhile=second_run if signum == signal.SIGINT else None)
    assert_interrupted(out, code, stderr, signum)
    for res in refused:
        assert res.returncode == 2
        assert re.fullmatch(r"bcfem run blister-rigid: error: --out \S+ is in use by another run \(pid \d+\)\n",
                            res.stderr), res.stderr


COMPILE_UNDER_A_SIGNAL = """
import os, signal, sys, threading
import dolfinx_solver
from mpi4py import MPI
import ufl
from dolfinx import fem, mesh
from bcfem import interrupt
interrupt.install(MPI.COMM_WORLD)
msh = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
u = fem.Function(fem.functionspace(msh, ("Lagrange", 4)))
energy = ufl.exp(ufl.sin(u) ** 7 + ufl.cos(u) ** 5) * ufl.inner(ufl.grad(u), ufl.grad(u)) ** 3 * ufl.dx
form = ufl.derivative(energy, u, ufl.TestFunction(u.function_space))  # a compile of 1-2 s
threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
fem.form(form, jit_options={"cache_dir": sys.argv[1]})
print("compiled", interrupt.requested())
"""


@pytest.mark.serial
def test_a_signal_during_a_form_compile_lets_it_finish(tmp_path):
    """FFCx removes a failed compile's lock file (the ``.c`` whose ``.so`` other processes wait
    for) on an Exception only: a signal raised mid-compile would leave it, and every later compile
    of that form would time out. bcfem defers the signal until the compile is done."""
    cache = tmp_path / "cache"
    done = subprocess.run([str(BIN / "python"), "-c", COMPILE_UNDER_A_SIGNAL, str(cache)], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["compiled", "True"]
    sources = {p.stem for p in cache.glob("*.c")}
    assert sources and all(list(cache.glob(f"{stem}*.so")) for stem in sources)


@pytest.mark.serial
@pytest.mark.parametrize("rank", [None, 1])
def test_a_signal_to_mpirun_or_one_rank_gives_the_same_status(tmp_path, rank):
    """mpirun passes the signal on to every rank; one that reaches a single rank stops every
    rank at the same Newton iteration (no rank is left waiting in a collective)."""
    out = tmp_path / "mpi"
    code, stderr = signalled(LONG, out, signal.SIGINT, r"^load ", ranks=2, rank=rank)
    assert assert_interrupted(out, code, stderr, signal.SIGINT)["ranks"] == 2


@pytest.fixture
def in_process(monkeypatch):
    """Run ``bcfem.cli.main`` in this process: its signal handlers and log set-up go afterwards."""
    from bcfem import cli
    from bcfem.log import logger

    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    monkeypatch.setattr(interrupt, "_installed", interrupt._installed)
    monkeypatch.setattr(interrupt, "_raise_at_once", interrupt._raise_at_once)
    monkeypatch.setattr(logger, "handlers", list(logger.handlers))
    monkeypatch.setattr(logger, "level", logger.level)
    monkeypatch.setattr(logger, "propagate", logger.propagate)
    yield cli.main
    for s, handler in handlers.items():
        signal.signal(s, handler)


def _lock(out: Path, pid: int) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / ".bcfem.lock").write_text(json.dumps({"pid": pid, "host": socket.gethostname()}))


def test_a_live_lock_refuses_the_run(tmp_path):
    out = tmp_path / "locked"
    _lock(out, os.getpid())  # a live process
    res = bcfem(*TINY, "--out", out)
    assert res.returncode == 2 and f"is in use by another run (pid {os.getpid()})" in res.stderr
    assert len(res.stderr.splitlines()) == 1 and sorted(p.name for p in out.iterdir()) == [".bcfem.lock"]


@pytest.mark.serial
def test_a_killed_runs_lock_is_taken_over(tmp_path, in_process):
    gone = subprocess.Popen(["true"])
    gone.wait()
    out = tmp_path / "stale"
    _lock(out, gone.pid)
    (out / f".fields.{gone.pid}.tmp.bp").mkdir()  # what the killed run was writing
    assert in_process([*TINY, "--out", str(out)]) == 0
    assert not (out / ".bcfem.lock").exists() and strict(out / "summary.json")["status"] == "ok"
    assert not list(out.glob(".*"))


@pytest.mark.serial
def test_out_that_is_a_file_is_bad_input(tmp_path, in_process, capsys):
    path = tmp_path / "results"
    path.write_text("mine")
    with pytest.raises(SystemExit) as exit:
        in_process([*TINY, "--out", str(path)])
    stderr = capsys.readouterr().err
    assert exit.value.code == 2 and "--out" in stderr and len(stderr.splitlines()) == 1
    assert path.read_text() == "mine" and sorted(p.name for p in tmp_path.iterdir()) == ["results"]


@pytest.mark.serial
def test_an_earlier_runs_files_go_and_the_users_stay(tmp_path, in_process, capsys):
    out = tmp_path / "again"
    assert in_process([*TINY, "--out", str(out)]) == 0
    assert (out / "pv.png").exists()
    (out / "notes.txt").write_text("the user's")
    capsys.readouterr()
    assert in_process([*TINY, "--no-plots", "--out", str(out)]) == 0
    files = ["branch.csv", "fields.bp", "summary.json"]
    assert strict(out / "summary.json")["files"] == files
    assert sorted(p.name for p in out.iterdir()) == sorted([*files, "notes.txt"])
    assert capsys.readouterr().out.strip() == f"wrote in {out}: " + ", ".join(files)


def test_json_is_strict_and_reads_back(tmp_path):
    data = {"a": math.inf, "b": -math.inf, "c": math.nan, "d": np.float64(math.inf), "e": [np.int64(3), 0.5]}
    io.write_json(tmp_path / "x.json", data, MPI.COMM_SELF)
    assert strict(tmp_path / "x.json") == {"a": "inf", "b": "-inf", "c": None, "d": "inf", "e": [3, 0.5]}
    assert io.read_json(tmp_path / "x.json") == {"a": math.inf, "b": -math.inf, "c": None, "d": math.inf,
                                                 "e": [3, 0.5]}
    # a sweep's point files too: a rerun reads its points back as they were
    points = sweep.grid_points(blister_rigid.Params(), [("alpha", [0.0])])
    rows = sweep.run(points, lambda params, comm: {"x": math.inf}, tmp_path / "s", MPI.COMM_SELF)
    assert rows[0]["x"] == math.inf and strict(next((tmp_path / "s" / "points").glob("*.json")))["x"] == "inf"
    assert strict(tmp_path / "s" / "summary.json")["status"] == "ok"


@pytest.mark.serial
def test_an_internal_error_is_a_failed_status_not_a_traceback(tmp_path, in_process, monkeypatch, capsys):
    import bcfem.run.trace

    def broken(*args, **kwargs):
        raise ZeroDivisionError("injected")

    monkeypatch.setattr(bcfem.run.trace, "trace", broken)
    out = tmp_path / "bug"
    assert in_process([*TINY, "--out", str(out)]) == 1
    stderr = capsys.readouterr().err
    assert "Traceback" not in stderr and len(stderr.splitlines()) == 1
    assert "internal error: ZeroDivisionError: injected" in stderr
    summary = strict(out / "summary.json")
    assert summary["status"] == "failed" and summary["error"] == "internal error: ZeroDivisionError: injected"
    assert "ZeroDivisionError" in summary["traceback"]


@pytest.mark.serial
def test_fit_json_records_the_parameters_the_fit_solved_with(tmp_path, in_process, monkeypatch):
    def solved(aspect, P1, params, comm, guess, tol):
        return {"alpha": 0.5, "adhesion": 3.0, "converged": True, "residual": [0.0, 0.0], "evaluations": 1,
                "message": "stub"}

    monkeypatch.setattr(blister_studies, "solve_fit", solved)
    out = tmp_path / "fit"
    assert in_process(["fit", "blister-rigid", "--aspect", "2", "--P1", "10", "--cells", "20", "--quiet",
                       "--out", str(out)]) == 0
    fit = strict(out / "fit.json")
    assert fit["status"] == "ok"
    assert fit["parameters"]["edge"] == "adhesive" and fit["parameters"]["cells"] == 40
    assert fit["parameters"]["stop_radius"] == 1.02 and fit["parameters"]["alpha"] == 0.5


SWEEP = ["sweep", "blister-rigid", "--grid", "alpha=0,2", "--grid", "adhesion=1,4", "--material", "gent",
         "--v-max", "10", "--cells", "30"]


@pytest.mark.serial
def test_an_interrupted_sweep_keeps_its_points_and_resumes(tmp_path):
    out = tmp_path / "sweep"
    code, stderr = signalled(SWEEP, out, signal.SIGINT, r"sweep: point \d")
    assert code == 130 and "Traceback" not in stderr, stderr[-2000:]
    summary = strict(out / "summary.json")
    kept = sorted(p.name for p in (out / "points").glob("*.json"))
    assert summary["status"] == "interrupted" and summary["finished"] == len(kept) >= 1
    assert not list((out / "points").glob(".claims-*")) and not (out / ".bcfem.lock").exists()
    res = bcfem(*SWEEP, "--out", out)
    assert res.returncode == 0, res.stderr
    assert f"{4 - len(kept)} points solved, {len(kept)} reused" in res.stderr
    assert strict(out / "summary.json")["status"] == "ok"


def test_a_sweep_with_failed_points_exits_1_and_counts_why(tmp_path):
    out = tmp_path / "failing"
    res = bcfem("sweep", "blister-rigid", "--grid", "alpha=0,1", "--cells", "20", "--v-max", "2", "--quiet",
                "--out", out, "-snes_max_it", "1", "-snes_rtol", "1e-30", "-snes_atol", "1e-30", "-snes_stol", "0")
    assert res.returncode == 1 and "Traceback" not in res.stderr
    assert "2 of 2 points failed" in res.stderr and "2 x ContinuationError" in res.stderr
    summary = strict(out / "summary.json")
    assert summary["status"] == "failed" and summary["failed"] == 2 and sum(summary["failures"].values()) == 2
    assert summary["error"] == "2 of 2 points failed"
