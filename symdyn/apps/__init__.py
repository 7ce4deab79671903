"""The lecture's applications on top of the derived dynamics, one package each.

- `compilation`: `symdyn.compile`, the generated C built for this machine, cached, and its
  functions called from Python (one state or a batch, in threads).
- `simulation`: `symdyn simulate`, the fixed-step and adaptive loops in C, a floating base on
  SE(3), closed loops, computed-torque control (`--track`), the trajectory and its CSV.
- `identification`: `symdyn identify` and `symdyn excite`, the measured logs and the base
  parameters by least squares, and exciting trajectories.
- `checking`: `symdyn check`, a student's answers against the derivation, and the derivation's
  steps (`derive --steps`).
- `analysis`: `symdyn analyze`, dynamic conditioning: the inertia ellipsoid, dynamic
  manipulability and the acceleration polytope.

`output` (plot formats, atomic writes) is shared by all of them. The packages import each
other only downwards in this order: compilation, identification, simulation; analysis and
checking sit beside them (tests/test_layers.py). The modules' old paths (`symdyn.apps.compile`,
...) still import: symdyn.module_aliases.
"""
