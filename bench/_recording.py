"""What recording a run costs the running plan: ticks a second with the record on and off.

A plan of debug operations under the run policy "forever" (a leaf RUNNING for three ticks,
then one that succeeds, over and over: status changes at every tick) is run by the executor
at the rate a plan runs at (``PLAN_RATE_HZ``: the tending trial's) and at a rate far above
what it reaches (``FLAT_OUT_HZ``), where every bit of the engine's time the recording takes
(the dispatcher thread writing each event's line holds Python's GIL meanwhile) shows. "On" is what a run on a cell records: the trace of every event, the
joints of an arm at 10 Hz and a 160x120 JPEG of each of two cameras a second (fake arm and
cameras answer at once, the cameras with a noisy picture, so the JPEG costs what a real
one does). On and off alternate, ``pairs`` times each; the ratio is the median's.
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from capabilities.base import CapabilityRegistry
from capabilities.cells import ManagedCell
from capabilities.run_sampler import THUMBNAIL_SIZE, JointSampler, ThumbnailSampler
from engine.build import build_tree
from engine.executor import Executor
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.trace import TraceRecorder
from engine.tree import RunPolicy
from engine.types import ParamType

__all__ = ["FLAT_OUT_HZ", "PLAN_RATE_HZ", "recording_tick_ratio"]

PLAN_RATE_HZ = 50.0  # the tending trial's rate (the Instructor's default is 20)
FLAT_OUT_HZ = 100_000.0  # asked of the executor: more than it reaches, so it ticks flat out


class _Arm:
    def joint_positions(self) -> list[float]:
        return [0.1, -1.2, 1.3, -1.6, -1.57, 0.0]


class _Frame:
    def __init__(self, rgb: np.ndarray) -> None:
        self.rgb = rgb


class _Camera:
    def __init__(self, seed: int) -> None:
        self._random = np.random.default_rng(seed)

    def preview(self, size: tuple[int, int]) -> _Frame:
        base = np.linspace(0, 255, size[0], dtype=np.uint8)[None, :, None]
        noise = self._random.integers(0, 24, (size[1], size[0], 3), dtype=np.uint8)
        return _Frame(base + noise)


def _plan() -> PlanSpec:
    work = NodeSpec(NodeKind.OPERATION, name="work", op="debug.running",
                    params={"ticks": Binding.fixed(3.0, ParamType.NUMBER)})  # fmt: skip
    done = NodeSpec(NodeKind.OPERATION, name="done", op="debug.succeed")
    top = NodeSpec(NodeKind.SEQUENCE, name="cycle", children=[work, done])
    return PlanSpec(top, "recording bench", run_policy=RunPolicy.FOREVER)


def _ticks_per_second(
    plan: PlanSpec, registry: Any, seconds: float, record: Path | None, rate_hz: float
) -> float:
    tree = build_tree(plan, registry)
    listeners: list[Any] = []
    samplers: list[Any] = []
    if record is not None:
        recorder = TraceRecorder(record, plan)
        cameras = {"shoulder": _Camera(1), "wrist": _Camera(2)}
        samplers = [JointSampler(_Arm(), recorder), ThumbnailSampler(cameras, recorder)]
        listeners = [recorder, *samplers]
    executor = Executor(tree, rate_hz, listeners, plan_name=plan.name)
    started = time.perf_counter()
    executor.start()
    time.sleep(seconds)
    executor.stop("bench over")
    result = executor.wait(10.0)
    elapsed = time.perf_counter() - started
    for sampler in samplers:
        sampler.wait(5.0)
    if result is None:
        raise RuntimeError("the bench's run did not end")
    return result.tick / elapsed


def _pairs(registry: Any, plan: PlanSpec, seconds: float, pairs: int, rate_hz: float) -> Any:
    """Median ticks a second with the record on and off, and the record's bytes a second."""
    on: list[float] = []
    off: list[float] = []
    sizes: list[int] = []
    with tempfile.TemporaryDirectory(prefix="costar-recording-bench-") as folder:
        for i in range(pairs):
            for recording in (i % 2 == 0, i % 2 != 0):  # alternate which goes first
                record = Path(folder) / f"run{i}.trace.jsonl" if recording else None
                rate = _ticks_per_second(plan, registry, seconds, record, rate_hz)
                (on if recording else off).append(rate)
                if record is not None:
                    sizes.append(record.stat().st_size)
    return statistics.median(on), statistics.median(off), statistics.median(sizes) / seconds


def recording_tick_ratio(seconds: float = 3.0, pairs: int = 3) -> dict[str, Any]:
    """Ticks a second with the record on divided by off at the plan's rate
    (``recording_tick_ratio``) and flat out (see the module doc).
    """
    registry = CapabilityRegistry(cell=ManagedCell())
    plan = _plan()
    figures: dict[str, Any] = {"thumbnail_size": list(THUMBNAIL_SIZE)}
    for name, rate_hz in (("at_plan_rate", PLAN_RATE_HZ), ("flat_out", FLAT_OUT_HZ)):
        on, off, size = _pairs(registry, plan, seconds, pairs, rate_hz)
        figures[name] = {
            "rate_hz": rate_hz,
            "ratio": round(on / off, 3),
            "ticks_per_s_recording": round(on, 1),
            "ticks_per_s_not_recording": round(off, 1),
            "record_bytes_per_s": round(size),
        }
    figures["recording_tick_ratio"] = figures["at_plan_rate"]["ratio"]
    return figures
