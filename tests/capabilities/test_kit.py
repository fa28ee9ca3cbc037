"""The capability kit: the manifest helper, per-cell state factories, cameras, settings."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import pytest

from capabilities.base import CapabilityEnv
from capabilities.kit import CapabilitySettingsError, Setting, camera, manifest
from engine.operations import OperationFailed, OperationKind, PortSpec
from engine.types import ParamType, Pose


class _Cell:
    name = "kit"

    def interfaces(self) -> Mapping[str, Any]:
        return {"rgbd:shoulder": "the shoulder camera"}

    def clock(self) -> float:
        return 0.0


def test_manifest_makes_the_id_from_the_capability() -> None:
    port = PortSpec("colour", (ParamType.TEXT,), default="red")
    made = manifest("lamp", "is_lit", OperationKind.CONDITION, "lit?", port, aliases=("lamp.lit",))
    assert (made.id, made.capability, made.ports, made.aliases) == (
        "lamp.is_lit",
        "lamp",
        (port,),
        ("lamp.lit",),
    )


def test_camera_finds_the_interface_or_says_which_is_missing() -> None:
    env = CapabilityEnv(_Cell(), "lamp")
    assert camera(env, "shoulder") == "the shoulder camera"
    with pytest.raises(OperationFailed, match="the kit cell has no wrist camera"):
        camera(env, "wrist")


@pytest.mark.parametrize(
    ("setting", "value", "expected"),
    [
        (Setting("a", float), 0, 0.0),
        (Setting("a", int), 0, 0),
        (Setting("a", bool), False, False),
        (Setting("a", str), "", ""),
        (Setting("a", tuple, size=2), [0, 1.5], (0.0, 1.5)),
        (Setting("a", Pose), {"position": [0, 0, 1], "orientation": [0, 0, 0, 1]}, Pose((0, 0, 1))),
    ],
)
def test_settings_parse_their_json_form_and_keep_zero(
    setting: Setting, value: Any, expected: Any
) -> None:
    assert setting.parse(value, "f") == expected


@pytest.mark.parametrize(
    ("setting", "value"),
    [(Setting("a", tuple, size=2), [1.0]), (Setting("a", int), True), (Setting("a", str), 3),
     (Setting("a", Pose), [1, 2, 3])],
)  # fmt: skip
def test_settings_refuse_a_wrong_type_naming_where(setting: Setting, value: Any) -> None:
    with pytest.raises(CapabilitySettingsError, match=r"^cell\.json: \$\.capabilities\.x\.a"):
        setting.parse(value, "cell.json: $.capabilities.x.a")
