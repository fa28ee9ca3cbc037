"""BehaviorTree.CPP's scripting language as engine.script runs it.

The cases follow the ones of BehaviorTree.CPP 4.10's ``tests/script_parser_test.cpp``,
``gtest_enums.cpp`` and ``gtest_blackboard.cpp`` (literals, equations, assignment rules,
enums, precedence and associativity, chained comparisons, unary and ternary operators,
statements, the tokenizer's edge cases, the root scope), in our own data, plus the errors'
lines and columns.
"""

from __future__ import annotations

from typing import Any

import pytest

from engine.blackboard import Blackboard
from engine.instances import Scope
from engine.script import (
    ScriptEnv,
    ScriptError,
    ScriptNameError,
    ScriptRunError,
    ScriptSyntaxError,
    ScriptTypeError,
    parse_script,
    run_script,
)
from engine.types import ParamType, Pose


def run(text: str, bb: Blackboard | None = None, enums: dict[str, int] | None = None) -> Any:
    return run_script(text, bb if bb is not None else Blackboard(), enums)


def same(value: Any, expected: Any) -> bool:
    """Equal in value and in Python type (an int is not a float, a bool is not an int)."""
    return type(value) is type(expected) and value == expected


# --- literals ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("417", 417),
        ("0", 0),
        ("0x1F", 31),
        ("0XfF", 255),
        ("0x7fffffffffffffff", 2**63 - 1),
        ("2.75", 2.75),
        ("1.5e3", 1500.0),
        ("2.5e-2", 0.025),
        ("4e2", 400.0),
        ("4E+1", 40.0),
        ("7e-1", 0.7),
        ("'pick the cup '", "pick the cup "),
        ("''", ""),
        ("'a;b == c'", "a;b == c"),
        ("true", True),
        ("false", False),
        ("'true'", "true"),
    ],
)
def test_literals_are_typed_as_parameters(text: str, expected: Any) -> None:
    assert same(run(text), expected)


def test_a_negated_literal_is_a_real_as_in_btcpp() -> None:
    assert same(run("-417"), -417.0)
    assert same(run("-2.75"), -2.75)
    assert same(run("- 0x10"), -16.0)


@pytest.mark.parametrize(
    ("text", "column", "words"),
    [
        ("0X1Fq", 1, "malformed number '0X1Fq'"),
        ("0x1F.", 1, "hexadecimal integer"),
        ("0x", 1, "hexadecimal digits"),
        ("0xZ", 1, "hexadecimal"),
        ("7bar", 1, "no letters right after it"),
        ("7@", 1, "no letters right after it"),
        ("48.", 1, "digits after the decimal point"),
        ("48.x", 1, "digits after the decimal point"),
        ("12.5mm", 1, "malformed number '12.5mm'"),
        ("7e", 1, "digits in the exponent"),
        ("7e-", 1, "digits in the exponent"),
        ("x := 'open", 6, "unterminated string"),
        ("x := 1 # note", 8, "unexpected character '#'"),
        ("a := 1 $ 2", 8, "unexpected character '$'"),
        ("'one' \"two\"", 7, "unexpected character '\"'"),
        ("0x10000000000000000", 1, "64-bit integer"),
        ("9223372036854775808", 1, "64-bit integer"),
    ],
)
def test_malformed_tokens_are_parse_errors_with_their_place(
    text: str, column: int, words: str
) -> None:
    with pytest.raises(ScriptSyntaxError) as caught:
        parse_script(text)
    assert (caught.value.line, caught.value.column) == (1, column)
    assert words in str(caught.value)
    assert str(caught.value).startswith(f"line 1, column {column}: ")


def test_the_largest_integers_parse() -> None:
    assert same(run("9223372036854775807"), 2**63 - 1)


@pytest.mark.parametrize("text", ["", "   ", "\t\n\r"])
def test_an_empty_script_is_an_error(text: str) -> None:
    with pytest.raises(ScriptSyntaxError, match="empty script"):
        parse_script(text)


@pytest.mark.parametrize("text", [";", " ; ;; ", "; x := 1"])
def test_a_script_cannot_start_with_a_semicolon(text: str) -> None:
    with pytest.raises(ScriptSyntaxError, match="expected a value, got ';'"):
        parse_script(text)


def test_an_unknown_name_parses_and_fails_when_run() -> None:
    script = parse_script("gripper_open")
    with pytest.raises(ScriptNameError, match="'gripper_open' does not exist"):
        script.run(ScriptEnv(Blackboard()))


def test_only_space_tab_newline_and_return_separate_tokens() -> None:
    assert run(" \t1\r\n+\n2 ") == 3.0
    with pytest.raises(ScriptSyntaxError, match="unexpected character"):
        parse_script("1 +\f2")
    with pytest.raises(ScriptSyntaxError, match="unexpected character 'é'"):
        parse_script("café := 1")


# --- equations (script_parser_test's Equations, in our numbers) ------------------------------


def test_equations_create_update_and_read_entries() -> None:
    bb = Blackboard()
    assert same(run("a:= 4; b:=7; a+b", bb), 11.0)
    assert bb.snapshot() == {"a": 4, "b": 7}
    assert same(bb.get("a"), 4)  # created from an integer: an integer entry
    assert same(run("a+=2", bb), 6)
    assert same(run("a += 2", bb), 8)
    assert same(run("a-=3", bb), 5)
    assert same(run("a -= 1", bb), 4)
    assert same(run("a*=3", bb), 12)
    assert same(run("-a", bb), -12.0)
    assert same(run("a/=4", bb), 3)
    assert bb.get("a") == 3
    assert same(run("b", bb), 7)
    assert same(run("b/2", bb), 3.5)
    assert same(run("b*2", bb), 14.0)
    assert same(run("b-a", bb), 4.0)
    assert same(run("b & a", bb), float(7 & 3))
    assert same(run("b | a", bb), float(7 | 3))
    assert same(run("b ^ a", bb), float(7 ^ 3))
    with pytest.raises(ScriptTypeError, match=r"'\^': expected an integer, got Number 4\.2"):
        run("b ^ 4.2", bb)


def test_an_integer_entry_keeps_integers() -> None:
    bb = Blackboard()
    run("n := 5", bb)
    with pytest.raises(ScriptTypeError, match="expected an integer"):
        run("n /= 2", bb)
    assert bb.get("n") == 5  # a failed assignment writes nothing
    assert same(run("n = 8.0", bb), 8)
    assert same(run("n = '12'", bb), 12)  # Text that reads as a number
    assert same(run("n = true", bb), 1)


def test_a_real_entry_stays_real() -> None:
    bb = Blackboard()
    run("r := 2.5", bb)
    assert same(run("r = 3", bb), 3.0)
    assert same(run("r /= 4", bb), 0.75)
    assert same(run("r = '1e1'", bb), 10.0)


def test_text_entries_join_and_keep_their_type() -> None:
    bb = Blackboard()
    assert same(run("P:='tool'; Q:=' '; R:='flange'; P+Q+R", bb), "tool flange")
    assert bb.snapshot() == {"P": "tool", "Q": " ", "R": "flange"}
    # spaces inside and around the quotes
    assert run("P= '  left'; Q= ' mid '; R= 'right   '  ", bb) == "right   "
    assert bb.snapshot() == {"P": "  left", "Q": " mid ", "R": "right   "}
    assert same(run("P += '!'", bb), "  left!")
    bb.set("n", 2)
    # an entry does not change its type once created
    with pytest.raises(ScriptTypeError, match="expected a number"):
        run("n = P", bb)
    with pytest.raises(ScriptTypeError, match="got Text 'wrong'"):
        run("n = 'wrong'", bb)
    with pytest.raises(ScriptTypeError, match=r"expected Text, got Number 1\.5"):
        run("P = 1.5", bb)
    with pytest.raises(ScriptTypeError, match="expected Text"):
        run("P := 1", bb)  # := on an existing entry is a plain write
    with pytest.raises(ScriptTypeError, match="expected two Numbers, got Text"):
        run("P -= 'x'", bb)
    with pytest.raises(ScriptTypeError, match="expected two Numbers or two Texts"):
        run("n += 'x'", bb)
    with pytest.raises(ScriptTypeError, match="expected two Numbers or two Texts"):
        run("P += 1", bb)
    assert bb.snapshot() == {"P": "  left!", "Q": " mid ", "R": "right   ", "n": 2}


@pytest.mark.parametrize(
    "text", [" 'cup' = 'bin' ", " 'cup' = 2.0 ", " 3.0 = 2.0 ", "(a) + 1 := 2"]
)
def test_only_an_entry_can_be_assigned(text: str) -> None:
    with pytest.raises(ScriptSyntaxError, match="expected an entry's name left of"):
        parse_script(text)


def test_assign_with_equals_needs_the_entry_and_writes_nothing() -> None:
    bb = Blackboard({"declared": ParamType.NUMBER})
    run("known := 1", bb)
    with pytest.raises(ScriptNameError, match="'fresh' does not exist") as caught:
        run("known = 2; fresh = 69", bb)
    assert (caught.value.line, caught.value.column) == (1, 18)
    assert set(bb.snapshot()) == {"known"}
    assert bb.get("known") == 2  # the statement before the failure ran
    # a declared entry exists without a value: = writes it, as BT.CPP's typed port entry
    assert same(run("declared = 4", bb), 4.0)


def test_the_right_side_is_not_evaluated_for_a_missing_entry() -> None:
    bb = Blackboard()
    run("count := 0", bb)
    with pytest.raises(ScriptNameError, match="'missing'"):
        run("missing = (count := 5)", bb)
    assert bb.get("count") == 0


def test_comparisons() -> None:
    bb = Blackboard()
    run("a := 2; b := 9", bb)
    assert run("a < b", bb) is True
    assert run("b > a", bb) is True
    assert run("b != a", bb) is True
    assert run("b == a", bb) is False
    assert run("a > b", bb) is False
    assert run("b <= 9", bb) is True
    assert run("b >= 9.5", bb) is False
    assert run(" 'bolt' == 'bolt'") is True
    assert run(" 'bolt' != 'nut'") is True
    assert run(" 'bolt' < 'nut'") is True
    assert run(" 'bolt' > 'nut'") is False
    assert run(" 'Z' < 'a'") is True  # byte order, as C++
    assert run("b == a ? 'yes' : 'no'", bb) == "no"
    assert run("b != a ? 'yes' : 'no'", bb) == "yes"
    assert run("b == 9", bb) is True
    assert run("a == 2", bb) is True


def test_equality_of_numbers_allows_a_float_epsilon() -> None:
    assert run("0.1 + 0.2 == 0.3") is True
    assert run("1 == 1.0000001") is True
    assert run("1 == 1.000001") is False
    assert run("1 != 1.0000001") is False
    assert run("1 < 1.0000001") is True  # order is exact


def test_text_compared_with_a_number_reads_as_a_number() -> None:
    bb = Blackboard()
    assert run(" s1:='7'; s2:=7; s1==s2", bb) is True
    assert run(" s1:='7'; s2:=8; s1!=s2", bb) is True
    assert run(" '2.5e1' > 20") is True
    assert run("1 == 'true'") is True
    assert run("0 == 'false'") is True
    assert run("3 == 'GREEN'", enums={"GREEN": 3}) is True
    with pytest.raises(ScriptTypeError, match="expected a number, true, false or an enum"):
        run("'seven' == 7")
    with pytest.raises(ScriptTypeError, match="got Text ' 7'"):
        run("' 7' == 7")


def test_values_of_other_types_cannot_be_compared_or_computed() -> None:
    bb = Blackboard()
    bb.set("home", Pose((0.4, 0.0, 0.3)))
    with pytest.raises(ScriptTypeError, match="cannot compare Pose"):
        run("home == 1", bb)
    with pytest.raises(ScriptTypeError, match="got Pose"):
        run("home + 1", bb)
    with pytest.raises(ScriptTypeError, match="expected a Number or a Bool, got Pose"):
        run("!home", bb)
    with pytest.raises(ScriptTypeError, match="as a condition, got Pose"):
        run("home ? 1 : 2", bb)
    with pytest.raises(ScriptTypeError, match="expected Pose, got Number"):
        run("home = 3", bb)
    assert run("there := home; there", bb) == Pose((0.4, 0.0, 0.3))


def test_booleans() -> None:
    bb = Blackboard()
    run("on:= true; off:= false", bb)
    assert same(bb.get("on"), True) and same(bb.get("off"), False)
    assert run(" off = true ", bb) is True
    assert run(" off = !false ", bb) is True
    assert run(" off = !off ", bb) is False
    assert run("on && off", bb) is False
    assert run("on || off", bb) is True
    assert run("on == 1", bb) is True  # a Bool is the number 1 or 0, as in BT.CPP
    assert same(run("on + on", bb), 2.0)
    assert run("off = 1", bb) is True
    assert run("off = 'false'", bb) is False
    with pytest.raises(ScriptTypeError, match="expected a Bool"):
        run("off = 2", bb)
    with pytest.raises(ScriptTypeError, match="expected a Bool"):
        run("off = 'maybe'", bb)


def test_logic_operators_on_comparisons() -> None:
    bb = Blackboard()
    run("a := 2; b := 9", bb)
    assert run("(b == a) && (a == 2)", bb) is False
    assert run("(b == a) || (a == 2)", bb) is True
    assert run(" b == a  &&  a == 2 ", bb) is False
    assert run(" b == a  ||  a == 2 ", bb) is True
    assert run("2 && 0.5") is True  # numbers are true when not 0
    with pytest.raises(ScriptTypeError, match="'&&': expected two Numbers or Bools"):
        run("'yes' && true")


def test_logic_operators_evaluate_both_sides_as_btcpp() -> None:
    bb = Blackboard()
    run("hits := 0", bb)
    assert run("false && (hits += 1)", bb) is False
    assert run("true || (hits += 1)", bb) is True
    assert bb.get("hits") == 2


def test_not_initialized_entries_fail_in_operators() -> None:
    bb = Blackboard({"level": ParamType.NUMBER})  # an entry with a type and no value
    for text in ("level < 0", "level == 0", "level > 0", "level + 1"):
        with pytest.raises(ScriptNameError, match="'level' has no value yet"):
            run(text, bb)
    with pytest.raises(ScriptNameError, match="'level' has no value for '\\+='"):
        run("level += 1", bb)
    bb.set("nothing", None)
    with pytest.raises(ScriptNameError, match="'nothing' has no value yet"):
        run("nothing", bb)


# --- declared types: the blackboard's, bridged -------------------------------------------------


def test_declared_types_convert_as_the_entry_is_typed() -> None:
    bb = Blackboard(
        {
            "speed": ParamType.NUMBER,
            "wait": ParamType.DURATION,
            "done": ParamType.BOOL,
            "label": ParamType.TEXT,
            "target": ParamType.POSE,
            "blob": ParamType.ANY,
        }
    )
    assert same(run("speed := 1", bb), 1.0)  # a Number parameter: the engine's float
    assert same(run("speed += 1", bb), 2.0)
    assert same(run("speed = 0.25", bb), 0.25)
    assert same(run("wait := '3'", bb), 3.0)
    assert same(run("done := 'true'", bb), True)
    assert same(run("done = 0", bb), False)
    assert same(run("label := 'cup'", bb), "cup")
    assert same(run("blob := 3", bb), 3)
    assert same(run("blob = 'anything'", bb), "anything")
    with pytest.raises(ScriptTypeError, match="expected Text, got Number 3"):
        run("label = 3", bb)
    with pytest.raises(ScriptTypeError, match="expected Pose, got Text"):
        run("target := 'somewhere'", bb)
    with pytest.raises(ScriptTypeError, match="expected a number"):
        run("speed = 'fast'", bb)
    assert bb.get("speed") == 0.25


def test_writes_reach_the_blackboards_listeners_as_the_writer() -> None:
    bb = Blackboard()
    seen: list[tuple[str, Any, str]] = []
    bb.add_write_listener(lambda key, value, writer: seen.append((key, value, writer)))
    parse_script("x := 1; x += 1; x").run(ScriptEnv(bb, writer="node-7"))
    assert seen == [("x", 1, "node-7"), ("x", 2, "node-7")]


# --- enums --------------------------------------------------------------------------------


def test_enums_read_as_integers() -> None:
    colours = {"AMBER": 2, "TEAL": 4, "CRIMSON": 6}
    bb = Blackboard()
    for text in ("A:=AMBER", "B:=AMBER", "C:=TEAL"):
        run(text, bb, colours)
    assert run("A==B", bb, colours) is True
    assert run("A!=C", bb, colours) is True
    assert same(bb.get("A"), 2) and same(bb.get("C"), 4)
    assert same(run("A", bb, colours), 2)


def test_enums_in_a_script_of_several_statements() -> None:
    enums = {"ANSWER": 41, "AMBER": 2, "TEAL": 4, "CRIMSON": 6}
    bb = Blackboard()
    run("A:=ANSWER; c1:=AMBER; c2:=TEAL; c3:=CRIMSON", bb, enums)
    assert bb.snapshot() == {"A": 41, "c1": 2, "c2": 4, "c3": 6}


def test_an_enum_wins_over_an_entry_and_cannot_be_assigned() -> None:
    bb = Blackboard()
    bb.set("TEAL", 99)
    assert run("TEAL", bb, {"TEAL": 4}) == 4
    with pytest.raises(ScriptNameError, match="'TEAL' is an enum value"):
        run("TEAL := 5", bb, {"TEAL": 4})


def test_an_enum_name_assigned_to_a_number_entry_as_text() -> None:
    bb = Blackboard({"device": ParamType.NUMBER})
    assert run("device := 'PUMP'", bb, {"PUMP": 3}) == 3.0


# --- precedence, associativity, chains ---------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("9 - 4 + 2", 7.0),  # left-associative
        ("20 - 6 - 3", 11.0),
        ("3 + 4 - 2", 5.0),
        ("36 / 6 / 2", 3.0),
        ("36 / 6 * 2", 12.0),
        ("3 + 4 * 5 - 2", 21.0),
        ("(3 + 4) * 5", 35.0),
        ("3 * (4 + 5)", 27.0),
        ("12 | 3 & 6", 14.0),  # & binds tighter than |
        ("12 ^ 10 | 1", 7.0),  # | and ^ bind alike, left to right
        ("1 | 2 == 3", True),  # | binds tighter than ==
        ("2 + 3 == 5", True),
        ("true && (12 | 0)", True),
        ("false || true && true", True),
        ("false && true || true", True),
        ("true || false && false", True),
        ("!false && false", False),  # ! binds tightest
        ("-2 * 3", -6.0),
        ("-(4 + 1)", -5.0),
        ("10 + -4", 6.0),
        ("2 * -3 + 1", -5.0),
        ("!!true", True),
        ("!true", False),
        ("!0", True),
        ("!7", False),
        ("~0", -1.0),
        ("~5", -6.0),
        ("~~9", 9.0),
        ("~2.9", -3.0),  # ~ truncates, as C++'s cast
        ("'a' .. 'b' .. 'c'", "abc"),
        ("1 + 2 .. 'x'", "3.000000x"),  # .. binds as +, left to right
    ],
)
def test_precedence_and_associativity(text: str, expected: Any) -> None:
    assert same(run(text), expected)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("2 < 4 < 6", True),
        ("6 > 4 > 2", True),
        ("2 < 4 > 6", False),
        ("4 == 4 == 4", True),
        ("4 == 4 != 1", True),
        ("2 <= 2 <= 3", True),
        ("3 >= 3 >= 4", False),
        ("1 < 3 < 2", False),  # not (1 < 3) < 2
        ("1 + 1 < 3 < 2 * 2", True),  # arithmetic binds tighter
        ("1 < 2 < 3 && 0", False),
    ],
)
def test_chained_comparisons(text: str, expected: bool) -> None:
    assert run(text) is expected


def test_a_chain_reads_each_operand_once_and_stops_at_the_first_false() -> None:
    bb = Blackboard()
    run("n := 0", bb)
    assert run("0 < (n += 1) < 3", bb) is True
    assert bb.get("n") == 1
    assert run("5 < 1 < (n += 1)", bb) is False
    assert bb.get("n") == 1


def test_compare_with_negative_numbers() -> None:
    bb = Blackboard()
    assert run("k:=0; k!=-2", bb) is True
    assert run("k:=-2; k!=-2", bb) is False
    assert run("k:=0; k==-2", bb) is False
    assert run("k:=0; k>-2", bb) is True
    assert run("k:=0; k<-2", bb) is False


# --- ternary, statements ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("true ? 5 : 8", 5),
        ("false ? 5 : 8", 8),
        ("true ? 4 + 1 : 20", 5.0),
        ("false ? 20 : 4 + 1", 5.0),
        ("7 > 3 ? 'high' : 'low'", "high"),
        ("7 < 3 ? 'high' : 'low'", "low"),
        ("false ? 1 : true ? 2 : 3", 2),  # right-nested
        ("0 ? 1 : 2", 2),
        ("0.5 ? 1 : 2", 1),
        ("'' ? 1 : 2", 2),
        ("'x' ? 1 : 2", 1),
        ("1 < 2 ? 1 : 2 + 10", 1),
    ],
)
def test_ternary(text: str, expected: Any) -> None:
    assert same(run(text), expected)


def test_only_the_branch_taken_runs() -> None:
    bb = Blackboard()
    run("t := 0; e := 0", bb)
    run("true ? (t += 1) : (e += 1)", bb)
    assert (bb.get("t"), bb.get("e")) == (1, 0)


def test_assignment_takes_a_whole_expression_and_chains_right() -> None:
    bb = Blackboard()
    assert run("m := 2 > 1 ? 'up' : 'down'", bb) == "up"
    assert run("p := q := 3", bb) == 3
    assert bb.get("p") == 3 and bb.get("q") == 3
    assert run("on := 1 < 2 && 3 > 4", bb) is False


def test_several_statements() -> None:
    bb = Blackboard()
    run("u:=3;;; v:=4;;", bb)
    assert bb.snapshot() == {"u": 3, "v": 4}
    assert same(run("u:=30; v:=40; u+v", bb), 70.0)
    assert run("u:=1\nv:=2", bb) == 2  # as BT.CPP: no ';' needed between statements
    assert run("w := 5;\nw", bb) == 5  # a newline inside the code attribute


def test_concatenation() -> None:
    bb = Blackboard()
    assert run("A:='pick'; B:=' place'; A .. B", bb) == "pick place"
    assert run("A .. ' ' .. B", bb) == "pick  place"
    assert run("X:='47'; Y:='48'; X..Y", bb) == "4748"  # "47..48" is not a real
    assert run("47..'a'") == "47a"
    assert run("'n=' .. 3") == "n=3"
    assert run("'r=' .. 0.5") == "r=0.500000"  # std::to_string of a double
    assert run("'ok=' .. true") == "ok=true"
    with pytest.raises(ScriptTypeError, match=r"'\.\.': expected a Text and a Text or a Number"):
        run("1 .. 2")
    with pytest.raises(ScriptTypeError, match="'-': expected two Numbers"):
        run("'a' - 'b'")


# --- the root scope -------------------------------------------------------------------------


def test_at_names_the_entry_at_the_top_of_the_tree() -> None:
    bb = Blackboard()
    inner = Scope(names="Pick#ab12cd/", outer=Scope())
    env = ScriptEnv(bb, key=inner.key)
    parse_script("local := 1; @total := 2; @total += local").run(env)
    assert bb.snapshot() == {"Pick#ab12cd/local": 1, "total": 3}
    assert parse_script("@total").run(env) == 3
    with pytest.raises(ScriptNameError, match="'total' does not exist"):
        parse_script("total").run(env)
    top = ScriptEnv(bb)
    assert parse_script("@total == total").run(top) is True


def test_a_bare_at_sign_is_not_a_name() -> None:
    with pytest.raises(ScriptSyntaxError, match="expected a name after '@'"):
        parse_script("@ := 1")


# --- errors: lines, columns, kinds ----------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "line", "column", "words"),
    [
        ("x := (1 + 2", 1, 12, "expected ')', got the end of the script"),
        ("x := 1 +", 1, 9, "expected a value, got the end of the script"),
        ("x := * 2", 1, 6, "expected a value, got '*'"),
        ("a := 1;\nb := 2;\nc := (3 ]", 3, 9, "unexpected character ']'"),
        ("a := 1;\n  b := ;", 2, 8, "expected a value, got ';'"),
        ("ok ? 1", 1, 7, "expected ':' of '?:'"),
        ("ok ? 1 ; 2", 1, 8, "expected ':' of '?:', got ';'"),
        ("1 + 2 = 3", 1, 7, "expected an entry's name left of '='"),
        ("a := )", 1, 6, "expected a value, got ')'"),
        ("a := 1 :", 1, 8, "expected a value, got ':'"),
        ("a := 1 ?", 1, 9, "expected a value"),
        ("a := ()", 1, 7, "expected a value, got ')'"),
        ("(1 + 2 '", 1, 8, "unterminated string"),
    ],
)
def test_parse_errors_name_line_and_column(text: str, line: int, column: int, words: str) -> None:
    with pytest.raises(ScriptSyntaxError) as caught:
        parse_script(text)
    error = caught.value
    assert (error.line, error.column) == (line, column)
    assert words in error.reason
    assert str(error) == f"line {line}, column {column}: {error.reason}"


@pytest.mark.parametrize(
    ("text", "kind", "line", "column", "words"),
    [
        ("a := 1;\nb := 2;\nc := a / (b - 2)", ScriptRunError, 3, 8, "division by zero"),
        ("a := 1;\nb := 2;\nc := a / (b - 2)", ScriptRunError, 3, 8, "Number 1 / Number 0"),
        ("a := 1\n  a += 'x'", ScriptTypeError, 2, 5, "expected two Numbers or two Texts"),
        ("t := 'x'; t * 2", ScriptTypeError, 1, 13, "'*': expected two Numbers, got Text 'x'"),
        ("q := 3;\n\nq = r", ScriptNameError, 3, 5, "'r' does not exist"),
        ("-'x'", ScriptTypeError, 1, 1, "'-' expected a Number or a Bool, got Text 'x'"),
        ("~'x'", ScriptTypeError, 1, 1, "'~' expected"),
        ("~1e30", ScriptTypeError, 1, 1, "64-bit integer"),
        ("3 & 0.5", ScriptTypeError, 1, 3, "expected an integer, got Number 0.5"),
        ("'a' < 1", ScriptTypeError, 1, 5, "got Text 'a'"),
        ("x := 1; x /= 0", ScriptRunError, 1, 11, "division by zero"),
    ],
)
def test_run_errors_are_typed_and_placed(
    text: str, kind: type[ScriptError], line: int, column: int, words: str
) -> None:
    with pytest.raises(kind) as caught:
        run(text)
    assert (caught.value.line, caught.value.column) == (line, column)
    assert words in caught.value.reason


def test_division_by_zero_is_not_a_type_error() -> None:
    with pytest.raises(ScriptRunError) as caught:
        run("1 / 0")
    assert not isinstance(caught.value, ScriptTypeError | ScriptNameError)


def test_errors_are_engine_errors() -> None:
    from engine.errors import EngineError

    assert issubclass(ScriptError, EngineError)
    assert issubclass(ScriptSyntaxError, ScriptError) and issubclass(ScriptRunError, ScriptError)


def test_a_large_invalid_script_fails_cleanly() -> None:
    chunk = "+6e66>6666.6+66\r6>6;6e62=6+6e66>66666'; en';o';o'; en'; \x7fn\x7fr;6.6+66.H>6+6\x806\x1e;@e66"
    with pytest.raises(ScriptSyntaxError):
        parse_script(chunk * 10)


@pytest.mark.parametrize(
    "text",
    ["(" * 5000 + "1" + ")" * 5000, "1" + " + 1" * 5000, "-" * 5000 + "1", "a := " * 3000 + "1"],
)
def test_deep_nesting_is_a_script_error_not_a_crash(text: str) -> None:
    with pytest.raises(ScriptSyntaxError, match="too deeply"):
        parse_script(text)


def test_nesting_below_the_limit_runs() -> None:
    assert run("(" * 150 + "1" + ")" * 150) == 1
    assert run("0" + " + 1" * 150) == 150.0


# --- a script as a condition --------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("true", True),
        ("1 > 2", False),
        ("3", True),
        ("0.0", False),
        ("'true'", True),
        ("'0'", False),
        ("x := 2; x == 2", True),
    ],
)
def test_check_gives_a_condition(text: str, expected: bool) -> None:
    assert parse_script(text).check(ScriptEnv(Blackboard())) is expected


def test_check_refuses_a_value_that_is_not_a_truth() -> None:
    with pytest.raises(ScriptTypeError, match="expected true or false, got Text 'maybe'") as caught:
        parse_script("a := 1;\n 'maybe'").check(ScriptEnv(Blackboard()))
    assert (caught.value.line, caught.value.column) == (2, 2)


def test_a_parsed_script_runs_again_on_new_values() -> None:
    script = parse_script("ticks := ticks + 1; ticks >= 3")
    bb = Blackboard()
    bb.set("ticks", 0)
    env = ScriptEnv(bb)
    assert [script.check(env) for _ in range(4)] == [False, False, True, True]
