"""Every ``demos/*.py`` runs to completion, in serial and under ``mpirun -n 2``.

Each demo is a script that ends in its own assertions, so exit code 0 means its
reference values were met. Demos take ``--out DIR`` for their results; the test
also checks that the expected files are there, that nothing temporary is left
behind and that only rank 0 printed.

Marked ``serial``: pytest itself must not run under mpirun, since it launches
mpirun. The runs on two ranks are ``slow`` and ``demo`` (``make test-all``): they check all
that a serial run does and that only rank 0 prints. The serial runs are a ``study`` (``make
study``), to keep CI within its time; the command-line contract is checked in the fast tier.
"""

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import on_ranks
from test_summary_schema import SCHEMA

pytestmark = pytest.mark.serial

BIN = Path(sys.executable).parent
DEMOS = sorted(p for p in (Path(__file__).resolve().parents[1] / "demos").glob("*.py") if not p.name.startswith("_"))
# files each demo must write into --out (any other demo must write a PNG and a CSV)
EXPECTED = {
    "blister_3d.py": ["pv.png", "membrane_circle.png", "curves.csv", "summary.json"],
    "blister_theories.py": ["theories.png", "curves.csv", "summary.json"],
    "blister_surface_tension.py": ["surface_tension.png", "curves.csv", "summary.json"],
    "blister_sliding.py": ["sliding_fig3_7.png", "sliding_fig3_8.png", "sliding_fig3_10.png", "curves.csv",
                           "profiles_V0.1.csv", "summary.json"],
    "blister_slippery.py": ["slippery_fig3_18.png", "slippery_fig3_19.png", "slippery_fig3_20.png",
                            "branches.csv", "profiles_V1.5.csv", "summary.json"],
    "crater_air.py": ["fig7_6.png", "fig7_7a.png", "fig7_5b.png", "crater_air.csv", "summary.json"],
    "crater_design.py": ["fig7_9.png", "fig7_10.png", "fig7_11.png", "fig8_4.png", "fig8_6_8_7.png",
                         "crater_design.csv", "summary.json"],
}
TIMEOUT = 600  # [s]; a deadlock at exit shows up as a timeout, not a hang


def run_demo(demo: Path, out: Path, ranks: int, *flags: str) -> subprocess.CompletedProcess:
    cmd = on_ranks([sys.executable, str(demo), "--out", str(out), *flags], ranks)
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}"}
    return subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=out.parent,
                          timeout=TIMEOUT)


def check_outputs(demo: Path, out: Path, res: subprocess.CompletedProcess) -> None:
    assert res.returncode == 0, f"{demo.name} failed:\n{res.stdout[-3000:]}\n{res.stderr[-3000:]}"
    files = {p.name for p in out.iterdir()}
    for name in EXPECTED.get(demo.name, []):
        assert name in files, f"{demo.name} did not write {name} (wrote {sorted(files)})"
        assert (out / name).stat().st_size > 0, f"{demo.name}: {name} is empty"
    assert any(f.endswith(".png") for f in files), f"{demo.name} wrote no PNG"
    assert any(f.endswith(".csv") for f in files), f"{demo.name} wrote no CSV"
    assert not [f for f in files if ".tmp" in f], f"{demo.name} left temporary files: {sorted(files)}"
    # the runner's summary schema (bcfem.run.study): status, counts, options, timings, versions
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "ok" and SCHEMA - {"columns"} <= set(summary), SCHEMA - set(summary)
    assert summary["newton_solves"] > 0 and summary["ranks"] >= 1


def test_demos_found():
    assert DEMOS, "no demos/*.py"
    missing = set(EXPECTED) - {d.name for d in DEMOS}
    assert not missing, f"EXPECTED names demos that do not exist: {sorted(missing)}"


def test_every_demo_takes_the_common_flags():
    """Each demo parses its command line with ``bcfem.run.demo.setup`` alone (no flags of its own),
    whose parser has --out, --quiet, --full, --refine and --dissertation-model."""
    from bcfem.run import demo
    options = {a for action in demo.parser("x", "x", "f", "r")._actions for a in action.option_strings}
    assert set(demo.FLAGS) <= options
    for path in DEMOS:
        tree = ast.parse(path.read_text())
        calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)]
        assert any(c.func.attr == "setup" and getattr(c.func.value, "id", "") == "demo" for c in calls), path.name
        imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        assert "argparse" not in imported, f"{path.name} parses flags of its own"
        # its solves go through a study, which writes summary.json in the runner's schema
        named = {getattr(c.func, "id", None) for c in ast.walk(tree) if isinstance(c, ast.Call)}
        assert "Study" in named and any(c.func.attr == "write" and getattr(c.func.value, "id", "") == "study"
                                        for c in calls), f"{path.name} writes its summary without its study"
        assert "branch_of" not in path.read_text(), f"{path.name} traces outside its study"


def test_every_figure_module_draws_one_results_object():
    """Each ``demos/_figures_<demo>.py`` has ``draw(results)``: one argument, the demo's results
    object (what the solve produced and the run), and its demo calls it with one positional argument."""
    figures = sorted(DEMOS[0].parent.glob("_figures_*.py"))
    assert figures, "no demos/_figures_*.py"
    for path in figures:
        draw = next(n for n in ast.parse(path.read_text()).body if isinstance(n, ast.FunctionDef) and n.name == "draw")
        names = [a.arg for a in draw.args.posonlyargs + draw.args.args + draw.args.kwonlyargs]
        assert names == ["results"] and not draw.args.vararg and not draw.args.kwarg, (path.name, names)
        demo = path.with_name(path.name.removeprefix("_figures_"))
        calls = [n for n in ast.walk(ast.parse(demo.read_text()))
                 if isinstance(n, ast.Call) and getattr(n.func, "id", "") == "draw"]
        assert calls and all(len(c.args) == 1 and not c.keywords for c in calls), demo.name


def test_a_demo_help_lists_the_flags():
    demo = next(d for d in DEMOS if d.stem == "blister_theories")
    res = subprocess.run([sys.executable, str(demo), "--help"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    for flag in ("--out", "--quiet", "--full", "--refine"):
        assert flag in res.stdout
    assert "cells across R0" in res.stdout  # its --refine says what it refines


@pytest.mark.parametrize("demo", DEMOS, ids=lambda p: p.stem)
@pytest.mark.slow
@pytest.mark.demo
@pytest.mark.study
def test_demo_serial(demo, tmp_path):
    out = tmp_path / "out"
    check_outputs(demo, out, run_demo(demo, out, ranks=1))


@pytest.mark.parametrize("demo", DEMOS, ids=lambda p: p.stem)
@pytest.mark.slow
@pytest.mark.demo
def test_demo_mpi(demo, tmp_path):
    out = tmp_path / "out"
    res = run_demo(demo, out, ranks=2)
    check_outputs(demo, out, res)
    # only rank 0 prints: every line of the demo's own output appears once
    lines = [line for line in res.stdout.splitlines() if line.strip()]
    assert lines, f"{demo.name} printed nothing on rank 0"
    assert len(lines) == len(set(lines)), f"{demo.name}: output repeated by several ranks:\n{res.stdout}"


@pytest.mark.parametrize("demo", [d for d in DEMOS if d.stem in ("crater_air", "crater_design")], ids=lambda p: p.stem)
@pytest.mark.slow
@pytest.mark.demo
@pytest.mark.study  # the scenes' tests check the dissertation's model; make study runs the demos on it
def test_crater_demo_on_the_dissertation_model(demo, tmp_path):
    """The crater demos pass their own checks again on ``--specimen dissertation`` (4a, Q1-P0), on
    two ranks; the design maps' commands name that model."""
    out = tmp_path / "out"
    check_outputs(demo, out, run_demo(demo, out, 2, "--dissertation-model"))
    summary = json.loads((out / "summary.json").read_text())
    if demo.stem == "crater_design":
        assert all("--specimen dissertation" in c for c in summary["commands"].values()), summary["commands"]
