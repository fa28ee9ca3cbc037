"""The emulator in a child process, driven from a test or a tool.

ur_rtde holds the GIL while it connects and while some calls wait, so an emulator in the same
process as the client would starve; the child process is also what a real controller is: a
separate machine that can die. Faults are sent on the child's standard input.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any, Self

from capabilities.cell_features import ClosesOnExit
from capabilities.ur_emulator.errors import EmulatorError
from capabilities.ur_emulator.servers import check_loopback
from engine.types import Pose

__all__ = ["EmulatorProcess"]

_ROOT = Path(__file__).resolve().parents[3]


class EmulatorProcess(ClosesOnExit):
    """``python -m capabilities.ur_emulator`` in a child process; a context manager.

    Args:
        host: a loopback address (127.0.0.0/8).
        version: "3.15", "5.9" or "5.12".
        speed: real-time factor of the simulated cell.
        unlock_delay: seconds before a protective stop can be unlocked.
        timeout: seconds to wait for the child to start and for each answer.
        scene: a scene of the simulated cell around the arm (None: the arm alone, which
            the command line calls ``--scene none``).
        seed: the scene's seed.
        write_cell: write a cell file whose robot is this emulator.
    """

    def __init__(
        self,
        host: str = "127.0.0.2",
        version: str = "5.12",
        speed: float = 1.0,
        unlock_delay: float = 5.0,
        timeout: float = 60.0,
        scene: str | None = None,
        seed: int = 0,
        write_cell: str | Path | None = None,
    ) -> None:
        self.host = check_loopback(host)
        self.version = version
        self._args = [
            sys.executable, "-m", "capabilities.ur_emulator", "--host", host,
            "--version", version, "--speed", str(speed), "--unlock-delay", str(unlock_delay),
            "--control", "stdin",
        ]  # fmt: skip  # a command line: each flag beside its value
        self._args += ["--scene", scene or "none", "--seed", str(seed)]
        if write_cell is not None:
            self._args += ["--write-cell", str(write_cell)]
        self._timeout = timeout
        self._proc: subprocess.Popen[str] | None = None
        self._lock = threading.Lock()

    def start(self) -> EmulatorProcess:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(_ROOT), env.get("PYTHONPATH")]))
        self._proc = subprocess.Popen(
            self._args,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=str(_ROOT),
            env=env,
        )
        first = self._read_line()
        if not first.get("ok"):
            self.kill()
            raise EmulatorError(f"the UR emulator did not start: {first.get('error')}")
        return self

    def _read_line(self) -> dict[str, Any]:
        proc = self._proc
        assert proc is not None and proc.stdout is not None
        stdout = proc.stdout
        result: list[str] = []
        reader = threading.Thread(target=lambda: result.append(stdout.readline()))
        reader.daemon = True
        reader.start()
        reader.join(self._timeout)
        line = result[0] if result else ""
        while line and not line.startswith("{"):  # library banners on stdout
            line = stdout.readline()
        if not line:
            error = ""
            if proc.poll() is not None and proc.stderr is not None:
                error = proc.stderr.read()[-2000:]
            return {"ok": False, "error": error.strip() or "no answer from the emulator"}
        answer: dict[str, Any] = json.loads(line)
        return answer

    def command(self, line: str) -> dict[str, Any]:
        """Send one control command ("protective_stop", "power_off", "state", ...).

        Raises:
            EmulatorError: the emulator refused the command or did not answer.
        """
        with self._lock:
            proc = self._proc
            if proc is None or proc.stdin is None or proc.poll() is not None:
                raise EmulatorError("the UR emulator is not running")
            proc.stdin.write(line + "\n")
            proc.stdin.flush()
            answer = self._read_line()
        if not answer.get("ok"):
            raise EmulatorError(f"UR emulator: {line}: {answer.get('error')}")
        return answer

    def state(self) -> dict[str, Any]:
        """Robot mode, safety mode, program, joints, outputs, freedrive, sim time."""
        return self.command("state")

    def set_input(self, bank: str, index: int, level: bool) -> None:
        """Set a digital input ("standard", "configurable" or "tool"; a foot pedal)."""
        self.command(f"input {bank} {index} {int(level)}")

    def teach_button(self, down: bool) -> None:
        """Press (True) or release the pendant's teach button."""
        self.command(f"teach_button {int(down)}")

    def truth_pose(self, name: str) -> Pose:
        """GROUND TRUTH of a scene object's pose (tests and scores only)."""
        answer = self.command(f"truth {name}")
        return Pose(tuple(answer["position"]), tuple(answer["orientation"]))

    def protective_stop(
        self, at: float | None = None, on_contact: bool = False, lag: float = 0.0
    ) -> None:
        """A protective stop now (with ``lag``: the program's end published that many s
        before the safety mode), at simulated time ``at``, or on the arm's next contact.
        """
        arg = " on_contact" if on_contact else (f" at={at}" if at is not None else "")
        arg = arg or (f" lag={lag}" if lag > 0 else "")
        self.command("protective_stop" + arg)

    def unlock(self) -> None:
        """Unlock a protective stop (the operator on the pendant; the dashboard's command).

        Raises:
            EmulatorError: refused: earlier than the unlock delay after the stop.
        """
        self.command("unlock")

    def emergency_stop(self) -> None:
        self.command("emergency_stop")

    def release_emergency_stop(self) -> None:
        self.command("release_emergency_stop")

    def power_off(self) -> None:
        self.command("power_off")

    def kill_script(self) -> None:
        self.command("kill_script")

    def disconnect(self) -> None:
        self.command("disconnect")

    def kill(self) -> None:
        """The controller dies at once (SIGKILL): every connection drops."""
        proc, self._proc = self._proc, None
        if proc is not None:
            proc.kill()
            proc.wait()
            for stream in (proc.stdin, proc.stdout, proc.stderr):
                if stream is not None:
                    stream.close()

    def close(self) -> None:
        """Ask the child to quit; kill it if it does not within the timeout."""
        proc = self._proc
        if proc is None:
            return
        if proc.poll() is None and proc.stdin is not None:
            try:
                proc.stdin.write("quit\n")
                proc.stdin.flush()
                proc.wait(timeout=self._timeout)
            except (OSError, subprocess.TimeoutExpired):
                pass
        self.kill()

    def __enter__(self) -> Self:
        self.start()
        return self
