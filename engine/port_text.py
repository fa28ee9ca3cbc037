"""Ports that BehaviorTree.CPP's built-in nodes read as text, ``{key}`` naming an entry.

A Switch's ``variable``, a SetBlackboard's ``value`` and ``output_key``, an UnsetBlackboard's
``key``: these settings keep their text as it is written in the file, and the node reads an
entry when the text is ``{key}`` (spaces inside the braces trimmed, ``@key`` at the top), as
BehaviorTree.CPP's ``getInput<std::string>`` does on every tick.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from engine.blackboard import MISSING
from engine.script.values import ScriptEnv, text_of

__all__ = ["braced", "port_text", "same_text"]

_INT_TEXT = re.compile(r"-?\d+")
_REAL_TEXT = re.compile(r"-?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?|-?(inf|infinity|nan)", re.I)
_FLOAT_EPSILON = 1.1920928955078125e-07  # std::numeric_limits<float>::epsilon()


def braced(text: str) -> str | None:
    """The entry ``{key}`` names (trimmed), or None when the text is a plain value."""
    stripped = text.strip()
    if len(stripped) >= 2 and stripped[0] == "{" and stripped[-1] == "}":
        return stripped[1:-1].strip()
    return None


def port_text(text: str, env: ScriptEnv) -> str | None:
    """The port's value as text: the entry's value for ``{key}`` (None when it has none),
    else the text itself.
    """
    name = braced(text)
    if name is None:
        return text
    value: Any = env.blackboard.get(env.key_of(name), MISSING)
    return None if value is MISSING else text_of(value)


def same_text(first: str, second: str, enums: Mapping[str, int] | None = None) -> bool:
    """BehaviorTree.CPP's Switch comparison: equal texts, or equal integers, or reals within
    a float's epsilon (an enum's name reads as its value).
    """
    if first == second:
        return True
    a, b = _integer(first, enums), _integer(second, enums)
    if a is not None and b is not None and a == b:
        return True
    x, y = _real(first, enums), _real(second, enums)
    return x is not None and y is not None and abs(x - y) <= _FLOAT_EPSILON


def _integer(text: str, enums: Mapping[str, int] | None) -> int | None:
    if enums and text in enums:
        return enums[text]
    return int(text) if _INT_TEXT.fullmatch(text) else None


def _real(text: str, enums: Mapping[str, int] | None) -> float | None:
    if enums and text in enums:
        return float(enums[text])
    return float(text) if _REAL_TEXT.fullmatch(text) else None
