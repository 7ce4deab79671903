"""MuJoCo's tendons and fluid forces, as far as symdyn's joint-space model can hold them.

A fixed tendon has the length L = sum_i c_i q_i over its joints (coefficients `coef`), so its
Jacobian J = c is constant, and its passive properties enter the equations of motion linearly:

    M   += a c c^T                      (armature a)
    tau += d c c^T qd                   (damping d: the force -d L' on the tendon)
    tau += f |c_i| sign(qd_i)           (frictionloss f, MuJoCo's constraint: one joint only)
    tau += k (L - L_spring) c           (stiffness k; MuJoCo's lengthspring L_spring)

symdyn's model keeps a joint's rotor inertia on the diagonal of M (`Motor`) and its friction per
joint (`Friction`), and has no springs. So a fixed tendon over ONE joint (its other coefficients
zero) is folded exactly into that joint: armature a c_i^2 to its rotor inertia, damping d c_i^2
to its viscous friction, frictionloss f |c_i| to its Coulomb friction. A tendon that couples
several joints cannot be written in that form: its armature (which would make M wrong) is
refused, its damping and frictionloss are warned about and left out; a tendon's stiffness, like a
joint's, is warned about and left out. Spatial tendons (wrapping sites and geoms) have a Jacobian
that depends on q: their armature is refused and their other passive forces warned about; fluid
forces (<option density viscosity>) are warned about. Tendons without passive properties
(actuator transmissions, limits) change nothing and pass silently.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..errors import SymdynError
from .mjcf_compile import mujoco_module, names

__all__ = ["TendonTerms", "tendon_terms"]


@dataclass
class TendonTerms:
    """What the tendons add to each dof (by MuJoCo's dof index), and what they leave out."""

    armature: dict[int, float] = field(default_factory=dict)
    damping: dict[int, float] = field(default_factory=dict)
    frictionloss: dict[int, float] = field(default_factory=dict)
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


def tendon_terms(model: Any, file: str, flags: set[str]) -> TendonTerms:
    """The tendons' terms per dof and the forces left out (see the module documentation);
    SymdynError for a tendon whose armature symdyn's M cannot hold. `flags` are the disabled
    <option><flag>s (symdyn.parsers.mjcf): a disabled damper, spring or frictionloss drops it."""
    out = TendonTerms()
    tendons = names(model, "tendon", model.ntendon, "tendon")
    joints = names(model, "jnt", model.njnt, "joint")
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
        if "stiffness" in present:
            out.ignored.append(f"the stiffness (spring) of {kind}")
            del present["stiffness"]
        if coef is not None and len(coef) == 1:
            ((dof, c),) = coef.items()
            for key, add in (("armature", c * c), ("damping", c * c), ("frictionloss", abs(c))):
                if key in present:
                    getattr(out, key)[dof] = getattr(out, key).get(dof, 0.0) + present[key] * add
            continue
        if "armature" in present:
            raise SymdynError(
                f"{kind} has armature {present['armature']:g}, which adds a c c^T to M (c its "
                + ("coefficients" if coef is not None else "Jacobian")
                + "): symdyn's M holds rotor inertia on its diagonal only, so it cannot be read; "
                "set the tendon's armature to 0 or put it on one joint",
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
