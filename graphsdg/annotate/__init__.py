"""Annotators: labels derived from render passes and the stage."""
