"""The capability framework: entry points, the registry, availability, aliases."""

from __future__ import annotations

import importlib.metadata
from collections.abc import Mapping
from typing import Any

import pytest

from capabilities.base import (
    ENTRY_POINT_GROUP,
    Capability,
    CapabilityEnv,
    CapabilityError,
    CapabilityRegistry,
    NullCell,
    load_entry_point_capabilities,
)
from capabilities.kit import CapabilitySettingsError, Setting
from engine.operations import Job, OperationKind, OperationManifest, OperationNotFound


class FakeCell:
    """A cell with the given interfaces."""

    name = "fake"

    def __init__(self, **interfaces: Any) -> None:
        self._interfaces = interfaces

    def interfaces(self) -> Mapping[str, Any]:
        return self._interfaces

    def clock(self) -> float:
        return 0.0


class Recorded:
    """An operation that keeps the env it was made with."""

    def __init__(self, env: CapabilityEnv) -> None:
        self.env = env

    def start(self, call: Any) -> Job:
        return Job.done()


def manifest(op_id: str, cap: str, aliases: tuple[str, ...] = ()) -> type[Recorded]:
    """An operation class of this manifest (the class a capability adds)."""
    made = OperationManifest(op_id, OperationKind.ACTION, "an operation", cap, aliases=aliases)
    return type("Recorded", (Recorded,), {"MANIFEST": made})


def capability(name: str, *ops: str, requires: tuple[str, ...] = ()) -> Capability:
    cap = Capability(name, f"the {name} capability", requires=requires)
    for op_id in ops:
        cap.add(manifest(op_id, name))
    return cap


# ---------------------------------------------------------------------- entry points


def test_the_debug_capability_is_found_through_its_entry_point() -> None:
    names = [e.name for e in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)]
    assert "debug" in names
    found = {c.name: c for c in load_entry_point_capabilities()}
    assert "debug" in found
    registry = CapabilityRegistry()  # default: every entry point
    assert "debug" in [c.name for c in registry.capabilities]
    assert registry.manifest("debug.succeed").capability == "debug"


class FakeEntryPoint:
    def __init__(self, name: str, made: Any) -> None:
        self.name = name
        self.value = f"fake.{name}:capability"
        self._made = made

    def load(self) -> Any:
        def make() -> Any:
            if isinstance(self._made, Exception):
                raise self._made
            return self._made

        return make


def use_entry_points(monkeypatch: pytest.MonkeyPatch, *entries: FakeEntryPoint) -> None:
    monkeypatch.setattr(importlib.metadata, "entry_points", lambda group: list(entries))


def test_entry_points_may_return_a_list_and_load_in_name_order(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    use_entry_points(
        monkeypatch,
        FakeEntryPoint("zeta", capability("zeta")),
        FakeEntryPoint("alpha", [capability("alpha"), capability("beta")]),
    )
    assert [c.name for c in load_entry_point_capabilities()] == ["alpha", "beta", "zeta"]


def test_a_broken_entry_point_is_named(monkeypatch: pytest.MonkeyPatch) -> None:
    use_entry_points(monkeypatch, FakeEntryPoint("broken", ImportError("no module named pybullet")))
    with pytest.raises(
        CapabilityError, match=r"entry point 'broken' \(fake.broken:capability\) failed: no module"
    ):
        load_entry_point_capabilities()


def test_an_entry_point_must_return_capabilities(monkeypatch: pytest.MonkeyPatch) -> None:
    use_entry_points(monkeypatch, FakeEntryPoint("odd", {"name": "odd"}))
    with pytest.raises(CapabilityError, match="'odd' returned dict, not a Capability"):
        load_entry_point_capabilities()


# ---------------------------------------------------------------------- registry


def test_duplicate_capability_names_are_refused() -> None:
    with pytest.raises(CapabilityError, match="two capabilities are called 'motion'"):
        CapabilityRegistry([capability("motion", "motion.a"), capability("motion", "motion.b")])


def test_an_operation_registered_twice_is_refused() -> None:
    cap = capability("motion", "motion.a")
    cap.add(manifest("motion.a", "motion"))
    with pytest.raises(CapabilityError, match=r"'motion\.a' is registered twice"):
        CapabilityRegistry([cap])


def test_operations_must_belong_to_their_capability() -> None:
    cap = Capability("motion", "moves")
    with pytest.raises(CapabilityError, match="belongs to 'gripper', not 'motion'"):
        cap.add(manifest("gripper.close", "gripper"))
    with pytest.raises(CapabilityError, match=r"must start with 'motion\.'"):
        cap.add(manifest("move_to", "motion"))


def test_unknown_operations_raise_operation_not_found() -> None:
    registry = CapabilityRegistry([capability("motion", "motion.a")])
    with pytest.raises(OperationNotFound):
        registry.manifest("motion.zzz")
    with pytest.raises(OperationNotFound):
        registry.availability("motion.zzz")
    with pytest.raises(OperationNotFound):
        registry.create("motion.zzz")


def test_aliases_resolve_to_the_current_operation() -> None:
    cap = Capability("motion", "moves")
    cap.add(manifest("motion.move_to", "motion", aliases=("motion.goto", "motion.go")))
    registry = CapabilityRegistry([cap])
    assert registry.manifest("motion.goto").id == "motion.move_to"
    assert isinstance(registry.create("motion.go"), Recorded)
    assert registry.aliases() == {"motion.goto": "motion.move_to", "motion.go": "motion.move_to"}
    assert [m.id for m in registry.manifests()] == ["motion.move_to"]


def test_availability_names_the_missing_interfaces() -> None:
    vision = capability("vision", "vision.detect", requires=("arm", "rgbd:wrist", "rgbd:shoulder"))
    plain = capability("plain", "plain.do")
    registry = CapabilityRegistry([vision, plain], cell=FakeCell(arm=object()))
    availability = registry.availability("vision.detect")
    assert not availability.available
    assert availability.reason == (
        "the fake cell has no rgbd:wrist, rgbd:shoulder (needed by the vision capability)"
    )
    assert registry.availability("plain.do").available


def test_the_default_cell_has_no_interfaces() -> None:
    registry = CapabilityRegistry([capability("arm", "arm.move", requires=("arm",))])
    assert isinstance(registry.cell, NullCell)
    assert "the none cell has no arm" in registry.availability("arm.move").reason


def _with_settings(setup: Any = None) -> Capability:
    cap = capability("motion", "motion.a")
    cap.settings = (
        Setting("speed", float, 0.5, "m/s"),
        Setting("margin", float, 0.01, "m"),
        Setting("count", int, 3),
    )
    cap.setup = setup
    return cap


def test_factories_get_the_cell_interfaces_and_their_settings() -> None:
    arm = object()
    registry = CapabilityRegistry(
        [_with_settings()], cell=FakeCell(arm=arm), settings={"motion": {"speed": 1, "margin": 0}}
    )
    first: Any = registry.create("motion.a")
    second = registry.create("motion.a")
    assert first is not second  # one instance per leaf
    env = first.env
    # declared defaults fill in; an int is a float for a float setting; an explicit 0 is 0
    assert (env.capability, dict(env.settings)) == (
        "motion",
        {"speed": 1.0, "margin": 0.0, "count": 3},
    )
    assert env.state is None
    assert env.interface("arm") is arm
    with pytest.raises(CapabilityError, match="the fake cell has no 'gripper' interface"):
        env.interface("gripper")


@pytest.mark.parametrize(
    ("settings", "expected"),
    [
        ({"motion": {"sped": 1.0}}, r"cell\.json: \$\.capabilities\.motion\.sped: unknown setting"),
        (
            {"motion": {"speed": "fast"}},
            r"\$\.capabilities\.motion\.speed: expected a number, got 'fast'",
        ),
        ({"motion": {"count": 2.5}}, r"\$\.capabilities\.motion\.count: expected an integer"),
        (
            {"motion": {"speed": True}},
            r"\$\.capabilities\.motion\.speed: expected a number, got True",
        ),
        ({"motion": []}, r"\$\.capabilities\.motion: expected an object"),
    ],
)
def test_bad_settings_name_the_file_and_the_key(settings: Any, expected: str) -> None:
    with pytest.raises(CapabilitySettingsError, match=expected):
        CapabilityRegistry([_with_settings()], settings=settings, settings_source="my.cell.json")


def test_setup_runs_once_per_cell_and_its_state_reaches_every_operation() -> None:
    made: list[CapabilityEnv] = []

    def setup(env: CapabilityEnv) -> dict[str, Any]:
        made.append(env)
        return {"speed": env.settings["speed"]}

    registry = CapabilityRegistry([_with_settings(setup)], settings={"motion": {"speed": 0.0}})
    first: Any = registry.create("motion.a")
    second: Any = registry.create("motion.a")
    assert len(made) == 1
    assert first.env.state is second.env.state
    assert first.env.state == {"speed": 0.0}
    other: Any = CapabilityRegistry([_with_settings(setup)]).create("motion.a")
    assert other.env.state is not first.env.state and len(made) == 2


def test_a_cell_supplies_its_settings_block() -> None:
    class FileCell(FakeCell):
        def capability_settings(self) -> tuple[dict[str, Any], str]:
            return {"motion": {"speed": "x"}}, "/cells/a.cell.json"

    with pytest.raises(
        CapabilitySettingsError, match=r"/cells/a\.cell\.json: \$\.capabilities\.motion\.speed"
    ):
        CapabilityRegistry([_with_settings()], cell=FileCell())


def test_a_block_for_no_installed_capability_is_an_error() -> None:
    with pytest.raises(
        CapabilitySettingsError, match=r"c\.json: \$\.capabilities\.motoin: no capability"
    ):
        CapabilityRegistry(settings={"motoin": {}}, settings_source="c.json")
    # a registry of chosen capabilities leaves the other capabilities' blocks alone
    CapabilityRegistry([_with_settings()], settings={"occupancy": {"x": 1}})
