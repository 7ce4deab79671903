"""The names of a free flyer's coordinates (symdyn.model.free_flyer), without SymPy.

Kept apart so that the warm command-line paths (a simulation's CSV columns, symdyn.apps.simulation.trajectory)
name a floating robot's coordinates without importing SymPy (docs/speed.md).
"""

from __future__ import annotations

__all__ = [
    "BASE_POSITION_NAMES",
    "BASE_VELOCITY_NAMES",
    "BASE_ACCELERATION_NAMES",
    "BASE_WRENCH_NAMES",
    "BASE_NAMES",
    "NQ_BASE",
    "NV_BASE",
]

#: the free flyer's configuration coordinates: origin, then the quaternion (scalar last)
BASE_POSITION_NAMES = ("x_b", "y_b", "z_b", "qx_b", "qy_b", "qz_b", "qw_b")
#: its velocity coordinates: linear then angular velocity of the base, in the base frame
BASE_VELOCITY_NAMES = ("vx_b", "vy_b", "vz_b", "wx_b", "wy_b", "wz_b")
#: their time derivatives
BASE_ACCELERATION_NAMES = ("ax_b", "ay_b", "az_b", "dwx_b", "dwy_b", "dwz_b")
#: the wrench on the base in the base frame: force then moment
BASE_WRENCH_NAMES = ("fx_b", "fy_b", "fz_b", "mx_b", "my_b", "mz_b")
#: every name of the free flyer's symbols: no parameter may take one
BASE_NAMES = BASE_POSITION_NAMES + BASE_VELOCITY_NAMES + BASE_ACCELERATION_NAMES + BASE_WRENCH_NAMES
NQ_BASE = len(BASE_POSITION_NAMES)
NV_BASE = len(BASE_VELOCITY_NAMES)
