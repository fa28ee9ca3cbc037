"""An imported plan with the XML line of each of its parts, so that what is found wrong
with the plan later (by plan validation) is reported at a line of the file.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from engine.spec import PlanSpec, SubtreeRef

__all__ = ["XmlImport", "XmlLines"]


@dataclass
class XmlLines:
    """Lines of an XML file by what they became in the plan.

    Attributes:
        root: the ``<root>`` element's line (for the plan as a whole).
        nodes: node id -> the line of its element (the first, when trees share an id).
        parameters: parameter name -> the line of its ``<Parameter>`` (the last, where a
            second declaration is the mistake).
        subtrees: subtree id and version -> the line of its ``<BehaviorTree>``.
    """

    root: int = 1
    nodes: dict[str, int] = field(default_factory=dict)
    parameters: dict[str, int] = field(default_factory=dict)
    subtrees: dict[SubtreeRef, int] = field(default_factory=dict)


@dataclass
class XmlImport:
    """A plan read from XML, the lines it came from, and the file as the user named it."""

    plan: PlanSpec
    lines: XmlLines
    file: str
