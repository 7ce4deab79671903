"""Dynamic conditioning of a manipulator (lecture slides 21-23).

At a state (q, qd), with M, V, G, F the robot's compiled functions and J the
world-aligned Jacobian of a frame (by default the last link's; the generated
NAME_F_jacobian, symdyn.apps.analysis.task_space), restricted to the chosen task axes
(rows x, y, z, rx, ry, rz):

* Generalized inertia ellipsoid (slide 21): with qd = 0 and no gravity,
  tau = M qdd; the unit sphere of joint accelerations maps onto the ellipsoid
  {M qdd : |qdd| <= 1} in joint-torque space. Its principal axes are the
  eigenvectors of M M^T and its semi-axis *lengths* are the square roots of the
  eigenvalues of M M^T, i.e. the singular values of M (for the symmetric
  positive-definite M, its eigenvalues), sorted from largest to smallest.
* Task-space accelerations (slides 22-23):
      xdd = J qdd + Jdot qd = J M^-1 L tau_hat + v_bias,  L = diag(torque limits),
      v_bias = Jdot qd - J M^-1 (V + G + F) = v_vel + v_grav,
      v_vel = Jdot qd - J M^-1 (V + F),  v_grav = -J M^-1 G.
  Jdot qd is exact: the generated NAME_F_jacobian_dot_qd, the frame's classical
  acceleration at qdd = 0 (symdyn.algorithms.frame_kinematics).
  F(qd) (friction) is zero at qd = 0 and for frictionless robots.
* Dynamic manipulability ellipsoid: tau_hat^T tau_hat <= 1 gives
      (xdd - v_bias)^T (J M^-1 L^2 M^-T J^T)^-1 (xdd - v_bias) <= 1;
  "matrix" is J M^-1 L^2 M^-T J^T, its semi-axes the square roots of its
  eigenvalues (the singular values of J M^-1 L). The measure reported is
      kappa_d = sqrt(det[J (M^T M)^-1 J^T])    (square root taken; no L),
  while the lecture prints det[J (M^T M)^-1 J^T] without the root
  (`DynamicManipulability.measure_squared`).
* Acceleration polytope: the image {J M^-1 L tau_hat + v_bias : |tau_hat_i| <= 1}
  of the torque hypercube, a zonotope. For a 2-D task space its vertices are the
  convex hull (monotone chain) of the 2^n images of the cube's vertices, in
  counter-clockwise order; in 3 or more dimensions they are the extreme images
  found facet by facet (each facet is normal to a set of generators), sorted.

The work is shared by symdyn.apps.analysis.task_space (axes, J, Jdot qd), symdyn.apps.analysis.geometry
(ellipsoids, hulls, zonotopes), symdyn.apps.analysis.conditioning (`analyze`, `Analysis`)
and symdyn.apps.analysis.analysis_plots (the pictures); this module gathers their public names.
"""

from __future__ import annotations

from .analysis_plots import plot_analysis, plot_workspace
from .conditioning import LENGTHS_NOTE, MEASURE_NOTE, Analysis, analyze
from .geometry import (
    AccelerationPolytope,
    DynamicManipulability,
    InertiaEllipsoid,
    acceleration_polytope,
    convex_hull_2d,
    dynamic_manipulability,
    ellipse_points,
    inertia_ellipsoid,
    zonotope_vertex_signs,
)
from .task_space import TASK_AXES, default_axes, default_frame, parse_axes, task_jacobian

__all__ = [
    "TASK_AXES",
    "InertiaEllipsoid",
    "DynamicManipulability",
    "AccelerationPolytope",
    "Analysis",
    "parse_axes",
    "default_axes",
    "default_frame",
    "task_jacobian",
    "inertia_ellipsoid",
    "dynamic_manipulability",
    "acceleration_polytope",
    "convex_hull_2d",
    "zonotope_vertex_signs",
    "analyze",
    "plot_analysis",
    "plot_workspace",
    "ellipse_points",
    "MEASURE_NOTE",
    "LENGTHS_NOTE",
]
