"""The plan file format's shared pieces: its constants, its error, and JSON-path helpers."""

from __future__ import annotations

import types
from collections.abc import Mapping

from engine.json_reader import JsonFileError, at, describe

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "KIND_ALIASES",
    "MAX_NESTING",
    "MAX_TREE_DEPTH",
    "PLAIN_FORMAT_VERSION",
    "SUBTREES_FORMAT_VERSION",
    "PLAN_SUFFIX",
    "READABLE_VERSIONS",
    "PlanFileError",
    "at",
    "describe",
]

FORMAT = "costar-plan"
# 2: the settings of logic nodes are typed port bindings in "params" (1: a "config" object);
# the operation timing.wait is the Wait node. 3: subtree instances and the "subtrees" they
# run; a plan without them is still written as 2, so older programs keep reading it.
# 4: nodes with pre- and post-conditions ("conditions"); a plan without any is written as 3
# or 2 as before.
FORMAT_VERSION = 4
SUBTREES_FORMAT_VERSION = 3
PLAIN_FORMAT_VERSION = 2
READABLE_VERSIONS: tuple[int, ...] = (1, 2, 3, 4)
PLAN_SUFFIX = ".costar.json"
# Python's JSON reader and writer recurse about twice per tree level; 400 levels stay well
# inside the default recursion limit of 1000 even when called from a deep GUI stack.
MAX_TREE_DEPTH = 400
# Each tree level is two JSON levels (a node, its children list), plus a few for the plan,
# a binding and its value: deeper text is refused with its JSON path before it is read.
MAX_NESTING = 2 * MAX_TREE_DEPTH + 8

KIND_ALIASES: Mapping[str, str] = types.MappingProxyType(
    {"fallback": "selector", "reactive_fallback": "reactive_selector"}
)

TOP_FIELDS: tuple[str, ...] = ("format", "format_version", "id", "name", "description")
TOP_FIELDS += (
    "run_policy",
    "give_up_after",
    "reset_cell",
    "scene",
    "parameters",
    "tree",
    "waypoints",
)
TOP_FIELDS += ("objects", "layout")
TOP_FIELDS += ("subtrees",)
NODE_FIELDS = ("id", "kind", "name", "op", "params", "children", "subtree", "conditions")
# A subtree definition: embedded in a plan's "subtrees", or the body of a library file.
SUBTREE_FIELDS: tuple[str, ...] = ("id", "name", "version", "date", "description")
SUBTREE_FIELDS += ("inputs", "outputs", "shared_names", "tree", "layout")
NODE_FIELDS_V1 = ("id", "kind", "name", "op", "params", "config", "children")


class PlanFileError(JsonFileError):
    """A plan file that cannot be read or written, with where and what was expected.

    The attributes are those of :class:`engine.json_reader.JsonFileError`: ``file`` (as
    given, ``"<string>"`` for text), ``json_path``, ``expected``, ``got``, ``line``, ``column``.
    """
