"""Plan files (``*.costar.json``): versioned JSON, read with clear errors, written atomically.

A plan file is plain JSON (DESIGN.md section 6)::

    {"format": "costar-plan", "format_version": 1, "id": ..., "name": ..., "description": ...,
     "run_policy": "once", "parameters": [...], "tree": {...} | null, "waypoints": [...],
     "objects": [...], "layout": {"nodes": {node id: {"x": ..., "y": ..., "collapsed": ...}}}}

Reading checks the shape of everything and names the file, the JSON path and what was
expected; unknown fields are refused so that typos are caught. Renamed node kinds
(:data:`KIND_ALIASES`) and renamed operations (the ``aliases`` argument) keep loading under
their new names. Nothing in a file is executed. Writing is deterministic (fixed key order,
indent 2, trailing newline, floats as ``repr``), so save -> load -> save gives the same bytes.

The reader accepts a decorator without a child and an empty composite: the editor saves
half-built plans. Validation (:mod:`engine.validation`) reports them, and a plan with such
errors does not start.
"""

from __future__ import annotations

from engine.plan_format import (
    FORMAT,
    FORMAT_VERSION,
    KIND_ALIASES,
    MAX_TREE_DEPTH,
    PLAN_SUFFIX,
    READABLE_VERSIONS,
    PlanFileError,
)
from engine.plan_reader import load_plan, loads_plan, plan_scene
from engine.plan_writer import dump_plan, save_plan

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "KIND_ALIASES",
    "MAX_TREE_DEPTH",
    "PLAN_SUFFIX",
    "READABLE_VERSIONS",
    "PlanFileError",
    "dump_plan",
    "load_plan",
    "loads_plan",
    "plan_scene",
    "save_plan",
]
