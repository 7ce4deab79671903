"""Robot-file text -> plain data: YAML (JSON is valid YAML), with repeated keys refused.

The text is read with PyYAML's SafeLoader (data only: nothing from the file is
executed or constructed beyond mappings, lists, strings and numbers). yaml.safe_load
silently keeps the last of repeated keys; a robot file must not repeat one, so the
node tree is checked before it is turned into data, and the error names the key's
line, the link and the field. Tab-indented JSON (valid JSON, not YAML) is read as JSON.
"""

from __future__ import annotations

import json

import yaml

from ..errors import SymdynError

__all__ = ["parse_text"]


def parse_text(text: str, file: str) -> object:
    """The data of a robot file's text (None for an empty document); SymdynError for bad YAML/JSON."""
    try:
        loader = yaml.SafeLoader(text)
        try:
            node = loader.get_single_node()
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

    try:
        return json.loads(text, object_pairs_hook=pairs)
    except json.JSONDecodeError as exc:
        raise SymdynError(
            f"invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}", file=file
        ) from None
    except RecursionError:
        raise SymdynError("invalid JSON: nested too deeply", file=file) from None


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
