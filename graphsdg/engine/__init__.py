"""The engine room: the runtime, the capture engine, the run loop and their progress line.

It stands above the stage, simulation, rendering, annotation and io rooms, and below Replicator's face
(:mod:`graphsdg.orchestrator`) and the graph.
"""
