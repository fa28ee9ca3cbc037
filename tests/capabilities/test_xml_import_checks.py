"""``costar import-xml`` writes only plans the project accepts, reads big files in linear time
and bounded memory, and answers any bytes with exit 0 or 2 (issue 23, items 3 and 4).
"""

from __future__ import annotations

import io
import random
import re
from pathlib import Path
from typing import Any

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.cli import main
from capabilities.xml_commands import operation_manifests
from engine.btcpp import export_xml
from engine.btcpp.xmltree import MAX_FILE_BYTES, MAX_VALUE_CHARS
from engine.files import load_plan
from engine.validation import ERROR, validate_plan

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "resources" / "examples"
SHIPPED = ["cup_to_bin", "kitting", "nodes/subtree", "nodes/catch", "nodes/parallel_m_of_n"]
SHIPPED += ["nodes/iterator", "nodes/action"]


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def registry() -> CapabilityRegistry:
    return CapabilityRegistry()


@pytest.fixture(scope="module")
def exports(registry: CapabilityRegistry) -> dict[str, str]:
    """The XML export of some shipped examples, by name."""
    manifests = operation_manifests(registry)
    return {
        name: export_xml(load_plan(EXAMPLES / f"{name}.costar.json"), manifests) for name in SHIPPED
    }


def import_text(tmp_path: Path, data: str | bytes) -> tuple[int, str, Path]:
    """Import XML text or bytes through the CLI; the exit code, stderr and the plan's path."""
    xml, plan = tmp_path / "in.xml", tmp_path / "out.costar.json"
    plan.unlink(missing_ok=True)
    xml.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)
    code, _, err = run_cli("import-xml", str(xml), str(plan))
    return code, err, plan


def assert_accepted(plan_file: Path, registry: CapabilityRegistry) -> None:
    """The file loads, and validation finds no error but a cell's (availability)."""
    plan = load_plan(plan_file, aliases=registry.aliases())
    errors = [
        p
        for p in validate_plan(plan, registry)
        if p.severity == ERROR and "cannot run on this cell" not in p.message
    ]
    assert errors == []


# ---- item 4: what import writes, validation accepts


def test_a_duplicated_parameter_is_refused_at_its_line(tmp_path: Path) -> None:
    xml = (
        '<root BTCPP_format="4" main_tree_to_execute="T">\n'
        '<CostarPlan tree="T" name="p">\n'
        '<Parameter name="A" type="Number" value="1.0"/>\n'
        '<Parameter name="A" type="Number" value="2.0"/>\n'
        "</CostarPlan>\n"
        '<BehaviorTree ID="T"><debug__running/></BehaviorTree>\n'
        "</root>\n"
    )
    code, err, plan = import_text(tmp_path, xml)
    assert code == 2 and not plan.exists()
    assert re.match(rf"error: {re.escape(str(tmp_path))}\S*in.xml: line 4: expected ", err)
    assert "'A' a second time" in err


def test_a_decorator_without_a_child_is_refused_at_its_line(
    tmp_path: Path, exports: dict[str, str]
) -> None:
    text = exports["nodes/action"].replace(
        "<debug__running", '<Inverter _uid="lone"/><debug__running'
    )
    text = text.replace('<BehaviorTree ID="Action">', '<BehaviorTree ID="Action"><Sequence>')
    text = text.replace("</BehaviorTree>", "</Sequence></BehaviorTree>")
    code, err, plan = import_text(tmp_path, text)
    line = next(n for n, t in enumerate(text.splitlines(), 1) if 'Inverter _uid="lone"' in t)
    assert code == 2 and not plan.exists()
    assert f"in.xml: line {line}: expected a plan costar validate accepts" in err
    assert "needs one node below it" in err


@pytest.mark.parametrize("through", ["itself", "another subtree"])
def test_a_subtree_that_holds_itself_is_refused(
    tmp_path: Path, exports: dict[str, str], through: str
) -> None:
    text = exports["nodes/subtree"]
    inner = '<debug__query name="find"'
    if through == "itself":
        text = text.replace(
            inner, '<SubTree ID="Go_to" TARGET="{TARGET}" REACHED="{R}" _uid="me"/>' + inner
        )
    else:  # Go_to runs Again, which runs Go_to
        again = (
            '<BehaviorTree ID="Again" _uid="examples.again"><Sequence _uid="a1">'
            '<SubTree ID="Go_to" TARGET="0.3;0.1;0.2;0.0;0.0;0.0;1.0" REACHED="{R}" _uid="back"/>'
            "</Sequence></BehaviorTree>\n"
        )
        text = text.replace(inner, '<SubTree ID="Again" _uid="me"/>' + inner)
        text = text.replace("<TreeNodesModel>", again + "<TreeNodesModel>")
    code, err, plan = import_text(tmp_path, text)
    assert code == 2 and not plan.exists()
    assert "holds an instance of itself" in err and "in.xml: line " in err


def test_duplicate_ids_are_refused(tmp_path: Path, exports: dict[str, str]) -> None:
    text = exports["nodes/subtree"]
    twice_tree = text.replace(
        "<TreeNodesModel>", '<BehaviorTree ID="Go_to"><Sequence/></BehaviorTree>\n<TreeNodesModel>'
    )
    code, err, _ = import_text(tmp_path, twice_tree)
    assert code == 2 and "a BehaviorTree ID no other BehaviorTree has" in err
    twice_model = text.replace("<TreeNodesModel>", '<TreeNodesModel><SubTree ID="Go_to"/>')
    code, err, _ = import_text(tmp_path, twice_model)
    assert code == 2 and "a model ID no other model has" in err
    twice_attr = text.replace('name="left"', 'name="left" name="again"')
    code, err, _ = import_text(tmp_path, twice_attr)
    assert code == 2 and "duplicate attribute" in err


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_export_imports_into_a_plan_validation_accepts(
    tmp_path: Path, exports: dict[str, str], name: str, registry: CapabilityRegistry
) -> None:
    code, err, plan = import_text(tmp_path, exports[name])
    assert (code, err) == (0, "")
    assert_accepted(plan, registry)


# ---- item 3: size, depth, long values; linear text


def test_a_file_over_the_limit_is_refused_before_it_is_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    big = tmp_path / "big.xml"
    with open(big, "wb") as handle:  # sparse: no time or disk spent on 20 MB
        handle.truncate(MAX_FILE_BYTES + 1)

    class Unread:
        """The file as the reader opens it, but reading it fails the test."""

        def __init__(self, file: str, mode: str) -> None:
            self._handle = open(file, mode)  # noqa: SIM115 - closed in __exit__

        def __enter__(self) -> Unread:
            return self

        def __exit__(self, *exc: object) -> None:
            self._handle.close()

        def fileno(self) -> int:
            return self._handle.fileno()

        def read(self, *args: Any) -> bytes:
            raise AssertionError("the file was read")

    monkeypatch.setattr("engine.btcpp.reader.open", Unread, raising=False)
    code, _, err = run_cli("import-xml", str(big), str(tmp_path / "out.costar.json"))
    assert code == 2 and not (tmp_path / "out.costar.json").exists()
    assert err == (
        f"error: {big}: expected a tree file of at most 20 MB ({MAX_FILE_BYTES} bytes), "
        f"got {MAX_FILE_BYTES + 1} bytes\n"
    )


def test_deep_nesting_is_refused_with_its_line(tmp_path: Path) -> None:
    deep = '<root BTCPP_format="4">\n' + "<Sequence>" * 100_000 + "</Sequence>" * 100_000
    code, err, plan = import_text(tmp_path, deep + "</root>")
    assert code == 2 and not plan.exists()
    assert "in.xml: line 2: expected well-formed UTF-8 XML, got elements nested at most" in err


def test_huge_attributes_and_texts_are_refused_with_their_line(
    tmp_path: Path, exports: dict[str, str]
) -> None:
    huge = "x" * (MAX_VALUE_CHARS + 1)
    text = exports["nodes/action"].replace('name="move"', f'name="{huge}"')
    code, err, _ = import_text(tmp_path, text)
    assert code == 2 and f"characters long, not {MAX_VALUE_CHARS + 1}" in err
    assert len(err) < 500  # the value itself is not printed
    text = exports["nodes/action"].replace("ticks spent RUNNING", huge)
    code, err, _ = import_text(tmp_path, text)
    assert code == 2 and "the text inside <input_port> at most" in err


def test_two_megabytes_of_short_text_lines_import(
    tmp_path: Path, exports: dict[str, str], registry: CapabilityRegistry
) -> None:
    """Text was appended line by line (quadratic); the timing is bench/xml_import.py's."""
    lines = "a short line of a port description\n" * 26_000  # 0.9 MB in one port's text
    text = exports["nodes/action"].replace("ticks spent RUNNING", lines)
    text = text.replace("status at the end", lines)  # and as much in another
    code, err, plan = import_text(tmp_path, text)
    assert (code, err) == (0, "")
    assert_accepted(plan, registry)


# ---- any bytes: exit 0 or 2, and 0 only with a file validation accepts


def _mutations(rng: random.Random, text: str) -> list[tuple[str, bytes]]:
    """One case of each kind for one exported file (name, bytes)."""
    data = text.encode("utf-8")
    flipped = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        flipped[rng.randrange(len(flipped))] = rng.randrange(256)
    lines = text.splitlines(keepends=True)
    at = rng.randrange(1, len(lines))
    node = next((ln for ln in lines[at:] if "_uid=" in ln and "<BehaviorTree" not in ln), "")
    uid = re.search(r'_uid="([^"]*)"', node)
    cases = [
        ("truncated", data[: rng.randrange(len(data))]),
        ("bytes flipped", bytes(flipped)),
        ("line dropped", "".join(lines[:at] + lines[at + 1 :]).encode()),
        ("line doubled", "".join(lines[: at + 1] + lines[at:]).encode()),
        ("latin-1", text.replace('name="', 'name="ÿé', 1).encode("latin-1", "replace")),
        ("utf-16 without BOM", text.encode("utf-16-le")),
        ("invalid utf-8", data.replace(b'name="', b'name="\xc3\x28', 1)),
        ("huge attribute", text.replace('name="', 'name="' + "n" * 1_100_000, 1).encode()),
        ("huge text", text.replace("</CostarPlan>", "t\n" * 600_000 + "</CostarPlan>").encode()),
        ("deep", _around_a_leaf(text, "<Inverter>" * 450, "</Inverter>" * 450).encode()),
        ("childless decorator", _around_a_leaf(text, "<Inverter/>", "").encode()),
    ]
    if uid is not None:  # a second node with the same _uid, in the same tree
        cases.append(("duplicate _uid", "".join([*lines[:at], node, *lines[at:]]).encode()))
    cases.append(("duplicate parameter", _parameter_twice(text).encode()))
    subtree = re.search(r'<BehaviorTree ID="([^"]+)" _uid', text)
    if subtree is not None:  # a subtree that runs itself
        tree_id = subtree.group(1)
        start = text.index(subtree.group(0))
        root_node = re.compile(r"<[^>]*[^/]>").search(text, text.index(">", start) + 1)
        assert root_node is not None
        inner = root_node.end()  # the first thing in the subtree's root node
        looped = text[:inner] + f'<SubTree ID="{tree_id}" _uid="loop"/>' + text[inner:]
        cases.append(("self-including subtree", looped.encode()))
    return cases


def _around_a_leaf(text: str, before: str, after: str) -> str:
    """``before`` and ``after`` put around the tree's last leaf (an operation's element)."""
    leaves = list(re.finditer(r"<[a-z]\w*__\w+ [^>]*/>", text))
    assert leaves
    leaf = leaves[-1]
    return text[: leaf.start()] + before + leaf.group(0) + after + text[leaf.end() :]


def _parameter_twice(text: str) -> str:
    """The plan's first parameter declared twice (a parameter A twice when it has none)."""
    if "<Parameter " in text:
        return re.sub(r"(<Parameter [^>]*/>)", r"\1\1", text, count=1)
    twice = '<Parameter name="A" type="Number"/>' * 2
    if re.search(r"<CostarPlan [^>]*/>", text):
        return re.sub(r"(<CostarPlan [^>]*?)\s*/>", rf"\1>{twice}</CostarPlan>", text, count=1)
    return re.sub(r"(<CostarPlan [^>]*>)", rf"\1{twice}", text, count=1)


def test_fuzzed_exports_import_with_exit_0_or_2_and_only_valid_plans(
    tmp_path: Path,
    exports: dict[str, str],
    registry: CapabilityRegistry,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Each command finds the installed capabilities again (once per process in use); here
    # that would be most of the time, so the cases share one cell-less registry.
    monkeypatch.setattr("capabilities.xml_commands.CapabilityRegistry", lambda: registry)
    rng = random.Random(20230423)  # fixed before any result was seen
    cases = [
        (f"{name}: {kind}", data)
        for name in SHIPPED
        for _ in range(2)
        for kind, data in _mutations(rng, exports[name])
    ]
    assert 100 <= len(cases) <= 200
    written = 0
    for label, data in cases:
        try:
            code, err, plan = import_text(tmp_path, data)
        except Exception as exc:  # pragma: no cover - the failure message says which case
            raise AssertionError(f"{label}: {exc!r}") from exc
        assert code in (0, 2), label
        assert (code == 0) == plan.exists(), label
        if code == 0:
            written += 1
            assert_accepted(plan, registry)
        else:
            assert err.startswith("error: ") and "Traceback" not in err, label
    assert written > 0  # some mutations (a line doubled in a description...) still import
