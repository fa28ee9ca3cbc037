"""The RTDE wire format as the emulator speaks it (protocol version 2).

A message is a header (uint16 size including the header, uint8 type) and a payload; numbers are
big-endian. Recipes name RTDE fields; their types come from :data:`OUTPUT_TYPES` and
:func:`input_type`.
"""

from __future__ import annotations

import re
import struct

from capabilities.ur_emulator.errors import EmulatorError

__all__ = [
    "DATA_PACKAGE",
    "GET_URCONTROL_VERSION",
    "PAUSE",
    "REQUEST_PROTOCOL_VERSION",
    "SETUP_INPUTS",
    "SETUP_OUTPUTS",
    "START",
    "TEXT_MESSAGE",
    "FORMATS",
    "input_type",
    "output_type",
    "pack_message",
    "recipe_format",
    "width",
]

REQUEST_PROTOCOL_VERSION = ord("V")
GET_URCONTROL_VERSION = ord("v")
TEXT_MESSAGE = ord("M")
DATA_PACKAGE = ord("U")
SETUP_OUTPUTS = ord("O")
SETUP_INPUTS = ord("I")
START = ord("S")
PAUSE = ord("P")

# RTDE type name -> struct format (big-endian, no prefix).
FORMATS: dict[str, str] = {
    "BOOL": "?",
    "UINT8": "B",
    "UINT32": "I",
    "UINT64": "Q",
    "INT32": "i",
    "DOUBLE": "d",
    "VECTOR3D": "3d",
    "VECTOR6D": "6d",
    "VECTOR6INT32": "6i",
    "VECTOR6UINT32": "6I",
}

_V6 = "VECTOR6D"
OUTPUT_TYPES: dict[str, str] = {
    "timestamp": "DOUBLE",
    **{
        name: _V6
        for name in [
            "target_q",
            "target_qd",
            "target_qdd",
            "target_current",
            "target_moment",
            "actual_q",
            "actual_qd",
            "actual_qdd",
            "actual_current",
            "actual_moment",
            "joint_control_output",
            "actual_TCP_pose",
            "actual_TCP_speed",
            "actual_TCP_force",
            "target_TCP_pose",
            "target_TCP_speed",
            "joint_temperatures",
            "actual_joint_voltage",
            "ft_raw_wrench",
            "payload_inertia",
            "actual_tool_flange_pose",
            "tcp_offset",
        ]
    },
    "actual_digital_input_bits": "UINT64",
    "actual_digital_output_bits": "UINT64",
    "actual_execution_time": "DOUBLE",
    "robot_mode": "INT32",
    "joint_mode": "VECTOR6INT32",
    "safety_mode": "INT32",
    "safety_status": "INT32",
    "actual_tool_accelerometer": "VECTOR3D",
    "payload_cog": "VECTOR3D",
    "elbow_position": "VECTOR3D",
    "elbow_velocity": "VECTOR3D",
    "speed_scaling": "DOUBLE",
    "target_speed_fraction": "DOUBLE",
    "actual_momentum": "DOUBLE",
    "actual_main_voltage": "DOUBLE",
    "actual_robot_voltage": "DOUBLE",
    "actual_robot_current": "DOUBLE",
    "runtime_state": "UINT32",
    "robot_status_bits": "UINT32",
    "safety_status_bits": "UINT32",
    "standard_analog_input0": "DOUBLE",
    "standard_analog_input1": "DOUBLE",
    "standard_analog_output0": "DOUBLE",
    "standard_analog_output1": "DOUBLE",
    "payload": "DOUBLE",
    "output_bit_registers0_to_31": "UINT32",
    "output_bit_registers32_to_63": "UINT32",
    "tool_output_voltage": "INT32",
    "tool_analog_input0": "DOUBLE",
    "tool_analog_input1": "DOUBLE",
}

_INPUT_TYPES: dict[str, str] = {
    "standard_digital_output_mask": "UINT8",
    "standard_digital_output": "UINT8",
    "configurable_digital_output_mask": "UINT8",
    "configurable_digital_output": "UINT8",
    "tool_digital_output_mask": "UINT8",
    "tool_digital_output": "UINT8",
    "speed_slider_mask": "UINT32",
    "speed_slider_fraction": "DOUBLE",
    "standard_analog_output_mask": "UINT8",
    "standard_analog_output_type": "UINT8",
    "standard_analog_output_0": "DOUBLE",
    "standard_analog_output_1": "DOUBLE",
    "input_bit_registers0_to_31": "UINT32",
    "input_bit_registers32_to_63": "UINT32",
    "external_force_torque": "VECTOR6D",
}

_REGISTER = re.compile(r"^(input|output)_(int|double|bit)_register_(\d+)$")
_REGISTER_TYPES = {"int": "INT32", "double": "DOUBLE", "bit": "BOOL"}


def _register_type(name: str, direction: str) -> str | None:
    match = _REGISTER.match(name)
    if match is None or match.group(1) != direction:
        return None
    index = int(match.group(3))
    kind = match.group(2)
    limit = 128 if kind == "bit" else 48
    if kind == "bit" and index < 64:
        return None  # bits 0-63 are the *_bit_registers0_to_31 / 32_to_63 words
    return _REGISTER_TYPES[kind] if index < limit else None


def output_type(name: str) -> str:
    """The RTDE type of an output field, or ``NOT_FOUND`` as a controller answers."""
    return OUTPUT_TYPES.get(name) or _register_type(name, "output") or "NOT_FOUND"


def input_type(name: str) -> str:
    """The RTDE type of an input field, or ``NOT_FOUND``."""
    return _INPUT_TYPES.get(name) or _register_type(name, "input") or "NOT_FOUND"


def pack_message(kind: int, payload: bytes = b"") -> bytes:
    """One RTDE message: the header and ``payload``."""
    size = 3 + len(payload)
    if size > 0xFFFF:
        raise EmulatorError(f"RTDE message of {size} bytes is too long")
    return struct.pack(">HB", size, kind) + payload


def width(kind: str) -> int:
    """How many numbers a value of an RTDE type has (3 or 6 for vectors, else 1)."""
    fmt = FORMATS[kind]
    return int(fmt[0]) if fmt[0].isdigit() else 1


def recipe_format(types: list[str]) -> str:
    """The struct format of a recipe's values (big-endian)."""
    return ">" + "".join(FORMATS[t] for t in types)
