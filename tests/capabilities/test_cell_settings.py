"""The cell file's ``capabilities`` block reaches the capabilities, checked."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.kit import CapabilitySettingsError
from capabilities.robot.cell_file import DEFAULT_CONFIG_PATH, CellConfig


def test_the_shipped_cell_file_gives_valid_settings() -> None:
    config = CellConfig.load()
    assert config.source == str(DEFAULT_CONFIG_PATH)
    assert set(config.capabilities) >= {"occupancy", "predicates", "perception"}
    registry = CapabilityRegistry(settings=config.capabilities, settings_source=config.source)
    assert registry.settings("occupancy")["table_margin"] == 0.008
    assert registry.settings("predicates")["tool_size"] == (0.06, 0.12, 0.16)


def _edited(tmp_path: Path, block: dict[str, object]) -> CellConfig:
    data = json.loads(DEFAULT_CONFIG_PATH.read_text(encoding="utf-8"))
    data["capabilities"] = block
    path = tmp_path / "my.cell.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return CellConfig.load(path)


def test_an_explicit_zero_is_zero(tmp_path: Path) -> None:
    config = _edited(tmp_path, {"occupancy": {"table_margin": 0, "mask_inflate": 0.0}})
    registry = CapabilityRegistry(settings=config.capabilities, settings_source=config.source)
    assert registry.settings("occupancy")["table_margin"] == 0.0
    assert registry.settings("occupancy")["mask_inflate"] == 0.0


@pytest.mark.parametrize(
    ("block", "where"),
    [
        ({"occupancy": {"table_margn": 0.01}}, "occupancy.table_margn: unknown setting"),
        ({"occupancy": {"table_margin": "8 mm"}}, "occupancy.table_margin: expected a number"),
        ({"perception": {"stride": 2.5}}, "perception.stride: expected an integer"),
    ],
)
def test_a_bad_setting_names_the_file_and_the_key(
    tmp_path: Path, block: dict[str, object], where: str
) -> None:
    config = _edited(tmp_path, block)
    with pytest.raises(CapabilitySettingsError) as caught:
        CapabilityRegistry(settings=config.capabilities, settings_source=config.source)
    assert str(caught.value).startswith(f"{tmp_path / 'my.cell.json'}: $.capabilities.{where}")
