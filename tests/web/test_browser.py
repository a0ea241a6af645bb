"""dh3-web's page in headless Chromium (Selenium), against dh3-service on the
simulator: the three hands appear, a grasp clicked on the hand with an object
shows GRASPED in the table and the log, and a move made by dh3ctl appears
without a reload.

Needs chromium, chromium-driver and python3-selenium (deploy/install-deps.sh).
DH3_SERVICE, DH3_WEB and DH3CTL name the programs (ctest sets them);
DH3_WEB_SCREENSHOT=FILE keeps a picture of the page at the end."""

import os
import sys

import pytest
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

sys.path.insert(0, os.path.dirname(__file__))
from webtest import DEADLINE, TOKEN, dh3ctl, hand, headless_chromium, service_and_web  # noqa: E402


@pytest.fixture(scope="module")
def web_url():
    with service_and_web() as url:
        yield url


@pytest.fixture(scope="module")
def browser():
    with headless_chromium() as driver:
        yield driver


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
    wait_for(browser, "the grip GRASPED", lambda d: cell(d, 1, "grip") == "GRASPED")
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
