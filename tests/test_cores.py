"""The halves' core locks (tests/cores.py): a test that starts several ranks runs alone, and two
halves that both want every core at once finish, one after the other."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

HOLDER = """
import json, sys, time
sys.path.insert(0, {tests!r})
import cores
cores.take_own()
time.sleep(0.2)  # the other half has its own core by now
cores.take_all()
start = time.monotonic()
time.sleep(0.5)
print(json.dumps([start, time.monotonic()]))
cores.release()
"""


@pytest.mark.serial
def test_two_halves_that_want_every_core_take_turns(tmp_path):
    script = tmp_path / "holder.py"
    script.write_text(HOLDER.format(tests=str(Path(__file__).parent)))
    env = {k: v for k, v in os.environ.items() if k != "BCFEM_TEST_CORES_LOG"}
    halves = [subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True,
                               env={**env, "BCFEM_TEST_CORES": f"{tmp_path}:{core}:2"}) for core in (0, 1)]
    spans = sorted(json.loads(h.communicate(timeout=30)[0]) for h in halves)  # a deadlock: timeout
    assert all(h.returncode == 0 for h in halves)
    assert spans[0][1] <= spans[1][0], f"both held every core at once: {spans}"
