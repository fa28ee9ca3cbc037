"""``costar ur-emulator`` (or ``python -m capabilities.ur_emulator``): run the emulator.

``--scene NAME --seed N`` loads a scene of the simulated cell around the emulated arm (the
simulated cell's default, cup_to_bin, unless named; ``--scene none``: the arm alone, no
cameras); ``--write-cell FILE`` writes a cell file whose robot is this emulator, so that
``costar run PLAN --cell FILE`` takes the real-robot path without a robot. Its cameras are
the frame streams the emulator serves (with ``--scene none`` they keep the source "sim",
which a UR cell has not: a plan that looks is refused by validation).

With ``--control stdin`` it reads fault commands from standard input, one a line, and answers
each with one JSON line (see :mod:`capabilities.ur_emulator.process`, which drives it so).
ur_rtde holds the GIL while it connects, so the emulator always runs in its own process.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import signal
import sys
import threading
from dataclasses import replace
from pathlib import Path
from typing import Any

from capabilities.cells import DEFAULT_SCENE
from capabilities.stream_camera import FRAME_PORT
from capabilities.ur_emulator import VERSIONS, UREmulator
from capabilities.ur_emulator.errors import EmulatorError
from capabilities.ur_emulator.servers import check_loopback

__all__ = ["NO_SCENE", "main", "run_command"]

NO_SCENE = "none"  # --scene none: the arm alone (no objects, no cameras)


def _protective_stop(emulator: UREmulator, args: list[str]) -> None:
    """protective_stop [on_contact | at=SIM_TIME | lag=S]."""
    arg = args[0] if args else ""
    if arg == "on_contact":
        emulator.protective_stop(on_contact=True)
    elif arg.startswith("at="):
        emulator.protective_stop(at=float(arg[3:]))
    elif arg.startswith("lag="):
        emulator.protective_stop(lag=float(arg[4:]))
    else:
        emulator.protective_stop()


def run_command(emulator: UREmulator, line: str) -> dict[str, Any]:
    """Do one control command; the answer is a JSON-able dict with "ok"."""
    words = line.split()
    if not words:
        return {"ok": False, "error": "empty command"}
    name, args = words[0], words[1:]
    ctl = emulator.ctl
    if name == "protective_stop":
        _protective_stop(emulator, args)
    elif name in (
        "unlock",
        "emergency_stop",
        "release_emergency_stop",
        "power_off",
        "kill_script",
        "disconnect",
    ):
        getattr(emulator, name)()
    elif name == "state":
        return _state(emulator)
    elif name == "input":  # input BANK INDEX 0|1: a digital input (a foot pedal)
        shift = {"standard": 0, "configurable": 8, "tool": 16}[args[0]]
        ctl.set_digital_input(shift + int(args[1]), args[2] == "1")
    elif name == "teach_button":  # teach_button 0|1: the pendant's freedrive button
        ctl.press_teach_button(args[0] == "1")
    elif name == "truth":  # GROUND TRUTH of a scene object, for tests that score a run
        if emulator.truth is None or not args:
            return {"ok": False, "error": "truth needs a scene (--scene) and an object name"}
        pose = emulator.truth(args[0])
        return {"ok": True, "position": list(pose.position), "orientation": list(pose.orientation)}
    elif name != "quit":
        return {"ok": False, "error": f"unknown command {name!r}"}
    return {"ok": True}


def _state(emulator: UREmulator) -> dict[str, Any]:
    """The answer to "state": the controller's modes, program, joints, I/O and popup."""
    ctl = emulator.ctl
    snap = ctl.snapshot()
    return {
        "ok": True,
        "robot_mode": snap["robot_mode"],
        "safety_mode": snap["safety_mode"],
        "program_running": ctl.program_running(),
        "q": list(snap["actual_q"]),
        "digital_outputs": ctl.digital_outputs(),
        "freedrive": ctl.freedrive_on,
        "speed_fraction": ctl.speed_fraction,
        "sim_time": emulator.cell.time(),
        "gripper_closed": emulator.cell.gripper.is_closed(),
        "moving": ctl.arm_moving(),
        "messages": ctl.messages[-5:],
        "popup": ctl.popup,
        "script_clients": len(ctl.script_clients),
        "takeovers": ctl.takeovers,
    }


def _serve_stdin(emulator: UREmulator, done: threading.Event) -> None:
    for line in sys.stdin:
        try:
            answer = run_command(emulator, line.strip())
        except Exception as exc:  # a bad command is answered, never fatal
            answer = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
        print(json.dumps(answer), flush=True)
        if line.strip() == "quit":
            break
    done.set()


def _serve(emulator: UREmulator, args: argparse.Namespace, done: threading.Event) -> None:
    if args.protective_stop_at is not None:
        emulator.protective_stop(at=args.protective_stop_at)
    if args.protective_stop_on_contact:
        emulator.protective_stop(on_contact=True)
    if args.control == "stdin":
        print(json.dumps({"ok": True, "ready": args.host}), flush=True)
        threading.Thread(target=_serve_stdin, args=(emulator, done), daemon=True).start()
    else:
        where = f" with {args.write_cell}" if args.write_cell else ""
        print(f"UR emulator (PolyScope {args.version}) on {args.host}{where}; Ctrl+C stops it")
        sys.stdout.flush()
    with contextlib.suppress(KeyboardInterrupt):
        done.wait()


def write_cell_file(
    path: str | Path, host: str, version: str, config: Any, cameras: bool = False
) -> None:
    """Write a cell file (atomically) whose robot is the emulator at ``host``; with
    ``cameras``, its cameras are the emulator's frame streams (else their source stays
    "sim", which a UR cell leaves out).

    Raises:
        EmulatorError: the file cannot be written.
    """
    from capabilities.robot.cell_robot import RobotSettings, ToolSettings
    from engine.plan_writer import write_atomic

    model = "UR5 CB3" if version.startswith("3.") else "UR5e"
    robot = RobotSettings(kind="ur", host=host, model=model, tool=ToolSettings("robotiq"))
    # The emulated cell's gripper answers as a Robotiq; its cameras (with a scene) are served
    # from the emulator's process. A UR cell ignores cameras whose source is "sim".
    streams = {
        name: replace(c, source="stream", where=f"{host}:{FRAME_PORT}")
        for name, c in config.cameras.items()
    }
    cell = replace(config, robot=robot, cameras=streams if cameras else config.cameras)
    data = json.dumps(cell.to_json(), indent=2) + "\n"
    try:
        write_atomic(Path(path), data.encode("utf-8"))
    except Exception as exc:
        raise EmulatorError(f"{path}: cannot write the cell file: {exc}") from exc


def _emulator(args: argparse.Namespace, stack: contextlib.ExitStack) -> UREmulator:
    """The emulator the arguments ask for; a scene's session is closed by ``stack``."""
    if args.scene == NO_SCENE:
        return UREmulator(args.host, args.version, speed=args.speed, unlock_delay=args.unlock_delay)
    from capabilities.sim.session import SimCellSession

    check_loopback(args.host)  # refuse a bad host before building a scene
    session = stack.enter_context(SimCellSession(args.scene, args.seed, args.speed))
    return UREmulator(
        args.host,
        args.version,
        cell=session.sim,
        unlock_delay=args.unlock_delay,
        cameras=session.cameras,
        truth=session.truth_pose,
    )


def main(argv: list[str] | None = None, prog: str = "python -m capabilities.ur_emulator") -> int:
    """Run the emulator from the command line until stopped; the exit status."""
    parser = argparse.ArgumentParser(
        prog=prog,
        description="A loopback UR controller (dashboard, script port, RTDE) backed by the "
        "simulated cell.",
    )
    parser.add_argument("--host", default="127.0.0.2", help="a loopback address (127.0.0.0/8)")
    parser.add_argument("--version", default="5.12", choices=sorted(VERSIONS))
    parser.add_argument(
        "--speed", type=float, default=1.0, help="real-time factor of the simulation (1.0)"
    )
    parser.add_argument(
        "--unlock-delay",
        type=float,
        default=5.0,
        help="seconds before a protective stop can be unlocked (default 5, as on a UR)",
    )
    parser.add_argument(
        "--protective-stop-at",
        type=float,
        default=None,
        metavar="SECONDS",
        help="inject a protective stop at this simulated time",
    )
    parser.add_argument(
        "--protective-stop-on-contact",
        action="store_true",
        help="a protective stop when the arm touches something",
    )
    parser.add_argument(
        "--scene",
        default=DEFAULT_SCENE,
        help=f"a scene of the simulated cell around the arm (default {DEFAULT_SCENE}, as the "
        f"simulated cell's; {NO_SCENE}: the arm alone, without cameras)",
    )
    parser.add_argument("--seed", type=int, default=0, help="scene seed (default 0)")
    parser.add_argument(
        "--write-cell", metavar="FILE", help="write a cell file whose robot is this emulator"
    )
    parser.add_argument(
        "--control",
        choices=("none", "stdin"),
        default="none",
        help="stdin: read fault commands from standard input (for tests)",
    )
    args = parser.parse_args(argv)
    done = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: done.set())
    try:
        with contextlib.ExitStack() as stack:
            emulator = stack.enter_context(_emulator(args, stack))
            if args.write_cell:
                write_cell_file(
                    args.write_cell,
                    args.host,
                    args.version,
                    emulator.cell.config,
                    cameras=args.scene != NO_SCENE,
                )
            _serve(emulator, args, done)
    except EmulatorError as exc:
        print(f"error: {exc}", file=sys.stderr, flush=True)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
