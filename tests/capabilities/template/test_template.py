"""The template capability, tested the way every capability should be."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import pytest

from capabilities.base import CapabilityEnv, CapabilityRegistry, NullCell
from capabilities.kit import CapabilitySettingsError, manifest
from capabilities.template import capability
from capabilities.template.operations import CAP, COLOUR, LampState
from engine.build import build_tree
from engine.operations import Job, OperationCall, OperationKind
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ParamType
from engine.validation import validate_plan


class LampCell:
    name = "lamp test cell"

    def __init__(self, lit: set[str]) -> None:
        self.lit = lit

    def interfaces(self) -> Mapping[str, Any]:
        return {"lamp": self}

    def is_lit(self, colour: str) -> bool:
        return colour in self.lit

    def clock(self) -> float:
        return 0.0


def _plan(colour: str) -> PlanSpec:
    node = NodeSpec(
        NodeKind.OPERATION,
        op="template.lamp_is_lit",
        params={"colour": Binding.fixed(colour, ParamType.TEXT)},
    )
    return PlanSpec(node, "lamp")


def test_condition_reads_the_backend() -> None:
    registry = CapabilityRegistry([capability()], cell=LampCell({"red"}))
    assert build_tree(_plan("red"), registry).tick() is Status.SUCCESS
    assert build_tree(_plan("green"), registry).tick() is Status.FAILURE


def test_unavailable_without_the_interface_and_says_why() -> None:
    registry = CapabilityRegistry([capability()], cell=NullCell())
    availability = registry.availability("template.lamp_is_lit")
    assert not availability.available
    assert "lamp" in availability.reason


def test_settings_come_from_the_cell_block_and_feed_the_state() -> None:
    registry = CapabilityRegistry(
        [capability()], cell=LampCell({"red"}), settings={"template": {"inverted": True}}
    )
    assert registry.settings("template") == {"inverted": True}
    assert build_tree(_plan("red"), registry).tick() is Status.FAILURE
    assert build_tree(_plan("green"), registry).tick() is Status.SUCCESS


def test_a_wrong_setting_names_the_file_and_key() -> None:
    with pytest.raises(
        CapabilitySettingsError,
        match=r"lamp\.cell\.json: \$\.capabilities\.template\.inverted: expected true or false",
    ):
        CapabilityRegistry([capability()], cell=LampCell(set()),
                           settings={"template": {"inverted": 0}}, settings_source="lamp.cell.json")  # fmt: skip
    with pytest.raises(CapabilitySettingsError, match=r"template\.colour: unknown setting"):
        CapabilityRegistry([capability()], cell=LampCell(set()),
                           settings={"template": {"colour": "red"}}, settings_source="x")  # fmt: skip


def test_a_new_operation_is_one_class_added_in_its_module() -> None:
    """CONTRIBUTING.md's "A new operation": the class (manifest, ports, start) and its
    ``cap.add`` are all it takes; the registry, validation and a built tree know it.
    """

    class LampIsDark:
        """template.lamp_is_dark (what a new operation in the module looks like)."""

        MANIFEST = manifest(
            CAP,
            "lamp_is_dark",
            OperationKind.CONDITION,
            "True when the light of the colour is off.",
            COLOUR,
        )

        def __init__(self, env: CapabilityEnv) -> None:
            self._state: LampState = env.state

        def start(self, call: OperationCall) -> Job:
            return Job.answer(not self._state.is_lit(call.input(COLOUR)))

    cap = capability()
    cap.add(LampIsDark)
    registry = CapabilityRegistry([cap], cell=LampCell({"red"}))
    assert registry.manifest("template.lamp_is_dark").port("colour") == COLOUR
    node = NodeSpec(
        NodeKind.OPERATION,
        op="template.lamp_is_dark",
        params={"colour": Binding.fixed("green", ParamType.TEXT)},
    )
    assert validate_plan(PlanSpec(node, "dark"), registry) == []
    assert build_tree(PlanSpec(node, "dark"), registry).tick() is Status.SUCCESS
    wrong = NodeSpec(
        NodeKind.OPERATION,
        op="template.lamp_is_dark",
        params={"colour": Binding.fixed("blue", ParamType.TEXT)},
    )
    assert [p.severity for p in validate_plan(PlanSpec(wrong, "dark"), registry)] == ["error"]
