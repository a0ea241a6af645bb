# Type stubs of dh3 (the compiled dh3._dh3 plus dh3/__init__.py).
from concurrent.futures import Future
from enum import IntEnum
from types import TracebackType
from typing import Callable, List, Optional, Tuple

class _Spelled(IntEnum): ...

class Code(_Spelled):
    OK = 0
    INVALID_ARGUMENT = 1
    UNKNOWN_HAND = 2
    TIMEOUT = 3
    BUS_DOWN = 4
    BUSY = 5
    NOT_INITIALIZED = 6
    DENIED = 7
    CANCELLED = 8
    FAILED = 9
    NO_SERVICE = 10
    NO_REPLY = 11
    SERVICE_LOST = 12
    NOT_CONNECTED = 13

class GraspOutcome(_Spelled):
    NONE = 0
    GRASPED = 1
    MISSED = 2

class GroupCommand(_Spelled):
    INITIALIZE = 0
    MOVE = 1
    ROTATE = 2
    GRASP = 3
    RELEASE = 4
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
    """A lookup that found nothing or a closed client: code says why."""
    code: Code
    message: str
    def __init__(self, code: Code, message: str) -> None: ...

class reg:
    """Register codes (function << 8 | sub-function)."""
    init_feedback: int
    initialize: int
    closing_force: int
    opening_force: int
    position: int
    rotation: int
    grip_status: int
    rotation_status: int
    can_id: int
    firmware_version: int
    baud_rate: int

def register_name(code: int) -> str:
    """"position" for 0x0602; empty for codes outside the map."""
def parse_register(text: str) -> Optional[int]:
    """A register by name ("position", "grip-status") or code ("0x0602"); None if none."""
def firmware_version_text(raw: int) -> str:
    """Firmware version 0x1301 as text: raw 0x04010200 reads "4.1.2.0"."""
def parse_hand_address(text: str) -> HandAddress:
    """The HandAddress of "service/bus/id"; raises Error(INVALID_ARGUMENT) otherwise."""

class HandAddress:
    """A hand, unique in a DDS domain. str() is "service/bus/id"."""
    service: str
    bus: str
    can_id: int
    def __init__(self, service: str, bus: str, can_id: int) -> None: ...
    def __eq__(self, other: object) -> bool: ...
    def __lt__(self, other: HandAddress) -> bool: ...
    def __hash__(self) -> int: ...

class Reply:
    """What a call returns: always a code and, unless OK, a message that says why."""
    @property
    def ok(self) -> bool:
        """True when code is Code.OK (also the Reply's truth value)."""
    def __bool__(self) -> bool: ...
    @property
    def code(self) -> Code: ...
    @property
    def message(self) -> str: ...
    @property
    def value(self) -> int:
        """READ: the value read. GRASP: the final position. Writes: the value written."""
    @property
    def grasp(self) -> GraspOutcome:
        """GRASP: GRASPED (holding something) or MISSED (closed on nothing)."""
    @property
    def found_ids(self) -> list[int]:
        """SCAN: the CAN IDs that answered."""
    @property
    def lease_holder(self) -> str:
        """Lease commands, and commands refused because of a lease: who holds it."""

class GroupMemberReply:
    """One hand's part of a group command."""
    @property
    def ok(self) -> bool: ...
    def __bool__(self) -> bool: ...
    @property
    def hand(self) -> HandAddress: ...
    @property
    def code(self) -> Code:
        """CANCELLED: another hand of the group failed first."""
    @property
    def message(self) -> str: ...
    @property
    def value(self) -> int: ...
    @property
    def grasp(self) -> GraspOutcome: ...

class GroupReply:
    """A group command's one reply: code OK if every hand's is, else the first failed hand's."""
    @property
    def ok(self) -> bool: ...
    def __bool__(self) -> bool: ...
    @property
    def code(self) -> Code: ...
    @property
    def message(self) -> str: ...
    @property
    def hands(self) -> List[GroupMemberReply]: ...

class HandStatus:
    """The latest status the service published for a hand."""
    @property
    def address(self) -> HandAddress: ...
    @property
    def name(self) -> str: ...
    @property
    def online(self) -> bool: ...
    @property
    def initialized(self) -> bool: ...
    @property
    def grip(self) -> GripState: ...
    @property
    def position(self) -> Optional[int]:
        """None until read."""
    @property
    def target_position(self) -> Optional[int]:
        """None until written."""
    @property
    def closing_force(self) -> Optional[int]:
        """None until read."""
    @property
    def opening_force(self) -> Optional[int]:
        """None until read."""
    @property
    def rotation(self) -> Optional[int]:
        """None until read."""
    @property
    def rotation_target(self) -> Optional[int]:
        """None until written."""
    @property
    def rotation_state(self) -> RotationState: ...
    @property
    def firmware_version(self) -> int: ...
    @property
    def firmware_version_text(self) -> str: ...
    @property
    def last_error(self) -> Code: ...
    @property
    def last_error_message(self) -> str: ...
    @property
    def lease_holder(self) -> str:
        """Empty when nobody holds a lease."""
    @property
    def timestamp_ns(self) -> int: ...
    @property
    def update_seq(self) -> int:
        """Increments on every change of this hand."""
    @property
    def read_at_ns(self) -> int:
        """When the hand last answered a read whose values are in this sample, on the service's wall clock (ns since the epoch); 0 before the hand ever answered."""
    @property
    def service_lost(self) -> bool:
        """True when the client marked the hand offline because its service left unannounced."""

class HandEvent:
    """Something that happened to a hand."""
    @property
    def hand(self) -> HandAddress: ...
    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> EventKind: ...
    @property
    def position(self) -> Optional[int]:
        """ARRIVED, GRASPED, MISSED: where the fingers stopped; the rotation events: where the
        rotation stopped; None when not read yet as the event went out (the status that
        follows says it). DROPPED: where the fingers held."""
    @property
    def target(self) -> int: ...
    @property
    def value(self) -> int: ...
    @property
    def message(self) -> str: ...
    @property
    def timestamp_ns(self) -> int: ...
    @property
    def event_seq(self) -> int:
        """Per service; 0 for events the client made itself."""
    @property
    def from_client(self) -> bool:
        """True for the events the client makes itself: OFFLINE when a service disappears, ONLINE when it is back."""
    @property
    def named_value(self) -> Optional[Tuple[str, int]]:
        """What value means, named: ('closing_force', 40) for GRASPED, ('grip_status', N) for ARRIVED, MISSED, DROPPED, ('rotation_status', N) for the rotation events, ('firmware_version', raw) for ONLINE, ('unanswered_requests', N) for OFFLINE; None where it says nothing the kind and the message do not."""

class HandInfo:
    @property
    def can_id(self) -> int: ...
    @property
    def name(self) -> str: ...

class BusInfo:
    @property
    def name(self) -> str: ...
    @property
    def spec(self) -> str: ...
    @property
    def link_up(self) -> bool: ...
    @property
    def hands(self) -> list[HandInfo]: ...

class WatchTraffic:
    """What reached this client of the statuses, events and service info."""
    @property
    def statuses(self) -> int: ...
    @property
    def events(self) -> int: ...
    @property
    def infos(self) -> int: ...
    @property
    def dropped_on_arrival(self) -> int:
        """Samples of cells it does not follow that reached it and were dropped."""

class CommandTraffic:
    """What reached this client over DDS for its commands."""
    @property
    def requests_written(self) -> int: ...
    @property
    def own_replies(self) -> int:
        """Replies carrying this client's id."""
    @property
    def foreign_replies(self) -> int:
        """Replies to other clients that reached this client and were dropped."""

class ServiceInfo:
    @property
    def name(self) -> str: ...
    @property
    def version(self) -> str: ...
    @property
    def host(self) -> str: ...
    @property
    def admin_allowed(self) -> bool: ...
    @property
    def buses(self) -> list[BusInfo]: ...
    @property
    def started_ns(self) -> int: ...
    @property
    def ready(self) -> bool:
        """The service is on the domain now and calls to it go out at once."""

class Subscription:
    """Keeps a callback registered until unsubscribe(), the end of a with block, or garbage
    collection. After unsubscribe() returns the callback is not running and will not run again."""
    def unsubscribe(self) -> None: ...
    def active(self) -> bool: ...
    def __enter__(self) -> Subscription: ...
    def __exit__(self, *args: object) -> None: ...

class Hand:
    """A handle on one hand. Commands return a Reply (NAME_async: a Future of one); timeouts in
    seconds, None: the client's default_timeout."""
    @property
    def address(self) -> HandAddress: ...
    def status(self) -> Optional[HandStatus]:
        """The latest status, None until the service published one."""
    def online(self) -> bool: ...
    def wait_until(self, predicate: Callable[[HandStatus], bool],
                   timeout: Optional[float] = None) -> Optional[HandStatus]:
        """Waits until predicate(status) is true (checked at once, then on every new status);
        returns that status, None on timeout."""
    def initialize(self, timeout: Optional[float] = None) -> Reply:
        """Initializes the hand; the reply comes once initialization finished."""
    def initialize_async(self, timeout: Optional[float] = None) -> Future[Reply]: ...
    def move_to(self, position: int, timeout: Optional[float] = None) -> Reply:
        """Moves the fingers to position percent (0 closed - 100 open)."""
    def move_to_async(self, position: int, timeout: Optional[float] = None) -> Future[Reply]: ...
    def rotate_to(self, percent: int, timeout: Optional[float] = None) -> Reply:
        """Rotates to percent of 90 degrees."""
    def rotate_to_async(self, percent: int, timeout: Optional[float] = None) -> Future[Reply]: ...
    def set_force(self, closing: int, opening: Optional[int] = None,
                  timeout: Optional[float] = None) -> Reply:
        """Sets the closing force and, when given, the opening force, in percent (20-100)."""
    def set_force_async(self, closing: int, opening: Optional[int] = None,
                        timeout: Optional[float] = None) -> Future[Reply]: ...
    def grasp(self, force: int, timeout: Optional[float] = None) -> Reply:
        """Closes with force percent: reply.grasp is GRASPED or MISSED; reply.value the final
        position."""
    def grasp_async(self, force: int, timeout: Optional[float] = None) -> Future[Reply]: ...
    def release(self, position: int, timeout: Optional[float] = None) -> Reply:
        """Opens to position; the reply comes once arrived."""
    def release_async(self, position: int, timeout: Optional[float] = None) -> Future[Reply]: ...
    def stop(self, timeout: Optional[float] = None) -> Reply:
        """Holds the current position; pending motion ends CANCELLED."""
    def stop_async(self, timeout: Optional[float] = None) -> Future[Reply]: ...
    def read(self, register_code: int, timeout: Optional[float] = None) -> Reply:
        """Reads a register (dh3.reg.position, ...); reply.value is what was read."""
    def read_async(self, register_code: int,
                   timeout: Optional[float] = None) -> Future[Reply]: ...
    def set_can_id(self, can_id: int, timeout: Optional[float] = None) -> Reply:
        """Administrative (the service must allow it; the hand needs a reboot after)."""
    def set_can_id_async(self, can_id: int, timeout: Optional[float] = None) -> Future[Reply]: ...
    def set_baud_rate(self, index: int, timeout: Optional[float] = None) -> Reply:
        """Administrative: baud rate index 0 (500 kbps) - 5 (100 kbps)."""
    def set_baud_rate_async(self, index: int,
                            timeout: Optional[float] = None) -> Future[Reply]: ...
    def scan_bus(self, timeout: Optional[float] = None) -> Reply:
        """Probes this hand's whole bus for hands now; reply.found_ids lists them."""
    def scan_bus_async(self, timeout: Optional[float] = None) -> Future[Reply]: ...
    def acquire_lease(self, ttl: float, timeout: Optional[float] = None) -> Reply:
        """While this client holds a lease (ttl seconds), other clients' motion and write
        commands are DENIED. It ends on release, expiry, or when this client leaves."""
    def acquire_lease_async(self, ttl: float,
                            timeout: Optional[float] = None) -> Future[Reply]: ...
    def renew_lease(self, ttl: float, timeout: Optional[float] = None) -> Reply: ...
    def renew_lease_async(self, ttl: float,
                          timeout: Optional[float] = None) -> Future[Reply]: ...
    def release_lease(self, timeout: Optional[float] = None) -> Reply: ...
    def release_lease_async(self, timeout: Optional[float] = None) -> Future[Reply]: ...
    def subscribe(self, callback: Callable[[HandEvent], None]) -> Subscription:
        """Calls callback(event) for each event of this hand from now on, on the client's thread.
        Keep the returned Subscription: the callback ends with it."""

class Client:
    """Finds DH-3 hands on a DDS domain and drives them. Never raises on creation: check
    connected() and error()."""
    def __init__(self, *, domain: int = 0, participant_name: str = "dh3-client",
                 xml_profile_file: str = "", xml_profile: str = "",
                 interfaces: list[str] = [], udp_only: bool = False,
                 shared_memory: bool = False, discovery_servers: list[str] = [], security_dir: str = "",
                 security_identity: str = "operator", default_timeout: float = 10.0,
                 follow: str = "") -> None: ...
    def close(self) -> None:
        """Leaves the domain: pending calls end NOT_CONNECTED, callbacks stop."""
    def __enter__(self) -> Client: ...
    def __exit__(self, exc_type: Optional[type[BaseException]], exc: Optional[BaseException],
                 tb: Optional[TracebackType]) -> None: ...
    def connected(self) -> bool: ...
    def error(self) -> str: ...
    def read_only(self) -> bool: ...
    def client_id(self) -> str: ...
    def command_traffic(self) -> CommandTraffic:
        """What reached this client over DDS for its commands, since it was created."""
    def watch_traffic(self) -> WatchTraffic:
        """What reached this client of the statuses, events and service info, since it was
        created."""
    def domain(self) -> int: ...
    def default_timeout(self) -> float: ...
    def services(self) -> list[ServiceInfo]: ...
    def service(self, name: str) -> Optional[ServiceInfo]: ...
    def hands(self) -> list[HandStatus]:
        """The latest status of every hand seen."""
    def status(self, address: HandAddress) -> Optional[HandStatus]: ...
    def wait_for_service(self, name: str = "", timeout: Optional[float] = None) -> ServiceInfo:
        """Waits until the named service (empty: any) is ready; Error(NO_SERVICE) on timeout."""
    def wait_for_statuses(self, timeout: Optional[float] = None) -> bool: ...
    def hand(self, address: HandAddress) -> Hand:
        """A hand by address; no lookup, no waiting."""
    def find_hand(self, spec: str) -> Hand:
        """A hand by "SERVICE/BUS/ID", "BUS/ID", "ID" or name among those known now."""
    def wait_for_hand(self, spec: str, timeout: Optional[float] = None) -> Hand:
        """Waits until spec names exactly one hand; raises Error (NO_SERVICE, UNKNOWN_HAND,
        INVALID_ARGUMENT) otherwise."""
    def scan(self, service: str, bus: str, timeout: Optional[float] = None) -> Reply: ...
    def scan_async(self, service: str, bus: str,
                   timeout: Optional[float] = None) -> Future[Reply]: ...
    def group(self, command: GroupCommand, hands: List[HandAddress], value: int = 0,
              timeout: Optional[float] = None) -> GroupReply:
        """One command to several hands of one service, together and all or none."""
    def group_async(self, command: GroupCommand, hands: List[HandAddress], value: int = 0,
                    timeout: Optional[float] = None) -> Future[GroupReply]: ...
    def subscribe(self, callback: Callable[[HandEvent], None],
                  only: Optional[HandAddress] = None) -> Subscription: ...
    def subscribe_status(self, callback: Callable[[HandStatus], None],
                         only: Optional[HandAddress] = None) -> Subscription: ...
