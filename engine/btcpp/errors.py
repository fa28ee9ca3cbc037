"""The errors of BehaviorTree.CPP XML export and import."""

from __future__ import annotations

from dataclasses import dataclass

from engine.errors import EngineError

__all__ = ["XmlExportError", "XmlFileError", "XmlProblem"]


class XmlExportError(EngineError):
    """A plan that cannot be written as BehaviorTree.CPP XML, with where and what was expected.

    Attributes:
        plan: the plan's name.
        where: the node path (and port) of the problem.
        expected: what the XML needs.
        got: what the plan has.
    """

    def __init__(self, plan: str, where: str, expected: str, got: str) -> None:
        self.plan, self.where, self.expected, self.got = plan, where, expected, got
        super().__init__(f"{plan}: {where}: expected {expected}, got {got}")


@dataclass(frozen=True)
class XmlProblem:
    """One thing wrong in an XML file: its line (0: the file as a whole, not read), what was
    expected and what was there.
    """

    line: int
    expected: str
    got: str

    def describe(self, file: str) -> str:
        where = f"line {self.line}: " if self.line > 0 else ""
        return f"{file}: {where}expected {self.expected}, got {self.got}"


class XmlFileError(EngineError):
    """An XML file that cannot be imported; lists every problem found, each with its line.

    Attributes:
        file: the file as the user named it (``"<string>"`` for text).
        problems: in the order of their lines (every unknown node type, not only the first).
    """

    def __init__(self, file: str, problems: list[XmlProblem]) -> None:
        self.file = file
        self.problems = sorted(problems, key=lambda p: p.line)
        lines = [p.describe(file) for p in self.problems]
        super().__init__("\n".join(lines))
