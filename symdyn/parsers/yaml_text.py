"""Robot-file text -> plain data: YAML (JSON is valid YAML), with repeated keys refused.

The text is read with PyYAML's SafeLoader (data only: nothing from the file is
executed or constructed beyond mappings, lists, strings and numbers). yaml.safe_load
silently keeps the last of repeated keys; a robot file must not repeat one, so the
node tree is checked before it is turned into data, and the error names the key's
line, the link and the field. Tab-indented JSON (valid JSON, not YAML) is read as JSON.

Anchors, aliases and merge keys (`&a`, `*a`, `<<: *a`) are allowed, but bounded: an alias
stands for a copy of its anchor's node, so a few hundred bytes of nested aliases can stand for
millions of nodes (a merge-key bomb of 24 levels doubles at each one). Before anything is
constructed, the size of the document with every alias expanded is counted on the node graph
(each node once, so the count itself takes linear time); a document whose aliases and merge keys
add more than MAX_EXPANDED_NODES = 100,000 nodes to those written is refused (the largest example
robot has fewer than 1,000 nodes in all). Nodes written out plainly are not counted against it:
their size is the text's own, and a plain file of 30,000 frames is no bomb.
"""

from __future__ import annotations

import json

import yaml

from ..errors import SymdynError

__all__ = ["parse_text", "MAX_EXPANDED_NODES"]

#: Most nodes the aliases and merge keys of a robot file may add once expanded.
MAX_EXPANDED_NODES = 100_000
#: Longest integer a robot file may write, in characters (the expression parser takes 30 digits).
MAX_INT_TEXT = 100


class _Loader(yaml.SafeLoader):
    """SafeLoader whose integers are refused beyond MAX_INT_TEXT characters before int() reads them
    (Python refuses more than 4300 digits with a ValueError, and YAML 1.1's base-60 integers grow
    with every ':')."""

    def construct_yaml_int(self, node: yaml.ScalarNode) -> int:
        if len(node.value) > MAX_INT_TEXT:
            raise yaml.constructor.ConstructorError(
                None, None, f"an integer of more than {MAX_INT_TEXT} characters", node.start_mark
            )
        return super().construct_yaml_int(node)


_Loader.add_constructor("tag:yaml.org,2002:int", _Loader.construct_yaml_int)


def parse_text(text: str, file: str) -> object:
    """The data of a robot file's text (None for an empty document); SymdynError for bad YAML/JSON."""
    try:
        loader = _Loader(text)
        try:
            node = loader.get_single_node()
            _check_expanded_size(node, file)
            _check_duplicate_keys(node, file)
            return None if node is None else loader.construct_document(node)
        finally:
            loader.dispose()
    except yaml.YAMLError as exc:
        if text.lstrip().startswith("{"):
            # Tab-indented JSON is valid JSON but not YAML; read it as the JSON it is.
            return _parse_json(text, file)
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        parts = [getattr(exc, "context", None), getattr(exc, "problem", None)]
        problem = ", ".join(p for p in parts if p) or str(exc)
        if mark is not None:
            raise SymdynError(
                f"invalid YAML at line {mark.line + 1}, column {mark.column + 1}: {problem}",
                file=file,
            ) from None
        raise SymdynError(f"invalid YAML: {problem}", file=file) from None
    except RecursionError:
        raise SymdynError("invalid YAML: nested too deeply", file=file) from None


def _parse_json(text: str, file: str) -> object:
    def pairs(items: list[tuple[str, object]]) -> dict:
        out: dict = {}
        for k, v in items:
            if k in out:
                raise SymdynError(f"duplicate key '{k}'", file=file, field=k)
            out[k] = v
        return out

    def integer(digits: str) -> int:
        if len(digits) > MAX_INT_TEXT:
            raise SymdynError(f"invalid JSON: an integer of more than {MAX_INT_TEXT} characters", file=file)
        return int(digits)

    try:
        return json.loads(text, object_pairs_hook=pairs, parse_int=integer)
    except json.JSONDecodeError as exc:
        raise SymdynError(
            f"invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}", file=file
        ) from None
    except RecursionError:
        raise SymdynError("invalid JSON: nested too deeply", file=file) from None


def _check_expanded_size(root: yaml.Node | None, file: str) -> None:
    """Refuse a document whose aliases and merge keys, expanded, add more than MAX_EXPANDED_NODES
    nodes to those written.

    A node's expanded size less the number of distinct nodes met so far (all its descendants
    among them) is at most what aliases add below it, so the refusal never counts plain nodes.
    """
    size: dict[int, int] = {}  # id(node) -> expanded size
    started: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [] if root is None else [(root, False)]
    while stack:
        node, children_done = stack.pop()
        if id(node) in size or (not children_done and id(node) in started):
            continue
        if isinstance(node, yaml.MappingNode):
            children = [n for pair in node.value for n in pair]
        elif isinstance(node, yaml.SequenceNode):
            children = list(node.value)
        else:
            size[id(node)] = 1
            continue
        if children_done:
            # a node that is its own descendant (a recursive alias) counts as one here
            size[id(node)] = 1 + sum(size.get(id(c), 1) for c in children)
            if size[id(node)] - len(size) > MAX_EXPANDED_NODES:
                raise SymdynError(
                    f"the document expands to more than {MAX_EXPANDED_NODES:,} nodes beyond those "
                    f"written once its aliases and merge keys (line {node.start_mark.line + 1}) are "
                    "expanded; write it out plainly",
                    file=file,
                )
            continue
        started.add(id(node))
        stack.append((node, True))
        stack.extend((c, False) for c in children if id(c) not in size)


def _check_duplicate_keys(root: yaml.Node | None, file: str) -> None:
    """yaml.safe_load silently keeps the last of repeated keys; a robot file must not repeat."""
    seen: set[int] = set()
    # (node, path of keys/indices from the top, (link index, link name) or None)
    stack: list[tuple[yaml.Node, tuple, tuple | None]] = [] if root is None else [(root, (), None)]
    while stack:
        node, path, link = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            keys: dict[tuple[str, str], int] = {}
            for key_node, value_node in node.value:
                key = getattr(key_node, "value", "?")
                if isinstance(key_node, yaml.ScalarNode) and key != "<<":
                    k = (key_node.tag, key)
                    if k in keys:
                        inner = path[2:] if link else path
                        raise SymdynError(
                            f"duplicate key '{key}' at line {key_node.start_mark.line + 1} "
                            f"(first at line {keys[k]})",
                            file=file,
                            link_index=link[0] if link else None,
                            link_name=link[1] if link else None,
                            field=".".join(str(x) for x in (*inner, key)),
                        )
                    keys[k] = key_node.start_mark.line + 1
                stack.append((value_node, (*path, key), link))
        elif isinstance(node, yaml.SequenceNode):
            for i, item in enumerate(node.value):
                item_link = link
                if path == ("links",):
                    item_link = (i + 1, _link_node_name(item, i + 1))
                stack.append((item, (*path, i), item_link))


def _link_node_name(node: yaml.Node, index: int) -> str:
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            if getattr(key_node, "value", None) == "name" and isinstance(value_node, yaml.ScalarNode):
                return str(value_node.value)
    return f"link{index}"
