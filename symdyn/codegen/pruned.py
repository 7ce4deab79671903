"""`generate --prune REL`: code from the significance-pruned configuration-space form.

The pruned form (symdyn.algorithms.pruning: AKB's "1 % model") replaces the derivation's
program: M, G, V = B [qd qd] + Csq [qd^2], C_kj = sum_i Gamma^k_ij qd_i, tau and the bias
are its closed forms (joint space), and the generated functions are built from them as from
any derivation (symdyn.codegen.functions). The guaranteed bound, and the joint ranges it holds
over (the robot's limits, else +-pi: symdyn.algorithms.pruning.joint_box), go into the headers.
"""

from __future__ import annotations

import dataclasses

import sympy as sp

from ..algorithms.pruning import prune_robot
from ..dynamics import ALL_QUANTITIES, Dynamics
from ..symbolic.program import Program

__all__ = ["pruned_dynamics"]


def pruned_dynamics(dyn: Dynamics, rel: float) -> tuple[Dynamics, tuple[str, ...]]:
    """A Dynamics whose quantities are the pruned configuration-space form of `dyn`, and
    the header lines that state what was dropped and the error bound it guarantees."""
    pruned = prune_robot(dyn.configuration_space, dyn.robot, rel)
    cs = pruned.configuration
    F = dyn.compact["F"]
    compact = {
        k: sp.Matrix(*dyn.compact[k].shape, cs.closed(k, dyn.qd, dyn.qdd, F))
        for k in ALL_QUANTITIES
        if k != "F"
    }
    compact["F"] = F
    out = dataclasses.replace(
        dyn, program=Program(), compact=compact, _closed={}, _compiled={}, _configuration=cs
    )
    notes = (
        f"Pruned model (--prune {rel:g}): terms of M, B, Csq, G below {rel:g} of their entry's",
        f"largest value over the joint ranges dropped, {pruned.terms_before} -> {pruned.terms_after}",
        f"terms; every entry errs by at most {pruned.worst():.4g} times its largest value (the sum of",
        "its dropped terms' maxima) while q stays in the joint ranges.",
        pruned.ranges[0].upper() + pruned.ranges[1:] + ".",
    )
    return out, notes
