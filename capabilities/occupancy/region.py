"""Counting what occupies a sphere of space in a point cloud (numpy only, no cell).

A point inside the sphere counts unless it lies on the table plane (the table is the
ground things stand on, never an occupant) or inside the robot's own body (masked with the
body model's capsules). A region is occupied when at least ``min_points`` points remain.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from engine.types import Region

__all__ = ["RegionReading", "estimate_table_z", "read_region"]

# The table must hold this share of a frame's points to be taken for the dominant plane.
_MIN_TABLE_SHARE = 0.15
_BIN = 0.004  # m: histogram bins of the plane search


@dataclass(frozen=True)
class RegionReading:
    """What one point cloud says about a region.

    Attributes:
        points: points that count as an occupant.
        in_region: all points inside the sphere.
        table: points inside the sphere dropped as the table surface.
        robot: points inside the sphere dropped as the robot's own body.
    """

    points: int
    in_region: int
    table: int
    robot: int

    def occupied(self, min_points: int) -> bool:
        """True when at least ``min_points`` points count."""
        return self.points >= min_points

    def describe(self, min_points: int) -> str:
        """One line for the run's log: what was counted and what was dropped."""
        return (
            f"{self.points} points in the region (needs {min_points}); "
            f"dropped {self.table} on the table, {self.robot} on the robot"
        )


def estimate_table_z(points: np.ndarray) -> float | None:
    """Height (m) of the table plane in a point cloud, or None if there is none.

    The table seen from above fills much of a frame, and so may the floor below it: the
    table is the highest 4 mm slice of heights (with a neighbour, as a plane may straddle
    two slices) that holds 15% of the points, refined by the median of the points near it.
    """
    if len(points) < 100:
        return None
    z = points[:, 2]
    lo, hi = float(np.min(z)), float(np.max(z))
    bins = max(1, int(np.ceil((hi - lo) / _BIN)) + 1)
    counts, edges = np.histogram(z, bins=bins, range=(lo, lo + bins * _BIN))
    padded = np.concatenate(([0], counts, [0]))
    pairs = counts + np.maximum(padded[:-2], padded[2:])
    planes = np.flatnonzero(pairs >= _MIN_TABLE_SHARE * len(points))
    if len(planes) == 0:
        return None
    top = int(planes[-1])
    # The fullest slice near the highest plane found.
    best = max(range(max(0, top - 1), min(bins, top + 2)), key=lambda i: counts[i])
    centre = (edges[best] + edges[best + 1]) / 2
    near = z[np.abs(z - centre) <= _BIN * 1.5]
    return float(np.median(near))


def read_region(
    points: np.ndarray,
    region: Region,
    table_z: float | None,
    table_margin: float,
    robot_mask: Callable[[np.ndarray], np.ndarray] | None = None,
) -> RegionReading:
    """Count the occupant points of ``region`` in an Nx3 world point cloud.

    Args:
        points: Nx3 world points (m).
        region: the sphere.
        table_z: height of the table plane (None: no table removal).
        table_margin: points closer than this (m) to the table plane are the table.
        robot_mask: maps Mx3 points to a boolean mask of those on the robot (None: no mask).
    """
    centre = np.asarray(region.center, dtype=float)
    offsets = points - centre
    inside = points[np.einsum("ij,ij->i", offsets, offsets) <= region.radius**2]
    in_region = len(inside)
    table = 0
    if table_z is not None and in_region:
        on_table = np.abs(inside[:, 2] - table_z) <= table_margin
        table = int(np.count_nonzero(on_table))
        inside = inside[~on_table]
    robot = 0
    if robot_mask is not None and len(inside):
        on_robot = robot_mask(inside)
        robot = int(np.count_nonzero(on_robot))
        inside = inside[~on_robot]
    return RegionReading(len(inside), in_region, table, robot)
