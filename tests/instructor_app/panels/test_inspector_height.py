"""The inspector uses the height it has in the main window (issue 9: it had about 170 px)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import ScriptedDialogs, make_window


def test_the_inspector_gets_most_of_the_right_column(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path, ScriptedDialogs())
    window.resize(1400, 900)
    window.show()
    qtbot.waitExposed(window)
    inspector = window.views.inspector
    qtbot.waitUntil(lambda: inspector.parameter_area.height() > 0)
    # At 1400x900 it had 186 px under a Plan dock of 317 px; the Plan tabs now take what is left.
    assert inspector.parameter_area.height() >= 300
    assert window.docks["inspector"].height() >= 2 * window.docks["plan"].height()
