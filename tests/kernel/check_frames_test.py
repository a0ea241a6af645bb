#!/usr/bin/env python3
"""check_frames.py against the protocol document: every frame the document
shows passes, and frames that break it are each reported. Runs on the host."""
import pathlib
import re
import subprocess
import sys
import tempfile

here = pathlib.Path(__file__).resolve().parent
checker = here / "check_frames.py"
spec = here.parent.parent / "docs/dh3-protocol.md"


def spec_frames():
    """(CAN ID, 8 payload bytes as hex) of every 14-byte frame in the document."""
    text = spec.read_text(encoding="utf-8")
    frames = re.findall(r"FF FE FD FC((?: [0-9A-F]{2}){9}) FB", text)
    out = []
    for frame in frames:
        octets = frame.split()
        out.append((int(octets[0], 16), "".join(octets[1:])))
    return out


def run(lines, *args):
    with tempfile.NamedTemporaryFile("w", suffix=".log", delete=False) as log:
        log.write("".join(lines))
    result = subprocess.run([sys.executable, str(checker), log.name, *args],
                            capture_output=True, text=True, check=False)
    pathlib.Path(log.name).unlink()
    return result.returncode, result.stdout


def line(stamp, can_id, payload, mark=None):
    return f"({stamp:.6f}) vcan0 {can_id:03X}#{payload}" + (f" {mark}" if mark else "") + "\n"


failures = []


def expect(what, condition, output):
    if not condition:
        failures.append(f"{what}:\n{output}")


frames = spec_frames()
expect("the document has its frames", len(frames) >= 30, f"{len(frames)} frames found")
# The document's "read CAN ID with ID 0" example sets the write flag on a read
# (docs/protocol-notes.md reading 1): as the frame stands it writes CAN ID 0,
# which the service never sends, so the checker must report it.
read_with_write_flag = (0, "1201010000000000")
expect("the document's read with the write flag is there", read_with_write_flag in frames, "")
status, out = run([line(1 + i * 0.05, can_id, payload)
                   for i, (can_id, payload) in enumerate(frames) if (can_id, payload) != read_with_write_flag])
expect("every other frame of the document passes", status == 0, out)
status, out = run([line(1.0, *read_with_write_flag)])
expect("a write of CAN ID 0 is reported", status == 1 and "outside 1-255" in out, out)

bad = {
    "0901000000000000": "not in the document",
    "0602020000000000": "read/write byte",
    "0602010065000000": "outside 0-100",
    "0502010013000000": "outside 20-100",
    "0F01010000000000": "only reads it",
    "1301010000000000": "only reads it",
    "1401010006000000": "outside 0-5",
    "0602000700000000": "reserve byte",
    "0F01000000050000": "none of 0, 2, 3",
}
for payload, problem in bad.items():
    status, out = run([line(1.0, 1, payload)])
    expect(f"{payload} is reported ({problem})", status == 1 and problem in out, out)
status, out = run(["(1.000000) vcan0 12345678#0602010000000000\n"])
expect("an extended frame is reported", status == 1 and "extended" in out, out)
status, out = run([line(1.0, 0x1FF, "0602010000000000")])
expect("an ID above 255 is reported", status == 1 and "above 255" in out, out)
status, out = run([line(1.0, 1, "060201003C00")])
expect("a short frame is reported", status == 1 and "6 data bytes" in out, out)

# The interval, on frames marked as the service's (T) only.
paced = [line(1.000, 1, "0602000000000000", "T"), line(1.001, 1, "060200003C000000", "R"),
         line(1.020, 1, "0602000000000000", "T"), line(1.021, 1, "060200003C000000", "R")]
status, out = run(paced, "--service-marks", "T")
expect("frames 20 ms apart pass", status == 0, out)
hurried = [line(1.000, 1, "0602000000000000", "T"), line(1.0195, 1, "0602000000000000", "T"),
           line(1.0196, 2, "0602000000000000", "T")]
status, out = run(hurried, "--service-marks", "T")
expect("frames 19.5 ms apart to one hand are reported", status == 1 and "19.500 ms" in out, out)
status, out = run([line(1.0, 1, "0602000000000000", "T")], "--service-marks", "T", "--hands", "1,2")
expect("a hand that never appears is reported", status == 1 and "hand 2: no frame" in out, out)
# A hand's reply may carry its status in the reserve byte (docs/protocol-notes.md), the service's request not.
status, out = run([line(1.0, 1, "0F01000200000000", "R")], "--service-marks", "T")
expect("status in the reserve byte from a hand passes", status == 0, out)
status, out = run([line(1.0, 1, "0F01000200000000", "T")], "--service-marks", "T")
expect("status in the reserve byte from the service is reported", status == 1, out)

checks = 5 + len(bad) + 3 + 5
print(f"{checks - len(failures)} passed, {len(failures)} failed")
for failure in failures:
    print("FAILED:", failure)
sys.exit(1 if failures else 0)
