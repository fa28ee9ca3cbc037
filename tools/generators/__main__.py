"""Run every generator, in the order their files depend on (make_tending reads the
ClearStopAndBackOff that make_clear_stop writes).
"""

from __future__ import annotations

import sys

from tools.generators import (
    make_cell_examples,
    make_clear_stop,
    make_examples,
    make_kitting,
    make_objects,
    make_pick_place,
    make_tending,
)


def main() -> int:
    """Run every generator, writing the shipped files under ``resources/``; the exit status."""
    status = make_objects.main([])
    for generator in (
        make_clear_stop,
        make_pick_place,
        make_examples,
        make_cell_examples,
        make_kitting,
        make_tending,
    ):
        generator.main()
    return status


if __name__ == "__main__":
    sys.exit(main())
