"""A small element tree that knows the line of every element (read with expat).

The standard library's ElementTree drops line numbers; import errors must name them. A
document type declaration is refused (no entities, so nothing can expand or be fetched).

Reading is linear in the size of the text and bounded: a file is fed to expat in chunks
(never held whole, as bytes and again as text), character data is collected in a list per
element and joined once at its end tag (``text += chunk`` copies the text so far for every
line: quadratic), and the limits below stop a file before it costs more than a plan can
need. Every limit is an :class:`XmlSyntaxError` with the line, never a RecursionError.
"""

from __future__ import annotations

import os
import xml.parsers.expat
from dataclasses import dataclass, field
from typing import BinaryIO

__all__ = [
    "MAX_DEPTH",
    "MAX_FILE_BYTES",
    "MAX_VALUE_CHARS",
    "Element",
    "XmlSyntaxError",
    "XmlTooLarge",
    "parse",
    "parse_file",
]

MAX_DEPTH = 400  # as deep as a plan may be (engine.plan_format.MAX_TREE_DEPTH), plus a little
# A plan with every example's subtrees is well under 1 MB as XML; 20 MB leaves room for
# hand-written descriptions while keeping the tree in memory small.
MAX_FILE_BYTES = 20_000_000
# One attribute value or one element's text: a waypoint is a few hundred characters.
MAX_VALUE_CHARS = 1_000_000
_CHUNK = 1 << 16


class XmlSyntaxError(ValueError):
    """The text is not well-formed XML (or declares a DTD, or is beyond a limit); ``line``
    is where.
    """

    def __init__(self, line: int, message: str) -> None:
        self.line = line
        super().__init__(message)


class XmlTooLarge(XmlSyntaxError):
    """The file is larger than its limit (line 0: it was not read whole).

    Attributes:
        size: the bytes the file has (at least: when it grew while read, those read).
        limit: the most bytes a tree file may have.
    """

    def __init__(self, size: int, limit: int) -> None:
        self.size, self.limit = size, limit
        super().__init__(0, f"{size} bytes, more than the {limit} a tree file may have")


@dataclass
class Element:
    """One XML element: its tag, attributes (in file order), children and start line."""

    tag: str
    attrs: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)
    text: str = ""  # the character data directly inside (a port's description)


class _Builder:
    """Expat's handlers: builds the elements, checks the limits as the text comes."""

    def __init__(self) -> None:
        # UTF-8 whatever the file declares: we write UTF-8, and a file in another encoding is
        # refused at its first byte that is not UTF-8 (expat still reads UTF-16 that it
        # recognises by its first bytes, as the XML standard asks).
        self.parser = xml.parsers.expat.ParserCreate("utf-8")
        self.parser.ordered_attributes = False
        self.parser.buffer_text = True  # fewer, larger character data calls
        self.stack: list[tuple[Element, list[str], list[int]]] = []  # element, text parts, size
        self.roots: list[Element] = []
        self.parser.StartElementHandler = self._start
        self.parser.EndElementHandler = self._end
        self.parser.CharacterDataHandler = self._data
        self.parser.StartDoctypeDeclHandler = self._doctype

    def _start(self, tag: str, attrs: dict[str, str]) -> None:
        line = self.parser.CurrentLineNumber
        if len(self.stack) >= MAX_DEPTH:
            raise XmlSyntaxError(line, f"elements nested at most {MAX_DEPTH} deep")
        for name, value in attrs.items():
            if len(value) > MAX_VALUE_CHARS:
                raise XmlSyntaxError(
                    line,
                    f"attribute {name[:40]!r} at most {MAX_VALUE_CHARS} characters long, "
                    f"not {len(value)}",
                )
        element = Element(tag, dict(attrs), line)
        (self.stack[-1][0].children if self.stack else self.roots).append(element)
        self.stack.append((element, [], [0]))

    def _end(self, tag: str) -> None:
        element, parts, _ = self.stack.pop()
        element.text = "".join(parts)

    def _data(self, text: str) -> None:
        if not self.stack:
            return
        element, parts, size = self.stack[-1]
        size[0] += len(text)
        if size[0] > MAX_VALUE_CHARS:
            raise XmlSyntaxError(
                self.parser.CurrentLineNumber,
                f"the text inside <{element.tag[:40]}> at most {MAX_VALUE_CHARS} characters long",
            )
        parts.append(text)

    def _doctype(self, *args: object) -> None:
        raise XmlSyntaxError(self.parser.CurrentLineNumber, "no document type declaration")

    def feed(self, data: str | bytes, final: bool) -> None:
        try:
            self.parser.Parse(data, final)
        except xml.parsers.expat.ExpatError as exc:
            message = xml.parsers.expat.errors.messages[exc.code]
            raise XmlSyntaxError(exc.lineno, f"{message} at column {exc.offset + 1}") from None

    def root(self) -> Element:
        return self.roots[0]


def parse(text: str) -> Element:
    """The root element of an XML text.

    Raises:
        XmlSyntaxError: not well-formed, a DTD, nested deeper than :data:`MAX_DEPTH`, or an
            attribute or text longer than :data:`MAX_VALUE_CHARS`.
    """
    builder = _Builder()
    builder.feed(text, True)
    return builder.root()


def parse_file(handle: BinaryIO, limit: int = MAX_FILE_BYTES) -> Element:
    """The root element of a UTF-8 XML file, read in chunks.

    Args:
        handle: the file, opened for reading bytes.
        limit: the most bytes read; checked with the file's size before anything is read
            and again as it is read (a file may grow, or not know its size).

    Raises:
        XmlTooLarge: the file is larger than ``limit``.
        XmlSyntaxError: as :func:`parse`.
    """
    size = os.fstat(handle.fileno()).st_size
    if size > limit:
        raise XmlTooLarge(size, limit)
    builder, read = _Builder(), 0
    while chunk := handle.read(_CHUNK):
        read += len(chunk)
        if read > limit:
            raise XmlTooLarge(read, limit)
        builder.feed(chunk, False)
    builder.feed(b"", True)
    return builder.root()
