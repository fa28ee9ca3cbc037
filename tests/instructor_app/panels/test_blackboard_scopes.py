"""The Blackboard panel: scopes (plan, shared names, subtree instances), writers and ticks,
and what it does with typed values (read in mm and degrees, or refused with a message).
"""

from __future__ import annotations

from pytestqt.qtbot import QtBot

from engine.blackboard import OPERATOR, BlackboardEntry
from engine.types import ParamType, Pose
from instructor_app.panels.blackboard import TICK, TIME, WRITER, BlackboardPanel


def entry(key: str, value: object, writer: str = "", tick: int = 0) -> BlackboardEntry:
    ptype = ParamType.POSE if isinstance(value, Pose) else None
    return BlackboardEntry(key, value, ptype, writer, tick, tick * 0.05)


def test_every_scope_is_shown_by_its_name(qtbot: QtBot) -> None:
    panel = BlackboardPanel()
    qtbot.addWidget(panel)
    panel.set_shared_names({"PART"})
    panel.set_entries(
        [
            entry("Pick#ab12cd/GRASP", Pose((0.4, 0.0, 0.3)), "ab12cd.../f00d", 4),
            entry("PART", "plate", "plan"),
            entry("Pick#ab12cd/Lift#99aa00/HEIGHT", 0.1),
            entry("TARGET", Pose(), "plan"),
            entry("Place#ee0000/GRASP", Pose()),
        ]
    )
    assert panel.scopes() == ["Plan", "Shared names", "Pick", "Pick > Lift", "Place"]
    assert panel.item("Pick#ab12cd/GRASP").text(0) == "GRASP"
    assert panel.item("Pick#ab12cd/GRASP").parent().text(0) == "Pick"
    assert panel.item("PART").parent().text(0) == "Shared names"


def test_writer_tick_and_time_are_shown_with_node_names(qtbot: QtBot) -> None:
    panel = BlackboardPanel()
    qtbot.addWidget(panel)
    panel.set_writer_names({"n1": "find target"}.get)
    panel.set_entry(entry("TARGET", Pose(), "plan"))
    assert panel.text_of("TARGET", WRITER) == "plan (start value)"
    panel.set_entry(entry("TARGET", Pose((0.4, 0.0, 0.3)), "n1", 7))
    assert panel.text_of("TARGET", WRITER) == "find target"
    assert (panel.text_of("TARGET", TICK), panel.text_of("TARGET", TIME)) == ("7", "0.35 s")
    panel.set_entry(entry("TARGET", Pose(), OPERATOR, 7))
    assert panel.text_of("TARGET", WRITER) == "you (while paused)"


def test_typed_values_are_read_in_their_type_or_refused(qtbot: QtBot) -> None:
    panel = BlackboardPanel()
    qtbot.addWidget(panel)
    panel.set_entry(entry("TARGET", Pose(), "plan"))
    panel.set_entry(entry("COUNT", 3.0, "plan"))
    edited: list[tuple[str, object]] = []
    panel.value_edited.connect(lambda key, value: edited.append((key, value)))
    panel.typed("COUNT", "4")
    assert edited == [] and "only while paused" in panel.message.text()
    panel.set_editable(True)
    assert panel.item("TARGET").flags() & panel.item("TARGET").flags().ItemIsEditable
    panel.typed("TARGET", "(500, 0, 200) mm, rpy (180, 0, 0)°")
    panel.typed("COUNT", "four")  # undeclared: read as the number it holds
    assert [key for key, _ in edited] == ["TARGET"]
    assert edited[0][1].position == (0.5, 0.0, 0.2)  # type: ignore[attr-defined]
    assert "COUNT holds a Number" in panel.message.text()
    assert panel.message.property("error") is True


def test_a_run_writing_many_names_costs_no_change_signal_per_cell(qtbot: QtBot) -> None:
    panel = BlackboardPanel()
    qtbot.addWidget(panel)
    keys = [f"Pick#ab12cd/K{i}" if i % 2 else f"K{i}" for i in range(200)]
    panel.set_entries([entry(key, 0.0, "n1", 1) for key in keys])
    changes: list[object] = []
    panel.tree.model().dataChanged.connect(lambda *args: changes.append(args))
    panel.set_entries([entry(key, 2.0, "n1", 2) for key in keys])
    assert changes == []  # held: one repaint instead
    assert all(panel.text_of(key) == "2" and panel.text_of(key, TICK) == "2" for key in keys)
