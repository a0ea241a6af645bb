"""What the dh3 Python tests share: a DDS domain and service name of their own
(the same scheme as tests/support/test_domain.hpp, so concurrent ctest runs
and the C++ tests do not meet), dh3-service on a simulated bus as a child
process, and a dh3.Client on that domain."""

import os
import signal
import subprocess
import sys
import tempfile

import pytest

import dh3

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "tests", "support"))
from test_domain import pick_domain  # noqa: E402

#: Generous: a loaded machine may be slow, a healthy one answers at once.
DEADLINE = 20.0

DOMAIN = pick_domain()
SERVICE = f"py{os.getpid()}"


def sim_config(init_time_ms: int = 50, ids=(1, 2, 3), position_speed: float = 400,
               init_timeout_ms: int = 120000, allow_admin: bool = False) -> str:
    """A sim bus "bus0", fast so tests are quick; hand 1 holds an object at 40."""
    hands = "".join(
        f"      - {{id: {i}{', object: 40' if i == 1 else ''}}}\n" for i in ids)
    return (f"allow_admin: {'true' if allow_admin else 'false'}\n"
            "buses:\n"
            "  - name: bus0\n"
            "    spec: sim\n"
            "    command_interval_ms: 2\n"
            "    poll_interval_moving_ms: 20\n"
            "    poll_interval_idle_ms: 50\n"
            f"    init_timeout_ms: {init_timeout_ms}\n"
            f"    sim: {{reply_delay_ms: 1, position_speed: {position_speed}, rotation_speed: 400, "
            f"init_time_ms: {init_time_ms}}}\n"
            "    hands:\n" + hands)


class Service:
    """dh3-service as a child process with a YAML config on this test's domain."""

    def __init__(self, config: str, name: str = SERVICE, extra=()):
        self.name = name
        handle, self.config_path = tempfile.mkstemp(prefix="dh3-pytest-", suffix=".yaml")
        with os.fdopen(handle, "w") as f:
            f.write(config)
        self.process = subprocess.Popen(
            [os.environ["DH3_SERVICE"], "--domain", str(DOMAIN), "--name", name,
             "--config", self.config_path, "--log-level", "warn", *extra],
            stdin=subprocess.DEVNULL)

    def stop(self, sig=signal.SIGTERM) -> int:
        if self.process.poll() is None:
            self.process.send_signal(sig)
        try:
            return self.process.wait(timeout=DEADLINE)
        finally:
            if os.path.exists(self.config_path):
                os.remove(self.config_path)

    def kill(self) -> int:
        return self.stop(signal.SIGKILL)


def spec(can_id: int, service: str = SERVICE) -> str:
    """"py1234/bus0/2" """
    return f"{service}/bus0/{can_id}"


@pytest.fixture(scope="module")
def service():
    running = Service(sim_config())
    yield running
    assert running.stop() == 0


@pytest.fixture(scope="module")
def client(service):
    with dh3.Client(domain=DOMAIN, default_timeout=DEADLINE) as c:
        assert c.connected(), c.error()
        yield c


@pytest.fixture
def hand(client):
    """Hand 2 (nothing between its fingers), initialized."""
    found = client.wait_for_hand(spec(2), timeout=DEADLINE)
    reply = found.initialize()
    assert reply.ok, reply.message
    return found
