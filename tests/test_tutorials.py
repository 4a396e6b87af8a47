"""The tutorials (``tutorials/*.py``, jupytext scripts that end in their own assertions) run to
completion serially and under ``mpirun -n 2``, and only rank 0 prints. Marked ``serial``:
pytest must not itself run under mpirun, since the test launches it."""

import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import on_ranks

pytestmark = pytest.mark.serial

BIN = Path(sys.executable).parent
TUTORIALS = sorted((Path(__file__).resolve().parents[1] / "tutorials").glob("*.py"))


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("tutorial", TUTORIALS, ids=lambda p: p.stem)
def test_a_tutorial_meets_its_closed_forms(tutorial, ranks, tmp_path):
    cmd = on_ranks([sys.executable, str(tutorial)], ranks)
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}"}
    res = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600)
    assert res.returncode == 0, f"{tutorial.name}:\n{res.stdout[-3000:]}\n{res.stderr[-3000:]}"
    lines = res.stdout.splitlines()
    assert lines and len(lines) == len(set(lines)), f"a line printed twice (by two ranks?): {lines}"


def test_every_tutorial_is_run():
    assert {p.stem for p in TUTORIALS} == {"add_a_term", "scene_from_nothing"}
