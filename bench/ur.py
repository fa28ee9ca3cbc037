"""UR cell figures against the loopback emulator, through the unmodified ur_rtde.

    .venv/bin/python bench/ur.py [--host 127.0.0.250] [--version 5.12] [--seconds 3]
                                 [--moves 5] [--json]

- rtde_receive_hz: RTDE state packages per second that ur_rtde's RTDEReceiveInterface takes
  in (distinct timestamps seen while polling it; a real e-Series streams 500 Hz, a CB3 125).
- movej_command_latency_ms: median time from URArm.move_joints() (what an operation's start
  calls) to the first joint motion the backend sees in its state.
- protective_stop_detect_ms: median time from asking the emulator for a protective stop (a
  pipe round trip included) to the running move's handle failing with it.
- protective_stop_halt_ticks: the most engine ticks (20 Hz) evaluated between the backend
  seeing an injected protective stop and the run being held (a plan of one long move on a UR
  cell opened from a cell file, through the executor's hold check): 0 means the first tick
  after it held the run; the goal is at most 1.
- rtde_receive_ratio: rtde_receive_hz over the rate the emulated controller publishes (its
  peer: 500 Hz on e-Series versions, 125 Hz on CB3).

Figures only, never pass/fail. ``--json`` prints one JSON object at the end.
"""

from __future__ import annotations

import argparse
import functools
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench._report import print_figures
from capabilities.ur.arm import URArm
from capabilities.ur.connection import URConnection, fault_reason
from capabilities.ur_emulator.process import EmulatorProcess
from engine.types import Pose


def receive_rate(host: str, seconds: float) -> float:
    """Packages per second ur_rtde's receive interface takes in."""
    import rtde_receive

    receive = rtde_receive.RTDEReceiveInterface(host)
    try:
        seen, last = 0, receive.getTimestamp()
        start = time.perf_counter()
        while time.perf_counter() - start < seconds:
            stamp = receive.getTimestamp()
            if stamp != last:
                seen, last = seen + 1, stamp
            time.sleep(0.0002)
        return seen / (time.perf_counter() - start)
    finally:
        receive.disconnect()


def _wait_moving(connection: URConnection, q0: tuple[float, ...], timeout: float = 5.0) -> float:
    start = time.perf_counter()
    while time.perf_counter() - start < timeout:
        if max(abs(a - b) for a, b in zip(connection.state.q, q0, strict=False)) > 1e-4:
            return time.perf_counter()
        time.sleep(0.0002)
    raise RuntimeError("the arm did not move")


def movej_latency(connection: URConnection, arm: URArm, moves: int) -> list[float]:
    """Milliseconds from move_joints() to the first motion seen, for ``moves`` small moves."""
    latencies = []
    for i in range(moves):
        q0 = arm.joint_positions()
        target = list(q0)
        target[0] += 0.05 if i % 2 == 0 else -0.05
        start = time.perf_counter()
        handle = arm.move_joints(target, 1.0, 2.0)
        latencies.append((_wait_moving(connection, q0) - start) * 1000.0)
        if not handle.wait(10) or not handle.ok:
            raise RuntimeError(f"moveJ failed: {handle.message}")
    return latencies


def stop_detection(emulator: EmulatorProcess, connection: URConnection, arm: URArm) -> float:
    """Milliseconds from the injected protective stop to the move failing with it."""
    q0 = arm.joint_positions()
    target = list(q0)
    target[0] += 1.0
    handle = arm.move_joints(target, 0.5, 1.0)
    _wait_moving(connection, q0)
    start = time.perf_counter()
    emulator.protective_stop()
    if not handle.wait(10) or "protective stop" not in handle.message:
        raise RuntimeError(f"the stop was not seen: {handle.message}")
    elapsed = (time.perf_counter() - start) * 1000.0
    connection.call(connection.clear_protective_stop)
    _wait(lambda: not fault_reason(connection.state))  # ready for the next move
    return elapsed


def halt_ticks(emulator: EmulatorProcess, cell_file: Path, repeats: int) -> int:
    """The most ticks from the backend seeing a protective stop to the run held."""
    from capabilities.base import CapabilityRegistry
    from capabilities.cells import open_cell
    from capabilities.faults import hold_check
    from engine.build import build_tree
    from engine.events import Event, RunHeld
    from engine.executor import Executor
    from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
    from engine.types import JointConfig, ParamType

    worst = 0
    with open_cell(str(cell_file)) as cell:
        for i in range(repeats):
            q = list(cell.arm.joint_positions())
            q[0] += 1.0 if i % 2 == 0 else -1.0
            move = NodeSpec(NodeKind.OPERATION, "move", op="motion.move_joints", params={
                "target": Binding.fixed(JointConfig(tuple(q)), ParamType.JOINTS),
                "speed": Binding.fixed(0.5, ParamType.NUMBER),
            })  # fmt: skip
            tree = build_tree(PlanSpec(move), CapabilityRegistry(cell=cell), clock=cell.clock)
            events: list[Event] = []
            executor = Executor(tree, 20.0, [events.append], hold=hold_check(cell))
            executor.start()
            _wait(lambda: emulator.state()["moving"])
            emulator.protective_stop()
            _wait(lambda: cell.connection.state.safety_mode == 3)
            seen = tree.ctx.tick_count
            _wait(functools.partial(_any_held, events))
            held = next(e for e in events if isinstance(e, RunHeld))
            worst = max(worst, held.tick - seen)
            executor.stop()
            executor.wait(10)
            cell.connection.call(cell.connection.clear_protective_stop)
            _wait(lambda: not cell.hold_reason())
    return worst


def _any_held(events: list[Any]) -> bool:
    from engine.events import RunHeld

    return any(isinstance(e, RunHeld) for e in events)


def _wait(predicate: Callable[[], bool], timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise RuntimeError("the emulator did not get there in time")
        time.sleep(0.001)


def main(argv: list[str] | None = None) -> int:
    """Measure the UR cell against the emulator; print the figures (``--json``: one JSON object)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.250")
    parser.add_argument("--version", default="5.12", choices=("3.15", "5.9", "5.12"))
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--moves", type=int, default=5)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    cell_file = Path(tempfile.mkdtemp(prefix="costar-bench-ur-")) / "emulated.cell.json"
    with EmulatorProcess(
        args.host, args.version, unlock_delay=0.0, write_cell=cell_file
    ) as emulator:
        hz = receive_rate(args.host, args.seconds)
        connection = URConnection(args.host)
        connection.open()
        try:
            arm = URArm(connection, Pose(), Pose(), (0.0,) * 6)
            latencies = movej_latency(connection, arm, args.moves)
            stops = [stop_detection(emulator, connection, arm) for _ in range(3)]
        finally:
            connection.close()
        ticks = halt_ticks(emulator, cell_file, 3)
    peer_hz = 500.0 if not args.version.startswith("3.") else 125.0
    result = {
        "version": args.version,
        "rtde_receive_hz": round(hz, 1),
        "emulator_publish_hz": peer_hz,
        "rtde_receive_ratio": round(hz / peer_hz, 3),
        "movej_command_latency_ms": round(statistics.median(latencies), 2),
        "movej_command_latency_max_ms": round(max(latencies), 2),
        "protective_stop_detect_ms": round(statistics.median(stops), 2),
        "protective_stop_halt_ticks": ticks,
    }
    print_figures(result, args.json, 32)
    return 0


if __name__ == "__main__":
    sys.exit(main())
