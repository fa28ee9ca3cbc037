"""The parser of BehaviorTree.CPP's scripting language (its ``src/script_parser.cpp``).

A Pratt parser, with the same binding of the operators, loosest first:

=========================  ============================================================
``:= = += -= *= /=``       assignment, to a name only; the right side is a whole expression
``? :``                    the condition's branches
``||``                     logical or
``&&``                     logical and
``== != < > <= >=``        comparison, chained (``1 < x < 3``)
``| ^``                    bitwise or, xor
``&``                      bitwise and
``+ - ..``                 add, subtract, join text
``* /``                    multiply, divide
``- ~ !``                  prefix: negate, complement, not
=========================  ============================================================

Statements are separated by ``;`` (any number of them, and BehaviorTree.CPP needs none
between two statements). A script with no statement is an error, as there.
"""

from __future__ import annotations

from collections.abc import Callable

from engine.script.errors import ScriptSyntaxError
from engine.script.expressions import (
    Assign,
    Binary,
    Compare,
    Expr,
    Literal,
    Name,
    Ternary,
    Unary,
)
from engine.script.tokens import Tok, Token, tokenize

__all__ = ["parse_statements"]

_ASSIGN = 2
_TERNARY = 4
_COMPARISON = 10
_PREFIX = 20
_ASSIGNMENTS = {Tok.CREATE, Tok.ASSIGN, Tok.ADD_TO, Tok.SUB_FROM, Tok.MUL_BY, Tok.DIV_BY}
_COMPARISONS = {Tok.EQ, Tok.NE, Tok.LT, Tok.GT, Tok.LE, Tok.GE}
_BINDING: dict[Tok, int] = {
    **dict.fromkeys(_ASSIGNMENTS, _ASSIGN),
    Tok.QUESTION: _TERNARY,
    Tok.OR: 6,
    Tok.AND: 8,
    **dict.fromkeys(_COMPARISONS, _COMPARISON),
    Tok.BIT_OR: 12,
    Tok.BIT_XOR: 12,
    Tok.BIT_AND: 14,
    Tok.PLUS: 16,
    Tok.MINUS: 16,
    Tok.DOTDOT: 16,
    Tok.STAR: 18,
    Tok.SLASH: 18,
}
_PREFIXES = {Tok.MINUS: "-", Tok.TILDE: "~", Tok.NOT: "!"}
_INT64 = 2**63


class _Parser:
    def __init__(self, tokens: list[Token], where: Callable[[int], tuple[int, int]]) -> None:
        self.tokens = tokens
        self.at = 0
        self.where = where

    def peek(self) -> Token:
        return self.tokens[self.at]

    def advance(self) -> Token:
        token = self.tokens[self.at]
        if token.kind is not Tok.END:
            self.at += 1
        return token

    def error(self, token: Token, why: str) -> ScriptSyntaxError:
        return ScriptSyntaxError(why, *self.where(token.pos))

    def expect(self, kind: Tok, what: str) -> Token:
        token = self.peek()
        if token.kind is not kind:
            raise self.error(token, f"expected {what}, got {_shown(token)}")
        return self.advance()

    def statements(self) -> list[Expr]:
        found: list[Expr] = []
        while self.peek().kind is not Tok.END:
            found.append(self.expression(0))
            while self.peek().kind is Tok.SEMICOLON:
                self.advance()
        return found

    def expression(self, min_binding: int) -> Expr:
        left = self.prefix()
        while True:
            kind = self.peek().kind
            binding = _BINDING.get(kind, -1)
            if binding < 0 or binding < min_binding:
                return left
            if kind in _ASSIGNMENTS:
                return self.assignment(left)
            if kind is Tok.QUESTION:
                return self.ternary(left)
            if kind in _COMPARISONS:
                left = self.comparison(left)
                continue
            token = self.advance()
            left = Binary(token.pos, token.text, left, self.expression(binding + 1))

    def prefix(self) -> Expr:
        token = self.advance()
        kind = token.kind
        if kind in _PREFIXES:
            return Unary(token.pos, _PREFIXES[kind], self.expression(_PREFIX))
        if kind is Tok.LPAREN:
            inside = self.expression(0)
            self.expect(Tok.RPAREN, "')'")
            return inside
        if kind is Tok.BOOLEAN:
            return Literal(token.pos, token.text == "true")
        if kind is Tok.INTEGER:
            return Literal(token.pos, self.integer(token))
        if kind is Tok.REAL:
            return Literal(token.pos, float(token.text))
        if kind is Tok.STRING:
            return Literal(token.pos, token.text)
        if kind is Tok.NAME:
            if token.text == "@":
                raise self.error(token, "expected a name after '@'")
            return Name(token.pos, token.text)
        if kind is Tok.ERROR:
            raise self.error(token, token.why)
        raise self.error(token, f"expected a value, got {_shown(token)}")

    def integer(self, token: Token) -> int:
        text = token.text
        value = int(text[2:], 16) if text[:2] in ("0x", "0X") else int(text, 10)
        if value >= _INT64:
            raise self.error(token, f"expected a 64-bit integer, got {text}")
        return value

    def assignment(self, target: Expr) -> Expr:
        token = self.advance()
        if not isinstance(target, Name):
            raise self.error(token, f"expected an entry's name left of {token.text!r}")
        return Assign(token.pos, token.text, target.name, self.expression(0))

    def ternary(self, condition: Expr) -> Expr:
        token = self.advance()
        then = self.expression(0)
        self.expect(Tok.COLON, "':' of '?:'")
        return Ternary(token.pos, condition, then, self.expression(_TERNARY))

    def comparison(self, first: Expr) -> Expr:
        ops: list[str] = []
        operands = [first]
        pos = self.peek().pos
        while self.peek().kind in _COMPARISONS:
            ops.append(self.advance().text)
            operands.append(self.expression(_COMPARISON + 1))
        return Compare(pos, tuple(ops), tuple(operands))


def _shown(token: Token) -> str:
    return "the end of the script" if token.kind is Tok.END else repr(token.text)


def parse_statements(text: str, where: Callable[[int], tuple[int, int]]) -> list[Expr]:
    """The statements of a script, parsed.

    Args:
        text: the script.
        where: an offset in it -> (line, column), for the errors.

    Raises:
        ScriptSyntaxError: the script is not in the language (at its line and column).
    """
    return _Parser(tokenize(text), where).statements()
