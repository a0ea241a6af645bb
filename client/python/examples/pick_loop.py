#!/usr/bin/env python3
"""pick_loop.py: grasps and releases one hand again and again, the way a robot
cell's program would drive it through the dh3 Python module (the Python twin of
client/examples/pick_loop.cpp).

    pick_loop.py --hand cell/bus0/1 --cycles 10 --force 40
    pick_loop.py --domain 5 --interface 192.168.1.20 --udp-only --hand 1
    pick_loop.py --security-dir /etc/dh3/pki --security-identity operator --hand 1

Exit 0 when every command succeeded (a grasp that closed on nothing is a
success: MISSED is an answer, not an error), 1 otherwise.
"""

import argparse
import sys

import dh3


def check(what: str, reply: dh3.Reply) -> bool:
    if reply.ok:
        return True
    print(f"pick_loop: {what}: {reply.code}: {reply.message}", file=sys.stderr)
    return False


def main() -> int:
    parser = argparse.ArgumentParser(
        description="grasp and release a DH-3 hand in a loop (a dh3 Python example)")
    parser.add_argument("-d", "--domain", type=int, default=0, help="DDS domain id (default 0)")
    parser.add_argument("-i", "--interface", action="append", default=[],
                        help="IPv4 address of a network interface for DDS (repeatable); "
                             "default loopback")
    parser.add_argument("--udp-only", action="store_true", help="no shared-memory transport")
    parser.add_argument("--discovery-server", action="append", default=[],
                        help="a Fast DDS discovery server, HOST[:PORT] (repeatable)")
    parser.add_argument("--xml", default="", help="Fast DDS XML profiles file")
    parser.add_argument("--profile", default="", help="participant profile name in --xml")
    parser.add_argument("--security-dir", default="", help="DDS Security credentials")
    parser.add_argument("--security-identity", default="operator",
                        help="identity in --security-dir (default operator)")
    parser.add_argument("--hand", required=True, help="the hand: SERVICE/BUS/ID, BUS/ID, ID or NAME")
    parser.add_argument("--cycles", type=int, default=3, help="grasp-release cycles (default 3)")
    parser.add_argument("--force", type=int, default=40,
                        help="closing force, 20-100 percent (default 40)")
    parser.add_argument("--open", type=int, default=100, help="position to release to (default 100)")
    parser.add_argument("-t", "--timeout", type=float, default=20.0,
                        help="seconds for each step (default 20)")
    args = parser.parse_args()
    if args.cycles < 0 or args.timeout <= 0:
        parser.error("--cycles must be >= 0 and --timeout > 0")

    client = dh3.Client(domain=args.domain, participant_name="pick_loop",
                        interfaces=args.interface, udp_only=args.udp_only,
                        discovery_servers=args.discovery_server, xml_profile_file=args.xml,
                        xml_profile=args.profile, security_dir=args.security_dir,
                        security_identity=args.security_identity, default_timeout=args.timeout)
    if not client.connected():
        print(f"pick_loop: {client.error()}", file=sys.stderr)
        return 1
    try:
        hand = client.wait_for_hand(args.hand)
    except dh3.Error as error:
        print(f"pick_loop: {error.message}", file=sys.stderr)
        return 1
    print(f"hand {hand.address}")

    # Initialize only if needed: re-initializing a hand that holds something
    # would open it.
    status = hand.status()
    if status is None or not status.initialized:
        if not check("initialize", hand.initialize()):
            return 1
        print("initialized")
    grasped = 0
    for cycle in range(1, args.cycles + 1):
        grasp = hand.grasp(args.force)
        if not check("grasp", grasp):
            return 1
        if grasp.grasp == dh3.GraspOutcome.GRASPED:
            grasped += 1
        print(f"cycle {cycle}: {grasp.grasp} at position {grasp.value}", flush=True)
        if not check("release", hand.release(args.open)):
            return 1
    print(f"done: {args.cycles} cycles, {grasped} grasped")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(130)
