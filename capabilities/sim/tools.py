"""What the gripper and the suction tool share: body frames, fixed attachments, contacts.

Grasping in pybullet by friction alone is fragile, so a tool that has closed on an object
attaches it with a fixed constraint (and detaches it on release): the simulator's stand-in
for friction or vacuum, decided by contact, never by perception.
"""

from __future__ import annotations

import numpy as np

from capabilities.bullet import pybullet
from capabilities.sim.transforms import matrix_to_pose, pose_to_matrix
from engine.types import Pose

__all__ = [
    "attach",
    "body_frame_matrix",
    "body_frame_pose",
    "detach",
    "is_dynamic",
    "link_com_matrix",
]

_ATTACH_FORCE = 400.0  # N: holds a few kg through fast moves


def _matrix(position: tuple[float, ...], orientation: tuple[float, ...]) -> np.ndarray:
    return pose_to_matrix(Pose.of(position, orientation))


def body_frame_matrix(client: int, body: int) -> np.ndarray:
    """World matrix of a body's URDF/base frame (pybullet reports the centre of mass)."""
    pos, orn = pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
    info = pybullet.getDynamicsInfo(body, -1, physicsClientId=client)
    com_in_frame = _matrix(info[3], info[4])
    return _matrix(pos, orn) @ np.linalg.inv(com_in_frame)


def body_frame_pose(client: int, body: int) -> Pose:
    """World pose of a body's URDF/base frame."""
    return matrix_to_pose(body_frame_matrix(client, body))


def link_com_matrix(client: int, body: int, link: int) -> np.ndarray:
    """World matrix of a link's centre-of-mass frame (what constraints are relative to)."""
    if link < 0:
        pos, orn = pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
        return _matrix(pos, orn)
    state = pybullet.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=client)
    return _matrix(state[0], state[1])


def is_dynamic(client: int, body: int) -> bool:
    """True for a body that can move (its base has mass)."""
    return float(pybullet.getDynamicsInfo(body, -1, physicsClientId=client)[0]) > 0.0


def attach(client: int, parent: int, parent_link: int, child: int) -> int:
    """Fix ``child`` to a link of ``parent`` where it is now; returns the constraint id."""
    parent_m = link_com_matrix(client, parent, parent_link)
    child_m = link_com_matrix(client, child, -1)
    rel = matrix_to_pose(np.linalg.inv(parent_m) @ child_m)
    cid = pybullet.createConstraint(
        parent,
        parent_link,
        child,
        -1,
        pybullet.JOINT_FIXED,
        (0.0, 0.0, 0.0),
        rel.position,
        (0.0, 0.0, 0.0),
        parentFrameOrientation=rel.orientation,
        childFrameOrientation=(0.0, 0.0, 0.0, 1.0),
        physicsClientId=client,
    )
    pybullet.changeConstraint(cid, maxForce=_ATTACH_FORCE, physicsClientId=client)
    pybullet.changeDynamics(  # a part asleep on the table moves with the tool from now on
        child, -1, activationState=pybullet.ACTIVATION_STATE_WAKE_UP, physicsClientId=client
    )
    return int(cid)


def detach(client: int, constraint: int) -> None:
    """Remove an attachment made by ``attach``."""
    pybullet.removeConstraint(constraint, physicsClientId=client)
