"""Our export loaded by BehaviorTree.CPP's own factory (4.10, strict about ids and attributes).

Needs a checker program built against a local BehaviorTree.CPP (its source is
``tools/btcpp/check_load.cpp``, with how to build it); set ``COSTAR_BTCPP_CHECK`` to it. Its
contract:

- ``CHECK MODELS.txt load TREE.xml``: registers every model of MODELS.txt as a simple
  action, condition, control or decorator with its typed ports (``BT::InputPort<double>`` ...), loads
  the XML with ``factory.createTreeFromText`` and prints ``BT::WriteTreeToXML``; exit 0, or
  the library's error on stderr and exit 1.
- ``CHECK MODELS.txt models``: prints ``BT::writeTreeNodesModelXML(factory)``.

MODELS.txt is :func:`btcpp_models.models_text` of our manifests (written from them, not from
the XML under test). Without the program these tests are skipped with that reason.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest
from btcpp_models import models_text
from test_btcpp_xml import EXAMPLES, _kitting, _nested

from capabilities.xml_commands import operation_manifests
from engine.btcpp import export_xml
from engine.files import load_plan
from engine.spec import PlanSpec

CHECKER = os.environ.get("COSTAR_BTCPP_CHECK", "")
pytestmark = [
    pytest.mark.btcpp,
    pytest.mark.skipif(
        not (CHECKER and os.access(CHECKER, os.X_OK)),
        reason="needs a BehaviorTree.CPP checker program: set COSTAR_BTCPP_CHECK (see the module doc)",
    ),
]


def _load_in_btcpp(tmp_path: Path, xml: str) -> subprocess.CompletedProcess[str]:
    models, tree = tmp_path / "models.txt", tmp_path / "tree.xml"
    models.write_text(models_text(operation_manifests().values()), encoding="utf-8")
    tree.write_text(xml, encoding="utf-8")
    return subprocess.run(
        [CHECKER, str(models), "load", str(tree)], capture_output=True, text=True, timeout=60
    )


def _plans() -> list[tuple[str, PlanSpec]]:
    return [(p.name, load_plan(p)) for p in EXAMPLES] + [
        ("kitting (subtrees)", _kitting()),
        ("nested subtrees", _nested()),
    ]


def test_btcpp_loads_the_export_of_every_example_and_a_plan_with_subtrees(tmp_path: Path) -> None:
    manifests = operation_manifests()
    failures = []
    for name, plan in _plans():
        result = _load_in_btcpp(tmp_path, export_xml(plan, manifests))
        if result.returncode != 0:
            failures.append(f"{name}: {result.stderr.strip()}")
    assert failures == []


def test_btcpp_refuses_what_it_should_so_the_check_can_fail(tmp_path: Path) -> None:
    xml = export_xml(load_plan(EXAMPLES[0]), operation_manifests())
    dotted = xml.replace("<motion__move_to ", "<motion.move_to ", 1)
    result = _load_in_btcpp(tmp_path, dotted)
    assert result.returncode == 1 and "forbidden character '.'" in result.stderr
    undeclared = xml.replace(" _uid=", " uid=", 1)
    result = _load_in_btcpp(tmp_path, undeclared)
    assert result.returncode == 1 and "not in the providedPorts()" in result.stderr
