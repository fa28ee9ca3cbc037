"""Fixed values as the text of an XML attribute, one documented form per type, exact.

BehaviorTree.CPP passes port values as text and converts them where they are read; the
forms below follow its conventions (numbers as text, ``;`` between the parts of a
composite value, ``json:`` before JSON, never ``{...}``, which is a blackboard reference) and give back the very same value when read (floats as Python's
shortest round-trip ``repr``):

=============  =====================================================  =====================
type           form                                                   example
=============  =====================================================  =====================
Number         a decimal number                                       ``0.25``
Duration       seconds, a decimal number                              ``1.5``
Text           the text itself                                        ``cup``
Bool           ``true`` or ``false`` (reading also takes 1/0/True...)   ``true``
ObjectModel    the object's name                                      ``plate_4``
Pose           ``x;y;z;qx;qy;qz;qw`` (m, unit quaternion)             ``0.4;0.1;0.02;0.0;1.0;0.0;0.0``
JointConfig    the joint angles in rad, ``;`` between them            ``0.0;-1.57;1.57;0.0;1.57;0.0``
Region         ``cx;cy;cz;radius`` (m)                                ``0.5;0.0;0.1;0.2``
Waypoint       ``json:`` and its JSON object, as in a plan file           ``json:{"name":"above",...}``
Any            ``json:`` and its JSON, as in a plan file                  ``json:[1,2]``
=============  =====================================================  =====================

The type a port's value has is in the file's TreeNodesModel (``type`` of the port, see
:data:`MODEL_TYPE`), or, where a port takes several types, on the node (``_types``).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable
from typing import Any

from engine.types import ParamType, ValueShapeError, decode_value, encode_value

__all__ = [
    "MODEL_TYPE",
    "param_type_of_model",
    "parse_value",
    "untyped_constant",
    "untyped_text",
    "value_text",
]

# The type names our ports have in a TreeNodesModel: C++'s where one fits, so that Groot2
# and BehaviorTree.CPP show familiar ones, our own names in a ``costar::`` namespace else.
MODEL_TYPE: dict[ParamType, str] = {
    ParamType.NUMBER: "double",
    ParamType.TEXT: "std::string",
    ParamType.BOOL: "bool",
    ParamType.DURATION: "costar::Duration",
    ParamType.POSE: "costar::Pose",
    ParamType.JOINTS: "costar::JointConfig",
    ParamType.OBJECT: "costar::ObjectModel",
    ParamType.REGION: "costar::Region",
    ParamType.WAYPOINT: "costar::Waypoint",
    ParamType.ANY: "BT::Any",
}
# Types BehaviorTree.CPP's own models name (demangled C++), read as ours.
_CPP_TYPES: dict[str, ParamType] = {
    **{name: ParamType.NUMBER for name in ("float", "int", "unsigned int", "long", "long long")},
    **{name: ParamType.NUMBER for name in ("unsigned long", "short", "unsigned short")},
    "std::chrono::milliseconds": ParamType.NUMBER,
    "BT::AnyTypeAllowed": ParamType.ANY,
    "std::__cxx11::basic_string<char, std::char_traits<char>, std::allocator<char> >": (
        ParamType.TEXT
    ),
    "BT::StringView": ParamType.TEXT,
    "std::string_view": ParamType.TEXT,
}
_JSON = "json:"  # BehaviorTree.CPP's own prefix of a value given as JSON
_BOOLS = {"true": True, "false": False, "True": True, "False": False, "1": True, "0": False}
_BOOLS |= {"TRUE": True, "FALSE": False}


def param_type_of_model(type_name: str | None) -> ParamType:
    """Our type of a TreeNodesModel port type (ours, or a C++ one); Text when unknown or
    absent (BehaviorTree.CPP hands untyped ports their text).
    """
    if not type_name:
        return ParamType.TEXT
    for ptype, name in MODEL_TYPE.items():
        if name == type_name:
            return ptype
    if type_name in _CPP_TYPES:
        return _CPP_TYPES[type_name]
    return ParamType.ANY if type_name.startswith(("BT::Any", "nlohmann::")) else ParamType.TEXT


def _numbers(values: tuple[float, ...]) -> str:
    if not all(math.isfinite(v) for v in values):
        raise ValueError(f"finite numbers, not {values}")
    return ";".join(repr(float(v)) for v in values)


def value_text(ptype: ParamType, value: Any) -> str:
    """The text form of a fixed value of type ``ptype`` (see the module doc).

    Raises:
        ValueError: the value holds a number that is not finite.
    """
    ptype = ParamType(ptype)
    numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
    if ptype in (ParamType.NUMBER, ParamType.DURATION) and numeric:
        return _numbers((float(value),))
    if ptype is ParamType.BOOL and isinstance(value, bool):
        return "true" if value else "false"
    if ptype is ParamType.TEXT and isinstance(value, str):
        return value
    encoded = encode_value(value)
    if ptype is ParamType.OBJECT and isinstance(encoded, str):
        return encoded
    if ptype is ParamType.POSE and isinstance(encoded, dict):
        return _numbers((*encoded["position"], *encoded["orientation"]))
    if ptype is ParamType.JOINTS and isinstance(encoded, list):
        return _numbers(tuple(encoded))
    if ptype is ParamType.REGION and isinstance(encoded, dict):
        return _numbers((*encoded["center"], encoded["radius"]))
    return _JSON + json.dumps(encoded, ensure_ascii=False, separators=(",", ":"), allow_nan=False)


def _split(text: str, count: int | None, what: str) -> list[float]:
    parts = text.split(";")
    try:
        numbers = [float(p) for p in parts]
    except ValueError:
        numbers = []
    if not numbers or (count is not None and len(numbers) != count):
        raise ValueError(f"{what}, not {text!r}")
    if not all(math.isfinite(n) for n in numbers):
        raise ValueError(f"finite numbers ({what}), not {text!r}")
    return numbers


def _pose(text: str) -> Any:
    n = _split(text, 7, "a pose x;y;z;qx;qy;qz;qw")
    return {"position": n[:3], "orientation": n[3:]}


def _region(text: str) -> Any:
    n = _split(text, 4, "a region cx;cy;cz;radius")
    return {"center": n[:3], "radius": n[3]}


def _no_constant(name: str) -> Any:
    raise ValueError(name)  # NaN and Infinity: a plan holds finite numbers only


def _json(text: str) -> Any:
    if not text.startswith(_JSON):
        raise ValueError(f"{_JSON} and a JSON value, not {text!r}")
    try:
        return json.loads(text[len(_JSON) :], parse_constant=_no_constant)
    except ValueError:
        raise ValueError(f"a JSON value, not {text!r}") from None


def _number(text: str) -> Any:
    return _split(text, 1, "a number")[0]


def _bool(text: str) -> Any:
    if text not in _BOOLS:
        raise ValueError(f"true or false, not {text!r}")
    return _BOOLS[text]


_PARSERS: dict[ParamType, Callable[[str], Any]] = {
    ParamType.NUMBER: _number,
    ParamType.DURATION: _number,
    ParamType.TEXT: lambda text: text,
    ParamType.BOOL: _bool,
    ParamType.OBJECT: lambda text: text,
    ParamType.POSE: _pose,
    ParamType.JOINTS: lambda text: _split(text, None, "joint angles a;b;c;..."),
    ParamType.REGION: _region,
    ParamType.WAYPOINT: _json,
    ParamType.ANY: _json,
}


def parse_value(ptype: ParamType, text: str) -> Any:
    """The value of type ``ptype`` that :func:`value_text` wrote as ``text``.

    Raises:
        ValueError: the text is not of that form; the message says what was expected.
    """
    ptype = ParamType(ptype)
    raw = _PARSERS[ptype](text)
    try:
        return decode_value(ptype, raw, "value")
    except ValueShapeError as exc:
        raise ValueError(f"{exc.expected} ({ptype.value}), not {text!r}") from None


_INT_TEXT = re.compile(r"[+-]?\d+")


def untyped_constant(text: str) -> object:
    """A constant given to an untyped SubTree port, as BehaviorTree.CPP stores it in the
    subtree's blackboard: an integer when the whole text is one, else a real, else the text.
    """
    if _INT_TEXT.fullmatch(text):
        return int(text)
    if "." in text or "e" in text or "E" in text:
        try:
            number = float(text)
        except ValueError:
            return text
        return number if math.isfinite(number) else text
    return text


def untyped_text(value: Any) -> str | None:
    """The text of a value for an untyped SubTree port that :func:`untyped_constant` reads
    back as the same value (None: the value needs ``json:``).
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        return None
    text = value if isinstance(value, str) else repr(value)
    again = untyped_constant(text)
    return text if type(again) is type(value) and again == value else None
