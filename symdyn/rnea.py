"""`symdyn.rnea`: the public entry of the numeric oracle (symdyn.oracle).

Both a module, whose functions are those of symdyn.oracle.rnea (inverse dynamics by the
spatial RNEA, the mass matrix by the CRBA, forward dynamics, energies, poses), and the
function symdyn.rnea(robot, q, qd, qdd, params=None, *, gravity=True, friction=True), inverse
dynamics tau = M(q) qdd + V(q, qd) + G(q) + F(qd). The regressor is
symdyn.oracle.regressor.regressor.
"""

from __future__ import annotations

import sys
import types

from .oracle.rnea import *  # noqa: F403  (the public functions, re-exported)
from .oracle.rnea import __all__, rnea  # noqa: F401  (__all__: the same public names)


class _CallableModule(types.ModuleType):
    """`symdyn.rnea` is both this module and the public function symdyn.rnea(robot, q, qd, qdd)."""

    def __call__(self, robot, q, qd, qdd, params=None, **kwargs):
        return rnea(robot, q, qd, qdd, params, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
