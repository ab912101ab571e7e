"""MuJoCo: the stage compiler, live sync, physics, and what scripts read back from it.

* :mod:`~graphsdg.sim.compiler`, :mod:`~graphsdg.sim.colliders`: USD (UsdPhysics
  included) -> MjSpec -> MjModel; :mod:`~graphsdg.sim.scene`: edits synced live,
  physics stepped and written back to the stage.
* :mod:`~graphsdg.sim.timeline`: play / pause / stop, time, tick events.
* :mod:`~graphsdg.sim.bodies` (rigid-body poses and velocities),
  :mod:`~graphsdg.sim.transforms` (world transforms), :mod:`~graphsdg.sim.bounds`
  (bounding boxes), :mod:`~graphsdg.sim.queries` (overlaps, ray casts, contacts).
* :mod:`~graphsdg.sim.placement`: surface and volume sampling behind
  ``rep.functional.randomizer.scatter_2d`` / ``scatter_3d``.
"""
