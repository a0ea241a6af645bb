#!/usr/bin/env python3
"""Checks a CAN bus recording (`candump -L`, optionally with -x) against the
DH-3 protocol document (docs/dh3-protocol.md): every frame a standard data
frame with the hand's ID (0-255) and 8 data bytes laid out as function,
sub-function, read/write, reserve, 32-bit little-endian data; only the
document's registers; R/W only 00 or 01; writes only to writable registers and
within the document's ranges. With -x marks (T: sent from the recording side,
the service's; R: received from the other end, the hands') it also checks the
minimum interval between two frames the service sent to one hand, on the
kernel's timestamps.

    check_frames.py LOG [--service-marks T] [--min-interval-ms 20] [--hands 1,2]

Prints one line per problem and a summary; exit status 1 if any problem.
"""
import argparse
import re
import sys

# (function, sub-function): (name, writable, range of the data field or None)
REGISTERS = {
    (0x08, 0x01): ("init feedback", True, None),
    (0x08, 0x02): ("initialize", True, None),
    (0x05, 0x02): ("closing force", True, (20, 100)),
    (0x05, 0x03): ("opening force", True, (20, 100)),
    (0x06, 0x02): ("position", True, (0, 100)),
    (0x07, 0x02): ("rotation", True, (0, 100)),
    (0x0F, 0x01): ("grip status", False, None),
    (0x0F, 0x02): ("rotation status", False, None),
    (0x12, 0x01): ("CAN ID", True, (1, 255)),
    (0x13, 0x01): ("firmware version", False, None),
    (0x14, 0x01): ("CAN baud rate", True, (0, 5)),
}
STATUS_VALUES = {0, 2, 3}  # default or moving, arrived, caught

LINE = re.compile(r"^\((\d+\.\d+)\)\s+(\S+)\s+([0-9A-Fa-f]+)#(R?)([0-9A-Fa-f]*)(?:\s+([TR]))?\s*$")


def check_payload(payload, sent_by_service):
    """Problems of one 8-byte payload; sent_by_service is None when unknown."""
    function, sub, rw, reserve = payload[0], payload[1], payload[2], payload[3]
    data = int.from_bytes(payload[4:8], "little", signed=True)
    register = REGISTERS.get((function, sub))
    if register is None:
        return [f"register 0x{function:02X}{sub:02X} is not in the document"]
    name, writable, value_range = register
    problems = []
    if rw not in (0, 1):
        problems.append(f"{name}: read/write byte 0x{rw:02X} (only 00 and 01 are allowed)")
        return problems
    if rw == 1 and not writable:
        problems.append(f"{name}: written, but the document only reads it")
    # The document's feedback lines put the status in the reserve byte; the
    # project accepts that variant from a hand (docs/protocol-notes.md, 2).
    status_in_reserve = function == 0x0F and rw == 0 and reserve in STATUS_VALUES and data == 0
    if reserve != 0 and not (status_in_reserve and sent_by_service is not True):
        problems.append(f"{name}: reserve byte 0x{reserve:02X} (must be 00)")
    if rw == 1 and value_range and not value_range[0] <= data <= value_range[1]:
        problems.append(f"{name}: data {data} outside {value_range[0]}-{value_range[1]}")
    if rw == 0:
        if sent_by_service is True and data != 0:
            problems.append(f"{name}: a read carries data {data} (the service sends 0)")
        if function == 0x0F and data not in STATUS_VALUES:
            problems.append(f"{name}: status {data} is none of 0, 2, 3")
        elif value_range and data != 0 and not value_range[0] <= data <= value_range[1]:
            problems.append(f"{name}: value {data} outside {value_range[0]}-{value_range[1]}")
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("--service-marks", choices=["T", "R"],
                        help="the -x mark of frames the service sent (omit if the log has none)")
    parser.add_argument("--min-interval-ms", type=float, default=20.0)
    parser.add_argument("--hands", default="", help="IDs expected on the bus, e.g. 1,2")
    args = parser.parse_args()

    problems = []
    frames = 0
    service_frames = {}  # hand ID -> kernel timestamps of frames the service sent
    seen_ids = set()
    with open(args.log, encoding="utf-8") as log:
        for number, line in enumerate(log, 1):
            if not line.strip():
                continue
            match = LINE.match(line)
            if not match:
                problems.append(f"line {number}: not a candump -L line: {line.rstrip()}")
                continue
            stamp, _, ident, remote, data_hex, mark = match.groups()
            frames += 1
            where = f"line {number} ({line.split(')', 1)[1].strip()})"
            if len(ident) != 3:
                problems.append(f"{where}: extended frame (CAN 2.0A only)")
                continue
            can_id = int(ident, 16)
            if remote:
                problems.append(f"{where}: remote frame")
                continue
            if can_id > 0xFF:
                problems.append(f"{where}: CAN ID 0x{can_id:03X} above 255")
            payload = bytes.fromhex(data_hex)
            if len(payload) != 8:
                problems.append(f"{where}: {len(payload)} data bytes (always 8)")
                continue
            seen_ids.add(can_id)
            sent_by_service = None
            if args.service_marks:
                if mark is None:
                    problems.append(f"{where}: no -x mark")
                    continue
                sent_by_service = mark == args.service_marks
                if sent_by_service:
                    service_frames.setdefault(can_id, []).append(float(stamp))
            problems += [f"{where}: {p}" for p in check_payload(payload, sent_by_service)]

    closest = None
    for can_id, stamps in sorted(service_frames.items()):
        for earlier, later in zip(stamps, stamps[1:]):
            gap_ms = (later - earlier) * 1000.0
            closest = gap_ms if closest is None else min(closest, gap_ms)
            if gap_ms < args.min_interval_ms:
                problems.append(f"hand {can_id}: two frames from the service {gap_ms:.3f} ms apart "
                                f"at {earlier:.6f} (at least {args.min_interval_ms:g} ms)")
    for wanted in filter(None, args.hands.split(",")):
        if int(wanted) not in seen_ids:
            problems.append(f"hand {wanted}: no frame on the bus")

    for problem in problems:
        print(problem)
    sent = sum(len(s) for s in service_frames.values())
    summary = f"check_frames: {frames} frames"
    if args.service_marks:
        summary += f", {sent} from the service"
        if closest is not None:
            summary += f", closest two to one hand {closest:.3f} ms apart"
    print(f"{summary}; {len(problems)} problems")
    if frames == 0:
        print("check_frames: the recording is empty")
        return 1
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
