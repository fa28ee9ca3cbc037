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
# How deeply a script may nest (parentheses, operators): the evaluator recurses as deep.
MAX_DEPTH = 200


class _Parser:
    def __init__(self, tokens: list[Token], where: Callable[[int], tuple[int, int]]) -> None:
        self.tokens = tokens
        self.at = 0
        self.where = where
        self.nesting = 0
        self.depths: dict[int, int] = {}  # id(expr) -> how deep its tree is

    def peek(self) -> Token:
        return self.tokens[self.at]

    def advance(self) -> Token:
        token = self.tokens[self.at]
        if token.kind is not Tok.END:
            self.at += 1
        return token

    def error(self, token: Token, why: str) -> ScriptSyntaxError:
        """The error at ``token``; at a malformed token, what that token lacks."""
        return ScriptSyntaxError(token.why or why, *self.where(token.pos))

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

    def made(self, expr: Expr, *parts: Expr) -> Expr:
        """``expr``, whose parts are ``parts``, once its depth is checked."""
        depth = 1 + max((self.depths.get(id(p), 1) for p in parts), default=0)
        if depth > MAX_DEPTH:
            raise ScriptSyntaxError(
                f"the script nests too deeply (more than {MAX_DEPTH} levels)", *self.where(expr.pos)
            )
        self.depths[id(expr)] = depth
        return expr

    def expression(self, min_binding: int) -> Expr:
        self.nesting += 1
        if self.nesting > MAX_DEPTH:
            why = f"the script nests too deeply (more than {MAX_DEPTH} levels)"
            raise self.error(self.peek(), why)
        try:
            return self._expression(min_binding)
        finally:
            self.nesting -= 1

    def _expression(self, min_binding: int) -> Expr:
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
            right = self.expression(binding + 1)
            left = self.made(Binary(token.pos, token.text, left, right), left, right)

    def prefix(self) -> Expr:
        token = self.advance()
        kind = token.kind
        if kind in _PREFIXES:
            operand = self.expression(_PREFIX)
            return self.made(Unary(token.pos, _PREFIXES[kind], operand), operand)
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
        value = self.expression(0)
        return self.made(Assign(token.pos, token.text, target.name, value), value)

    def ternary(self, condition: Expr) -> Expr:
        token = self.advance()
        then = self.expression(0)
        self.expect(Tok.COLON, "':' of '?:'")
        otherwise = self.expression(_TERNARY)
        return self.made(Ternary(token.pos, condition, then, otherwise), condition, then, otherwise)

    def comparison(self, first: Expr) -> Expr:
        ops: list[str] = []
        operands = [first]
        pos = self.peek().pos
        while self.peek().kind in _COMPARISONS:
            ops.append(self.advance().text)
            operands.append(self.expression(_COMPARISON + 1))
        return self.made(Compare(pos, tuple(ops), tuple(operands)), *operands)


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
