"""dh3-web's page in headless Chromium (Selenium), against dh3-service on the
simulator: the hands appear (three there, one configured but offline), a
wrong token is said at once, a token's role is shown and what it may not
use is off with the reason (a viewer's: every command; an operator's: CAN ID
and baud rate) while dh3-web still refuses them itself, a grasp clicked on the hand with an object shows
GRASPED on its card and in the log, a move made by dh3ctl appears without a
reload; an emptied or invalid field sends nothing; an offline hand and a hand
leased by another client take no commands, with the reason; STOP ALL stays
in view and nothing is beyond the right edge at 1280, 800 and 400 px
(screenshots kept); a frozen service's hands are marked not live, a killed
one's lost. The health panel shows each service's host, version, domain,
admin and buses; commissioning scans a bus, reads firmware and registers,
sets forces, and asks before a CAN ID change (cancelled: nothing sent);
alarms (dh3-web's list, one for every screen) list an offline hand, a failed
command and a lost service until acknowledged, on the page or through the API, and on a transfer box (dh3-sim) a dropped object and the bus
going down too; a service that allows no admin commands has them off, with
the reason.

Needs chromium, chromium-driver and python3-selenium (deploy/install-deps.sh).
DH3_SERVICE, DH3_WEB, DH3CTL and DH3_SIM name the programs (ctest sets them);
DH3_WEB_SCREENSHOTS=DIR keeps the pictures there (ctest: the build tree)."""

import os
import re
import signal
import subprocess
import sys
import urllib.request

import pytest
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select
from selenium.webdriver.support.ui import WebDriverWait

sys.path.insert(0, os.path.dirname(__file__))
from webtest import (ADMIN_TOKEN, DEADLINE, DOMAIN, SERVICE, TOKEN, VIEW_TOKEN, api,  # noqa: E402
                     dh3ctl, hand, headless_chromium, page_files, service_and_web, start_web,
                     stop)

PAGE_LIMIT = 100 * 1024


@pytest.fixture(scope="module")
def cell():
    with service_and_web() as running:
        yield running


@pytest.fixture(scope="module")
def browser():
    with headless_chromium() as driver:
        yield driver


def wait_for(driver, what, predicate):
    return WebDriverWait(driver, DEADLINE, poll_frequency=0.05).until(
        lambda d: predicate(d), message=what)


def card(driver, can_id: int):
    return driver.find_element(By.CSS_SELECTOR, f'article[data-hand="{hand(can_id)}"]')


def cell_text(driver, can_id: int, field: str) -> str:
    return driver.find_element(
        By.CSS_SELECTOR, f'article[data-hand="{hand(can_id)}"] [data-field="{field}"]').text


def button(driver, can_id: int, command: str):
    return card(driver, can_id).find_element(By.CSS_SELECTOR, f'button[data-command="{command}"]')


def set_field(driver, can_id: int, name: str, text: str) -> None:
    field = card(driver, can_id).find_element(By.CSS_SELECTOR, f'input[data-input="{name}"]')
    field.clear()
    if text:
        field.send_keys(text)


def log_lines(driver) -> list:
    return [item.text for item in driver.find_elements(By.CSS_SELECTOR, "#log li")]


def use_token(driver, token: str) -> None:
    driver.find_element(By.ID, "token").send_keys(token)
    driver.find_element(By.CSS_SELECTOR, "#token-form button").click()


def requests_written(url: str) -> int:
    status, health = api(url, "/api/health")
    assert status == 200, health
    return health["requests_written"]


def alarm(driver, key: str):
    """The alarm listed under `key` as {"state": "active" or "over", "text"},
    or None; read in one go in the page, which may be updating the list."""
    return driver.execute_script("""
        const item = [...document.querySelectorAll('#alarms li')].find((i) => i.dataset.alarm === arguments[0]);
        return item ? {state: item.className, text: item.textContent} : null;""", key)


def alarm_keys(driver, prefix: str) -> list:
    return driver.execute_script("""
        return [...document.querySelectorAll('#alarms li')].map((i) => i.dataset.alarm)
            .filter((key) => key.startsWith(arguments[0]));""", prefix)


def acknowledge(driver, key: str) -> None:
    driver.execute_script("""
        [...document.querySelectorAll('#alarms li')].find((i) => i.dataset.alarm === arguments[0])
            .querySelector('button').click();""", key)
    wait_for(driver, f"alarm {key} gone", lambda d: alarm(d, key) is None)


def commission(driver, can_id: int, command: str) -> None:
    """Selects the hand in the commissioning panel and clicks `command`."""
    Select(driver.find_element(By.ID, "commission-hand")).select_by_value(hand(can_id))
    button = driver.find_element(By.CSS_SELECTOR, f'button[data-commission="{command}"]')
    wait_for(driver, f"{command} on", lambda d: button.is_enabled())
    button.click()


def commission_result(driver, command: str) -> str:
    """The newest result of `command` in the commissioning panel ("" before any)."""
    found = driver.find_elements(By.CSS_SELECTOR, f'#commission-results li[data-command="{command}"]')
    return found[0].text if found else ""


def open_page(driver, url: str) -> None:
    driver.get(url)
    wait_for(driver, "three hands online", lambda d: all(
        d.find_elements(By.CSS_SELECTOR, f'article[data-hand="{hand(i)}"]')
        and cell_text(d, i, "online") == "online" for i in (1, 2, 3)))
    wait_for(driver, "the page live",
             lambda d: d.find_element(By.ID, "connection").text.startswith("Live"))


def test_the_page_is_small_and_self_contained(cell):
    total = 0
    files = page_files(cell.url)
    assert "app.js" in files and "style.css" in files and len(files) > 3, files
    for path in files:
        with urllib.request.urlopen(cell.url + path, timeout=DEADLINE) as response:
            body = response.read()
        total += len(body)
        assert b"http://" not in body and b"https://" not in body, path
    print(f"page: {total} bytes in {len(files)} files")
    assert total < PAGE_LIMIT


def test_a_wrong_token_is_said_at_once_and_commands_stay_off(cell, browser):
    open_page(browser, cell.url)
    assert "left" in cell_text(browser, 1, "hand")
    assert not button(browser, 1, "init").is_enabled()
    assert "commands need the token" in cell_text(browser, 1, "blocked")
    assert not browser.find_element(By.ID, "stop-all").is_enabled()
    assert browser.find_element(By.ID, "stop-all-blocked").text == \
        "Stop all off: commands need the token; enter it above"
    use_token(browser, "not-the-token-0123456789")
    wait_for(browser, "the wrong token reported", lambda d: d.find_element(
        By.ID, "token-state").text.startswith("Error: the token is wrong"))
    assert not button(browser, 1, "init").is_enabled()
    assert "the token is wrong" in cell_text(browser, 1, "blocked")
    use_token(browser, TOKEN)
    wait_for(browser, "the token accepted", lambda d: d.find_element(
        By.ID, "token-state").text.startswith("Token accepted"))
    wait_for(browser, "hand 1's buttons on", lambda d: button(d, 1, "init").is_enabled())


def token_state(driver) -> str:
    return driver.find_element(By.ID, "token-state").text


def enabled_command_controls(driver) -> list:
    """Every button, field and list of the page that is on, but for the
    token's form, the commissioning panel's choice of hand and the closed
    confirmation dialog."""
    return driver.execute_script("""
        return [...document.querySelectorAll('button, input, select')]
            .filter((e) => !e.disabled && !e.closest('#token-form, dialog') && e.id !== 'commission-hand')
            .map((e) => e.outerHTML.slice(0, 80));""")


def commission_control(driver, selector: str):
    panel = driver.find_element(By.ID, "commission-title").find_element(By.XPATH, "..")
    return panel.find_element(By.CSS_SELECTOR, selector)


VIEW_ONLY = "this token may only view: commands need an operator's token"
ADMIN_ONLY = "admin only: this token is an operator's; CAN ID and baud-rate changes need an admin's"


def test_a_view_token_sees_no_command_on(cell, browser):
    # hand 4's alarm brings an Acknowledge button: it must be off too.
    wait_for(browser, "hand 4's alarm", lambda d: alarm(d, f"offline:{hand(4)}") is not None)
    use_token(browser, VIEW_TOKEN)
    wait_for(browser, "the viewer's role shown", lambda d: token_state(d) ==
             "Token accepted: view. This token may only view: every command is off.")
    wait_for(browser, "every command off", lambda d: enabled_command_controls(d) == [])
    for can_id in (1, 2, 3):
        assert cell_text(browser, can_id, "blocked") == "Commands off: " + VIEW_ONLY
        assert button(browser, can_id, "move").get_attribute("title") == VIEW_ONLY
    assert browser.find_element(By.ID, "stop-all-blocked").text == "Stop all off: " + VIEW_ONLY
    Select(browser.find_element(By.ID, "commission-hand")).select_by_value(hand(1))
    wait_for(browser, "commissioning off with the reason", lambda d: d.find_element(
        By.ID, "commission-blocked").text == "Commands off: " + VIEW_ONLY)
    # dh3-web refuses the viewer's command itself; nothing reaches the hand.
    written = requests_written(cell.url)
    status, reply = api(cell.url, f"/api/hands/{hand(1)}/stop", {}, token=VIEW_TOKEN)
    assert (status, reply["code"]) == (403, "READ_ONLY_TOKEN"), reply
    assert requests_written(cell.url) == written


def test_an_operator_token_drives_the_hands_but_not_admin_commands(cell, browser):
    use_token(browser, TOKEN)
    wait_for(browser, "the operator's role shown", lambda d: token_state(d).startswith(
        "Token accepted: operator. Commands go to the hands; CAN ID and baud-rate changes are "
        "admin only."))
    wait_for(browser, "hand 1's buttons on", lambda d: button(d, 1, "move").is_enabled())
    assert browser.find_element(By.ID, "stop-all").is_enabled()
    assert not browser.find_element(By.ID, "stop-all-blocked").is_displayed()
    Select(browser.find_element(By.ID, "commission-hand")).select_by_value(hand(1))
    wait_for(browser, "the admin commands off with the reason", lambda d: d.find_element(
        By.ID, "admin-blocked").text == "CAN ID and baud rate off: " + ADMIN_ONLY)
    for command in ("set-can-id", "set-baud"):
        shown = commission_control(browser, f'button[data-commission="{command}"]')
        assert not shown.is_enabled(), command
        assert shown.get_attribute("title") == ADMIN_ONLY
    assert not commission_control(browser, 'input[data-input="can_id"]').is_enabled()
    assert not browser.find_element(By.ID, "baud").is_enabled()
    for command in ("scan", "versions", "read", "force"):
        assert commission_control(browser, f'button[data-commission="{command}"]').is_enabled(), command
    assert browser.find_element(By.ID, "register").is_enabled()
    assert browser.find_element(By.ID, "commission-blocked").text == ""
    # dh3-web refuses the operator's admin command itself.
    written = requests_written(cell.url)
    status, reply = api(cell.url, f"/api/hands/{hand(1)}/set-can-id", {"can_id": 9, "confirm": True})
    assert (status, reply["code"]) == (403, "ADMIN_TOKEN_NEEDED"), reply
    assert requests_written(cell.url) == written


def test_the_health_panel_shows_each_service(cell, browser):
    status, listed = api(cell.url, "/api/hands")
    assert status == 200, listed
    info = next(s for s in listed["services"] if s["service"] == SERVICE)
    assert info["host"]
    panel = f'article.service[data-service="{SERVICE}"]'

    def shown(d, name):
        return d.find_element(By.CSS_SELECTOR, f'{panel} [data-field="{name}"]').text
    wait_for(browser, "the service's card", lambda d: shown(d, "state") == "ready")
    assert shown(browser, "host") == info["host"]
    assert shown(browser, "version") == info["version"]
    wait_for(browser, "the domain", lambda d: shown(d, "domain") == str(DOMAIN))
    assert shown(browser, "admin") == "allowed"
    wait_for(browser, "bus0, its link and its hands", lambda d: shown(d, "buses").startswith(
        "bus0 (sim:1,2,3): link up; 3 of 4 hands online; hand 4 reports "))
    assert "dh3_bus_load_percent" in browser.find_element(By.CSS_SELECTOR, f"{panel} .note").text
    assert f"on DDS domain {DOMAIN}: connected" in browser.find_element(By.ID, "console-health").text


def test_a_cell_coming_up_beside_its_console_raises_no_alarm(cell, browser):
    """dh3-web started with the service: while the service is not ready yet
    its hands' first statuses say offline; that is neither a lost service
    nor an offline hand. The hand that never answers is."""
    wait_for(browser, "hand 4's alarm", lambda d: alarm(d, f"offline:{hand(4)}") is not None)
    status, listed = api(cell.url, "/api/alarms")
    assert status == 200, listed
    keys = [a["key"] for a in listed["alarms"]]
    assert f"service:{SERVICE}" not in keys, listed
    for can_id in (1, 2, 3):
        assert f"offline:{hand(can_id)}" not in keys, listed


def test_an_offline_hand_is_an_alarm_until_acknowledged(cell, browser):
    key = f"offline:{hand(4)}"
    wait_for(browser, "hand 4's alarm", lambda d: alarm(d, key) is not None)
    assert alarm(browser, key)["state"] == "active"
    assert f"hand {hand(4)} (absent) OFFLINE: the hand does not answer" in alarm(browser, key)["text"]
    assert browser.find_element(By.ID, "alarm-summary").text.startswith("ALARMS: ")
    acknowledge(browser, key)
    # Still offline: not raised again while the condition lasts.
    wait_for(browser, "the card still offline", lambda d: cell_text(d, 4, "online").startswith("OFFLINE"))
    browser.execute_script("refresh();")
    assert alarm(browser, key) is None


def test_an_offline_hand_takes_no_commands(cell, browser):
    wait_for(browser, "hand 4 offline",
             lambda d: cell_text(d, 4, "online") == "OFFLINE: the hand does not answer")
    assert "not-live" in card(browser, 4).get_attribute("class")
    assert cell_text(browser, 4, "blocked") == "Commands off: the hand is offline"
    for command in ("init", "move", "stop", "acquire-lease"):
        assert not button(browser, 4, command).is_enabled(), command


def test_a_grasp_shows_on_the_card_and_the_log_and_another_client_is_followed(cell, browser):
    browser.execute_script("window.dh3NotReloaded = true;")
    button(browser, 1, "init").click()
    wait_for(browser, "hand 1 initialized", lambda d: cell_text(d, 1, "initialized") == "yes")
    set_field(browser, 1, "force", "40")
    button(browser, 1, "grasp").click()
    wait_for(browser, "GRASPED on the card",
             lambda d: "grasp: OK GRASPED at position" in cell_text(d, 1, "result"))
    wait_for(browser, "the grip GRASPED", lambda d: cell_text(d, 1, "grip") == "GRASPED")
    wait_for(browser, "GRASPED in the log", lambda d: any(
        hand(1) in line and " GRASPED " in line for line in log_lines(d)))

    # Another client moves hand 2: the page follows without a reload.
    assert dh3ctl("init", hand(2)).returncode == 0
    moved = dh3ctl("move", hand(2), "30")
    assert moved.returncode == 0, moved.stderr
    wait_for(browser, "dh3ctl's move on the card",
             lambda d: cell_text(d, 2, "position") == "30 / 30")
    wait_for(browser, "dh3ctl's move in the log", lambda d: any(
        hand(2) in line and " ARRIVED " in line for line in log_lines(d)))
    assert browser.execute_script("return window.dh3NotReloaded === true;")

    # A refusal is shown where it happened, in words.
    button(browser, 3, "move").click()
    wait_for(browser, "hand 3's refusal",
             lambda d: "Error in move (HTTP 409 NOT_INITIALIZED)" in cell_text(d, 3, "result"))


def test_a_failed_command_is_an_alarm_until_acknowledged(cell, browser):
    failed = alarm_keys(browser, "command:")
    assert len(failed) == 1
    assert (f"Command to hand {hand(3)} failed: Error in move (HTTP 409 NOT_INITIALIZED)"
            in alarm(browser, failed[0])["text"])
    acknowledge(browser, failed[0])


def test_the_alarms_are_the_consoles_acknowledged_on_one_screen_gone_from_all(cell, browser):
    """The list is dh3-web's: a command that failed through the API is listed
    on the page; acknowledged by another client it is gone from the page; a
    reload brings back neither it nor hand 4's, acknowledged while it lasts."""
    status, reply = api(cell.url, f"/api/hands/{hand(3)}/move", {"position": 30})
    assert status == 409, reply
    words = f"Command to hand {hand(3)} failed: Error in move (HTTP 409 NOT_INITIALIZED)"
    wait_for(browser, "the API's failure on the page", lambda d: any(
        words in (alarm(d, key) or {}).get("text", "") for key in alarm_keys(d, "command:")))
    status, listed = api(cell.url, "/api/alarms")
    assert status == 200, listed
    failed = [a for a in listed["alarms"] if words in a["text"] and not a["acknowledged"]]
    assert len(failed) == 1, listed
    status, acknowledged = api(cell.url, f"/api/alarms/{failed[0]['id']}/acknowledge", {})
    assert status == 200 and acknowledged["acknowledged"], acknowledged
    wait_for(browser, "gone from the page", lambda d: alarm(d, failed[0]["key"]) is None)

    open_page(browser, cell.url)
    wait_for(browser, "the list from dh3-web", lambda d: d.execute_script(
        "return alarmList.version >= arguments[0];", listed["version"]))
    assert alarm(browser, failed[0]["key"]) is None
    assert alarm(browser, f"offline:{hand(4)}") is None
    assert cell_text(browser, 4, "online").startswith("OFFLINE")
    status, listed = api(cell.url, "/api/alarms")
    assert any(a["key"] == f"offline:{hand(4)}" and a["acknowledged"] and a["active"]
               for a in listed["alarms"]), listed


def test_the_log_says_where_motions_stopped_in_the_cards_words(cell, browser):
    # An event goes out on the status read that shows the end; where the
    # fingers stopped may be read in the frame after it: the log then takes it
    # from the status read just after the event.
    def line(d, can_id, kind):
        return next(text for text in log_lines(d) if hand(can_id) in text and f" {kind} " in text)
    wait_for(browser, "where the grasp stopped", lambda d: re.search(
        r"\(left\) GRASPED at position 40( \(read just after\))? with force 40$", line(d, 1, "GRASPED")))
    wait_for(browser, "where the move stopped", lambda d: re.search(
        r"\(right\) ARRIVED at position 30( \(read just after\))? \(target 30\)$", line(d, 2, "ARRIVED")))
    grasped = line(browser, 1, "GRASPED")
    assert cell_text(browser, 1, "grip") in grasped


@pytest.mark.parametrize("text,problem", [
    ("", "empty"), ("150", "150 is out of range"), ("-5", "-5 is out of range"),
    ("12.5", "is not a whole number")])
def test_an_invalid_position_sends_nothing(cell, browser, text, problem):
    written = requests_written(cell.url)
    set_field(browser, 2, "position", text)
    button(browser, 2, "move").click()
    wait_for(browser, "the field's error beside it", lambda d: problem in card(d, 2).find_element(
        By.CSS_SELECTOR, '[data-error="position"]').text)
    assert "nothing sent" in card(browser, 2).find_element(
        By.CSS_SELECTOR, '[data-error="position"]').text
    wait_for(browser, "the card says it was not sent",
             lambda d: cell_text(d, 2, "result") == "move: not sent (a field above is not valid)")
    assert requests_written(cell.url) == written
    assert cell_text(browser, 2, "position") == "30 / 30"


def test_a_typed_position_moves_the_hand(cell, browser):
    set_field(browser, 2, "position", "70")
    assert card(browser, 2).find_element(By.CSS_SELECTOR, '[data-error="position"]').text == ""
    button(browser, 2, "move").click()
    wait_for(browser, "hand 2 at 70", lambda d: cell_text(d, 2, "position") == "70 / 70")


def test_a_hand_leased_by_another_client_takes_no_commands(cell, browser):
    other, other_url = start_web(cell.token_path)
    try:
        wait_for(browser, "the other console sees hand 3",
                 lambda d: api(other_url, f"/api/hands/{hand(3)}")[0] == 200)
        status, reply = api(other_url, f"/api/hands/{hand(3)}/acquire-lease", {"ttl_ms": 60000})
        assert status == 200, reply
        holder = reply["lease_holder"]
        program, host = holder.split("@")
        wait_for(browser, "hand 3 held by the other console", lambda d: cell_text(d, 3, "blocked") ==
                 f"Commands off: held by {program} on host {host} (its lease)")
        assert not button(browser, 3, "move").is_enabled()
        assert not button(browser, 3, "acquire-lease").is_enabled()
        # This console's own lease leaves its buttons on.
        set_field(browser, 2, "ttl", "30")
        button(browser, 2, "acquire-lease").click()
        wait_for(browser, "hand 2 held by this console",
                 lambda d: cell_text(d, 2, "lease") == "held by this console")
        assert button(browser, 2, "move").is_enabled()
        button(browser, 2, "release-lease").click()
        wait_for(browser, "hand 2's lease given back", lambda d: cell_text(d, 2, "lease") == "free")
        status, reply = api(other_url, f"/api/hands/{hand(3)}/release-lease", {})
        assert status == 200, reply
        wait_for(browser, "hand 3's buttons on again", lambda d: button(d, 3, "move").is_enabled())
    finally:
        stop(other)


def test_a_scan_from_the_page_lists_the_hands(cell, browser):
    commission(browser, 1, "scan")
    wait_for(browser, "the scan's result", lambda d: commission_result(d, "scan").endswith(
        f"{hand(1)} scan of bus {SERVICE}/bus0: hands 1, 2, 3 answered; configured but silent: 4"))


def test_firmware_and_a_register_are_read_and_forces_set(cell, browser):
    commission(browser, 2, "versions")
    wait_for(browser, "the firmware", lambda d: "firmware: hand 1 " in commission_result(d, "versions"))
    versions = commission_result(browser, "versions")
    for can_id in (1, 2, 3):
        assert f"hand {can_id} Error" not in versions
    assert "hand 4 Error in version (HTTP 504 TIMEOUT)" in versions  # offline: said, not skipped
    browser.find_element(By.ID, "register").clear()
    browser.find_element(By.ID, "register").send_keys("position")
    commission(browser, 2, "read")
    wait_for(browser, "the register's value",
             lambda d: commission_result(d, "read").endswith("read position: value 70"))
    panel = browser.find_element(By.ID, "commission-title").find_element(By.XPATH, "..")
    for name, value in (("closing", "60"), ("opening", "30")):
        field = panel.find_element(By.CSS_SELECTOR, f'input[data-input="{name}"]')
        field.clear()
        field.send_keys(value)
    commission(browser, 2, "force")
    wait_for(browser, "the forces on the card", lambda d: cell_text(d, 2, "force") == "60 / 30")
    assert commission_result(browser, "force").endswith("force: OK")


def test_a_can_id_change_asks_first_and_sends_nothing_when_cancelled(cell, browser):
    use_token(browser, ADMIN_TOKEN)  # the rest of the module's tests run with it
    wait_for(browser, "the admin's role shown", lambda d: token_state(d) ==
             "Token accepted: admin. Commands go to the hands, CAN ID and baud-rate changes too.")
    written = requests_written(cell.url)
    field = commission_control(browser, 'input[data-input="can_id"]')
    wait_for(browser, "the CAN ID field on", lambda d: field.is_enabled())
    field.clear()
    field.send_keys("9")
    commission(browser, 3, "set-can-id")
    dialog = browser.find_element(By.ID, "confirm")
    wait_for(browser, "the confirmation", lambda d: dialog.get_attribute("open") is not None)
    assert f"Change the CAN ID of hand {hand(3)} from 3 to 9?" in dialog.text
    assert "must then be rebooted" in dialog.text
    browser.find_element(By.ID, "confirm-cancel").click()
    wait_for(browser, "cancelled", lambda d: commission_result(d, "set-can-id").endswith(
        "set-can-id: not sent (cancelled)"))
    assert dialog.get_attribute("open") is None
    assert requests_written(cell.url) == written


def beyond_the_right_edge(driver) -> list:
    return driver.execute_script("""
        const width = document.documentElement.clientWidth;
        const out = [...document.querySelectorAll('button, input, label, meter, #connection')]
            .filter((e) => e.getBoundingClientRect().right > width + 0.5)
            .map((e) => e.outerHTML.slice(0, 80));
        if (document.documentElement.scrollWidth > width) out.push('the page scrolls sideways');
        return out;""")


def stop_all_in_view(driver) -> bool:
    return driver.execute_script("""
        window.scrollTo(0, document.documentElement.scrollHeight);
        const r = document.getElementById('stop-all').getBoundingClientRect();
        return r.top >= 0 && r.bottom <= window.innerHeight && r.right <= window.innerWidth;""")


@pytest.mark.parametrize("width", [1280, 800, 400])
def test_every_control_fits_the_width_and_stop_all_stays_in_view(cell, browser, width):
    browser.set_window_size(width, 900)
    inner = browser.execute_script("return window.innerWidth;")
    browser.set_window_size(width + (width - inner), 900)  # the viewport itself this wide
    wait_for(browser, f"the viewport {width} px wide",
             lambda d: d.execute_script("return window.innerWidth;") == width)
    assert beyond_the_right_edge(browser) == []
    assert stop_all_in_view(browser)
    folder = os.environ.get("DH3_WEB_SCREENSHOTS")
    if folder:
        os.makedirs(folder, exist_ok=True)
        browser.execute_script("window.scrollTo(0, 0);")
        height = browser.execute_script("return document.documentElement.scrollHeight;")
        browser.set_window_size(width + (width - inner), min(height + 120, 4000))
        browser.save_screenshot(os.path.join(folder, f"web-console-{width}.png"))
        browser.set_window_size(width + (width - inner), 900)


def test_stop_all_stops_every_hand_the_page_shows(cell, browser):
    browser.set_window_size(1400, 1400)
    written = requests_written(cell.url)
    button(browser, 3, "init").click()
    wait_for(browser, "hand 3 initialized", lambda d: cell_text(d, 3, "initialized") == "yes")
    browser.find_element(By.ID, "stop-all").click()
    # Sent to the offline hand too: it says why it did not stop.
    wait_for(browser, "every hand answered", lambda d: d.find_element(
        By.ID, "stop-all-result").text.startswith(
            f"Error: Stop all: 3 of 4 stopped; not {hand(4)} (Error in stop (HTTP 504 TIMEOUT)"))
    for can_id in (1, 2, 3):
        assert cell_text(browser, can_id, "result") == "stop: OK"
    assert requests_written(cell.url) == written + 5  # init and four stops


def test_a_frozen_service_is_stale_and_a_killed_one_lost(cell, browser):
    """Last: it ends the module's service."""
    wait_for(browser, "hand 1's buttons on", lambda d: button(d, 1, "init").is_enabled())
    cell.service.send_signal(signal.SIGSTOP)
    try:
        wait_for(browser, "every hand marked not live", lambda d: all(
            "not-live" in card(d, i).get_attribute("class")
            and cell_text(d, i, "online").startswith(("STALE", "LOST")) for i in (1, 2, 3)))
        wait_for(browser, "the page not live",
                 lambda d: d.find_element(By.ID, "connection").text.startswith("NOT LIVE"))
    finally:
        cell.service.send_signal(signal.SIGCONT)
    wait_for(browser, "live again", lambda d: all(
        cell_text(d, i, "online") == "online" for i in (1, 2, 3)))
    cell.service.send_signal(signal.SIGKILL)
    cell.service.wait()
    wait_for(browser, "every hand lost", lambda d: all(
        cell_text(d, i, "online").startswith("LOST: service ") for i in (1, 2, 3)))
    wait_for(browser, "the page says the service is lost", lambda d: d.find_element(
        By.ID, "connection").text.startswith("NOT LIVE: service "))
    assert not button(browser, 1, "move").is_enabled()
    assert "its service is lost" in cell_text(browser, 1, "blocked")
    key = f"service:{SERVICE}"
    wait_for(browser, "the service's alarm", lambda d: (alarm(d, key) or {}).get("state") == "active")
    assert f"Service {SERVICE} lost: its hands take no commands" in alarm(browser, key)["text"]
    acknowledge(browser, key)


def test_a_service_without_admin_commands_has_them_off_with_the_reason(cell, browser):
    """After the module's service is gone: a cell of its own."""
    name = SERVICE + "noadmin"
    with service_and_web(allow_admin=False, name=name) as other:
        browser.get(other.url)
        use_token(browser, ADMIN_TOKEN)  # the service's refusal, not the token's
        address = f"{name}/bus0/1"
        wait_for(browser, "its hand 1 online", lambda d: d.find_elements(
            By.CSS_SELECTOR, f'article[data-hand="{address}"]') and d.find_element(
            By.CSS_SELECTOR, f'article[data-hand="{address}"] [data-field="online"]').text == "online")
        wait_for(browser, "the token accepted", lambda d: d.find_element(
            By.ID, "token-state").text.startswith("Token accepted"))
        panel = f'article.service[data-service="{name}"]'
        wait_for(browser, "admin not allowed in its health", lambda d: d.find_element(
            By.CSS_SELECTOR, f'{panel} [data-field="admin"]').text == "not allowed (its allow_admin is off)")
        Select(browser.find_element(By.ID, "commission-hand")).select_by_value(address)
        wait_for(browser, "the reason", lambda d: d.find_element(By.ID, "admin-blocked").text ==
                 f"CAN ID and baud rate off: admin only: service {name} does not allow CAN ID and "
                 "baud-rate changes (allow_admin)")
        for command in ("set-can-id", "set-baud"):
            assert not browser.find_element(
                By.CSS_SELECTOR, f'button[data-commission="{command}"]').is_enabled(), command
        for command in ("scan", "versions", "read", "force"):
            assert browser.find_element(
                By.CSS_SELECTOR, f'button[data-commission="{command}"]').is_enabled(), command


def box_config(port: int) -> str:
    """Hand 2 behind a transfer box (dh3-sim on `port`)."""
    return f"""buses:
  - name: bus0
    spec: tcp:127.0.0.1:{port}
    command_interval_ms: 2
    poll_interval_moving_ms: 20
    poll_interval_idle_ms: 50
    hands:
      - {{id: 2, name: holder}}
"""


def tell(sim: subprocess.Popen, line: str) -> None:
    """One line to dh3-sim's standard input; its answer must be ok."""
    sim.stdin.write(line + "\n")
    sim.stdin.flush()
    answer = sim.stdout.readline()
    assert answer.startswith("ok"), f"{line}: {answer}"


def test_a_dropped_object_and_a_bus_down_are_alarms(cell, browser):
    """After the module's service is gone: a cell of its own, on a transfer box."""
    sim = subprocess.Popen([os.environ["DH3_SIM"], "--listen", "127.0.0.1:0", "--hands", "2",
                            "--object", "2:40"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                           stderr=subprocess.DEVNULL, text=True)
    try:
        line = sim.stdout.readline()
        assert line.startswith("listening 127.0.0.1:"), line
        port = int(line.split(":")[-1])
        name = SERVICE + "box"
        with service_and_web(name=name, config_text=box_config(port)) as other:
            address = f"{name}/bus0/2"
            card_of = f'article[data-hand="{address}"]'
            browser.get(other.url)
            use_token(browser, TOKEN)  # acknowledging is a command
            wait_for(browser, "hand 2 online", lambda d: d.find_elements(By.CSS_SELECTOR, card_of)
                     and d.find_element(By.CSS_SELECTOR, f'{card_of} [data-field="online"]').text
                     == "online")
            assert api(other.url, f"/api/hands/{address}/init", {})[0] == 200
            status, reply = api(other.url, f"/api/hands/{address}/grasp", {"force": 40})
            assert status == 200 and reply["grasp"] == "GRASPED", reply
            tell(sim, "drop 2")
            wait_for(browser, "the drop's alarm", lambda d: alarm_keys(d, f"event:{address}:"))
            drop = alarm_keys(browser, f"event:{address}:")[0]
            assert (f"hand {address} (holder) DROPPED: the object fell from the fingers"
                    in alarm(browser, drop)["text"])
            acknowledge(browser, drop)

            tell(sim, "quit")
            sim.wait(timeout=DEADLINE)
            key = f"bus:{name}/bus0"
            wait_for(browser, "the bus's alarm", lambda d: alarm(d, key) is not None)
            assert (f"Bus {name}/bus0 down (tcp:127.0.0.1:{port}): its hands cannot be reached"
                    in alarm(browser, key)["text"])
            wait_for(browser, "the link DOWN in the health panel", lambda d: d.find_element(
                By.CSS_SELECTOR, f'article.service[data-service="{name}"] [data-field="buses"]')
                .text.startswith(f"bus0 (tcp:127.0.0.1:{port}): link DOWN"))
            acknowledge(browser, key)
    finally:
        stop(sim)
