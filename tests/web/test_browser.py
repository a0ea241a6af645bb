"""dh3-web's page in headless Chromium (Selenium), against dh3-service on the
simulator: the three hands appear, a grasp clicked on the hand with an object
shows GRASPED in the table and the log, and a move made by dh3ctl appears
without a reload.

Needs chromium, chromium-driver and python3-selenium (deploy/install-deps.sh).
DH3_SERVICE, DH3_WEB and DH3CTL name the programs (ctest sets them);
DH3_WEB_SCREENSHOT=FILE keeps a picture of the page at the end."""

import fcntl
import os
import subprocess
import tempfile

import pytest
from selenium import webdriver
from selenium.webdriver.chrome.service import Service as ChromeService
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

#: Generous: a loaded machine may be slow, a healthy one answers at once.
DEADLINE = 30.0
TOKEN = "browser-test-token-0123456789"
_domain_lock = None


def pick_domain() -> int:
    """A DDS domain no other test process uses (tests/support/test_domain.hpp's
    lock-file scheme)."""
    global _domain_lock
    first, count = 10, 200
    start = os.getpid() % count
    for i in range(count):
        candidate = first + (start + i) % count
        lock = open(f"/tmp/dh3-test-domain-{candidate}.lock", "a+")
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.close()
            continue
        _domain_lock = lock  # held while this process lives
        return candidate
    return first + start


DOMAIN = pick_domain()
SERVICE = f"web{os.getpid()}"
CONFIG = """buses:
  - name: bus0
    spec: sim
    command_interval_ms: 2
    poll_interval_moving_ms: 20
    poll_interval_idle_ms: 50
    sim: {reply_delay_ms: 1, position_speed: 100, rotation_speed: 400, init_time_ms: 50}
    hands:
      - {id: 1, name: left, object: 40}
      - {id: 2, name: right}
      - {id: 3}
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


@pytest.fixture(scope="module")
def web_url():
    with tempfile.TemporaryDirectory(prefix="dh3-web-test-") as tmp:
        config = os.path.join(tmp, "sim.yaml")
        token = os.path.join(tmp, "token")
        with open(config, "w") as f:
            f.write(CONFIG)
        with open(token, "w") as f:
            f.write(TOKEN + "\n")
        service = subprocess.Popen(
            [os.environ["DH3_SERVICE"], "--domain", str(DOMAIN), "--name", SERVICE,
             "--config", config, "--log-level", "warn"], stdin=subprocess.DEVNULL)
        web = subprocess.Popen(
            [os.environ["DH3_WEB"], "--domain", str(DOMAIN), "--listen", "127.0.0.1:0",
             "--token-file", token, "--log-level", "warn"],
            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, text=True)
        try:
            line = web.stdout.readline()
            assert line.startswith("dh3-web: serving http://127.0.0.1:"), line
            yield line.split()[2]
        finally:
            stop(web)
            stop(service)


@pytest.fixture(scope="module")
def browser():
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu",
                     "--disable-dev-shm-usage", "--window-size=1400,1400"):
        options.add_argument(argument)
    driver = webdriver.Chrome(service=ChromeService("/usr/bin/chromedriver"), options=options)
    yield driver
    driver.quit()


def dh3ctl(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([os.environ["DH3CTL"], "--domain", str(DOMAIN), "--timeout", "20",
                           *args], capture_output=True, text=True, timeout=60)


def wait_for(driver, what, predicate):
    return WebDriverWait(driver, DEADLINE, poll_frequency=0.05).until(
        lambda d: predicate(d), message=what)


def cell(driver, can_id: int, field: str) -> str:
    return driver.find_element(
        By.CSS_SELECTOR, f'tr[data-hand="{hand(can_id)}"] [data-field="{field}"]').text


def log_lines(driver) -> list:
    return [item.text for item in driver.find_elements(By.CSS_SELECTOR, "#log li")]


def test_the_page_shows_the_hands_grasps_and_follows_another_client(web_url, browser):
    browser.get(web_url)
    wait_for(browser, "three hands online", lambda d: all(
        d.find_elements(By.CSS_SELECTOR, f'tr[data-hand="{hand(i)}"]')
        and cell(d, i, "online") == "online" for i in (1, 2, 3)))
    assert "left" in cell(browser, 1, "hand")
    browser.execute_script("window.dh3NotReloaded = true;")

    browser.find_element(By.ID, "token").send_keys(TOKEN)
    browser.find_element(By.CSS_SELECTOR, "#token-form button").click()
    controls = browser.find_element(By.CSS_SELECTOR, f'tr[data-controls="{hand(1)}"]')
    controls.find_element(By.CSS_SELECTOR, 'button[data-command="init"]').click()
    wait_for(browser, "hand 1 initialized", lambda d: cell(d, 1, "initialized") == "yes")
    force = controls.find_element(By.CSS_SELECTOR, 'input[data-input="force"]')
    force.clear()
    force.send_keys("40")
    controls.find_element(By.CSS_SELECTOR, 'button[data-command="grasp"]').click()
    wait_for(browser, "GRASPED in the table",
             lambda d: "grasp: OK GRASPED at position" in cell(d, 1, "result"))
    wait_for(browser, "the grip CAUGHT", lambda d: cell(d, 1, "grip") == "CAUGHT")
    wait_for(browser, "GRASPED in the log", lambda d: any(
        hand(1) in line and " GRASPED " in line for line in log_lines(d)))

    # Another client moves hand 2: the page follows without a reload.
    assert dh3ctl("init", hand(2)).returncode == 0
    moved = dh3ctl("move", hand(2), "30")
    assert moved.returncode == 0, moved.stderr
    wait_for(browser, "dh3ctl's move in the table",
             lambda d: cell(d, 2, "position") == "30 / 30")
    wait_for(browser, "dh3ctl's move in the log", lambda d: any(
        hand(2) in line and " ARRIVED " in line for line in log_lines(d)))
    assert browser.execute_script("return window.dh3NotReloaded === true;")

    # A refusal is shown where it happened, in words.
    controls3 = browser.find_element(By.CSS_SELECTOR, f'tr[data-controls="{hand(3)}"]')
    controls3.find_element(By.CSS_SELECTOR, 'button[data-command="move"]').click()
    wait_for(browser, "hand 3's refusal",
             lambda d: "Error in move (HTTP 409 NOT_INITIALIZED)" in cell(d, 3, "result"))

    if os.environ.get("DH3_WEB_SCREENSHOT"):
        browser.save_screenshot(os.environ["DH3_WEB_SCREENSHOT"])
