"""The PyTorch backend (target "torch"): the NumPy backend's printer with `torch.`, and templates/torch/.

`render(ctx)` gives NAME_torch.py (docs/torch.md).
"""

from .target import TOOLS, file_name, render

__all__ = ["render", "file_name", "TOOLS"]
