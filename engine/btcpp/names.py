r"""Our ids in BehaviorTree.CPP's allowed characters, reversibly.

BehaviorTree.CPP 4.8.4 and later refuse model ids (and BehaviorTree ids) that hold ``.``,
``:``, ``/``, spaces, quotes, ``<>&*?|\`` or control characters, and an XML element name
must start with a letter. Operation ids are ``capability.verb_object``, so the usual id
only needs its dots mapped: ``motion.move_to`` <-> ``motion__move_to``. That "plain" form is
used when it can be undone unambiguously: the id is letters and digits in runs joined by
single ``_`` or ``.``, starting with a letter (then a ``__`` can only have been a dot).

Any other id is written in the "escaped" form: a leading ``_`` and then every character
that is not an ASCII letter or digit as ``_<hex code>_`` (``my op.x`` ->
``_my_20_op_2e_x``). A plain form never starts with ``_``, so the two never meet.
"""

from __future__ import annotations

import re
from collections.abc import Collection

__all__ = [
    "decode_id",
    "decode_port",
    "encode_id",
    "encode_port",
    "is_model_name",
    "readable_tree_id",
]

_RUN = r"[A-Za-z0-9]+(?:_[A-Za-z0-9]+)*"
_PLAIN = re.compile(rf"[A-Za-z](?:[A-Za-z0-9]*)(?:_[A-Za-z0-9]+)*(?:\.{_RUN})*\Z")
_PLAIN_ENCODED = re.compile(rf"[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)*(?:__{_RUN})*\Z")
_ESCAPE = re.compile(r"_([0-9a-f]{1,6})_")
_FORBIDDEN = set(" \t\n\r<>&\"'/\\:*?|.")
# Names BehaviorTree.CPP keeps for itself as model ids.
_RESERVED = {"Root", "root"}


def encode_id(name: str, avoid: Collection[str] = ()) -> str:
    """The model id BehaviorTree.CPP accepts for one of our ids (see the module doc).

    Args:
        name: our id.
        avoid: model ids taken by other nodes (BehaviorTree.CPP's built-ins): a plain form
            that would be one of them is escaped instead.
    """
    plain = name.replace(".", "__")
    if _PLAIN.match(name) and name not in _RESERVED and plain not in avoid:
        return plain
    return "_" + "".join(c if c.isascii() and c.isalnum() else f"_{ord(c):x}_" for c in name)


def decode_id(model: str) -> str:
    """Our id of a model id written by :func:`encode_id`.

    Raises:
        ValueError: ``model`` is in neither form (says what was expected).
    """
    if model.startswith("_"):
        body, out, pos = model[1:], [], 0
        while pos < len(body):
            if body[pos] != "_":
                if not (body[pos].isascii() and body[pos].isalnum()):
                    break
                out.append(body[pos])
                pos += 1
                continue
            match = _ESCAPE.match(body, pos)
            if match is None:
                break
            out.append(chr(int(match.group(1), 16)))
            pos = match.end()
        else:
            return "".join(out)
        raise ValueError(f"an escaped id (_ then letters, digits and _<hex>_ codes), not {model!r}")
    if not _PLAIN_ENCODED.match(model):
        raise ValueError(f"a model id of letters, digits and _, not {model!r}")
    return model.replace("__", ".")


def encode_port(port: str) -> str:
    """The attribute name of one of our port names. BehaviorTree.CPP takes a port name that
    starts with a letter, has no forbidden character and is not ``name`` or ``ID``; any other
    (and one that starts with ``p_``) is written ``p_`` + :func:`encode_id`.
    """
    plain = port[:1].isascii() and port[:1].isalpha() and is_model_name(port)
    if plain and port not in ("name", "ID") and not port.startswith("p_"):
        return port
    return "p_" + encode_id(port)


def decode_port(attr: str) -> str:
    """Our port name of an attribute written by :func:`encode_port`.

    Raises:
        ValueError: a ``p_`` name that is not an encoded id.
    """
    return decode_id(attr[2:]) if attr.startswith("p_") else attr


def is_model_name(name: str) -> bool:
    """True when BehaviorTree.CPP accepts ``name`` as a model or tree id as it is."""
    return (
        bool(name)
        and name not in _RESERVED
        and not any(c in _FORBIDDEN or ord(c) < 32 or ord(c) == 127 for c in name)
    )


def readable_tree_id(name: str, taken: set[str]) -> str:
    """A BehaviorTree id for a plan or subtree name that reads like it: characters other than
    letters and digits become ``_``; a clash with ``taken`` gets ``_2``, ``_3``... The name itself
    is kept elsewhere in the file, so this need not be reversible.
    """
    words = re.findall(r"[^\W_]+", name)  # letters and digits, any script
    base = "_".join(words)
    if not base or not (base[0].isalpha() or base[0] == "_") or base in _RESERVED:
        base = f"T_{base}"
    candidate, number = base, 2
    while candidate in taken:
        candidate, number = f"{base}_{number}", number + 1
    taken.add(candidate)
    return candidate
