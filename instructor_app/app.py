"""``costar-instructor``: the desktop application.

``costar-instructor [PLAN | example:NAME] [--cell sim|none|FILE] [--seed N] [--run]
[--screenshot PNG] [--size WxH]``

Without ``--screenshot`` it opens the window and runs the event loop. With it, it renders the
main window to a PNG and exits, after the run finished when ``--run`` is given, so that a
picture can be taken on a machine without a screen (``QT_QPA_PLATFORM=offscreen`` is set
when there is no display). Exit codes: 0 ok; 1 the run was refused or did not succeed (with
``--screenshot --run``); 2 bad arguments or an unreadable plan (with ``--screenshot``);
3 the run did not finish within ``--timeout`` (the picture is still written).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

# NodeGraphQt loads Qt.py, which loads every Qt module, QtMultimedia too; with no audio server
# its backend lookup logs noise on every start. The Instructor plays no sound.
os.environ.setdefault("QT_LOGGING_RULES", "qt.multimedia*=false")

from PySide6.QtCore import QEvent, QEventLoop, QSettings, QTimer
from PySide6.QtGui import QIcon
from PySide6.QtWidgets import QApplication, QWidget

from capabilities.cells import cell_argument
from engine.files import plan_scene
from engine.library import LIBRARY_ENV
from engine.status import Status
from instructor_app.document.model import DocumentError
from instructor_app.main_window import Dialogs, MainWindow
from instructor_app.panels.cameras import camera_interfaces
from instructor_app.runtime.controller import RunOutcome
from instructor_app.runtime.session import CellSession
from instructor_app.settings import APPLICATION, ORGANIZATION, AppSettings
from instructor_app.stop_signals import quit_on_signals
from resources import plan_argument, resource_path

__all__ = [
    "main",
    "HeadlessDialogs",
    "EXIT_OK",
    "EXIT_RUN_FAILED",
    "EXIT_BAD_INPUT",
    "EXIT_TIMEOUT",
]

EXIT_OK, EXIT_RUN_FAILED, EXIT_BAD_INPUT, EXIT_TIMEOUT = 0, 1, 2, 3


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="costar-instructor",
        description="Teach a robot a task by composing a behavior tree.",
    )
    parser.add_argument(
        "plan", nargs="?", help="a plan file (*.costar.json) or example:NAME (costar examples)"
    )
    parser.add_argument(
        "--cell",
        type=cell_argument,
        default="sim",
        help="the cell to work with: sim (the default, the simulated cell), "
        "none, or a cell file (*.cell.json); it opens after the window shows",
    )
    parser.add_argument("--seed", type=int, default=0, help="scene seed of the simulated cell")
    parser.add_argument(
        "--scene",
        help="scene of the simulated cell when the plan names none (name or path; default "
        "cup_to_bin), e.g. tending for the wire bender; a plan that names one opens on it",
    )
    parser.add_argument("--run", action="store_true", help="run the plan once it is open")
    parser.add_argument(
        "--library",
        metavar="FOLDER",
        help="the subtree library folder (default: $COSTAR_LIBRARY, else the "
        "setting, else the user's)",
    )
    parser.add_argument(
        "--screenshot",
        metavar="PNG",
        help="render the window to PNG and exit (after the run with --run)",
    )
    parser.add_argument(
        "--size",
        type=_size,
        default=(1920, 1080),
        metavar="WxH",
        help="with --screenshot: the window's size (default 1920x1080)",
    )
    parser.add_argument(
        "--timeout",
        type=float,
        default=120.0,
        help="with --screenshot --run: give up after this many seconds (exit 3)",
    )
    return parser


def _size(text: str) -> tuple[int, int]:
    """``1400x900`` -> (1400, 900)."""
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected WIDTHxHEIGHT such as 1400x900, got {text!r}"
        ) from None
    if width < 200 or height < 200:
        raise argparse.ArgumentTypeError(f"{text!r} is too small: at least 200x200")
    return width, height


def main(argv: Sequence[str] | None = None) -> int:
    """Run the Instructor; returns the exit code."""
    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:  # argparse exits on --help (0) and on bad arguments (2)
        return int(exc.code or 0)
    if args.library:  # the option beats the environment and the setting (engine.library)
        os.environ[LIBRARY_ENV] = args.library
    if args.plan:
        try:
            args.plan = plan_argument(args.plan)
        except FileNotFoundError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return EXIT_BAD_INPUT
    if args.screenshot and not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    app = QApplication.instance() or QApplication(
        [sys.argv[0] if sys.argv else "costar-instructor"]
    )
    app.setOrganizationName(ORGANIZATION)
    app.setApplicationName(APPLICATION)
    app.setWindowIcon(QIcon(str(resource_path("icons", "costar-instructor.svg"))))
    if args.screenshot:
        return _screenshot(args)
    return _interactive(args)


def _start_session(args: argparse.Namespace, speed: float | None) -> CellSession:
    """A session on the cell without a robot (opens at once), so that the window can show
    before the cell asked for is open; the window then opens that one in the background.
    """
    session = CellSession(args.cell, seed=args.seed, scene=args.scene, speed=speed)
    if args.plan:  # the scene the plan was taught on, so that opening it reopens nothing
        session.scene = plan_scene(args.plan) or args.scene
    session.open("none")
    return session


def _interactive(args: argparse.Namespace) -> int:
    session = _start_session(args, speed=1.0)  # real time on screen
    session.cell_failed.connect(lambda message: print(f"error: {message}", file=sys.stderr))
    restore = lambda: None  # noqa: E731
    try:
        window = MainWindow(session)

        def end_on_signal() -> None:  # as the close button, without asking to save
            window.shutdown(keep_recovery=True)
            session.close()  # the arm halts before the connection closes
            QApplication.quit()

        restore = quit_on_signals(window, end_on_signal)
        window.show()
        window.switch_cell(args.cell)
        QTimer.singleShot(0, window.offer_recoveries)
        if args.plan:
            QTimer.singleShot(0, lambda: _open_plan(window, args.plan, args.run))
        return QApplication.exec()
    finally:
        restore()
        session.close()


def _open_plan(window: MainWindow, plan: str, run: bool) -> None:
    """Open the plan of the command line; with ``--run``, run it once the cell is open."""
    if window.open_plan(plan) and run:
        _when_ready(window.session, window.controller.run)


def _when_ready(session: CellSession, then: Callable[[], object]) -> None:
    """Call ``then()`` once no cell is opening any more (at once when none is)."""
    if not session.opening:
        then()
        return

    def ready(_ok: bool) -> None:
        session.cell_ready.disconnect(ready)
        then()

    session.cell_ready.connect(ready)


def _wait_for_cell(session: CellSession) -> None:
    """Run the event loop until the cell that is opening is open (or failed)."""
    if not session.opening:
        return
    loop = QEventLoop()
    session.cell_ready.connect(loop.quit)
    loop.exec()
    session.cell_ready.disconnect(loop.quit)


def _wait_for_camera_pictures(window: MainWindow, timeout_s: float = 5.0) -> None:
    """Run the event loop until every camera of the cell shows a picture (bounded: a camera
    that never sends one leaves its pane empty in the picture, as it would on screen).
    """
    panel = window.cell_views.cameras
    cameras = set(camera_interfaces(window.session.cell))
    loop = QEventLoop()
    poll = QTimer()
    poll.setInterval(20)

    def check() -> None:
        if cameras <= set(panel.shown):
            loop.quit()

    poll.timeout.connect(check)
    QTimer.singleShot(int(timeout_s * 1000), loop.quit)
    poll.start()
    if not cameras <= set(panel.shown):
        loop.exec()
    poll.stop()


def _screenshot(args: argparse.Namespace) -> int:
    # As fast as possible when running for a picture; real time otherwise (nothing moves).
    session = _start_session(args, speed=None if args.run else 1.0)
    with tempfile.TemporaryDirectory(prefix="costar-shot-") as scratch:
        # A throwaway settings file and recovery folder: a picture never touches the user's.
        settings = AppSettings(QSettings(str(Path(scratch, "s.ini")), QSettings.Format.IniFormat))
        window = MainWindow(session, settings, HeadlessDialogs(), Path(scratch, "recovery"))
        try:
            window.switch_cell(args.cell)
            _wait_for_cell(session)  # the picture shows the cell asked for, ready
            if args.plan:
                try:
                    window.document.open(args.plan)
                except DocumentError as exc:
                    print(f"error: {exc}", file=sys.stderr)
                    return EXIT_BAD_INPUT
            window.resize(*args.size)
            window.arrange_cell_views()  # the picture's size may give them a column
            window.show()
            _wait_for_camera_pictures(window)  # shown: a hidden camera panel captures nothing
            code = _run_for_picture(window, args.timeout) if args.run else EXIT_OK
            _grab(window, Path(args.screenshot))
            return code
        finally:
            window.shutdown()
            window.hide()
            window.deleteLater()
            # Now, not when the application is torn down: a window container (the 3D
            # view's) in a window still waiting for deletion then crashes Qt.
            QApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete.value)
            session.close()


def _run_for_picture(window: MainWindow, timeout: float) -> int:
    controller = window.controller
    loop = QEventLoop()
    outcome: list[RunOutcome] = []
    refused: list[Any] = []

    def finished(result: object) -> None:
        assert isinstance(result, RunOutcome)
        outcome.append(result)
        loop.quit()

    controller.run_finished.connect(finished)
    controller.run_refused.connect(refused.extend)
    timer = QTimer()
    timer.setSingleShot(True)
    timer.timeout.connect(loop.quit)
    timer.start(int(timeout * 1000))
    if not controller.run():
        for problem in refused:
            print(problem, file=sys.stderr)
        return EXIT_RUN_FAILED
    loop.exec()
    if not outcome:
        print(f"error: the run did not finish within {timeout:g} s", file=sys.stderr)
        return EXIT_TIMEOUT
    print(f"run ended: {outcome[0].status.value} after {outcome[0].event.tick} ticks")
    # A run its conditions skipped did what it was told: nothing failed.
    return EXIT_OK if outcome[0].status in (Status.SUCCESS, Status.SKIPPED) else EXIT_RUN_FAILED


def _node_to_show(window: MainWindow) -> str | None:
    """The node the picture's inspector shows: the failing node, else the first motion."""
    failed = window.controller.statuses
    for node_id, status in failed.items():
        if status is Status.FAILURE and not window.document.node(node_id).children:
            return node_id
    first_op = None
    for _, node in window.document.plan.walk():
        if node.op and node.op.startswith("motion.") and node.params:
            return node.id
        first_op = first_op or (node.id if node.op else None)
    return first_op


def _grab(window: MainWindow, path: Path) -> None:
    if window.views.validation.pending():  # the problems list shows the plan as it is
        window.views.validation.revalidate()
    shown = _node_to_show(window)
    if shown is not None:
        window.select_node(shown)
    # Dock layouts settle over a few event-loop turns (tabified docks re-parent their tab
    # bars); let them, so that the picture shows the window as a person would see it, and
    # fit the plan to the canvas's settled size.
    settle = QEventLoop()
    QTimer.singleShot(200, settle.quit)
    settle.exec()
    window.views.canvas.fit_all()
    QApplication.processEvents()
    path.parent.mkdir(parents=True, exist_ok=True)
    picture = window.grab()
    window.cell_views.scene3d.draw_view_into(picture, window)
    if not picture.save(str(path), "PNG"):
        raise OSError(f"could not write {path}")
    print(f"wrote {path}")


class HeadlessDialogs(Dialogs):
    """No person to ask: never save, never restore, errors go to stderr."""

    def ask_save_changes(self, parent: QWidget, name: str) -> str:
        return "discard"

    def ask_restore(self, parent: QWidget, description: str) -> bool:
        return False

    def error(self, parent: QWidget, title: str, text: str) -> None:
        print(f"error: {title}: {text}", file=sys.stderr)

    def ask_text(self, parent: QWidget, title: str, label: str, text: str) -> str | None:
        return None


if __name__ == "__main__":
    sys.exit(main())
