"""A small element tree that knows the line of every element (read with expat).

The standard library's ElementTree drops line numbers; import errors must name them. A
document type declaration is refused (no entities, so nothing can expand or be fetched).
"""

from __future__ import annotations

import xml.parsers.expat
from dataclasses import dataclass, field

__all__ = ["Element", "XmlSyntaxError", "parse"]

MAX_DEPTH = 400  # as deep as a plan may be (engine.plan_format.MAX_TREE_DEPTH), plus a little


class XmlSyntaxError(ValueError):
    """The text is not well-formed XML (or declares a DTD); ``line`` is where."""

    def __init__(self, line: int, message: str) -> None:
        self.line = line
        super().__init__(message)


@dataclass
class Element:
    """One XML element: its tag, attributes (in file order), children and start line."""

    tag: str
    attrs: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)
    text: str = ""  # the character data directly inside (a port's description)


def parse(text: str) -> Element:
    """The root element of an XML text.

    Raises:
        XmlSyntaxError: not well-formed, a DTD, or nested deeper than :data:`MAX_DEPTH`.
    """
    parser = xml.parsers.expat.ParserCreate()
    parser.ordered_attributes = False
    stack: list[Element] = []
    roots: list[Element] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        element = Element(tag, dict(attrs), parser.CurrentLineNumber)
        if len(stack) >= MAX_DEPTH:
            raise XmlSyntaxError(element.line, f"elements nested at most {MAX_DEPTH} deep")
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    def end(tag: str) -> None:
        stack.pop()

    def data(text: str) -> None:
        if stack:
            stack[-1].text += text

    def doctype(*args: object) -> None:
        raise XmlSyntaxError(parser.CurrentLineNumber, "no document type declaration")

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = data
    parser.StartDoctypeDeclHandler = doctype
    try:
        parser.Parse(text, True)
    except xml.parsers.expat.ExpatError as exc:
        raise XmlSyntaxError(exc.lineno, xml.parsers.expat.errors.messages[exc.code]) from None
    return roots[0]
