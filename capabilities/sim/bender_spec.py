"""The wire bender of a scene file and its fault model: what it makes, when, and how badly.

An optional ``bender`` block of a scene file makes one of its fixtures (a ``wire_bender``
model) produce wireforms; the plan is drawn once from the scene's seed::

    "bender": {
      "fixture": "bender", "parts": 50, "shapes": ["wireform_u", "wireform_step"],
      "first_at": [8.0, 10.0], "interval": 20.0, "swing": 0.8, "hold": 0.6,
      "spread": {"x": 0.008, "y": 0.008, "yaw": 0.08},
      "faults": {"bad_weld": 0.02, "bad_grasp": 0.05, "interval_spread": 0.35}
    }

The first part comes ``first_at`` seconds after the bender starts, each next one an
interval later drawn uniformly in ``interval * (1 +- interval_spread)``; each part's shape is
drawn from ``shapes``. The welding arm swings down in ``swing`` seconds before a part is
released, stays ``hold`` seconds and swings back. A part lands at the bender's exit shifted
by up to ``spread`` (m, m, rad), its weld bead on the exit point (where the bender held it
to weld). The fault model (:class:`FaultModel`, defaults from the
paper's Table I: 2 bad welds and about 5 bad grasps per 100 parts) marks a part's weld bad
(it comes apart when the part is lifted) or its first grasp bad (the part slips out); a run
may set other rates (``SimCellSession(faults=...)``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from capabilities.sim.scene_spec import SceneFileError, parse_block
from engine.json_reader import JsonReader

__all__ = [
    "BenderSpec",
    "FaultModel",
    "PlannedPart",
    "parse_bender",
    "plan_parts",
]

Range = tuple[float, float]


@dataclass(frozen=True)
class FaultModel:
    """Per-part fault rates and how irregular the bender is.

    Attributes:
        bad_weld: probability that a part's weld is bad (it comes apart when lifted).
        bad_grasp: probability that the first grasp of a part slips (the part drops).
        interval_spread: production intervals vary by up to this fraction of the interval.
    """

    bad_weld: float = 0.02
    bad_grasp: float = 0.05
    interval_spread: float = 0.35

    def __post_init__(self) -> None:
        for name in ("bad_weld", "bad_grasp"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ValueError(f"fault rate {name} must be in 0..1, got {getattr(self, name)}")
        if not 0.0 <= self.interval_spread < 1.0:
            raise ValueError(f"interval_spread must be in 0..1, got {self.interval_spread}")


@dataclass(frozen=True)
class BenderSpec:
    """The ``bender`` block of a scene file (see the module doc)."""

    fixture: str
    shapes: tuple[str, ...]
    parts: int = 50
    first_at: Range = (3.0, 5.0)
    interval: float = 12.0
    swing: float = 0.8
    hold: float = 0.6
    spread: tuple[float, float, float] = (0.008, 0.008, 0.08)
    faults: FaultModel = FaultModel()
    lift: float = 0.025  # m above the table that counts as lifted (handled)


@dataclass(frozen=True)
class PlannedPart:
    """A part the bender will release ``offset`` seconds after it starts (ground truth)."""

    offset: float
    name: str
    shape: str
    bad_weld: bool
    bad_grasp: bool
    shift: tuple[float, float, float]  # x, y (m) and yaw (rad) off the exit, bender frame


def _faults(r: JsonReader) -> FaultModel:
    d = FaultModel()
    return FaultModel(
        bad_weld=r.number("bad_weld", d.bad_weld, lo=0.0, hi=1.0),
        bad_grasp=r.number("bad_grasp", d.bad_grasp, lo=0.0, hi=1.0),
        interval_spread=r.number("interval_spread", d.interval_spread, lo=0.0, hi=0.95),
    )


def _spec(r: JsonReader) -> BenderSpec:
    d = BenderSpec("", ())
    shapes = tuple(s.as_text(nonempty=True) for s in r.items("shapes", "model names", False))
    if not shapes:
        r.fail("a non-empty list of wireform model names", key="shapes")
    first = r.vector2("first_at", d.first_at)
    if not 0.0 <= first[0] <= first[1]:
        r.fail("a range [lo, hi] with 0 <= lo <= hi", key="first_at")
    spread = r.child("spread", ("x", "y", "yaw"))
    return BenderSpec(
        fixture=r.text("fixture", nonempty=True),
        shapes=shapes,
        parts=r.integer("parts", d.parts, lo=0),
        first_at=first,
        interval=r.number("interval", d.interval, lo=0.5),
        swing=r.number("swing", d.swing, lo=0.05, hi=10.0),
        hold=r.number("hold", d.hold, lo=0.0, hi=60.0),
        spread=(
            spread.number("x", d.spread[0], lo=0.0, hi=0.2),
            spread.number("y", d.spread[1], lo=0.0, hi=0.2),
            spread.number("yaw", d.spread[2], lo=0.0, hi=math.pi),
        ),
        faults=_faults(r.child("faults", ("bad_weld", "bad_grasp", "interval_spread"))),
        lift=r.number("lift", d.lift, lo=0.005, hi=0.5),
    )


_FIELDS = (
    "fixture",
    "parts",
    "shapes",
    "first_at",
    "interval",
    "swing",
    "hold",
    "spread",
    "faults",
    "lift",
)


def parse_bender(data: Any, source: str = "<scene>") -> BenderSpec | None:
    """The ``bender`` block of a parsed scene file, or None if it has none.

    Raises:
        SceneFileError: the block is off; the message names ``source`` and the JSON path.
    """
    spec = parse_block(data, source, "bender", _FIELDS, _spec)
    if spec is None:
        return None
    if spec.interval < 2 * spec.swing + spec.hold:
        raise SceneFileError(
            f"{source}: $.bender.interval: at least swing * 2 + hold "
            f"({2 * spec.swing + spec.hold:g} s) expected, got {spec.interval:g}"
        )
    return spec


def plan_parts(
    spec: BenderSpec, seed: int | None, faults: FaultModel | None = None
) -> list[PlannedPart]:
    """The bender's production, drawn from ``seed`` (release offsets, in order).

    Args:
        spec: the scene's bender block.
        seed: the scene's seed (None: not reproducible).
        faults: rates to use instead of the scene's.
    """
    if faults is not None:
        spec = replace(spec, faults=faults)
    rng = np.random.default_rng(None if seed is None else [seed, 5113])
    rates = spec.faults
    # Each interval must leave room for the arm to swing down, hold and swing back.
    least = 2 * spec.swing + spec.hold + 0.1
    lo = max(least, spec.interval * (1 - rates.interval_spread))
    hi = max(lo, spec.interval * (1 + rates.interval_spread))
    at = float(rng.uniform(*spec.first_at))
    at = max(at, spec.swing)
    parts = []
    for index in range(spec.parts):
        shape = spec.shapes[int(rng.integers(len(spec.shapes)))]
        bad_weld = bool(rng.random() < rates.bad_weld)
        bad_grasp = bool(rng.random() < rates.bad_grasp)
        sx, sy, syaw = (float(rng.uniform(-s, s)) for s in spec.spread)
        parts.append(
            PlannedPart(at, f"part_{index + 1:03d}", shape, bad_weld, bad_grasp, (sx, sy, syaw))
        )
        at += float(rng.uniform(lo, hi))
    return parts
