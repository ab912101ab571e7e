"""The error a compile raises for a stage that cannot become a MuJoCo model."""
from __future__ import annotations


class CompileError(ValueError):
    """The stage holds something that cannot become a MuJoCo model."""
