"""MuJoCo: the stage compiler, live sync, physics stepping and the timeline (the engine).

Isaac's user-facing physics API over it (prim views, scene queries, the timeline
interface) is one room up, in :mod:`graphsdg.physics`.

* :mod:`~graphsdg.sim.compiler`, :mod:`~graphsdg.sim.colliders`: USD (UsdPhysics
  included) -> MjSpec -> MjModel; :mod:`~graphsdg.sim.scene`: edits synced live,
  physics stepped and written back to the stage.
* :mod:`~graphsdg.sim.timeline`: play / pause / stop, time, tick events.
* :mod:`~graphsdg.sim.bounds`: bounding boxes.
* :mod:`~graphsdg.sim.placement`: surface and volume sampling behind
  ``rep.functional.randomizer.scatter_2d`` / ``scatter_3d``.
"""
