"""Run > Publish Runs for Groot2: the controller serves each run to a Groot2 client."""

from __future__ import annotations

import socket
from pathlib import Path
from typing import Any

from PySide6.QtCore import QSettings

from engine.files import dump_plan
from engine.status import Status
from instructor_app.runtime.controller import RunController
from instructor_app.runtime.session import CellSession
from instructor_app.settings import GROOT2_PORT, AppSettings
from tests.capabilities.groot2.groot2_client import Client, free_port_pair
from tests.instructor_app.gui_driver import ScriptedDialogs, make_window
from tests.instructor_app.runtime.plans import endless_plan
from tests.instructor_app.runtime.test_run_controller import finish, make

RUNNING = 1


def test_runs_are_published_while_the_setting_is_on(qtbot: Any, none_session: CellSession) -> None:
    document, controller, seen = make(none_session)
    document.load_text(dump_plan(endless_plan()), None)
    slow = next(n.id for _, n in document.plan.walk() if n.name == "slow")
    port = free_port_pair()
    controller.set_groot2_port(port)
    client = Client(port)
    try:
        tree_ids = []
        for _ in range(2):  # the publisher stays up between runs; each run is a new tree
            controller.run()
            qtbot.waitUntil(lambda: controller.statuses.get(slow) is Status.RUNNING)
            tree_id, uid_of = client.uids()
            statuses = client.statuses_once(uid_of["slow"], RUNNING)
            assert statuses == {uid_of["top"]: RUNNING, uid_of["slow"]: RUNNING}
            tree_ids.append(tree_id)
            finish(qtbot, controller, controller.stop)
        assert tree_ids[0] != tree_ids[1]
    finally:
        client.close()
        controller.set_groot2_port(None)
    assert any(text == f"Groot2: publishing the runs on 127.0.0.1:{port}" for text, _ in seen.logs)
    with socket.socket() as again:  # turned off: the port is free
        again.bind(("127.0.0.1", port))


def test_a_taken_port_is_logged_and_the_run_goes_on(qtbot: Any, none_session: CellSession) -> None:
    document, controller, seen = make(none_session)
    document.load_text(dump_plan(endless_plan()), None)
    port = free_port_pair()
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", port))
        taken.listen()
        controller.set_groot2_port(port)
        assert controller.run()
        finish(qtbot, controller, controller.stop)
    assert any("Groot2: not published" in t and "taken" in t for t, lvl in seen.logs)


def test_the_setting_and_its_port_are_kept(tmp_path: Path) -> None:
    settings = AppSettings(QSettings(str(tmp_path / "s.ini"), QSettings.Format.IniFormat))
    assert (settings.groot2_publish(), settings.groot2_port()) == (False, GROOT2_PORT)
    settings.set_groot2_publish(True)
    settings.set_groot2_port(2000)
    again = AppSettings(QSettings(str(tmp_path / "s.ini"), QSettings.Format.IniFormat))
    assert (again.groot2_publish(), again.groot2_port()) == (True, 2000)


def test_controller_without_the_setting_publishes_nothing(none_session: CellSession) -> None:
    _, controller, _ = make(none_session)
    assert isinstance(controller, RunController)
    assert controller.groot2_port is None


def test_the_run_menu_turns_publishing_on_and_off_with_its_port(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, none_session, tmp_path, dialogs)
    publish = window.actions_by_name["groot2"]
    assert not publish.isChecked() and window.controller.groot2_port is None
    publish.trigger()
    assert window.settings.groot2_publish()
    assert window.controller.groot2_port == GROOT2_PORT  # bound only when a run starts
    dialogs.port_answers = [2001, None]
    window.actions_by_name["groot2_port"].trigger()
    assert window.controller.groot2_port == 2001 == window.settings.groot2_port()
    window.actions_by_name["groot2_port"].trigger()  # cancelled: kept
    assert window.controller.groot2_port == 2001
    publish.trigger()
    assert window.controller.groot2_port is None and not window.settings.groot2_publish()
