"""UR cell figures against the loopback emulator, through the unmodified ur_rtde.

    .venv/bin/python bench/ur.py [--host 127.0.0.250] [--version 5.12] [--seconds 3]
                                 [--moves 5] [--json]

- rtde_receive_hz: RTDE state packages per second that ur_rtde's RTDEReceiveInterface takes
  in (distinct timestamps seen while polling it; a real e-Series streams 500 Hz, a CB3 125).
- movej_command_latency_ms: median time from URArm.move_joints() (what an operation's start
  calls) to the first joint motion the backend sees in its state.
- protective_stop_detect_ms: median time from asking the emulator for a protective stop (a
  pipe round trip included) to the running move's handle failing with it.

Figures only, never pass/fail. ``--json`` prints one JSON object at the end.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from capabilities.ur.arm import URArm
from capabilities.ur.connection import URConnection
from capabilities.ur.emulator.process import EmulatorProcess
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
    deadline = time.monotonic() + 10.0
    while not connection.state.program_running and time.monotonic() < deadline:
        time.sleep(0.01)
    return elapsed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.250")
    parser.add_argument("--version", default="5.12", choices=("3.15", "5.9", "5.12"))
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--moves", type=int, default=5)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    with EmulatorProcess(args.host, args.version, unlock_delay=0.0) as emulator:
        hz = receive_rate(args.host, args.seconds)
        connection = URConnection(args.host)
        connection.open()
        try:
            arm = URArm(connection, Pose(), Pose(), (0.0,) * 6)
            latencies = movej_latency(connection, arm, args.moves)
            stops = [stop_detection(emulator, connection, arm) for _ in range(3)]
        finally:
            connection.close()
    result = {
        "version": args.version,
        "rtde_receive_hz": round(hz, 1),
        "movej_command_latency_ms": round(statistics.median(latencies), 2),
        "movej_command_latency_max_ms": round(max(latencies), 2),
        "protective_stop_detect_ms": round(statistics.median(stops), 2),
    }
    if args.json:
        print(json.dumps(result))
    else:
        for key, value in result.items():
            print(f"{key:32s} {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
