"""``costar-instructor``: the desktop application.

The canvas, palette and inspector arrive with the Instructor issue; until then this entry
point checks that the plan given (if any) loads and says what to use meanwhile.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

__all__ = ["main"]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="costar-instructor", description=__doc__)
    parser.add_argument("plan", nargs="?", help="a plan file (*.costar.json) to open")
    args = parser.parse_args(argv)
    print(
        "CoSTAR Instructor: the graphical editor is not built yet (it comes with the Instructor issue)."
    )
    print(
        "Meanwhile, plans run from the command line: costar validate PLAN, costar run PLAN, costar ops."
    )
    if args.plan:
        from engine.files import PlanFileError, load_plan

        try:
            plan = load_plan(args.plan)
        except PlanFileError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        print(f"{args.plan}: {plan.name or 'plan'} loads ({sum(1 for _ in plan.walk())} nodes).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
