"""The JAX backend (target "jax"): the NumPy backend's printer with `jnp.`, and templates/jax/.

`render(ctx)` gives NAME_jax.py (docs/jax.md).
"""

from .target import TOOLS, file_name, render

__all__ = ["render", "file_name", "TOOLS"]
