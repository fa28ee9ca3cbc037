"""A camera's smaller live preview (the camera panel's 320x240) and the furniture in the scene
layout (the 3D scene's table and holster).
"""

from __future__ import annotations

import numpy as np

from capabilities.sim.session import SimCellSession


def test_a_preview_renders_the_same_view_at_a_smaller_size() -> None:
    with SimCellSession("cup_to_bin", seed=0, shoulder_size=(640, 480)) as cell:
        camera = cell.cameras["shoulder"]
        full, small = camera.capture(), camera.capture(size=(320, 240))
        assert full.rgb.shape == (480, 640, 3) and small.rgb.shape == (240, 320, 3)
        assert np.isclose(small.K[1, 1], full.K[1, 1] / 2)  # same field of view
        assert small.T_world_camera == full.T_world_camera
        # The same scene: the median depth of the two pictures agrees within a centimetre.
        assert abs(np.nanmedian(full.depth) - np.nanmedian(small.depth)) < 0.01
        fixtures = {name: size for name, _pose, size in cell.scene_layout()["fixtures"]}
        assert set(fixtures) == {"table", "holster"}
        assert fixtures["table"] == cell.sim.config.table.size
