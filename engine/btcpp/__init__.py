"""BehaviorTree.CPP v4 XML, both ways: plans open in Groot2 and BehaviorTree.CPP, and back.

A plan is written as::

    <root BTCPP_format="4" main_tree_to_execute="Cup_to_bin">
      <CostarPlan format_version="1" tree="Cup_to_bin" id=".." name="Cup to bin" ...>
        <Parameter name="CUP_POSE" type="Pose"/>   (also Waypoint, Object, Layout)
      </CostarPlan>
      <BehaviorTree ID="Cup_to_bin">
        <Sequence name="pick" _uid="3f.." _x="0.0" _y="120.0">
          <motion__move_to target="{CUP_POSE}" speed="0.25" _uid=".."/>
          <SubTree ID="Transfer" name="Transfer 4-hole" OBJECT="plate_4" _uid=".."/>
        </Sequence>
      </BehaviorTree>
      <BehaviorTree ID="Transfer" _uid="kitting.transfer" _name="Transfer" _version="1" ...>
      <TreeNodesModel>
        <Action ID="motion__move_to">
          <input_port name="target" type="costar::Waypoint">where to move</input_port> ...
        <SubTree ID="Transfer"><input_port name="OBJECT" type="costar::ObjectModel" .../>
        <Decorator ID="Iterator"> ...
      </TreeNodesModel>
    </root>

- One ``<BehaviorTree>`` for the plan (named in ``main_tree_to_execute``) and one per
  subtree its instances run; an instance is a ``<SubTree>`` whose attributes remap the
  subtree's declared inputs and outputs (BehaviorTree.CPP's port remapping, the ports
  declared in the TreeNodesModel's ``<SubTree>`` with types, defaults and descriptions); a
  name the subtree shares on purpose is remapped to itself (``BIN_POSE="{BIN_POSE}"``); an
  output the instance does not copy out goes to the private sink ``{_}``, since
  BehaviorTree.CPP wants every declared port remapped. Reading XML without SubTree models
  (BehaviorTree.CPP's ``WriteTreeToXML`` keeps none), a subtree's ports are the names its
  instances remap: outputs where an operation inside writes them, inputs else.
- Operations in the compact syntax, their ids mapped reversibly to the characters
  BehaviorTree.CPP 4.8.4+ accepts (:mod:`engine.btcpp.names`); every operation used is
  declared in the TreeNodesModel with its typed ports, conditions as ``<Condition>``,
  queries as ``<Action>`` with output ports.
- Import knows: the mapped built-ins, Iterator and Enforce, ``<SubTree>`` of a tree in the
  file, and operations (those of the given manifests; without manifests, the Actions and
  Conditions the file's TreeNodesModel declares). ``<include path=...>`` brings in another
  file's trees (:mod:`engine.btcpp.includes`). A ``<SubTree _autoremap="true">`` of a tree
  without a model shares every name its tree uses (but ``_private`` ones) with the instance's
  scope, as BehaviorTree.CPP's autoremap does. The tree run is the one
  ``main_tree_to_execute`` names, else the file's only tree (not an included one), else its
  first (as BehaviorTree.CPP writes a loaded tree: the main one first). Any other node
  type, unknown ports and values not in their port's form are problems, all of them reported
  with their lines (:class:`XmlFileError`).
- The pre- and post-conditions of any node as BehaviorTree.CPP's own attributes
  (``_failureIf``, ``_successIf``, ``_skipIf``, ``_while``, ``_onSuccess``, ``_onFailure``,
  ``_post``, ``_onHalted``), read and written as they are and run by
  :mod:`engine.conditions`; a script that does not parse is reported by validation.
- Logic nodes as BehaviorTree.CPP's built-ins, Iterator and Enforce as declared
  decorators (:mod:`engine.btcpp.logic`); ``Script`` and ``ScriptCondition`` with their
  ``code`` as it is, run by :mod:`engine.script`.
- A reference is ``{NAME}``; a fixed value is text in one exact form per type
  (:mod:`engine.btcpp.values`).
- What BehaviorTree.CPP has no place for is in ``_``-attributes, which it ignores: our node
  ids (``_uid``), canvas positions (``_x``, ``_y``, ``_collapsed``), a value's type where
  a port takes several (``_types="target=Pose"``), exact settings (``_success="1.0"``), and
  the plan's own data in ``<CostarPlan>`` (BehaviorTree.CPP reads only BehaviorTree,
  TreeNodesModel and include elements of the root). The label is BehaviorTree.CPP's ``name``.
"""

from __future__ import annotations

from engine.btcpp.errors import XmlExportError, XmlFileError, XmlProblem
from engine.btcpp.imported import XmlImport, XmlLines
from engine.btcpp.reader import import_xml, load_xml, read_xml
from engine.btcpp.writer import export_xml

__all__ = [
    "XmlExportError",
    "XmlFileError",
    "XmlImport",
    "XmlLines",
    "XmlProblem",
    "export_xml",
    "import_xml",
    "load_xml",
    "read_xml",
]
