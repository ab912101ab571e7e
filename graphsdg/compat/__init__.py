"""Run scripts written for Isaac Sim unchanged (``graphsdg run --compat isaac``).

Nothing here is imported by ``import graphsdg``: the Isaac / Omniverse module
names exist only after :func:`graphsdg.compat.isaac.install`.
"""
