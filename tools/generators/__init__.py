"""The generators of the shipped files: they write part of ``resources/`` from code, byte for
byte the same on every run, and are not shipped themselves.

Run them from the repository's root (each writes into the ``resources/`` folder beside this
``tools/`` folder)::

    python -m tools.generators                      # all of them, in order
    python -m tools.generators.make_objects         # object models and meshes (--check)
    python -m tools.generators.make_clear_stop      # recovery/ClearStopAndBackOff
    python -m tools.generators.make_pick_place      # pick_place/Pick and Place
    python -m tools.generators.make_examples        # figure3_debug and nodes/*
    python -m tools.generators.make_cell_examples   # cup_to_bin(_vision), tending_paper
    python -m tools.generators.make_kitting         # the kitting library and plan
    python -m tools.generators.make_tending         # the tending library and plan

Every plan and subtree is built with :mod:`tools.generators.plan_builder` (node ids from the
generator's namespace, the shipped date).
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["RESOURCES"]

# The shipped files of this checkout (not of an installed package: these write the sources).
RESOURCES = Path(__file__).resolve().parents[2] / "resources"
