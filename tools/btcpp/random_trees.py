"""Random BehaviorTree.CPP v4 trees of built-in nodes, scripts and pre/post conditions.

Each tree is a root Sequence whose first child, a Script, sets three integer entries
(``a``, ``b``, ``c``); its second child is a random subtree of depth 2 to 5 and 3 to 15
nodes: controls, decorators, AlwaysSuccess/AlwaysFailure, Script and ScriptCondition over
the three entries, with random pre- and post-conditions. No time-based node (Sleep, Delay,
Timeout). Tree ``i`` of seed ``s`` depends on ``s`` and ``i`` only (``random.Random`` seeded
with an integer), so the same command writes the same files on any machine::

    python -m tools.btcpp.random_trees --seed 27 --count 100 --out tests/engine/data/btcpp/random

tests/engine/test_btcpp_random_trees.py runs the files written by this and compares them with
what BehaviorTree.CPP 4.10 did with them (tools/btcpp/run_xml.cpp).
"""

from __future__ import annotations

import argparse
import random
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import quoteattr

__all__ = ["SEED", "COUNT", "tree_xml", "file_name", "main"]

SEED = 27
COUNT = 100
ENTRIES = ("a", "b", "c")

CONTROLS = (
    "Sequence",
    "Fallback",
    "ReactiveSequence",
    "ReactiveFallback",
    "SequenceWithMemory",
    "AsyncSequence",
    "AsyncFallback",
    "Parallel",
    "ParallelAll",
    "IfThenElse",
    "WhileDoElse",
    "Switch2",
    "Switch3",
    "TryCatch",
)
DECORATORS = (
    "Inverter",
    "ForceSuccess",
    "ForceFailure",
    "Repeat",
    "RetryUntilSuccessful",
    "KeepRunningUntilFailure",
    "RunOnce",
    "Precondition",
)
# Nodes that tick over several ticks are picked more often, so that most trees run a while.
_CONTROL_PICKS = (*CONTROLS, "SequenceWithMemory", *(("AsyncSequence", "AsyncFallback") * 3))
_DECORATOR_PICKS = (*DECORATORS, *(("Repeat", "RetryUntilSuccessful") * 3))
LEAVES = ("AlwaysSuccess", "AlwaysFailure", "Script", "ScriptCondition")
_LEAF_PICKS = (*LEAVES, "AlwaysSuccess", "Script")
PRE = ("_skipIf", "_failureIf", "_successIf", "_while")
POST = ("_onSuccess", "_onFailure", "_post", "_onHalted")


@dataclass
class _Node:
    tag: str
    attrs: dict[str, str] = field(default_factory=dict)
    children: list[_Node] = field(default_factory=list)

    def size(self) -> int:
        return 1 + sum(child.size() for child in self.children)

    def depth(self) -> int:
        return 1 + max((child.depth() for child in self.children), default=0)

    def lines(self, indent: int) -> list[str]:
        pad = "  " * indent
        attrs = "".join(f" {key}={quoteattr(value)}" for key, value in self.attrs.items())
        if not self.children:
            return [f"{pad}<{self.tag}{attrs}/>"]
        inner = [line for child in self.children for line in child.lines(indent + 1)]
        return [f"{pad}<{self.tag}{attrs}>", *inner, f"{pad}</{self.tag}>"]


class _Maker:
    def __init__(self, rng: random.Random) -> None:
        self.rng = rng

    # -- scripts -----------------------------------------------------------------------

    def entry(self) -> str:
        return self.rng.choice(ENTRIES)

    def operand(self) -> str:
        return self.entry() if self.rng.random() < 0.5 else str(self.rng.randint(0, 4))

    def comparison(self) -> str:
        op = self.rng.choice(("<", "<=", ">", ">=", "==", "!="))
        left = self.entry()
        if self.rng.random() < 0.2:
            left = f"{left} + {self.entry()}"
        return f"{left} {op} {self.operand()}"

    def condition(self) -> str:
        roll = self.rng.random()
        if roll < 0.6:
            return self.comparison()
        if roll < 0.75:
            return f"!({self.comparison()})"
        joint = self.rng.choice(("&&", "||"))
        return f"{self.comparison()} {joint} {self.comparison()}"

    def assignment(self) -> str:
        target = self.entry()
        roll = self.rng.random()
        if roll < 0.35:
            return f"{target} += {self.rng.randint(1, 2)}"
        if roll < 0.5:
            return f"{target} -= 1"
        if roll < 0.65:
            return f"{target} := {self.entry()} + {self.operand()}"
        if roll < 0.75:
            return f"{target} = {self.entry()} * 2"
        if roll < 0.85:
            return f"{target} := {self.comparison()} ? {self.operand()} : {self.operand()}"
        return f"{target} := {self.rng.randint(0, 4)}"

    def script(self) -> str:
        return "; ".join(self.assignment() for _ in range(self.rng.randint(1, 2)))

    # -- nodes -------------------------------------------------------------------------

    def leaf(self) -> _Node:
        tag = self.rng.choice(_LEAF_PICKS)
        if tag == "Script":
            return _Node(tag, {"code": self.script()})
        if tag == "ScriptCondition":
            code = self.condition()
            if self.rng.random() < 0.4:
                code = f"{self.assignment()}; {code}"
            return _Node(tag, {"code": code})
        return _Node(tag)

    def node(self, depth: int, budget: int) -> _Node:
        """A subtree of at most ``budget`` nodes whose depth is at most ``depth``."""
        if depth <= 1 or budget <= 1:
            return self.with_conditions(self.leaf())
        if budget == 2 or self.rng.random() < 0.4:
            node = self.decorator()
            node.children = [self.node(depth - 1, budget - 1)]
            return self.with_conditions(node)
        node, least, most = self.control()
        count = min(self.rng.randint(least, most), budget - 1)
        if count < least:
            node = self.decorator()
            node.children = [self.node(depth - 1, budget - 1)]
            return self.with_conditions(node)
        shares = self.split(budget - 1, count)
        node.children = [self.node(depth - 1, share) for share in shares]
        if node.tag in ("IfThenElse", "WhileDoElse"):
            # BehaviorTree.CPP 4.10 throws when their condition child is SKIPPED (README):
            # a leaf with no pre-condition, never skipped.
            condition = self.leaf()
            if self.rng.random() < 0.3:
                condition.attrs[self.rng.choice(POST)] = self.script()
            node.children[0] = condition
        if node.tag in ("ReactiveSequence", "ReactiveFallback"):
            # Ours re-check only the conditions before the running child, BehaviorTree.CPP
            # starts every child again (README): conditions before the last child.
            for index in range(len(node.children) - 1):
                node.children[index] = self.with_conditions(
                    _Node("ScriptCondition", {"code": self.condition()})
                )
        self.fix_counts(node)
        return self.with_conditions(node)

    def split(self, budget: int, count: int) -> list[int]:
        shares = [1] * count
        for _ in range(budget - count):
            if self.rng.random() < 0.6:
                shares[self.rng.randrange(count)] += 1
        return shares

    def control(self) -> tuple[_Node, int, int]:
        tag = self.rng.choice(_CONTROL_PICKS)
        if tag in ("IfThenElse", "WhileDoElse"):
            return _Node(tag), 2, 3
        if tag.startswith("Switch"):
            cases = int(tag[-1])
            attrs = {"variable": "{" + self.entry() + "}"}
            values = self.rng.sample(range(5), cases)
            attrs |= {f"case_{n + 1}": str(value) for n, value in enumerate(values)}
            return _Node(tag, attrs), cases + 1, cases + 1
        if tag == "TryCatch":
            return _Node(tag, {"catch_on_halt": self.rng.choice(("true", "false"))}), 2, 3
        return _Node(tag), 1, 4

    def fix_counts(self, node: _Node) -> None:
        """Thresholds of a Parallel or ParallelAll that its children can reach."""
        count = len(node.children)
        if node.tag == "Parallel":
            node.attrs["success_count"] = str(self.rng.choice((-1, *range(1, count + 1))))
            node.attrs["failure_count"] = str(self.rng.choice((-1, *range(1, count + 1))))
        elif node.tag == "ParallelAll":
            node.attrs["max_failures"] = str(self.rng.randint(1, count))

    def decorator(self) -> _Node:
        tag = self.rng.choice(_DECORATOR_PICKS)
        if tag == "Repeat":
            return _Node(tag, {"num_cycles": str(self.rng.choice((-1, 1, 2, 2, 3, 3)))})
        if tag == "RetryUntilSuccessful":
            return _Node(tag, {"num_attempts": str(self.rng.randint(1, 3))})
        if tag == "RunOnce":
            return _Node(tag, {"then_skip": self.rng.choice(("true", "false"))})
        if tag == "Precondition":
            otherwise = self.rng.choice(("FAILURE", "SUCCESS"))
            return _Node(tag, {"if": self.condition(), "else": otherwise})
        return _Node(tag)

    def with_conditions(self, node: _Node) -> _Node:
        if self.rng.random() < 0.3:
            node.attrs[self.rng.choice(PRE)] = self.condition()
        if self.rng.random() < 0.3:
            node.attrs[self.rng.choice(POST)] = self.script()
        return node


def _can_skip(node: _Node) -> bool:
    """Whether ``node`` may answer SKIPPED (a pre-condition, RunOnce, or a child's skip)."""
    if "_skipIf" in node.attrs or "_while" in node.attrs:
        return True
    if node.tag == "RunOnce" and node.attrs.get("then_skip") == "true":
        return True
    return any(_can_skip(child) for child in node.children)


def _no_halt_of_skipped(node: _Node) -> None:
    """No ``_onHalted`` (nor TryCatch's ``catch_on_halt``) on a node whose child may skip.

    BehaviorTree.CPP 4.10 leaves a control or decorator that answered SKIPPED in the RUNNING
    status its tick set, so a later halt runs its ``_onHalted`` (or its catch) although it
    never ran; we do not copy that (README).
    """
    if any(_can_skip(child) for child in node.children):
        node.attrs.pop("_onHalted", None)
        if node.tag == "TryCatch":
            node.attrs["catch_on_halt"] = "false"
    for child in node.children:
        _no_halt_of_skipped(child)


def tree_xml(seed: int, index: int) -> str:
    """The XML of tree ``index`` of ``seed``: depth 2 to 5 and 3 to 15 nodes below the root."""
    rng = random.Random(seed * 100_003 + index)
    maker = _Maker(rng)
    while True:
        depth = rng.randint(2, 5)
        body = maker.node(depth, rng.randint(3, 15))
        if 3 <= body.size() <= 15 and body.depth() >= 2:
            break
    _no_halt_of_skipped(body)
    start = f"a := {rng.randint(0, 2)}; b := {rng.randint(1, 4)}; c := 0"
    root = _Node("Sequence", children=[_Node("Script", {"code": start}), body])
    lines = [
        '<root BTCPP_format="4" main_tree_to_execute="Main">',
        '  <BehaviorTree ID="Main">',
        *root.lines(2),
        "  </BehaviorTree>",
        "</root>",
    ]
    return "\n".join(lines) + "\n"


def file_name(index: int) -> str:
    """The file of tree ``index``: tree_000.xml, tree_001.xml, ..."""
    return f"tree_{index:03d}.xml"


def main(argv: list[str] | None = None) -> None:
    """Write ``--count`` trees of ``--seed`` into ``--out``."""
    parser = argparse.ArgumentParser(description="Random BehaviorTree.CPP v4 trees.")
    parser.add_argument("--seed", type=int, default=SEED)
    parser.add_argument("--count", type=int, default=COUNT)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for index in range(args.count):
        (args.out / file_name(index)).write_text(tree_xml(args.seed, index), encoding="utf-8")


if __name__ == "__main__":
    main()
