"""Contacts with the world: a named frame of the robot held by the environment (docs/contacts.md).

A `Contact` {name, frame, kind} constrains the motion of one named frame F of the robot (a link
or a Robot.frames entry), in Pinocchio's conventions:

    kind "point"  (CONTACT_3D, LOCAL_WORLD_ALIGNED): 3 rows, the linear velocity of F's origin in
                  world-aligned axes, v_F = Jc qd;
    kind "6d"     (CONTACT_6D, LOCAL): 6 rows, F's spatial velocity in its own axes, linear then
                  angular.

A robot's contacts (Robot.contacts) stack their rows in declaration order: NLAMBDA = 3 per point
contact + 6 per 6d contact, NCONTACT contacts. The constrained dynamics (symdyn.algorithms.contacts)
solve M qdd + b + F = tau + Jc^T lambda with Jc qdd + gamma = 0 for the active contacts.

Names are identifiers (a letter or `_` first, then letters, digits and `_`), unique among the
contacts; the frame must exist (checked by the Robot against its frames). `with_contacts` builds
the contacts of a loader's `contacts=` keyword or of `--contacts FRAME[:point|6d]`.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace

from ..errors import SymdynError
from .names import identifier

__all__ = [
    "Contact",
    "CONTACT_KINDS",
    "check_contacts",
    "contacts_from",
    "contact_rows",
    "parse_contact_option",
    "with_contacts",
]

#: The kinds of contact and the rows (constraint equations) each gives.
CONTACT_KINDS = {"point": 3, "6d": 6}
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
#: the longest contact name accepted (it is spelled in comments and messages)
MAX_NAME = 64


@dataclass(frozen=True)
class Contact:
    """A contact named `name` at the robot's frame `frame`, of kind "point" or "6d"."""

    name: str
    frame: str
    kind: str = "point"

    @property
    def rows(self) -> int:
        """3 (point) or 6 (6d) constraint rows."""
        return CONTACT_KINDS[self.kind]


def contact_rows(contacts: Sequence[Contact]) -> int:
    """NLAMBDA: the rows of all contacts, 3 per point and 6 per 6d."""
    return sum(c.rows for c in contacts)


def _text(value: object) -> str:
    return repr(value) if not isinstance(value, str) or len(value) <= 40 else repr(value[:40] + "...")


def check_contacts(
    robot_name: str, contacts: Iterable[Contact], frame_names: Iterable[str], where: str
) -> None:
    """Refuse a contact that is not a Contact, a bad or duplicate name, an unknown kind or frame.

    Raises:
        SymdynError: one line naming `where` (file and field, or the option) and the contact.
    """
    frames = set(frame_names)
    seen: set[str] = set()
    for k, c in enumerate(contacts):
        at = f"{where}[{k}]"
        if not isinstance(c, Contact):
            raise SymdynError(f"robot '{robot_name}': {at}: expected a Contact, got {_text(c)}")
        if not (isinstance(c.name, str) and _NAME.match(c.name) and len(c.name) <= MAX_NAME):
            raise SymdynError(
                f"robot '{robot_name}': {at}.name: {_text(c.name)} is not a contact name (letters, digits "
                f"and underscores, not starting with a digit, at most {MAX_NAME} characters)"
            )
        if c.name in seen:
            raise SymdynError(f"robot '{robot_name}': {at}.name: duplicate contact name '{c.name}'")
        seen.add(c.name)
        if not isinstance(c.kind, str) or c.kind not in CONTACT_KINDS:
            raise SymdynError(
                f"robot '{robot_name}': {at}.type: contact '{c.name}' has type {_text(c.kind)}, "
                "expected point or 6d"
            )
        if not isinstance(c.frame, str) or c.frame not in frames:
            raise SymdynError(
                f"robot '{robot_name}': {at}.frame: contact '{c.name}' is at {_text(c.frame)}, "
                "which is no frame of the robot (a link or a frame: docs/frames.md)"
            )


def _one(spec: object, k: int, where: str) -> Contact:
    """A Contact from a Contact, a mapping {name, frame, type} or a string FRAME[:point|6d]."""
    if isinstance(spec, Contact):
        return spec
    if isinstance(spec, str):
        return parse_contact_option(spec, where)
    if isinstance(spec, Mapping):
        unknown = sorted(str(key) for key in spec if key not in ("name", "frame", "type"))
        if unknown:
            raise SymdynError(f"{where}[{k}]: unknown field {_text(unknown[0])} (expected name, frame, type)")
        if "frame" not in spec:
            raise SymdynError(f"{where}[{k}]: missing required field 'frame'")
        frame = spec["frame"]
        if not isinstance(frame, str):
            raise SymdynError(f"{where}[{k}].frame: expected a frame's name, got {_text(frame)}")
        name = spec.get("name", _default_name(frame))
        kind = spec.get("type", "point")
        return Contact(name, frame, kind)
    raise SymdynError(
        f"{where}[{k}]: expected a contact {{name, frame, type}} or 'FRAME[:point|6d]', got {_text(spec)}"
    )


def _default_name(frame: str) -> str:
    """A contact's name when none is given: its frame's, made an identifier if it is not one."""
    return frame if _NAME.match(frame) else identifier(frame, "contact")


def parse_contact_option(text: str, where: str = "--contacts") -> Contact:
    """`FRAME[:point|6d]` (the command line's --contacts): named after its frame, a point by default."""
    frame, sep, kind = text.rpartition(":") if ":" in text else (text, "", "point")
    if sep and kind not in CONTACT_KINDS:
        raise SymdynError(f"{where} {_text(text)}: unknown contact type {_text(kind)} (expected point or 6d)")
    if not frame:
        raise SymdynError(f"{where} {_text(text)}: expected FRAME[:point|6d]")
    return Contact(_default_name(frame), frame, kind or "point")


def contacts_from(specs: object, where: str = "contacts") -> tuple[Contact, ...]:
    """Contacts from a sequence of Contact, {name, frame, type} or 'FRAME[:point|6d]' (None: none).
    The frames and names are checked when the Robot is built (check_contacts)."""
    if specs is None:
        return ()
    if isinstance(specs, (str, bytes, Mapping, Contact)) or not isinstance(specs, Iterable):
        raise SymdynError(f"{where}: expected a list of contacts, got {_text(specs)}")
    return tuple(_one(s, k, where) for k, s in enumerate(specs))


def with_contacts(robot, specs: object):
    """`robot` (a Robot) with the contacts `specs` (contacts_from) in place of its own; None: as it is.

    Raises:
        SymdynError: a bad contact, naming the robot's file, the contact and the field.
    """
    if specs is None:
        return robot
    try:
        contacts = contacts_from(specs)
    except SymdynError as e:
        raise SymdynError(e.reason, file=robot.source) from None
    return replace(robot, contacts=contacts)
