"""Robot-file text -> data (symdyn.parsers.yaml_text): aliases and merge keys bounded before
construction, integers bounded before int() reads them. Each hostile case is refused within a
time bound (tests/timebound.py) with one line naming the file."""

from __future__ import annotations

import pytest
import yaml
from timebound import refused, within

from symdyn.errors import SymdynError
from symdyn.parsers import robot_from_data
from symdyn.parsers.yaml_text import MAX_EXPANDED_NODES, parse_text


def merge_bomb(levels: int) -> str:
    """Each level merges two copies of the one before: 2**levels keys once expanded."""
    text = "a0: &a0 {k: 1}\n"
    for i in range(1, levels + 1):
        text += f"a{i}: &a{i} {{<<: [*a{i - 1}, *a{i - 1}], k{i}: 1}}\n"
    return text


def alias_bomb(levels: int) -> str:
    """The billion laughs: each list holds nine copies of the one before."""
    text = "l0: &l0 [x]\n"
    for i in range(1, levels + 1):
        text += f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 9)}]\n"
    return text


def test_a_merge_key_bomb_is_refused_before_it_is_constructed(tmp_path, capsys):
    """24 levels in 856 bytes took minutes and gigabytes; the count on the node graph is linear."""
    path = tmp_path / "bomb.yaml"
    path.write_text(merge_bomb(24))
    line = refused(capsys, "derive", path, seconds=5)
    assert line.startswith(f"symdyn: error: {path}: the document expands to more than 100,000 nodes")


def test_an_alias_bomb_is_refused():
    with within(5), pytest.raises(SymdynError, match="expands to more than"):
        parse_text(alias_bomb(9), "f.yaml")


def test_aliases_and_merge_keys_of_an_ordinary_size_are_read_as_written_out():
    """A shared inertia and a merged link read as the same document written out plainly."""
    text = """
common: &link {joint: revolute, mass: 1, inertia: &I {ixx: 1, iyy: 2, izz: 3}}
links:
  - <<: *link
    name: a
  - {<<: *link, name: b, mass: 2, inertia: *I}
"""
    plain = """
common: {joint: revolute, mass: 1, inertia: {ixx: 1, iyy: 2, izz: 3}}
links:
  - {joint: revolute, mass: 1, inertia: {ixx: 1, iyy: 2, izz: 3}, name: a}
  - {joint: revolute, mass: 2, inertia: {ixx: 1, iyy: 2, izz: 3}, name: b}
"""
    assert parse_text(text, "f.yaml") == yaml.safe_load(plain)


def test_the_bound_counts_expanded_nodes():
    """A merge bomb of n levels has 2**n - 1 + ... nodes: under the bound it is read, over it not."""
    small = merge_bomb(10)  # about 2**10 keys expanded
    assert len(parse_text(small, "f.yaml")["a10"]) == 11
    assert MAX_EXPANDED_NODES < 2**17
    with pytest.raises(SymdynError, match="expands"):
        parse_text(merge_bomb(17), "f.yaml")


def test_a_recursive_alias_does_not_hang():
    with within(5), pytest.raises(SymdynError, match="a link must be a mapping, got a list"):
        robot_from_data(parse_text("name: t\nlinks: &a [*a]\n", "f.yaml"), "f.yaml")


@pytest.mark.parametrize(
    "text, message",
    [
        ("mass: " + "9" * 5000, "invalid YAML at line 1, column 7: an integer of more than 100 characters"),
        ('{\n\t"mass": ' + "9" * 5000 + "}", "invalid JSON: an integer of more than 100 characters"),
    ],
)
def test_integers_with_thousands_of_digits_are_refused_in_one_line(text, message):
    """Python's int() refuses more than 4300 digits with a ValueError (an internal error before)."""
    with within(5), pytest.raises(SymdynError, match=message):
        parse_text(text, "f.yaml")


def test_a_plain_file_larger_than_the_bound_is_no_alias_bomb():
    """21,000 frames written out plainly are 105,000 nodes, more than the bound, and no alias
    adds any: read as written (a file of 30,000 frames was refused as an alias bomb)."""
    frames = [{"name": f"f{i}", "link": "forearm"} for i in range(21_000)]
    text = "frames:\n" + "".join(f"  - {{name: {f['name']}, link: {f['link']}}}\n" for f in frames)
    assert 5 * len(frames) > MAX_EXPANDED_NODES
    with within(60):
        assert parse_text(text, "f.yaml") == {"frames": frames}


def test_an_alias_bomb_inside_a_large_plain_file_is_still_refused():
    """The plain nodes around it do not pay for what the aliases add."""
    plain = "".join(f"p{i}: [{i}, {i}, {i}]\n" for i in range(5_000))
    match = "expands to more than 100,000 nodes beyond those written"
    with within(20), pytest.raises(SymdynError, match=match):
        parse_text(plain + alias_bomb(6), "f.yaml")
