"""The robot description file (YAML; JSON is valid YAML) -> `symdyn.model.robot.Robot`.

The format is documented in docs/robot-files.md. Loading is data
only: the text is read with ``yaml.safe_load`` and every number-or-expression
goes through the whitelisting parser of `symdyn.model.expressions`; nothing from the
file is executed.

Free parameters (`Robot.params`) are ordered by first appearance in the
document as written: the top-level keys in their written order, lists in
order, mapping keys in their written order (a parameter's own key counts as
an appearance), and within an expression left to right. A name with a value
in `parameters` is not free; its value (which may use other parameters) is
resolved and stored in `Robot.values`, in file order.

DH angles written as decimals (alpha, theta) within 1e-9 rad of a multiple of
pi/2 are taken as that exact multiple; within 1e-3 rad of a nonzero multiple but
not 1e-9 (1.5708) they are kept with a SymdynWarning (symdyn.model.angles).

The text is parsed by symdyn.parsers.yaml_text, its fields read by
symdyn.parsers.robot_fields, its `parent:` and `mimic:` names resolved by
symdyn.parsers.robot_tree; this module resolves parameter values, checks the
numbers and builds the Robot with the DH rows of symdyn.parsers.dh, each row
relative to the frame of the link's parent.
"""

from __future__ import annotations

import sympy as sp

from ..errors import SymdynError, link_fields
from ..model.angles import constant_angle
from ..model.bounded import bounded_subs
from ..model.frames import Frame
from ..model.free_flyer import BASE_NAMES
from ..model.friction import coulomb_fields
from ..model.inertia import tensor_from_components
from ..model.physical import check_link_numbers
from ..model.robot import DEFAULT_GRAVITY, BaseBody, Friction, Link, Motor, Robot
from ..spatial.transform import Transform
from .dh import dh_link, to_body
from .frame_fields import model_frames
from .loop_fields import model_actuated, model_loops
from .poe_file import PoeFileReader
from .robot_fields import LinkData, RobotFileReader
from .robot_tree import link_mimics, link_parents
from .yaml_text import parse_text

__all__ = ["robot_from_bytes", "robot_from_data"]

#: Largest resolved parameter value (nodes of its expression tree).
_MAX_NODES = 20000


def robot_from_bytes(raw: bytes, file: str, digest: str) -> Robot:
    """The `Robot` of a robot description file's bytes (YAML or JSON; `file` names it in messages,
    `digest` is their sha256, symdyn.parsers.source.read_source).

    Raises SymdynError (naming file, link and field) for any bad input; warns
    with SymdynWarning for implausible inertial data. symdyn.parsers.by_content.load_robot
    reads the file and sends it here or to the URDF reader, by its content.
    """
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise SymdynError(f"not UTF-8 text (bad byte at offset {exc.start})", file=file) from None
    data = parse_text(text, file)
    return _build(data, file, digest)


def robot_from_data(data: dict, source: str | None = None) -> Robot:
    """Build a `Robot` from already-loaded file data (a dict as from yaml.safe_load).

    `source` names the origin in messages and becomes `Robot.source`.
    """
    return _build(data, None if source is None else str(source), None)


def _resolve_values(reader: RobotFileReader) -> dict[str, sp.Expr]:
    """Substitute parameter values into each other; refuse cycles and runaway growth."""
    values = reader.values
    deps = {n: [m for m in reader.value_names[n] if m in values] for n in values}
    resolved: dict[str, sp.Expr] = {}
    state: dict[str, int] = {}  # 1 = on the stack, 2 = done
    for root in values:
        if state.get(root) == 2:
            continue
        stack: list[tuple[str, int]] = [(root, 0)]
        path: list[str] = [root]
        state[root] = 1
        while stack:
            node, k = stack[-1]
            if k < len(deps[node]):
                stack[-1] = (node, k + 1)
                nxt = deps[node][k]
                if state.get(nxt) == 1:
                    cycle = path[path.index(nxt) :] + [nxt]
                    raise reader.error(
                        "parameter values depend on each other in a cycle: " + " -> ".join(cycle),
                        field=f"parameters.{nxt}",
                    )
                if state.get(nxt) != 2:
                    state[nxt] = 1
                    stack.append((nxt, 0))
                    path.append(nxt)
                continue
            stack.pop()
            path.pop()
            state[node] = 2
            mapping = {sp.Symbol(m): resolved[m] for m in deps[node]}
            value = bounded_subs(values[node], mapping, _fail(reader, f"parameters.{node}"))
            _check_size(value, reader, f"parameters.{node}")
            resolved[node] = value
    return {n: resolved[n] for n in values}


def _check_size(expr: sp.Expr, reader: RobotFileReader, field: str) -> None:
    for count, _ in enumerate(sp.preorder_traversal(expr)):
        if count > _MAX_NODES:
            raise reader.error("value grows too large after substituting parameters", field=field)
    if expr.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise reader.error(f"value is not finite after substituting parameters ({expr})", field=field)


def _fail(reader: RobotFileReader, field: str, link: LinkData | None = None):
    """A `fail` for symdyn.model.bounded that names the file, the link and the field."""
    return lambda message: reader.error(message, link=link, field=field)


def _link_expressions(link: LinkData):
    """(field, expression) of every number-or-expression a link entry holds."""
    for name in ("gamma", "b", "a", "alpha", "d", "theta", "mass"):
        yield name, getattr(link, name)
    yield "friction.viscous", link.viscous
    yield from coulomb_fields(link.coulomb, link.coulomb_minus).items()
    yield "motor.inertia", link.motor_inertia
    yield "motor.gear_ratio", link.gear_ratio
    yield from ((f"com.{ax}", v) for ax, v in zip("xyz", link.com, strict=True))
    yield from ((f"inertia.{k}", v) for k, v in link.inertia.items())
    if link.mimic is not None:
        yield from (("mimic.multiplier", link.mimic[1]), ("mimic.offset", link.mimic[2]))
    if link.limits is not None:
        yield from (("limits.lower", link.limits[0]), ("limits.upper", link.limits[1]))


def _poe_expressions(poe):
    """(field, expression) of every entry of a product-of-exponentials link (PoeLink)."""
    for field, matrix in (
        ("frame.rotation", poe.M.R),
        ("frame", poe.M.p),
        ("spatial_inertia", poe.G),
        ("screw", poe.S),
    ):
        yield from ((field, x) for x in matrix)


def _check_substituted(reader: RobotFileReader, subs: dict) -> None:
    """Substitute the parameter values into every field with the bounds of symdyn.model.bounded,
    so that no power that a value completes (b**e with e: 9**9) is evaluated later."""
    for i, link in enumerate(reader.links):
        fields = _link_expressions(link)
        if isinstance(reader, PoeFileReader):
            fields = (*fields, *_poe_expressions(reader.poe[i]))
        for field, expr in fields:
            if isinstance(expr, sp.Basic):
                bounded_subs(expr, subs, _fail(reader, field, link))
    for ax, v in zip("xyz", reader.gravity or (), strict=False):
        bounded_subs(v, subs, _fail(reader, f"gravity.{ax}"))


def _check_link_numbers(
    reader: RobotFileReader, link: LinkData, tensor: sp.ImmutableMatrix, subs: dict
) -> None:
    """Refuse impossible numbers of a link (`tensor`: its inertia as written) once parameters have values."""
    check_link_numbers(
        link.mass.xreplace(subs),
        tensor.xreplace(subs),
        {
            "friction.viscous": link.viscous.xreplace(subs),
            **{k: v.xreplace(subs) for k, v in coulomb_fields(link.coulomb, link.coulomb_minus).items()},
            "motor.inertia": link.motor_inertia.xreplace(subs),
        },
        link.gear_ratio.xreplace(subs),
        file=reader.file,
        **link_fields(link),
    )


def _build(data: object, file: str | None, digest: str | None) -> Robot:
    poe = isinstance(data, dict) and data.get("convention") == "poe"
    reader = PoeFileReader(file) if poe else RobotFileReader(file)
    reader.read(data)
    values = _resolve_values(reader)
    subs = {sp.Symbol(n): v for n, v in values.items()}
    params = tuple(sp.Symbol(n) for n in dict.fromkeys(reader.order) if n not in values)
    _check_substituted(reader, subs)
    links = reader.links_of_model(subs) if isinstance(reader, PoeFileReader) else _dh_links(reader, subs)
    for ld in reader.links:
        reader.check_limits(ld, subs)
    gravity = reader.gravity
    if gravity is None:
        gravity = DEFAULT_GRAVITY
    assert reader.name is not None
    frames = model_frames(reader, reader.frames, links)
    if isinstance(reader, PoeFileReader) and reader.end_effector_given:
        if any(f.name == "end_effector" for f in frames) or any(lk.name == "end_effector" for lk in links):
            raise reader.error("the name 'end_effector' is PoE's end-effector frame", field="frames")
        frames = (Frame("end_effector", len(links) - 1, links[-1].frame), *frames)
    return Robot(
        name=reader.name,
        links=tuple(links),
        gravity=sp.ImmutableMatrix(3, 1, list(gravity)),
        params=params,
        values=tuple((sp.Symbol(n), v) for n, v in values.items()),
        source=file,
        source_sha256=digest,
        convention=reader.convention,
        frames=frames,
        base=reader.base,
        loops=model_loops(reader, reader.loops, links),
        actuated=model_actuated(reader, reader.actuated, links),
        floating=reader.base_body is not None,
        base_body=_base_body(reader, subs),
        contacts=reader.contacts,
    )


def _base_body(reader: RobotFileReader, subs: dict) -> BaseBody:
    """A floating base's body (base frame, inertia about its centre of mass), its numbers checked
    once parameters have values; massless for a fixed base (unused there)."""
    if reader.base_body is None:
        return BaseBody()
    clash = sorted({str(n) for n in reader.order} & set(BASE_NAMES))
    if clash:
        raise reader.error(
            f"parameter '{clash[0]}' is the name of a floating base coordinate (rename the parameter)",
            field=f"parameters.{clash[0]}",
        )
    mass, com, components = reader.base_body
    tensor = tensor_from_components(components)
    check_link_numbers(
        mass.xreplace(subs), tensor.xreplace(subs), {}, sp.S.One, file=reader.file, link_name="base"
    )
    return BaseBody("base", mass, sp.ImmutableMatrix(3, 1, list(com)), sp.ImmutableMatrix(tensor))


def _dh_links(reader: RobotFileReader, subs: dict) -> list[Link]:
    """The links of a DH robot file (standard or modified), each row relative to its parent's frame."""
    parents, mimics = link_parents(reader), link_mimics(reader)
    links: list[Link] = []
    frames: list[Transform] = []  # each link's DH frame in its body frame
    for i, ld in enumerate(reader.links):
        for key in ("alpha", "theta", "gamma"):
            if getattr(ld, key).free_symbols:  # a parameter's value may make it a constant like pi**2/4
                value = getattr(ld, key).xreplace(subs)
                double = constant_angle(value, file=reader.file, **link_fields(ld), field=key)
                if double is not value:
                    setattr(ld, key, double)
        tensor = tensor_from_components(ld.inertia)
        _check_link_numbers(reader, ld, tensor, subs)
        prev = frames[parents[i]] if parents[i] >= 0 else Transform.identity()
        placement, axis, frame = dh_link(
            reader.convention, ld.joint, ld.a, ld.alpha, ld.d, ld.theta, prev, gamma=ld.gamma, b=ld.b
        )
        frames.append(frame)
        com, inertia = to_body(frame, ld.com, tensor)
        links.append(
            Link(
                name=ld.name,
                joint=ld.joint,
                placement=placement,
                axis=axis,
                mass=ld.mass,
                com=com,
                inertia=inertia,
                friction=Friction(ld.viscous, ld.coulomb, ld.coulomb_minus),
                motor=Motor(ld.motor_inertia, ld.gear_ratio),
                frame=frame,
                parent=None if parents[i] == i - 1 else parents[i],
                mimic=mimics[i],
                limits=ld.limits,
            )
        )
    return links
