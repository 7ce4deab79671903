"""Spatial algebra over SymPy expressions, the package's lowest floor (as Pinocchio's spatial/):
rigid transforms (`transform`), zero-aware 3-vectors (`vectors`), spatial motions and forces,
angular part first (`motion`), and spatial inertias (`inertia`)."""
