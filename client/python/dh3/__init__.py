"""dh3: drive DH-3 robot hands on a DDS domain from Python (libdh3client).

    import dh3
    client = dh3.Client(domain=0)
    hand = client.wait_for_hand("cell/bus0/1", timeout=5.0)  # raises dh3.Error if not found
    if not (r := hand.initialize()):
        print(r.code.name, r.message)
    grasp = hand.grasp(40)            # grasp.grasp is GraspOutcome.GRASPED or MISSED
    later = hand.move_to_async(100)   # concurrent.futures.Future of a Reply

Every command has a blocking form, returning a Reply, and an asynchronous one
(NAME_async) returning a concurrent.futures.Future. Each takes a timeout in
seconds (None: the client's default_timeout) and always ends, with the
service's reply or with the client's own code (NO_SERVICE, NO_REPLY,
SERVICE_LOST, NOT_CONNECTED) and a message. Commands do not raise; lookups
(wait_for_hand, find_hand, wait_for_service) raise dh3.Error.

Threads: a Client and its Hands may be used from any number of threads at once;
blocking calls release the GIL, and Ctrl-C ends them. Event and status callbacks
run on one thread of the client, in the order samples arrived, with the GIL.

When a service leaves the domain its pending calls end SERVICE_LOST and its
hands are reported offline; when it comes back under the same name the same
Hand objects work again.
"""

import atexit as _atexit
import enum as _enum

from ._dh3 import (
    BusInfo,
    Client,
    CommandTraffic,
    GroupMemberReply,
    GroupReply,
    Hand,
    HandAddress,
    HandEvent,
    HandInfo,
    HandStatus,
    Reply,
    ServiceInfo,
    Subscription,
    WatchTraffic,
    firmware_version_text,
    parse_hand_address,
    parse_register,
    reg,
    register_name,
)
from . import _dh3

__all__ = [
    "BusInfo", "Client", "Code", "CommandTraffic", "Error", "EventKind", "GraspOutcome", "GripState",
    "GroupCommand", "GroupMemberReply", "GroupReply", "Hand",
    "HandAddress", "HandEvent", "HandInfo", "HandStatus", "Reply", "RotationState",
    "ServiceInfo", "Subscription", "WatchTraffic", "firmware_version_text", "parse_hand_address",
    "parse_register", "reg", "register_name",
]


class _Spelled(_enum.IntEnum):
    """str() is libdh3client's spelling: "INVALID_ARGUMENT", "GRASPED", ..."""

    def __str__(self) -> str:
        return self.name


class Code(_Spelled):
    """The outcome of a call. The first group comes from the service; the
    second is the client's own when no service answer exists."""

    OK = 0
    INVALID_ARGUMENT = 1  #: out-of-range value or malformed request; never sent to a bus
    UNKNOWN_HAND = 2  #: no such service, bus or hand
    TIMEOUT = 3  #: the service says: the hand did not answer in time
    BUS_DOWN = 4  #: the link to the bus is down
    BUSY = 5  #: the hand's command queue is full
    NOT_INITIALIZED = 6  #: motion before initialization
    DENIED = 7  #: administrative command not allowed, or another client holds the lease
    CANCELLED = 8  #: superseded by a newer motion command, a stop, or shutdown
    FAILED = 9  #: the hand answered, but the command did not succeed
    NO_SERVICE = 10  #: the hand's service was not found on the domain before the deadline
    NO_REPLY = 11  #: the request went out but no reply came before the deadline
    SERVICE_LOST = 12  #: the service left the domain (or restarted) while the call was pending
    NOT_CONNECTED = 13  #: the client has no DDS participant (set-up failed, or it is closed)


class GraspOutcome(_Spelled):
    NONE = 0
    GRASPED = 1
    MISSED = 2


class GroupCommand(_Spelled):
    """What Client.group() sends to every hand of the group."""

    INITIALIZE = 0
    MOVE = 1  #: value = position 0-100
    ROTATE = 2  #: value = 0-100 percent of 90 degrees
    GRASP = 3  #: value = closing force 20-100
    RELEASE = 4  #: value = position to open to
    SET_CLOSING_FORCE = 5
    SET_OPENING_FORCE = 6


class GripState(_Spelled):
    UNKNOWN = 0
    MOVING = 1
    ARRIVED = 2
    GRASPED = 3
    MISSED = 4
    DROPPED = 5


class RotationState(_Spelled):
    UNKNOWN = 0
    MOVING = 1
    ARRIVED = 2
    BLOCKED = 3


class EventKind(_Spelled):
    ONLINE = 0
    OFFLINE = 1
    INITIALIZED = 2
    INIT_FAILED = 3
    ARRIVED = 4
    GRASPED = 5
    MISSED = 6
    DROPPED = 7
    ROTATION_ARRIVED = 8
    ROTATION_BLOCKED = 9
    FAULT = 10
    TAKEN_OVER = 11


class Error(Exception):
    """A lookup that found nothing (wait_for_hand, find_hand, wait_for_service,
    parse_hand_address) or a closed client: code says why, message explains."""

    def __init__(self, code: Code, message: str) -> None:
        super().__init__(f"{Code(code).name}: {message}")
        self.code = Code(code)
        self.message = message


# Close the clients and let pending Futures complete before Python shuts down:
# the threads that complete them need the interpreter.
_atexit.register(_dh3._shutdown)
