"""The ``predicates`` capability: the paper's Predicator (IV-B).

Conditions about recognised objects: spatial relations in a chosen frame of reference,
motion over a time window, and contact (touching, near collision) between objects and
between the tool and an object, computed in a private pybullet client.
"""

from __future__ import annotations

from capabilities.predicates.collision import PredicateError
from capabilities.predicates.operations import capability

__all__ = ["PredicateError", "capability"]
