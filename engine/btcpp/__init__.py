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
  subtree's declared inputs and outputs (BehaviorTree.CPP's port remapping); a name the
  subtree shares on purpose is remapped to itself (``BIN_POSE="{BIN_POSE}"``).
- Operations in the compact syntax, their ids mapped reversibly to the characters
  BehaviorTree.CPP 4.8.4+ accepts (:mod:`engine.btcpp.names`); every operation used is
  declared in the TreeNodesModel with its typed ports, conditions as ``<Condition>``,
  queries as ``<Action>`` with output ports.
- Logic nodes as BehaviorTree.CPP's built-ins, Iterator and Enforce as declared
  decorators (:mod:`engine.btcpp.logic`).
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
from engine.btcpp.reader import import_xml, load_xml
from engine.btcpp.writer import export_xml

__all__ = ["XmlExportError", "XmlFileError", "XmlProblem", "export_xml", "import_xml", "load_xml"]
