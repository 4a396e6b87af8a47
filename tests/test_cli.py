"""The CLI contract of ``bcfem run blister-rigid``: outputs, bad input, MPI invariance."""

import json
import subprocess
import sys

import numpy as np
import pytest
from helpers import bcfem, refused, same_loads

from bcfem.io import read_csv

#: the time split of summary.json and --profile, in order
PARTS = ["assembly", "discrete_terms", "factorisation", "linear_solve", "newton_other", "stability", "jit", "other"]

ARGS = ["run", "blister-rigid", "--material", "gent", "--Jm", "100", "--alpha", "0.5",
        "--v-max", "6", "--cells", "60", "--degree", "2", "--quiet"]


def read(out):
    return read_csv(out / "branch.csv"), json.loads((out / "summary.json").read_text())


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial") / "run"
    res = bcfem(*ARGS, "--out", str(out))
    assert res.returncode == 0, res.stderr
    return out, res


def test_outputs_follow_the_contract(serial):
    out, res = serial
    rows, summary = read(out)
    assert {"V_over_V0", "P", "aspect", "contact_angle_deg", "energy"} <= set(rows[0])
    assert {"parameters", "limit_points", "dofs", "ranks", "wall_time_s", "versions"} <= set(summary)
    assert set(summary["versions"]) >= {"bcfem", "dolfinx", "petsc"}
    assert summary["parameters"]["alpha"] == 0.5 and summary["ranks"] == 1
    assert [lp["kind"] for lp in summary["limit_points"]] == ["max", "min"]
    assert all({"V_over_V0", "P", "kind"} <= set(lp) for lp in summary["limit_points"])
    assert (out / "pv.png").stat().st_size > 10_000
    assert (out / "fields.bp").is_dir()
    assert float(rows[-1]["V_over_V0"]) == pytest.approx(6.0, abs=1e-9)
    assert not list(out.glob(".*tmp*")), "temporary files left behind"
    assert "pv.png" in res.stdout
    # the cost: counts, and a time split that adds up to the wall time
    assert summary["status"] == "ok" and summary["error"] is None
    assert summary["steps"] == len(rows) and summary["newton_iterations"] >= summary["steps"]
    split = summary["time_split_s"]
    assert list(split) == PARTS
    assert set(summary["jit"]) == {"compiled", "compile_s", "loaded", "load_s"}
    assert split["jit"] >= summary["jit"]["compile_s"]  # compiling and loading
    assert split["assembly"] > 0 and split["factorisation"] > 0 and split["linear_solve"] > 0
    assert split["newton_other"] > 0 and split["other"] > 0
    assert sum(split.values()) == pytest.approx(summary["wall_time_s"], rel=1e-9)


def test_profile_prints_the_time_split(tmp_path):
    res = bcfem("run", "blister-rigid", "--v-max", "0.5", "--cells", "20", "--quiet", "--profile",
                "--out", tmp_path / "p")
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert lines[0].startswith("wall time") and "Newton iterations" in lines[0]
    assert [line.split()[0] for line in lines[1:9]] == PARTS
    assert lines[9].startswith("forms compiled") and lines[10].startswith("peak memory per rank")


def test_mpi_gives_the_serial_branch(serial, tmp_path):
    out_serial, _ = serial
    out = tmp_path / "mpi"
    res = bcfem(*ARGS, "--out", str(out), ranks=2)
    assert res.returncode == 0, res.stderr
    rows1, s1 = read(out_serial)
    rows2, s2 = read(out)
    assert s2["ranks"] == 2
    for a, b in zip(s1["limit_points"], s2["limit_points"], strict=True):
        assert b["P"] == pytest.approx(a["P"], rel=1e-8)
        assert b["V_over_V0"] == pytest.approx(a["V_over_V0"], rel=1e-8)
    # the rows at the same arc length, and the end V/V0 = 6, which the steps do not decide
    pairs = same_loads(rows2, rows1, "s") + [(rows2[-1], rows1[-1])]
    assert pairs[0][0] is rows2[0]
    for key in ("V_over_V0", "P", "aspect", "contact_angle_deg", "energy"):
        x1 = np.array([a[key] for _, a in pairs])
        x2 = np.array([b[key] for b, _ in pairs])
        np.testing.assert_allclose(x2, x1, rtol=1e-8, atol=1e-10)


def test_petsc_options_pass_through(tmp_path):
    """Unprefixed and prefixed (bcfem_<scene>_<stage>_) options win over bcfem's; summary.json
    records the effective options by full name, and PETSc reports none of them unused."""
    out = tmp_path / "opts"
    res = bcfem(*ARGS, "--v-max", "0.5", "--out", str(out), "-snes_max_it", "17",
                env={"PETSC_OPTIONS": "-bcfem_blister_rigid_branch_snes_rtol 1e-9"})
    assert res.returncode == 0, res.stderr
    _, summary = read(out)
    assert summary["status"] == "ok" and summary["steps"] > 0 and summary["newton_iterations"] > 0
    assert summary["petsc_options"]["bcfem_blister_rigid_branch_snes_max_it"] == "17"
    assert summary["petsc_options"]["bcfem_blister_rigid_branch_snes_rtol"] == "1e-9"
    assert "unused" not in res.stderr + res.stdout


def test_a_crater_that_cannot_converge_fails_and_keeps_its_converged_rows(tmp_path):
    """The user's options win in every stage, the retrace included: a Newton of one
    iteration that must reach 1e-30 cannot, so the run says failed, keeps the rows that
    converged (the rest state) and exits 1."""
    out = tmp_path / "fail"
    res = bcfem("run", "crater", "--preload", "0.2", "--size-crater", "0.12", "--quiet", "--out", str(out),
                "-snes_max_it", "1", "-snes_rtol", "1e-30", "-snes_atol", "1e-30", "-snes_stol", "0")
    assert res.returncode == 1, res.stderr
    assert "solver failed" in res.stderr and "traced again" in res.stderr
    rows, summary = read(out)
    assert summary["status"] == "failed" and "no converged state" in summary["error"]
    assert summary["petsc_options"]["bcfem_crater_load_snes_max_it"] == "1"
    assert len(rows) == summary["steps"] >= 1 and float(rows[0]["eps"]) == 0.0
    assert (out / "cycle.png").exists()


@pytest.mark.parametrize("args, word", [
    (["--Jm", "0"], "Jm"),
    (["--Jm", "-5"], "Jm"),
    (["--alpha", "-0.1"], "alpha"),
    (["--v-max", "0"], "v-max"),
    (["--v-max", "-1"], "v-max"),
    (["--cells", "1"], "cells"),
    (["--material", "rubber"], "material"),
    (["--degree", "9"], "degree"),
])
def test_bad_input_exits_2_and_writes_nothing(tmp_path, args, word):
    assert word in refused("run", "blister-rigid", *args, out=tmp_path / "bad")


def test_unknown_scene_exits_2(tmp_path):
    res = bcfem("run", "no-such-scene", "--out", str(tmp_path / "x"))
    assert res.returncode == 2 and "no-such-scene" in res.stderr


def test_help_states_units():
    res = bcfem("run", "--help")
    assert res.returncode == 0 and "blister-rigid" in res.stdout
    res = bcfem("run", "blister-rigid", "--help")
    assert res.returncode == 0
    for text in ("dp R0 / (mu_f t0)", "gamma_l / (mu_f t0)", "V0 = 4/3 pi R0^3", "z(0) / R0"):
        assert text in res.stdout


@pytest.mark.slow
@pytest.mark.parametrize("edge", ["adhesive", "sliding", "slippery"])
def test_moving_edges_under_mpi_equal_serial(tmp_path, edge):
    args = ["run", "blister-rigid", "--edge", edge, "--alpha", "0.5", "--adhesion", "2.5",
            "--v-max", "2", "--cells", "40", "--quiet"]
    runs = []
    for ranks in (1, 2):
        out = tmp_path / f"n{ranks}"
        res = bcfem(*args, "--out", str(out), ranks=ranks)
        assert res.returncode == 0, res.stderr
        runs.append(read(out))
    (rows1, s1), (rows2, s2) = runs
    pairs = same_loads(rows2, rows1, "s") + [(rows2[-1], rows1[-1])]
    assert pairs[0][0] is rows2[0]
    for key in ("V_over_V0", "P", "aspect", "R1_over_R0", "r1_over_R0"):
        np.testing.assert_allclose([b[key] for b, _ in pairs], [a[key] for _, a in pairs], rtol=1e-8, atol=1e-10)
    if edge != "sliding":
        assert s2["delamination_onset"]["V_over_V0"] == pytest.approx(
            s1["delamination_onset"]["V_over_V0"], rel=1e-8)


@pytest.mark.serial
def test_a_script_may_import_dolfinx_before_bcfem():
    """FEniCSx scripts import dolfinx first; in bcfem's venv that loads MPI first as it must
    (tools/bcfem-mpi-first.pth), and a plain Python start loads no MPI at all."""
    script = ("import dolfinx; import bcfem; from mpi4py import MPI; "
              "print(dolfinx.mesh.create_unit_interval(MPI.COMM_SELF, 2))")
    res = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    res = subprocess.run([sys.executable, "-c", "import sys; print('mpi4py' in sys.modules)"], capture_output=True,
                         text=True, timeout=60)
    assert res.stdout.strip() == "False"


SCRIPT = """
import sys
import bcfem
from mpi4py import MPI
from bcfem.scenes import blister_rigid
params = blister_rigid.Params(material="neo-hookean", v_max=0.5, cells=20)
if sys.argv[1] == "trace":
    bcfem.trace(blister_rigid.build(params, MPI.COMM_WORLD), quiet=sys.argv[2] == "quiet")[1].close()
else:
    summary = bcfem.solve_into(blister_rigid.build(params, MPI.COMM_WORLD), sys.argv[2], MPI.COMM_WORLD)
    assert summary["status"] == "ok"
"""


@pytest.mark.serial
def test_a_script_sees_progress_lines_and_writes_the_standard_folder(tmp_path):
    def script(*args):
        res = subprocess.run([sys.executable, "-c", SCRIPT, *args], capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr
        return res.stderr

    assert "V_over_V0" in script("trace", "loud") and script("trace", "quiet") == ""
    script("run", str(tmp_path / "out"))
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "ok" and {"branch.csv", "summary.json", "pv.png"} <= set(summary["files"])
