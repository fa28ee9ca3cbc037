"""Blackboard and log panels: values shown readably, lines kept up to a limit."""

from __future__ import annotations

import math

from pytestqt.qtbot import QtBot

from engine.types import Pose
from engine.units import rpy_to_quaternion
from instructor_app.panels.blackboard import BlackboardPanel
from instructor_app.panels.log import LogPanel


def test_blackboard_rows_sorted_and_updated(qtbot: QtBot) -> None:
    panel = BlackboardPanel()
    qtbot.addWidget(panel)
    panel.set_value("ZETA", 1.5)
    panel.set_values(
        {"ALPHA": True, "CUP_POSE": Pose((0.1, 0.2, 0.3), rpy_to_quaternion(0, 0, math.pi))}
    )
    plan = panel.tree.topLevelItem(0)
    names = [plan.child(r).text(0) for r in range(plan.childCount())]
    assert panel.scopes() == ["Plan"] and names == ["ALPHA", "CUP_POSE", "ZETA"]
    assert panel.text_of("CUP_POSE") == "(100.0, 200.0, 300.0) mm, rpy (0.0, 0.0, 180.0)°"
    panel.set_value("ZETA", 2.0)
    assert plan.childCount() == 3 and panel.text_of("ZETA") == "2"
    assert panel.values()["ALPHA"] is True
    panel.clear()
    assert panel.tree.topLevelItemCount() == 0 and panel.values() == {}


def test_log_lines_have_time_and_level_and_are_capped(qtbot: QtBot) -> None:
    panel = LogPanel(max_lines=3, clock=lambda: 1_700_000_000.25)
    qtbot.addWidget(panel)
    panel.append("started")
    panel.append("<b>not html</b>", level="warning")
    lines = panel.lines()
    assert lines[0].endswith(".250 INFO    started")
    assert "WARNING <b>not html</b>" in lines[1]
    for i in range(5):
        panel.append(f"line {i}", level="error")
    assert len(panel.lines()) == 3 and panel.lines()[-1].endswith("ERROR   line 4")
    panel.clear()
    assert panel.lines() == []
