"""symdyn: symbolic equations of motion for robot manipulators, and code generated from them."""

__version__ = "0.1.0"
