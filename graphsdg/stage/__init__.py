"""The OpenUSD stage: the scene description every other part reads and edits."""
from graphsdg.stage.context import close_stage, get_stage, new_stage, open_stage, save, stage_context

__all__ = ["new_stage", "open_stage", "get_stage", "close_stage", "save", "stage_context"]
