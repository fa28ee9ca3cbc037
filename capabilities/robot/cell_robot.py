"""The ``robot`` block of a cell file: the simulated arm, or a UR controller at a host.

A cell file (``*.cell.json``, see ``resources/schemas/cell.schema.json``) describes one cell;
its ``robot`` block says what moves: ``{"kind": "sim"}`` (the pybullet cell, the default) or

    {"kind": "ur", "host": "192.168.1.10", "model": "UR5e",
     "payload": {"mass": 1.2, "center_of_gravity": [0, 0, 0.05]},
     "tool": {"kind": "suction", "vacuum": "tool 0", "sensor": "standard 1"},
     (or "tool": {"kind": "robotiq"})
     "inputs": {"pedal": "standard 0"}}

The simulated arm's block may set its safety limits, as a UR's safety configuration does on
the controller: ``{"kind": "sim", "force_limit": 150, "unlock_delay": 5}`` (a contact above
``force_limit`` N with a fixture is a protective stop, which cannot be unlocked earlier than
``unlock_delay`` s after it happened).

The mounting is the file's ``robot_base`` and the TCP its ``tcp_offsets`` entry for the tool.
Nothing here talks to a robot: this is the file's meaning only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from engine.json_reader import JsonReader

__all__ = ["DigitalPinName", "Payload", "RobotSettings", "ToolSettings", "read_robot"]

ROBOT_KINDS = ("sim", "ur")
UR_MODELS = ("UR5 CB3", "UR5e")  # CB3 controllers run PolyScope 3, e-Series PolyScope 5
UR_TOOL_KINDS = ("suction", "robotiq")
TCP_OF_TOOL = {"suction": "suction", "robotiq": "gripper"}  # the tool's tcp_offsets entry
INPUT_ROLES = ("pedal",)
_BANKS = {"standard": 8, "configurable": 8, "tool": 2}
# A UR's default safety configuration: 150 N force limit (normal mode), and PolyScope refuses
# to unlock a protective stop earlier than 5 s after it happened.
FORCE_LIMIT = 150.0  # N
UNLOCK_DELAY = 5.0  # s

DigitalPinName = tuple[str, int]  # (bank, index): ("tool", 0)


@dataclass(frozen=True)
class Payload:
    """What the arm carries beyond its flange: mass (kg), centre of gravity (m, flange frame)."""

    mass: float = 0.0
    center_of_gravity: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class ToolSettings:
    """The tool on the flange and the digital pins that drive it.

    Attributes:
        kind: "suction" (a vacuum cup switched by a digital output) or "robotiq" (a Robotiq
            gripper through its URCap's socket on the controller, port 63352).
        vacuum: the output that switches the vacuum (suction).
        sensor: the input that reads "part held" (None: the vacuum state stands in for it).
    """

    kind: str = "suction"
    vacuum: DigitalPinName = ("tool", 0)
    sensor: DigitalPinName | None = None


@dataclass(frozen=True)
class RobotSettings:
    """The ``robot`` block.

    Attributes:
        kind: "sim" or "ur".
        host: the UR controller's address ("" for the simulated cell).
        model: "UR5 CB3" or "UR5e".
        payload: the payload set on the controller.
        tool: the tool on the flange.
        inputs: digital inputs by role ("pedal": the collaboration capability's foot pedal).
        force_limit: (simulated arm) the contact force (N) with a fixture, the table or a
            machine above which the arm makes a protective stop.
        unlock_delay: (simulated arm) seconds after a protective stop before it can be
            unlocked. A UR controller has both in its own safety configuration.
    """

    kind: str = "sim"
    host: str = ""
    model: str = "UR5e"
    payload: Payload = Payload()
    tool: ToolSettings = ToolSettings()
    inputs: dict[str, DigitalPinName] = field(default_factory=dict)
    force_limit: float = FORCE_LIMIT
    unlock_delay: float = UNLOCK_DELAY

    def to_json(self) -> dict[str, object]:
        """The JSON form (what :func:`read_robot` reads)."""
        if self.kind == "sim":
            limits = {"force_limit": self.force_limit, "unlock_delay": self.unlock_delay}
            if (self.force_limit, self.unlock_delay) == (FORCE_LIMIT, UNLOCK_DELAY):
                limits = {}
            return {"kind": "sim", **limits}
        tool: dict[str, object] = {"kind": self.tool.kind, "vacuum": _pin_text(self.tool.vacuum)}
        if self.tool.sensor is not None:
            tool["sensor"] = _pin_text(self.tool.sensor)
        return {
            "kind": self.kind,
            "host": self.host,
            "model": self.model,
            "payload": {
                "mass": self.payload.mass,
                "center_of_gravity": list(self.payload.center_of_gravity),
            },
            "tool": tool,
            "inputs": {role: _pin_text(pin) for role, pin in self.inputs.items()},
        }


def _pin_text(pin: DigitalPinName) -> str:
    return f"{pin[0]} {pin[1]}"


def _pin(r: JsonReader) -> DigitalPinName:
    """A digital pin written "bank index": "tool 0", "standard 3", "configurable 7"."""
    words = r.as_text().split()
    expected = 'a digital pin: "standard 0-7", "configurable 0-7" or "tool 0-1"'
    if len(words) != 2 or words[0] not in _BANKS or not words[1].isdigit():
        r.fail(expected)
    bank, index = words[0], int(words[1])
    if index >= _BANKS[bank]:
        r.fail(expected)
    return bank, index


def read_robot(r: JsonReader) -> RobotSettings:
    """Read the ``robot`` block of a cell file (``r`` reads the whole file).

    Raises:
        JsonFileError: a field is off; the message names the file and JSON path.
    """
    if not r.has("robot"):
        return RobotSettings()
    ur_fields = ("kind", "host", "model", "payload", "tool", "inputs")
    block = r.child("robot", (*ur_fields, "force_limit", "unlock_delay"), ("kind",))
    kind = block.choice("kind", ROBOT_KINDS)
    if kind == "sim":
        block.as_object(("kind", "force_limit", "unlock_delay"))
        return RobotSettings(
            force_limit=block.number("force_limit", FORCE_LIMIT, lo=0.0, above=True),
            unlock_delay=block.number("unlock_delay", UNLOCK_DELAY, lo=0.0),
        )
    block.as_object(ur_fields)  # a UR's limits are in its own safety configuration
    host = block.text("host", nonempty=True)
    payload = block.child("payload", ("mass", "center_of_gravity"))
    tool = block.child("tool", ("kind", "vacuum", "sensor"))
    inputs = block.child("inputs", INPUT_ROLES)
    return RobotSettings(
        kind=kind,
        host=host,
        model=block.choice("model", UR_MODELS, "UR5e"),
        payload=Payload(
            payload.number("mass", 0.0, lo=0.0, hi=5.0),  # a UR5 carries 5 kg at most
            payload.vector3("center_of_gravity", (0.0, 0.0, 0.0)),
        ),
        tool=ToolSettings(
            tool.choice("kind", UR_TOOL_KINDS, "suction"),
            _pin(tool.at("vacuum")) if tool.has("vacuum") else ("tool", 0),
            _pin(tool.at("sensor")) if tool.has("sensor") else None,
        ),
        inputs={role: _pin(inputs.at(role)) for role in inputs.as_object()},
    )
