"""The tokenizer of BehaviorTree.CPP's scripting language (its ``src/script_tokenizer.cpp``).

Tokens are numbers (decimal integers, ``0x`` hexadecimal integers, reals with a fraction or
an exponent), single-quoted strings (no escapes), ``true`` / ``false``, names (a letter, ``_``
or ``@`` then letters, digits and ``_``) and the operators. Only space, tab, newline and
carriage return separate tokens. A malformed number (``3foo``, ``65.``, ``0x``, ``3e+``), an
unterminated string or an unknown character becomes an ``ERROR`` token, which the parser
reports where it meets it.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

__all__ = ["Tok", "Token", "tokenize"]


class Tok(enum.Enum):
    """Token kinds; an operator's value is its text."""

    INTEGER = "integer"
    REAL = "real"
    STRING = "string"
    BOOLEAN = "boolean"
    NAME = "name"
    ERROR = "error"
    END = "end of script"
    # operators, two characters first
    DOTDOT = ".."
    AND = "&&"
    OR = "||"
    EQ = "=="
    NE = "!="
    LE = "<="
    GE = ">="
    CREATE = ":="
    ADD_TO = "+="
    SUB_FROM = "-="
    MUL_BY = "*="
    DIV_BY = "/="
    PLUS = "+"
    MINUS = "-"
    STAR = "*"
    SLASH = "/"
    BIT_AND = "&"
    BIT_OR = "|"
    BIT_XOR = "^"
    TILDE = "~"
    NOT = "!"
    LT = "<"
    GT = ">"
    ASSIGN = "="
    QUESTION = "?"
    COLON = ":"
    LPAREN = "("
    RPAREN = ")"
    SEMICOLON = ";"


_OPERATORS: dict[str, Tok] = {
    t.value: t
    for t in Tok
    if t not in (Tok.INTEGER, Tok.REAL, Tok.STRING, Tok.BOOLEAN, Tok.NAME, Tok.ERROR, Tok.END)
}
_SPACE = " \t\n\r"
_DIGITS = "0123456789"
_HEX = _DIGITS + "abcdefABCDEF"
_LETTERS = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
_NAME_START = _LETTERS + "_@"
_NAME_CHARS = _LETTERS + _DIGITS + "_"


@dataclass(frozen=True)
class Token:
    """One token: its kind, its text (a string's without the quotes) and its offset.

    Attributes:
        kind: what it is.
        text: its characters.
        pos: the offset of its first character in the script.
        why: for an ERROR token, what was expected there.
    """

    kind: Tok
    text: str
    pos: int
    why: str = ""


def _skip_name_chars(src: str, i: int, also: str = "") -> int:
    while i < len(src) and (src[i] in _NAME_CHARS or src[i] in also):
        i += 1
    return i


def _scan_hex(src: str, i: int) -> tuple[int, str]:
    """(end, error) of the hexadecimal number whose ``0x`` starts at ``i``."""
    j = i + 2
    start = j
    while j < len(src) and src[j] in _HEX:
        j += 1
    error = "" if j > start else "hexadecimal digits after 0x"
    if j < len(src) and (src[j] == "." or src[j] in _NAME_CHARS):
        return _skip_name_chars(src, j, "."), "a hexadecimal integer (no fraction or letters)"
    return j, error


def _scan_decimal(src: str, i: int) -> tuple[int, str, bool]:
    """(end, error, is_real) of the decimal number that starts at ``i``."""
    j = i
    while j < len(src) and src[j] in _DIGITS:
        j += 1
    real = False
    if src.startswith(".", j) and not src.startswith("..", j):  # "65..x" is 65 then ".."
        if j + 1 < len(src) and src[j + 1] in _DIGITS:
            real = True
            j += 1
            while j < len(src) and src[j] in _DIGITS:
                j += 1
        else:
            return _skip_name_chars(src, j + 1, "."), "digits after the decimal point", real
    if j < len(src) and src[j] in "eE":
        real = True
        j += 1
        if j < len(src) and src[j] in "+-":
            j += 1
        if j >= len(src) or src[j] not in _DIGITS:
            return j, "digits in the exponent", real
        while j < len(src) and src[j] in _DIGITS:
            j += 1
    if j < len(src) and src[j] in _NAME_START:
        return _skip_name_chars(src, j + 1), "a number (no letters right after it)", real
    return j, "", real


def _number(src: str, i: int) -> Token:
    if src.startswith(("0x", "0X"), i):
        end, error = _scan_hex(src, i)
        real = False
    else:
        end, error, real = _scan_decimal(src, i)
    text = src[i:end]
    if error:
        return Token(Tok.ERROR, text, i, f"malformed number {text!r}: expected {error}")
    return Token(Tok.REAL if real else Tok.INTEGER, text, i)


def tokenize(src: str) -> list[Token]:
    """The tokens of a script, ending with one END token."""
    tokens: list[Token] = []
    i = 0
    while i < len(src):
        c = src[i]
        if c in _SPACE:
            i += 1
        elif c == "'":
            end = src.find("'", i + 1)
            if end < 0:
                why = "a closing ' (the string is not terminated)"
                tokens.append(Token(Tok.ERROR, src[i:], i, f"unterminated string: expected {why}"))
                i = len(src)
            else:
                tokens.append(Token(Tok.STRING, src[i + 1 : end], i))
                i = end + 1
        elif c in _DIGITS:
            token = _number(src, i)
            tokens.append(token)
            i += len(token.text)
        elif c in _NAME_START:
            end = _skip_name_chars(src, i + 1)
            text = src[i:end]
            kind = Tok.BOOLEAN if text in ("true", "false") else Tok.NAME
            tokens.append(Token(kind, text, i))
            i = end
        else:
            op = _OPERATORS.get(src[i : i + 2]) or _OPERATORS.get(c)
            if op is None:
                why = f"unexpected character {c!r}: expected a value or an operator"
                tokens.append(Token(Tok.ERROR, c, i, why))
                i += 1
            else:
                tokens.append(Token(op, op.value, i))
                i += len(op.value)
    tokens.append(Token(Tok.END, "", len(src)))
    return tokens
