"""examples/pick_loop.py drives a hand like the C++ pick_loop."""

import os
import subprocess
import sys

from conftest import DEADLINE, DOMAIN, spec

EXAMPLE = os.path.join(os.environ.get("DH3_PYTHON_EXAMPLES",
                                      os.path.join(os.path.dirname(__file__), "..", "examples")),
                       "pick_loop.py")


def run(*args):
    return subprocess.run([sys.executable, EXAMPLE, "--domain", str(DOMAIN), "--timeout",
                           str(DEADLINE), *args], capture_output=True, text=True, timeout=120)


def test_pick_loop_grasps_the_object_every_cycle(service):
    done = run("--hand", spec(1), "--cycles", "3", "--force", "40")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == f"hand {spec(1)}"
    assert [l for l in lines if l.startswith("cycle ")][2].startswith("cycle 3: GRASPED at position")
    assert lines[-1] == "done: 3 cycles, 3 grasped"


def test_pick_loop_fails_on_a_missing_hand_or_a_bad_force(service):
    # Long enough for a new participant to discover the service on a busy
    # machine: the wait for hand 9 lasts all of it.
    missing = run("--hand", spec(9), "--timeout", "10")
    assert missing.returncode == 1
    assert "no hand bus0/9" in missing.stderr
    bad = run("--hand", spec(2), "--force", "5")
    assert bad.returncode == 1
    assert "grasp: INVALID_ARGUMENT" in bad.stderr
