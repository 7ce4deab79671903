"""The `symdyn` command (entry point `symdyn.cli:main`)."""

from .main import main

__all__ = ["main"]
