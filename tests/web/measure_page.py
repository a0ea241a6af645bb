#!/usr/bin/python3
"""Measures dh3-web's page: its size (as served, and as sent gzip-compressed)
and the time from a hand's change to the page, in headless Chromium against
dh3-service on the simulator. Prints figures; asserts nothing about them.

A change's time is when the service read the new values from the hand (the
status's read_at_ns, which the page shows as "Read at" to the millisecond,
truncated); it reaches the page when a MutationObserver in the page sees the
hand's row show them (performance.timeOrigin + now(), the same host's clock).
So the figure covers the service publishing, DDS to dh3-web, the stream and
the page's own work.
Hand 2 moves back and forth through the API, one move after the other has
arrived; each new position read is one change.

  DH3_SERVICE=build/service/app/dh3-service/dh3-service DH3_WEB=build/client/dh3-web \\
  DH3CTL=build/client/dh3ctl tests/web/measure_page.py [--moves 40]"""

import argparse
import gzip
import json
import os
import sys
import time
import urllib.request

sys.path.insert(0, os.path.dirname(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "scale"))
from plantlib import percentile  # noqa: E402
from webtest import (DEADLINE, TOKEN, api, hand, headless_chromium, page_files,  # noqa: E402
                     service_and_web)
from selenium.webdriver.support.ui import WebDriverWait  # noqa: E402

OBSERVER = """
window.dh3Seen = [];
const row = document.querySelector('[data-hand="HAND"]');
const text = (name) => row.querySelector('[data-field="' + name + '"]').textContent;
new MutationObserver(() => {
  const now = performance.timeOrigin + performance.now();
  const [h, m, s] = text("read_at").split(":");
  const read = new Date();
  read.setHours(Number(h), Number(m), Math.floor(Number(s)), Math.round((Number(s) % 1) * 1000));
  window.dh3Seen.push([text("position"), now - read.getTime()]);
}).observe(row, {childList: true, characterData: true, subtree: true});
"""


def fetch(url: str, headers=None, body=None):
    request = urllib.request.Request(url, data=body, headers=headers or {})
    with urllib.request.urlopen(request, timeout=DEADLINE) as response:
        return response.read(), dict(response.headers)


def page_size(url: str) -> None:
    total = sent = 0
    files = page_files(url)
    for path in files:
        raw, _ = fetch(url + path)
        packed, headers = fetch(url + path, {"Accept-Encoding": "gzip"})
        if headers.get("Content-Encoding") == "gzip":
            assert gzip.decompress(packed) == raw
        total += len(raw)
        sent += len(packed)
        print(f"  /{path:18} {len(raw):6} bytes, sent {len(packed):6} "
              f"({headers.get('Content-Encoding', 'identity')})")
    print(f"page: {total} bytes ({sent} sent with gzip), {len(files)} requests, no other resources")


def wait_until_arrived(url: str, address: str, target: int) -> None:
    for _ in range(int(DEADLINE / 0.02)):
        status = json.loads(fetch(f"{url}api/hands/{address}")[0])
        if status["position"] == target and status["target_position"] == target:
            return
        time.sleep(0.02)
    raise TimeoutError(f"{address} did not arrive at {target}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--moves", type=int, default=40)
    args = parser.parse_args()
    with service_and_web(position_speed=100) as cell, headless_chromium() as driver:
        url = cell.url
        page_size(url)
        address = hand(2)
        post = lambda command, body: fetch(  # noqa: E731
            f"{url}api/hands/{address}/{command}",
            {"Authorization": "Bearer " + TOKEN, "Content-Type": "application/json"},
            json.dumps(body).encode())
        for _ in range(int(DEADLINE / 0.05)):  # until dh3-web has seen the hand
            if api(url, f"/api/hands/{address}")[0] == 200:
                break
            time.sleep(0.05)
        post("init", {})
        driver.get(url)
        WebDriverWait(driver, DEADLINE).until(
            lambda d: d.execute_script(
                f'return !!document.querySelector(\'[data-hand="{address}"]\')'))
        timing = driver.execute_script(
            "const n = performance.getEntriesByType('navigation')[0];"
            "return [n.responseEnd - n.startTime, n.domContentLoadedEventEnd - n.startTime];")
        print(f"page load (headless Chromium, loopback): response {timing[0]:.1f} ms, "
              f"DOMContentLoaded {timing[1]:.1f} ms")
        driver.execute_script(OBSERVER.replace("HAND", address))
        for i in range(args.moves):
            target = 20 if i % 2 == 0 else 80
            post("move", {"position": target})
            wait_until_arrived(url, address, target)
        WebDriverWait(driver, DEADLINE).until(
            lambda d: d.execute_script("return window.dh3Seen.length") > 0)
        seen = driver.execute_script("return window.dh3Seen")
        latencies = []
        previous = None
        for position, latency in seen:
            if position != previous:  # a sample with the same values again is no change
                latencies.append(latency)
            previous = position
        print(f"change to page: {len(latencies)} changes of {address} over {args.moves} moves; "
              f"p50 {percentile(latencies, 0.5):.1f} ms, p99 {percentile(latencies, 0.99):.1f} ms, "
              f"max {max(latencies):.1f} ms")


if __name__ == "__main__":
    main()
