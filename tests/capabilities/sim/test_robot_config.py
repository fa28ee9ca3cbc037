"""The cell configuration file."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from capabilities.robot.cell_file import DEFAULT_CONFIG_PATH, CellConfig, CellConfigError


def test_default_file_matches_the_built_in_defaults() -> None:
    loaded = CellConfig.load(DEFAULT_CONFIG_PATH)
    assert loaded.source == str(DEFAULT_CONFIG_PATH)
    # The file also gives capability settings (checked by the registry, tests/capabilities/
    # test_cell_settings.py); the built-in configuration leaves them to the capabilities.
    assert loaded.capabilities
    assert dataclasses.replace(loaded, capabilities={}) == CellConfig()
    assert CellConfig.from_json(CellConfig().to_json()) == CellConfig()


def test_a_bad_field_names_the_file_and_json_path(tmp_path: Path) -> None:
    data = CellConfig().to_json()
    data["holster_pose"]["position"] = [0.1, "x", 0.0]
    path = tmp_path / "cell.json"
    path.write_text(json.dumps(data))
    with pytest.raises(CellConfigError, match=r"cell\.json.*\$\.holster_pose\.position"):
        CellConfig.load(path)


def test_the_cell_file_describes_the_cameras() -> None:
    from capabilities.robot.cell_file import DEFAULT_CONFIG_PATH, CellConfig

    config = CellConfig.load(DEFAULT_CONFIG_PATH)
    assert set(config.cameras) == {"shoulder", "wrist"}
    assert config.cameras["shoulder"].size == (640, 480) and not config.cameras["shoulder"].on_wrist
    assert config.cameras["wrist"].on_wrist
    assert CellConfig.from_json(config.to_json()) == config


def test_a_bad_camera_entry_names_its_json_path() -> None:
    import pytest

    from capabilities.robot.cell_file import CellConfig, CellConfigError

    data = CellConfig().to_json()
    data["cameras"]["shoulder"]["size"] = [640, "tall"]
    with pytest.raises(
        CellConfigError, match=r"\$\.cameras\.shoulder\.size\[1\]: expected a whole"
    ):
        CellConfig.from_json(data)


def test_a_session_builds_the_configured_cameras() -> None:
    import dataclasses

    from capabilities.robot.cell_file import CellConfig
    from capabilities.sim.session import SimCellSession

    config = CellConfig()
    small = dataclasses.replace(config.cameras["shoulder"], size=(160, 120))
    config = dataclasses.replace(config, cameras={**config.cameras, "shoulder": small})
    with SimCellSession("empty", config=config) as session:
        frame = session.interfaces()["rgbd:shoulder"].capture()
        assert frame.rgb.shape == (120, 160, 3)
        assert frame.T_world_camera == small.pose
