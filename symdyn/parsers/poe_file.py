"""Robot files with `convention: poe`: Modern Robotics' M_{i-1,i}, G_i, S_i (docs/robot-files.md).

    convention: poe
    links:
      - name: shoulder
        frame: {position: [x, y, z], rotation: [[...], [...], [...]]}   # M_{i-1,i}
        spatial_inertia: [Ixx, Iyy, Izz, m, m, m]   # the diagonal of G_i, or its 6 rows
        screw: [wx, wy, wz, vx, vy, vz]              # S_i, space frame
        limits: [lower, upper]                       # optional: the joint's range (rad or m)
    end_effector: {position: [...], rotation: [...]}  # M_{n,n+1}: the frame `end_effector`

The top-level keys name, gravity and parameters are read as in every robot file
(symdyn.parsers.robot_fields); the links are turned into the general model by
symdyn.parsers.poe.
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from ..spatial.transform import Transform
from .poe import PoeLink, poe_links
from .robot_fields import LINK_NAME, TOP_KEYS, LinkData, RobotFileReader

__all__ = ["POE_TOP_KEYS", "POE_LINK_KEYS", "FRAME_KEYS", "PoeFileReader"]

#: a robot file's keys, with the end-effector frame after the links
POE_TOP_KEYS = (*TOP_KEYS[:6], "end_effector", *TOP_KEYS[6:])
POE_LINK_KEYS = ("name", "frame", "spatial_inertia", "screw", "limits")
FRAME_KEYS = ("position", "rotation")


class PoeFileReader(RobotFileReader):
    """The fields of a `convention: poe` robot file, read in written order."""

    def __init__(self, file: str | None) -> None:
        super().__init__(file)
        self.convention = "poe"
        self.poe: list[PoeLink] = []
        self.end_effector = Transform.identity()
        self.end_effector_given = False

    def read(self, data: object) -> None:
        if isinstance(data, dict):
            self.mapping(data, POE_TOP_KEYS, None)
            for key in ("name", "links"):
                if key not in data:
                    raise self.error("missing required field", field=key)
            for key, value in data.items():
                getattr(self, f"_read_{key}")(value)
        else:
            super().read(data)

    def _read_convention(self, value: object) -> None:
        assert value == "poe"

    def _read_end_effector(self, value: object) -> None:
        self.end_effector = self.frame(value, "end_effector", None)
        self.end_effector_given = True

    def frame(self, value: object, field: str, link: LinkData | None) -> Transform:
        """{position: [x, y, z], rotation: 3 rows of 3} (either may be left out: 0, identity)."""
        entries = self.mapping(value, FRAME_KEYS, field, link)
        p = entries.get("position")
        position = self.vector(p, f"{field}.position", link) if p is not None else (0, 0, 0)
        R = sp.eye(3)
        if entries.get("rotation") is not None:
            R = self.rows(entries["rotation"], 3, 3, f"{field}.rotation", link)
        return Transform(sp.ImmutableMatrix(R), sp.ImmutableMatrix(3, 1, list(position)))

    def rows(self, value: object, nrows: int, ncols: int, field: str, link: LinkData | None):
        """A matrix written as a list of `nrows` lists of `ncols` numbers or expressions."""
        ok = isinstance(value, list) and len(value) == nrows
        ok = ok and all(isinstance(r, list) and len(r) == ncols for r in value)
        if not ok:
            raise self.error(
                f"expected {nrows} rows of {ncols} numbers or expressions", link=link, field=field
            )
        return sp.ImmutableMatrix(
            [
                [self.expr(x, f"{field}[{r}][{c}]", link) for c, x in enumerate(row)]
                for r, row in enumerate(value)
            ]
        )

    def _read_link(self, i: int, raw: object) -> LinkData:
        given = raw.get("name") if isinstance(raw, dict) else None
        link = LinkData(index=i, name=given if isinstance(given, str) else f"link{i}")
        if not isinstance(raw, dict):
            raise self.error(f"a link must be a mapping, got {type(raw).__name__}", link=link)
        self.mapping(raw, POE_LINK_KEYS, None, link)
        for key in ("frame", "spatial_inertia", "screw"):
            if key not in raw:
                raise self.error("missing required field", link=link, field=key)
        if "name" in raw and not (isinstance(raw["name"], str) and LINK_NAME.match(raw["name"])):
            raise self.error(
                f"link name must be letters, digits, '_', '.' or '-', got {raw['name']!r}",
                link=link,
                field="name",
            )
        parts: dict[str, object] = {}
        for key, value in raw.items():
            if key == "frame":
                parts[key] = self.frame(value, "frame", link)
            elif key == "spatial_inertia":
                parts[key] = self.spatial_inertia(value, link)
            elif key == "screw":
                if not (isinstance(value, list) and len(value) == 6):
                    raise self.error(
                        "expected [wx, wy, wz, vx, vy, vz] (6 entries)", link=link, field="screw"
                    )
                parts[key] = sp.ImmutableMatrix(
                    [self.expr(x, f"screw[{k}]", link) for k, x in enumerate(value)]
                )
            elif key == "limits":
                self.limits(value, link)
        self.poe.append(PoeLink(link.name, parts["frame"], parts["spatial_inertia"], parts["screw"]))
        return link

    def spatial_inertia(self, value: object, link: LinkData) -> sp.ImmutableMatrix:
        """G_i: 6 rows of 6, or the 6 entries of its diagonal [Ixx, Iyy, Izz, m, m, m]."""
        if isinstance(value, list) and len(value) == 6 and not any(isinstance(x, list) for x in value):
            return sp.ImmutableMatrix(
                sp.diag(*[self.expr(x, f"spatial_inertia[{k}]", link) for k, x in enumerate(value)])
            )
        return self.rows(value, 6, 6, "spatial_inertia", link)

    def links_of_model(self, subs: dict) -> list:
        """The general model's links (symdyn.parsers.poe), parameters as written; `subs` (the
        parameter values) only to check the masses and inertias."""

        def fail(message: str, index: int | None, field: str):
            link = self.links[index - 1] if index is not None else None
            names = {"M.rotation": "frame.rotation", "G": "spatial_inertia", "S": "screw"}
            return self.error(message, link=link, field=names.get(field, field))

        links = poe_links(self.poe, self.end_effector, fail, subs, self.file)
        return [replace(lk, limits=ld.limits) for lk, ld in zip(links, self.links, strict=True)]
