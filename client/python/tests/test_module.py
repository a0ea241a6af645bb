"""The module itself, without a service: names, enums, stubs, argument checks."""

import ast
import inspect
import os

import pytest

import dh3
from conftest import DOMAIN


@pytest.mark.parametrize("enum", [dh3.Code, dh3.GraspOutcome, dh3.GripState,
                                  dh3.RotationState, dh3.EventKind])
def test_enums_are_python_enums_spelled_like_libdh3client(enum):
    import enum as std_enum
    assert issubclass(enum, std_enum.IntEnum)
    for member in enum:
        assert dh3._dh3._to_string(enum.__name__, int(member)) == member.name
        assert str(member) == member.name
    # One past the last member is outside the C++ enum too.
    past = max(enum) + 1
    assert dh3._dh3._to_string(enum.__name__, int(past)) != "", enum


def test_code_to_string():
    assert dh3._dh3.to_string(dh3.Code.SERVICE_LOST) == "SERVICE_LOST"


def test_registers():
    assert dh3.reg.position == 0x0602
    assert dh3.reg.firmware_version == 0x1301
    assert dh3.register_name(dh3.reg.closing_force) == "closing_force"
    assert dh3.parse_register("grip-status") == dh3.reg.grip_status
    assert dh3.parse_register("0x0602") == 0x0602
    assert dh3.parse_register("nonsense") is None
    assert dh3.firmware_version_text(0x04010200) == "4.1.2.0"


def test_hand_address():
    address = dh3.HandAddress("cell", "bus0", 3)
    assert str(address) == "cell/bus0/3"
    assert address == dh3.parse_hand_address("cell/bus0/3")
    assert address != dh3.HandAddress("cell", "bus0", 4)
    assert len({address, dh3.HandAddress("cell", "bus0", 3)}) == 1
    assert dh3.HandAddress("a", "b", 1) < dh3.HandAddress("b", "a", 0)
    with pytest.raises(dh3.Error) as error:
        dh3.parse_hand_address("bus0/3")
    assert error.value.code == dh3.Code.INVALID_ARGUMENT


def test_bad_timeouts_raise_value_error():
    with pytest.raises(ValueError):
        dh3.Client(domain=DOMAIN, default_timeout=-1.0)
    with dh3.Client(domain=DOMAIN) as client:
        hand = client.hand(dh3.HandAddress("nobody", "bus0", 1))
        with pytest.raises(ValueError):
            hand.move_to(10, timeout=float("nan"))
        with pytest.raises(ValueError):
            hand.acquire_lease(-5.0)


def test_options_are_keywords_and_a_bad_domain_is_reported_not_raised():
    with dh3.Client(domain=DOMAIN, participant_name="pytest", udp_only=True,
                    interfaces=["127.0.0.1"], default_timeout=2.5) as client:
        assert client.connected(), client.error()
        assert client.domain() == DOMAIN
        assert client.default_timeout() == 2.5
        assert client.client_id() != ""
        assert not client.read_only()
    with pytest.raises(TypeError):
        dh3.Client(DOMAIN)  # keywords only
    bad = dh3.Client(domain=999)
    assert not bad.connected()
    assert bad.error() != ""


def test_a_closed_client_answers_not_connected():
    client = dh3.Client(domain=DOMAIN)
    hand = client.hand(dh3.HandAddress("nobody", "bus0", 1))
    client.close()
    assert not client.connected()
    assert hand.initialize().code == dh3.Code.NOT_CONNECTED
    with pytest.raises(dh3.Error) as error:
        client.hands()
    assert error.value.code == dh3.Code.NOT_CONNECTED


def _stub_tree():
    path = os.path.join(os.path.dirname(dh3.__file__), "__init__.pyi")
    with open(path) as f:
        return ast.parse(f.read())


def _check_property_type(cls, class_name, name, stub):
    """A property the module may give None for is Optional in the stubs, and
    only such a one: pybind11's getter says "-> Optional[...]"."""
    doc = getattr(cls, name).fget.__doc__ or ""
    if not doc.startswith("("):
        return  # defined in Python, no signature to compare
    module_optional = "-> Optional[" in doc.split("\n", 1)[0]
    stub_optional = stub.returns is not None and ast.unparse(stub.returns).startswith("Optional[")
    assert module_optional == stub_optional, \
        f"{class_name}.{name}: the module says {doc.strip()}, the stubs {ast.unparse(stub.returns)}"


def test_the_stubs_describe_the_module():
    """Every public name and method of the module is in __init__.pyi and the
    other way round, with the same parameter names."""
    tree = _stub_tree()
    stub_names = {node.name for node in tree.body
                  if isinstance(node, (ast.ClassDef, ast.FunctionDef))}
    assert set(dh3.__all__) <= stub_names
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            assert hasattr(dh3, node.name), node.name
        if not isinstance(node, ast.ClassDef) or node.name.startswith("_"):
            continue
        cls = getattr(dh3, node.name)
        stub_members = {n.name: n for n in node.body if isinstance(n, ast.FunctionDef)}
        stub_members.update({n.target.id: n for n in node.body
                             if isinstance(n, ast.AnnAssign)})
        stub_members.update({t.id: n for n in node.body if isinstance(n, ast.Assign)
                             for t in n.targets})
        public = {name for name in dir(cls) if not name.startswith("_")}
        if isinstance(cls, type) and issubclass(cls, BaseException):
            public = {"code", "message"}
        if node.name in ("Code", "GraspOutcome", "GroupCommand", "GripState", "RotationState",
                         "EventKind"):
            public = set(cls.__members__)
        if node.name == "reg":
            public = {name for name in dir(dh3.reg) if not name.startswith("_")}
        missing = public - set(stub_members)
        extra = {name for name in stub_members if not name.startswith("_")} - public
        assert not missing, f"{node.name}: not in the stubs: {sorted(missing)}"
        assert not extra, f"{node.name}: only in the stubs: {sorted(extra)}"
        for name, member in stub_members.items():
            if not isinstance(member, ast.FunctionDef) or name.startswith("_"):
                continue
            if any(isinstance(d, ast.Name) and d.id == "property" for d in member.decorator_list):
                _check_property_type(cls, node.name, name, member)
                continue
            stub_params = [a.arg for a in member.args.args + member.args.kwonlyargs][1:]
            doc = getattr(cls, name).__doc__ or ""
            # pybind11 docstrings start with the signature: "name(self: ..., a: int, ...)".
            signature = doc.split("\n", 1)[0]
            for param in stub_params:
                assert f"{param}:" in signature, f"{node.name}.{name}: {param} not in {signature}"


def test_values_not_read_are_none_in_the_stubs():
    """HandStatus gives None, never -1, for what the hand has not reported yet."""
    stub = next(node for node in _stub_tree().body
                if isinstance(node, ast.ClassDef) and node.name == "HandStatus")
    returns = {n.name: ast.unparse(n.returns) for n in stub.body if isinstance(n, ast.FunctionDef)}
    for name in ("position", "target_position", "closing_force", "opening_force", "rotation",
                 "rotation_target"):
        assert returns[name] == "Optional[int]", name
        assert "None until" in getattr(dh3.HandStatus, name).__doc__, name


def test_docstrings_come_with_the_module():
    assert "percent" in dh3.Hand.move_to.__doc__
    assert "GRASPED" in dh3.Hand.grasp.__doc__
    assert "UNKNOWN_HAND" in dh3.Client.wait_for_hand.__doc__
    assert inspect.getdoc(dh3.Reply.value)


def test_close_ends_a_wait_in_another_thread():
    import threading
    client = dh3.Client(domain=DOMAIN, default_timeout=60.0)
    outcome = {}
    started = threading.Event()

    def wait():
        started.set()
        try:
            client.wait_for_hand("nobody-here/bus0/1", timeout=60.0)
        except dh3.Error as error:
            outcome["code"] = error.code

    thread = threading.Thread(target=wait)
    thread.start()
    started.wait()
    client.close()
    thread.join(timeout=30)
    assert not thread.is_alive()
    # Closed while it waited (NOT_CONNECTED), or before it began (the same).
    assert outcome["code"] == dh3.Code.NOT_CONNECTED


HEADER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "include", "dh3",
                      "client.hpp")


def _cpp_block(text, start):
    """The text of a C++ class or struct from `start` to its closing "};"."""
    begin = text.index(start)
    return text[begin:text.index("\n};", begin)]


def test_every_client_option_is_a_keyword():
    import re
    with open(HEADER) as f:
        options = _cpp_block(f.read(), "struct ClientOptions {")
    fields = re.findall(r"^\s+[\w:<>, ]+?\s(\w+)(?:\s*=[^;]*|\{[^}]*\})?;", options, re.M)
    assert "domain" in fields and "default_timeout" in fields, fields
    signature = dh3.Client.__init__.__doc__.split("\n", 1)[0]
    for field in fields:
        assert f"{field}:" in signature, field


def test_every_hand_and_client_command_has_both_forms():
    import re
    with open(HEADER) as f:
        text = f.read()
    hand = _cpp_block(text, "class DH3_CLIENT_API Hand {")
    client = _cpp_block(text, "class DH3_CLIENT_API Client {")
    hand_commands = re.findall(r"^\s+Reply (\w+)\(", hand, re.M)
    client_commands = re.findall(r"^\s+Reply (\w+)\(", client, re.M)
    assert "grasp" in hand_commands and "scan" in client_commands
    for name in hand_commands:
        assert hasattr(dh3.Hand, name) and hasattr(dh3.Hand, name + "_async"), name
    for name in client_commands:
        assert hasattr(dh3.Client, name) and hasattr(dh3.Client, name + "_async"), name
    for name in re.findall(r"^\s+(?:\[\[nodiscard\]\] )?[\w:<>, ]+ (\w+)\([^)]*\)(?: const)?;",
                           client, re.M):
        assert name == "Client" or hasattr(dh3.Client, name), name
