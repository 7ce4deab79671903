"""The independent numeric oracle: rigid-body dynamics of a `Robot` with NumPy only.

Every symbolic derivation and every generated function is judged against these modules, so
they share no code with them and read only the model (symdyn.model): `inputs` converts a
`Robot` to NumPy arrays and checks the arguments, `spatial` holds Featherstone's spatial
kinematics, `rnea` the inverse dynamics (RNEA), mass matrix (CRBA), forward dynamics, energies
and poses, and `regressor` the regressor Y of tau = Y pi. The public entry is `symdyn.rnea`
(symdyn/rnea.py re-exports `rnea`'s public functions and is callable as symdyn.rnea(...)).
"""
