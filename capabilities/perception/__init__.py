"""The ``perception`` capability: model-based object recognition (paper IV-B's Perceptor).

Recognises the object library's models on the table in the RGB-D point cloud of a camera
(plane removal, clustering, model registration with symmetries), classifies the metal plates
by their holes, keeps object identities between looks, and stores what it sees in the cell's
world model.
"""

from __future__ import annotations

from capabilities.perception.errors import PerceptionError
from capabilities.perception.operations import capability

__all__ = ["PerceptionError", "capability"]
