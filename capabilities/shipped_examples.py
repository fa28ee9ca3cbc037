"""``costar examples``: the plans shipped with the application, by the name ``example:`` takes."""

from __future__ import annotations

import argparse
import textwrap
from typing import TextIO

from engine.errors import EngineError
from engine.files import load_plan
from resources import example_name, example_plans

__all__ = ["cmd_examples"]

_WIDTH = 100


def cmd_examples(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """List each shipped plan: its ``example:`` name, its title and its description.

    The one-plan-per-node-kind examples (``nodes/...``) follow on one line of names.

    Returns:
        0, or 2 when a shipped plan does not read (the message names it).
    """
    broken = 0
    for path in example_plans():
        try:
            plan = load_plan(path)
        except (EngineError, OSError) as exc:
            print(f"error: {exc}", file=err)
            broken += 1
            continue
        print(f"{example_name(path)}: {plan.name}", file=out)
        for line in textwrap.wrap(plan.description, _WIDTH - 4):
            print(f"    {line}", file=out)
    nodes = [example_name(p) for p in example_plans(True) if "/" in example_name(p)]
    if nodes:
        print("one plan per node kind (debug operations, no robot):", file=out)
        for line in textwrap.wrap(", ".join(nodes), _WIDTH - 4):
            print(f"    {line}", file=out)
    print("run one with: costar run example:NAME (or open it in costar-instructor)", file=out)
    return 2 if broken else 0
