"""The live view's floor and table top, drawn by numpy into pictures rendered without them, are
what pybullet's renderer draws for the same surfaces as boxes: the same colour on every pixel,
the same depth, objects in front of them kept, nothing past their edges or beyond ``far``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

import numpy as np
import pytest

from capabilities.bullet import pybullet as p
from capabilities.robot.camera_mounts import look_at
from capabilities.robot.cell_file import CellConfig
from capabilities.sim.cameras import CameraConfig, FixedMount, SimCamera
from capabilities.sim.flat_surfaces import FlatSurfaces
from capabilities.sim.world import build_world, light_surfaces

pytestmark = pytest.mark.sim

CONFIG = CellConfig()
VIEWS = {
    # (eye, target): the shoulder camera's view, close over the table's corner (floor and
    # table top fill the picture), from past the floor's edge (the background shows), low
    # over the table looking at the cube, and from under the table top's height
    "shoulder": ((-0.15, 0.45, 1.50), (0.58, -0.02, 0.0)),
    "corner": ((1.05, -0.7, 0.35), (0.85, -0.5, -0.2)),
    "edge": ((0.6, 2.2, 1.0), (0.6, 3.5, -0.75)),
    "low": ((0.2, 0.35, 0.08), (0.6, 0.0, 0.03)),
    "under": ((1.4, 0.3, -0.3), (0.55, 0.0, -0.3)),
}


def _box(client: int, half: tuple[float, ...], centre: tuple[float, ...], rgba: tuple) -> None:
    visual = p.createVisualShape(
        p.GEOM_BOX, halfExtents=half, rgbaColor=rgba, physicsClientId=client
    )
    p.createMultiBody(0.0, -1, visual, basePosition=centre, physicsClientId=client)


def _world(with_boxes: bool) -> int:
    """The light world with a cube on the table; ``with_boxes``: the floor and the table top
    as pybullet boxes (the reference), else without them.
    """
    client = p.connect(p.DIRECT)
    build_world(client, CONFIG, light=True)
    _box(client, (0.03, 0.03, 0.03), (0.6, 0.0, 0.03), (0.8, 0.1, 0.1, 1.0))
    if with_boxes:
        floor, table = light_surfaces(CONFIG)
        half = CONFIG.table.size[0] / 2, CONFIG.table.size[1] / 2, CONFIG.table.size[2] / 2
        _box(client, half, (*CONFIG.table.center, table.z - half[2]), table.rgba)
        _box(client, (floor.x[1], floor.y[1], 0.005), (0.0, 0.0, floor.z - 0.005), floor.rgba)
    return client


@pytest.fixture(scope="module")
def clients() -> Iterator[tuple[int, int]]:
    boxes, drawn = _world(True), _world(False)
    yield boxes, drawn
    p.disconnect(boxes)
    p.disconnect(drawn)


@pytest.mark.parametrize("view", sorted(VIEWS))
def test_drawn_surfaces_are_the_renderers_to_the_pixel(clients: tuple[int, int], view: str) -> None:
    boxes, drawn = clients
    camera = SimCamera(view, CameraConfig(near=0.05, far=3.0), FixedMount(look_at(*VIEWS[view])))
    surfaces = FlatSurfaces(light_surfaces(CONFIG), camera.config.light_direction)
    exact = camera.capture(boxes)
    plain = camera.capture(drawn)
    ours = camera.capture(drawn, surfaces=surfaces)
    assert np.array_equal(ours.rgb, exact.rgb), (
        f"{view}: {np.sum(ours.rgb != exact.rgb)} values differ"
    )
    assert np.array_equal(np.isnan(ours.depth), np.isnan(exact.depth))
    both = np.isfinite(exact.depth)
    np.testing.assert_allclose(ours.depth[both], exact.depth[both], atol=1e-4)
    if view != "under":  # the surfaces are seen (from under the table top, only the floor)
        assert np.mean(ours.rgb != plain.rgb) > 0.1


def test_a_surface_seen_from_below_and_a_camera_nearer_than_far_draw_nothing_there() -> None:
    client = _world(False)
    try:
        config = dataclasses.replace(CameraConfig(), far=0.5)  # the floor is 0.75 m below
        camera = SimCamera("short", config, FixedMount(look_at((0.5, 0.0, 0.3), (0.52, 0.0, -1.0))))
        surfaces = FlatSurfaces(light_surfaces(CONFIG), config.light_direction)
        ours = camera.capture(client, surfaces=surfaces)
        assert np.nanmax(ours.depth) < 0.5
        assert np.isclose(np.nanmedian(ours.depth), 0.3, atol=1e-3)  # the table top, 0.3 m down
        below = SimCamera(
            "below", CameraConfig(), FixedMount(look_at((0.5, 0.0, -1.0), (0.52, 0.0, 1.0)))
        )
        seen = below.capture(client, surfaces=surfaces)
        assert np.array_equal(seen.rgb, below.capture(client).rgb)  # under the floor: not drawn
    finally:
        p.disconnect(client)
