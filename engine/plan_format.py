"""The plan file format's shared pieces: its constants, its error, and JSON-path helpers."""

from __future__ import annotations

import json
import re
import types
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from engine.errors import EngineError

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "KIND_ALIASES",
    "MAX_TREE_DEPTH",
    "PLAN_SUFFIX",
    "READABLE_VERSIONS",
    "PlanFileError",
    "at",
    "describe",
]

FORMAT = "costar-plan"
# 2: the settings of logic nodes are typed port bindings in "params" (1: a "config" object);
# the operation timing.wait is the Wait node.
FORMAT_VERSION = 2
READABLE_VERSIONS: tuple[int, ...] = (1, 2)
PLAN_SUFFIX = ".costar.json"
# Python's JSON reader and writer recurse about twice per tree level; 400 levels stay well
# inside the default recursion limit of 1000 even when called from a deep GUI stack.
MAX_TREE_DEPTH = 400

KIND_ALIASES: Mapping[str, str] = types.MappingProxyType(
    {"fallback": "selector", "reactive_fallback": "reactive_selector"}
)

TOP_FIELDS: tuple[str, ...] = ("format", "format_version", "id", "name", "description")
TOP_FIELDS += ("run_policy", "reset_cell", "parameters", "tree", "waypoints", "objects", "layout")
NODE_FIELDS = ("id", "kind", "name", "op", "params", "children")
NODE_FIELDS_V1 = ("id", "kind", "name", "op", "params", "config", "children")
IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


class PlanFileError(EngineError):
    """A plan file that cannot be read or written, with where and what was expected.

    Attributes:
        file: the file as given (``"<string>"`` for text).
        json_path: where in the document (``$.tree.children[1].params.target``); empty when
            the problem is the file as a whole.
        expected: what should have been there.
        got: what was there.
        line: line of a JSON syntax error (1-based), else None.
        column: column of a JSON syntax error (1-based), else None.
    """

    def __init__(
        self,
        file: str,
        json_path: str,
        expected: str,
        got: str,
        line: int | None = None,
        column: int | None = None,
    ) -> None:
        self.file = file
        self.json_path = json_path
        self.expected = expected
        self.got = got
        self.line = line
        self.column = column
        where = [Path(file).name or file]
        if line is not None:
            where.append(f"line {line} column {column}")
        if json_path:
            where.append(json_path)
        super().__init__(f"{': '.join(where)}: expected {expected}, got {got}")


def describe(value: Any) -> str:
    """A short plain description of a JSON value for error messages."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return f"the number {value!r}"
    if isinstance(value, str):
        text = value if len(value) <= 40 else value[:37] + "..."
        return f"the text {text!r}"
    if isinstance(value, list):
        return f"a list of {len(value)} item{'' if len(value) == 1 else 's'}"
    if isinstance(value, dict):
        keys = ", ".join(list(value)[:6]) + (", ..." if len(value) > 6 else "")
        return f"an object with {keys}" if value else "an empty object"
    return type(value).__name__


def at(path: str, key: str | int) -> str:
    """The JSON path of ``key`` inside ``path``: ``$.tree``, ``$.tree.children[0]``."""
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if IDENT.match(key) else f"{path}[{json.dumps(key)}]"
