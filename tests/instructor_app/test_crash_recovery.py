"""A real crash: an Instructor process is killed (SIGKILL) after its autosave; the next start
offers the recovery file and restores the edits.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

from gui_driver import ScriptedDialogs, make_window

from instructor_app.runtime.session import CellSession

ROOT = Path(__file__).resolve().parents[2]

# The doomed session: open a plan, edit it, let the 200 ms autosave timer write the recovery
# copy, say so, then wait to be killed.
CHILD = textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication
    from instructor_app.main_window import MainWindow
    from instructor_app.runtime.session import CellSession
    from instructor_app.settings import AppSettings

    folder, plan = Path(sys.argv[1]), sys.argv[2]
    app = QApplication([])
    session = CellSession("none")
    session.open()
    settings = AppSettings(QSettings(str(folder / "child.ini"), QSettings.Format.IniFormat))
    window = MainWindow(session, settings, None, folder / "recovery", autosave_interval_ms=200)
    window.document.open(plan)
    window.document.rename(window.document.plan.tree.id, "edited just before the crash")
    deadline = time.monotonic() + 30
    while not list((folder / "recovery").glob("*.costar.json")) and time.monotonic() < deadline:
        app.processEvents()
        time.sleep(0.02)
    print("autosaved", flush=True)
    while True:
        app.processEvents()
        time.sleep(0.05)
    """
)


def test_a_killed_instructor_is_restored_on_the_next_start(
    qtbot: Any, tmp_path: Path, figure3_path: Path
) -> None:
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", PYTHONPATH=str(ROOT))
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(tmp_path), str(figure3_path)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
    )  # fmt: skip
    try:
        assert child.stdout is not None
        line = child.stdout.readline()
        assert line.strip() == "autosaved", child.stderr.read() if child.stderr else ""
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait(timeout=30)
    assert child.returncode == -signal.SIGKILL

    session = CellSession("none")
    session.open()
    dialogs = ScriptedDialogs()
    dialogs.restore_answers = [True]
    window = make_window(qtbot, session, tmp_path, dialogs)
    assert window.offer_recoveries()
    assert [kind for kind, _ in dialogs.asked] == ["restore"]
    assert window.document.plan.tree is not None
    assert window.document.plan.tree.name == "edited just before the crash"
    assert window.document.dirty
    session.close()
