"""The template capability, tested the way every capability should be."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from capabilities.base import CapabilityRegistry, NullCell
from capabilities.template import capability
from engine.build import build_tree
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ParamType


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
