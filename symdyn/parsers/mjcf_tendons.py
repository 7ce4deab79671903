"""MuJoCo's tendons, joint springs and fluid forces, as far as symdyn's joint-space model holds them.

A fixed tendon has the length L = sum_i c_i q_i over its joints (coefficients `coef`), so its
Jacobian J = c is constant, and its passive properties enter the equations of motion linearly:

    M   += a c c^T                      (armature a)
    tau += d c c^T qd                   (damping d: the force -d L' on the tendon)
    tau += f c sign(c^T qd)             (frictionloss f, MuJoCo's constraint, as Coulomb's law)
    tau += k (L - L_spring) c           (stiffness k; MuJoCo's lengthspring L_spring)

A fixed tendon over ONE joint (its other coefficients zero) is folded exactly into that joint:
armature a c_i^2 to its rotor inertia, damping d c_i^2 to its viscous friction, frictionloss
f |c_i| to its Coulomb friction (so the regressor and identification still take it). A tendon
over several joints, and the stiffness of any fixed tendon, become a `symdyn.model.tendons.Tendon`
(`Coupling` here, by MuJoCo's dof index; symdyn.parsers.mjcf turns dofs into links), and so does a
joint's own spring (`stiffness` about `springref`: one coefficient 1). MuJoCo's spring with a dead
band (springlength "lo hi", lo < hi) is refused. On a floating base, whose dynamics take no
tendons yet, they are left out with a warning as before (a coupling armature is refused).
Spatial tendons (wrapping sites and geoms) have a Jacobian that depends on q: their armature is
refused and their other passive forces warned about; fluid forces (<option density viscosity>)
are warned about. Tendons without passive properties (actuator transmissions, limits) change
nothing and pass silently.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..errors import SymdynError
from .mjcf_compile import mujoco_module, names

__all__ = ["Coupling", "TendonTerms", "tendon_terms"]


@dataclass(frozen=True)
class Coupling:
    """A fixed tendon or a joint's spring as MuJoCo compiled it: coefficients by dof index."""

    name: str
    coefficients: dict[int, float]
    armature: float = 0.0
    damping: float = 0.0
    frictionloss: float = 0.0
    stiffness: float = 0.0
    springlength: float = 0.0


@dataclass
class TendonTerms:
    """What the tendons add to each dof (by MuJoCo's dof index), and what they leave out."""

    armature: dict[int, float] = field(default_factory=dict)
    damping: dict[int, float] = field(default_factory=dict)
    frictionloss: dict[int, float] = field(default_factory=dict)
    #: the tendons and joint springs the model keeps as couplings (symdyn.model.tendons)
    couplings: list[Coupling] = field(default_factory=list)
    #: descriptions of the forces left out, for SymdynWarnings
    ignored: list[str] = field(default_factory=list)


def _coefficients(model: Any, t: int) -> dict[int, float] | None:
    """A fixed tendon's coefficient per dof (repeated joints summed, zeros dropped); None for a
    spatial tendon."""
    joint = int(mujoco_module().mjtWrap.mjWRAP_JOINT)
    start, count = int(model.tendon_adr[t]), int(model.tendon_num[t])
    out: dict[int, float] = {}
    for w in range(start, start + count):
        if int(model.wrap_type[w]) != joint:
            return None
        dof = int(model.jnt_dofadr[int(model.wrap_objid[w])])
        out[dof] = out.get(dof, 0.0) + float(model.wrap_prm[w])
    return {d: c for d, c in out.items() if c != 0}


def _spring_length(model: Any, t: int, file: str, name: str) -> float:
    """The tendon's relaxed length MuJoCo compiled (lengthspring), refused with a dead band."""
    low, high = (float(x) for x in model.tendon_lengthspring[t])
    if low != high:
        raise SymdynError(
            f"fixed tendon '{name}' has a spring with a dead band (springlength {low:g} {high:g}), "
            "which is not a potential symdyn's G can hold: give one springlength",
            file=file,
            field=f"tendon({name}).springlength",
        )
    return low


def _joint_springs(model: Any, flags: set[str], joints: list[str]) -> list[Coupling]:
    """Each hinge or slide joint's spring k (q - springref) as a coupling over its dof alone."""
    if "spring" in flags:
        return []
    out = []
    for j in range(model.njnt):
        k = float(model.jnt_stiffness[j])
        if k != 0 and int(model.jnt_type[j]) in (2, 3):  # slide, hinge
            ref = float(model.qpos_spring[int(model.jnt_qposadr[j])])
            out.append(
                Coupling(
                    f"joint {joints[j]} spring",
                    {int(model.jnt_dofadr[j]): 1.0},
                    stiffness=k,
                    springlength=ref,
                )
            )
    return out


def tendon_terms(model: Any, file: str, flags: set[str], floating: bool = False) -> TendonTerms:
    """The tendons' terms per dof, the couplings and the forces left out (see the module
    documentation); SymdynError for a tendon whose armature symdyn's M cannot hold. `flags` are
    the disabled <option><flag>s (symdyn.parsers.mjcf): a disabled damper, spring or frictionloss
    drops it. `floating`: the robot's base floats, whose dynamics take no couplings (left out)."""
    out = TendonTerms()
    tendons = names(model, "tendon", model.ntendon, "tendon")
    joints = names(model, "jnt", model.njnt, "joint")
    if floating:
        stiff = [joints[j] for j in range(model.njnt) if float(model.jnt_stiffness[j]) != 0]
        if stiff and "spring" not in flags:
            out.ignored.append(f"the stiffness (spring) of joint {', '.join(repr(n) for n in stiff)}")
    else:
        out.couplings += _joint_springs(model, flags, joints)
    for t in range(model.ntendon):
        coef = _coefficients(model, t)
        passive = {
            "armature": float(model.tendon_armature[t]),
            "damping": 0.0 if "damper" in flags else float(model.tendon_damping[t]),
            "frictionloss": 0.0 if "frictionloss" in flags else float(model.tendon_frictionloss[t]),
            "stiffness": 0.0 if "spring" in flags else float(model.tendon_stiffness[t]),
        }
        present = {k: v for k, v in passive.items() if v != 0}
        if not present or coef == {}:
            continue
        if coef is not None:
            listed = ", ".join(repr(joints[int(model.dof_jntid[d])]) for d in coef)
            kind = f"fixed tendon '{tendons[t]}' (over joint{'s' if len(coef) > 1 else ''} {listed})"
        else:
            kind = f"spatial tendon '{tendons[t]}'"
        if coef is not None and len(coef) == 1:
            ((dof, c),) = coef.items()
            for key, add in (("armature", c * c), ("damping", c * c), ("frictionloss", abs(c))):
                if key in present:
                    getattr(out, key)[dof] = getattr(out, key).get(dof, 0.0) + present.pop(key) * add
        if coef is not None and not floating and present:
            length = _spring_length(model, t, file, tendons[t]) if "stiffness" in present else 0.0
            out.couplings.append(Coupling(tendons[t], coef, springlength=length, **present))
            continue
        if "stiffness" in present:
            out.ignored.append(f"the stiffness (spring) of {kind}")
            del present["stiffness"]
        if "armature" in present:
            raise SymdynError(
                f"{kind} has armature {present['armature']:g}, which adds a c c^T to M (c its "
                + ("coefficients" if coef is not None else "Jacobian")
                + "): "
                + (
                    "symdyn's model of a floating base takes no tendons yet"
                    if coef is not None
                    else "symdyn models fixed tendons only"
                )
                + "; set the tendon's armature to 0 or put it on one joint",
                file=file,
                field=f"tendon({tendons[t]}).armature",
            )
        out.ignored += [f"the {key} of {kind}" for key in present]
    if float(model.opt.density) != 0 or float(model.opt.viscosity) != 0:
        out.ignored.append(
            f"the fluid force model of <option density={float(model.opt.density):g} "
            f"viscosity={float(model.opt.viscosity):g}>"
        )
    return out
