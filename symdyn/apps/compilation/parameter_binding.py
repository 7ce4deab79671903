"""The values of a robot's free parameters, bound to its compiled functions as one vector.

`CompiledDynamics` (symdyn.apps.compilation.compile) passes the vector as the generated
functions' last argument p. From the Robot the values pass its own checks
(Robot.param_values); from the cache alone only the names are known (`RobotInfo`), and the values
are given by name or in the robot's order.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np

from ...errors import SymdynError
from ...model.parameter_names import parameter_names_problem

__all__ = ["RobotInfo", "bind_parameters"]


@dataclasses.dataclass(frozen=True)
class RobotInfo:
    """What the applications need of a robot when it comes from the cache: its name and size."""

    name: str
    n: int
    params: tuple[str, ...] = ()


def bind_parameters(names: list[str], robot, params) -> np.ndarray | None:
    """The parameter vector in `names` order (None when there are none); `robot` is the Robot, or
    the RobotInfo of a cache hit."""
    if robot is not None and not isinstance(robot, RobotInfo):
        values = robot.param_values(params) if robot.params else {}
        by_name = {str(k): v for k, v in values.items()}
        if params is not None and not robot.params and len(params):
            raise SymdynError(f"robot '{robot.name}' has no free parameters, got {params!r}")
    elif params is None:
        if names:
            raise SymdynError(f"the robot has free parameters ({', '.join(names)}); give their values")
        by_name = {}
    elif isinstance(params, Mapping):
        by_name = {str(k): float(v) for k, v in params.items()}
        problem = parameter_names_problem(by_name, names, robot.name)
        if problem:
            raise SymdynError(f"parameters: {problem}")
    else:
        given = [float(v) for v in params]
        if len(given) != len(names):
            raise SymdynError(
                f"parameters: expected {len(names)} values ({', '.join(names)}), got {len(given)}"
            )
        by_name = dict(zip(names, given, strict=True))
    return np.array([float(by_name[n]) for n in names], dtype=np.float64) if names else None
