"""The cell configuration file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from capabilities.sim.config import DEFAULT_CONFIG_PATH, CellConfig
from capabilities.sim.errors import SimError


def test_default_file_matches_the_built_in_defaults() -> None:
    assert CellConfig.load(DEFAULT_CONFIG_PATH) == CellConfig()
    assert CellConfig.from_json(CellConfig().to_json()) == CellConfig()


def test_a_bad_field_names_the_file_and_json_path(tmp_path: Path) -> None:
    data = CellConfig().to_json()
    data["holster_pose"]["position"] = [0.1, "x", 0.0]
    path = tmp_path / "cell.json"
    path.write_text(json.dumps(data))
    with pytest.raises(SimError, match=r"cell\.json.*\$\.holster_pose\.position"):
        CellConfig.load(path)
