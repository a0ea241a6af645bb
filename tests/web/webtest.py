"""What dh3-web's browser test and its page measurement share: a DDS domain of
their own, dh3-service on the simulator and dh3-web as child processes, and
headless Chromium driven by Selenium.

DH3_SERVICE, DH3_WEB, DH3CTL and DH3_SIM name the programs."""

import contextlib
import json
import os
import re
import subprocess
import sys
import tempfile
import urllib.error
import urllib.request
from dataclasses import dataclass

from selenium import webdriver
from selenium.webdriver.chrome.service import Service as ChromeService

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from test_domain import pick_domain  # noqa: E402

#: Generous: a loaded machine may be slow, a healthy one answers at once.
DEADLINE = 30.0
#: The tokens of dh3-web's token file, one of each role: TOKEN an operator's.
TOKEN = "browser-test-token-0123456789"
VIEW_TOKEN = "browser-test-viewer-0123456789"
ADMIN_TOKEN = "browser-test-admin-0123456789"
DOMAIN = pick_domain()
SERVICE = f"web{os.getpid()}"


def sim_config(position_speed: int = 100, allow_admin: bool = True) -> str:
    """Three hands on bus0; hand 1 ("left") holds an object at 40; hand 4 is
    configured but not there (offline). CAN ID and baud-rate changes allowed
    unless `allow_admin` is False."""
    return f"""allow_admin: {str(allow_admin).lower()}
buses:
  - name: bus0
    spec: sim:1,2,3
    command_interval_ms: 2
    poll_interval_moving_ms: 20
    poll_interval_idle_ms: 50
    sim: {{reply_delay_ms: 1, position_speed: {position_speed}, rotation_speed: 400, init_time_ms: 50}}
    hands:
      - {{id: 1, name: left, object: 40}}
      - {{id: 2, name: right}}
      - {{id: 3}}
      - {{id: 4, name: absent}}
"""


def hand(can_id: int) -> str:
    return f"{SERVICE}/bus0/{can_id}"


def stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
    try:
        process.wait(timeout=DEADLINE)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def start_web(token_path: str) -> tuple:
    """dh3-web on DOMAIN and a free port; (process, its URL)."""
    web = subprocess.Popen(
        [os.environ["DH3_WEB"], "--domain", str(DOMAIN), "--listen", "127.0.0.1:0",
         "--token-file", token_path, "--log-level", "warn"],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, text=True)
    line = web.stdout.readline()
    if not line.startswith("dh3-web: serving http://127.0.0.1:"):
        stop(web)
        raise AssertionError("dh3-web did not start: " + line)
    return web, line.split()[2]


@dataclass
class Cell:
    """A running dh3-service (on the simulator) and dh3-web."""
    url: str
    service: subprocess.Popen
    web: subprocess.Popen
    token_path: str


@contextlib.contextmanager
def service_and_web(position_speed: int = 100, allow_admin: bool = True, name: str = SERVICE,
                    config_text: str = ""):
    """dh3-service (named `name`, on sim_config() unless `config_text` is
    given) and dh3-web (VIEW_TOKEN a viewer's, TOKEN an operator's and
    ADMIN_TOKEN an admin's); yields the Cell."""
    with tempfile.TemporaryDirectory(prefix="dh3-web-test-") as tmp:
        config = os.path.join(tmp, "sim.yaml")
        token = os.path.join(tmp, "token")
        with open(config, "w") as f:
            f.write(config_text or sim_config(position_speed, allow_admin))
        with open(token, "w") as f:
            f.write(f"view {VIEW_TOKEN}\noperator {TOKEN}\nadmin {ADMIN_TOKEN}\n")
        os.chmod(token, 0o600)  # dh3-web refuses a token others may read
        service = subprocess.Popen(
            [os.environ["DH3_SERVICE"], "--domain", str(DOMAIN), "--name", name,
             "--config", config, "--log-level", "warn"], stdin=subprocess.DEVNULL)
        web = None
        try:
            web, url = start_web(token)
            yield Cell(url, service, web, token)
        finally:
            if web is not None:
                stop(web)
            stop(service)


def page_files(url: str) -> list:
    """The page's files as dh3-web serves them: "" (index.html), then the
    scripts and style sheets it names, in its order."""
    with urllib.request.urlopen(url, timeout=DEADLINE) as response:
        index = response.read().decode()
    return [""] + re.findall(r'<(?:script src|link rel="stylesheet" href)="/([^"]+)"', index)


def api(url: str, path: str, body=None, token: str = TOKEN) -> tuple:
    """(HTTP status, JSON reply) of GET (or, with a body, POST) url + path."""
    headers = {"Authorization": "Bearer " + token, "Content-Type": "application/json"}
    data = None if body is None else json.dumps(body).encode()
    request = urllib.request.Request(url.rstrip("/") + path, data=data, headers=headers)
    try:
        with urllib.request.urlopen(request, timeout=DEADLINE) as response:
            return response.status, json.loads(response.read())
    except urllib.error.HTTPError as error:
        return error.code, json.loads(error.read())


@contextlib.contextmanager
def headless_chromium(height: int = 1400):
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu",
                     "--disable-dev-shm-usage", f"--window-size=1400,{height}"):
        options.add_argument(argument)
    driver = webdriver.Chrome(service=ChromeService("/usr/bin/chromedriver"), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def dh3ctl(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([os.environ["DH3CTL"], "--domain", str(DOMAIN), "--timeout", "20",
                           *args], capture_output=True, text=True, timeout=60)
