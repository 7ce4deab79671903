"""The dynamics algorithms, written symbolically over named intermediates: joint frames,
recursive Newton-Euler, the composite-rigid-body algorithm (M and G), the Coriolis matrix,
Lagrange's equations and forward kinematics with Jacobians."""
