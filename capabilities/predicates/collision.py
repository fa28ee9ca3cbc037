"""Distances between object models at recognised poses, in a private pybullet client.

The predicates capability keeps its own DIRECT client holding one static body per object
model (its collision shape from the library: box, compound of boxes, cylinder, or the
convex hull of the mesh) and one for the tool; a query places the bodies at the given
poses and asks pybullet for their closest points. The simulator's client is never used:
this works the same on the real cell, from what perception recognised.
"""

from __future__ import annotations

import contextlib
import importlib
import math
import threading
from typing import Any

from capabilities.errors import CapabilityError
from engine.types import Pose

__all__ = ["CollisionWorld", "PredicateError", "TOOL"]

TOOL = "__tool__"
_FAR = 1.0  # m: distances beyond this are reported as infinity


class PredicateError(CapabilityError):
    """A predicate cannot be evaluated (an unknown model, a missing interface)."""


class CollisionWorld:
    """A private pybullet DIRECT client with the library's shapes; safe from any thread.

    Args:
        library: the object library (``get(name)`` -> ObjectModelSpec).
        tool_size: full size (m) of the tool's box.
        tool_center: the box centre in the TCP frame (default: from the flange to just past
            the TCP, like a parallel gripper whose fingertips reach 1.5 cm past its TCP).
    """

    def __init__(
        self,
        library: Any,
        tool_size: tuple[float, float, float] = (0.06, 0.12, 0.16),
        tool_center: tuple[float, float, float] = (0.0, 0.0, -0.065),
    ) -> None:
        # Imported here: loading the capability (the palette, the CLI) needs no pybullet.
        p = importlib.import_module("capabilities.bullet").pybullet
        self._p = p
        self._library = library
        self._lock = threading.Lock()
        self._client = p.connect(p.DIRECT)
        self._bodies: dict[str, int] = {}
        self._tool_center = Pose(tool_center)
        half = [s / 2 for s in tool_size]
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=self._client)
        self._bodies[TOOL] = p.createMultiBody(0.0, shape, physicsClientId=self._client)

    def close(self) -> None:
        """Disconnect the private client (idempotent)."""
        p = self._p
        with self._lock:
            if self._client >= 0:
                p.disconnect(self._client)
                self._client = -1

    def __del__(self) -> None:
        # At interpreter shutdown pybullet may be gone already.
        with contextlib.suppress(Exception):
            self.close()

    def distance(self, a: tuple[str, Pose], b: tuple[str, Pose]) -> float:
        """Signed distance (m) between two models at poses: negative when they overlap,
        ``inf`` when more than 1 m apart. A name of ``TOOL`` is the tool at a TCP pose.
        """
        with self._lock:
            if self._client < 0:
                raise PredicateError("the collision world is closed")
            body_a, body_b = self._place(*a), self._place(*b)
            points = self._p.getClosestPoints(body_a, body_b, _FAR, physicsClientId=self._client)
        if not points:
            return math.inf
        return float(min(point[8] for point in points))

    def _place(self, name: str, pose: Pose) -> int:
        p = self._p
        body = self._body(name)
        if name == TOOL:
            pose = pose.compose(self._tool_center)
        p.resetBasePositionAndOrientation(
            body, pose.position, pose.orientation, physicsClientId=self._client
        )
        return body

    def _body(self, name: str) -> int:
        p = self._p
        if name not in self._bodies:
            shape = self._shape(name)
            self._bodies[name] = p.createMultiBody(0.0, shape, physicsClientId=self._client)
        return self._bodies[name]

    def _shape(self, name: str) -> int:
        p = self._p
        try:
            spec = self._library.get(name)
        except Exception as exc:  # an unknown model: say which, as the predicate's failure
            raise PredicateError(f"no object model {name!r}: {exc}") from exc
        c, client = spec.collision, self._client
        if c.kind == "cylinder":
            return int(
                p.createCollisionShape(
                    p.GEOM_CYLINDER,
                    radius=c.radius,
                    height=c.height,
                    collisionFramePosition=(0.0, 0.0, c.height / 2),
                    physicsClientId=client,
                )
            )
        if c.kind in ("box", "compound"):
            return int(
                p.createCollisionShapeArray(
                    [p.GEOM_BOX] * len(c.boxes),
                    halfExtents=[[s / 2 for s in b.size] for b in c.boxes],
                    collisionFramePositions=[list(b.position) for b in c.boxes],
                    physicsClientId=client,
                )
            )
        if c.kind == "convex_hull":
            return int(
                p.createCollisionShape(
                    p.GEOM_MESH, fileName=str(spec.mesh_file), physicsClientId=client
                )
            )
        raise PredicateError(f"object model {name!r} has an unknown collision type {c.kind!r}")
