"""Spatial algebra over SymPy expressions: homogeneous transforms, zero-aware 3-vectors,
and spatial motions, forces and inertias (angular part first)."""
