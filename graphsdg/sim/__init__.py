"""MuJoCo: the stage compiler, live sync, physics, and what scripts read back from it.

* :mod:`~graphsdg.sim.compiler`: USD -> MjSpec -> MjModel, one module per schema it
  reads (:mod:`~graphsdg.sim.gprims`, :mod:`~graphsdg.sim.materials`,
  :mod:`~graphsdg.sim.lights`, :mod:`~graphsdg.sim.rigid_bodies`,
  :mod:`~graphsdg.sim.colliders`, :mod:`~graphsdg.sim.masses`,
  :mod:`~graphsdg.sim.joints`, :mod:`~graphsdg.sim.physics_scene`, ...) into a
  :mod:`~graphsdg.sim.compiled_scene`; :mod:`~graphsdg.sim.scene`: edits synced
  live (each aspect by its module: :mod:`~graphsdg.sim.geom_poses`, ...), physics
  stepped and written back to the stage (:mod:`~graphsdg.sim.pose_write_back`).
* :mod:`~graphsdg.sim.timeline`: play / pause / stop, time, tick events.
* :mod:`~graphsdg.sim.bodies` (rigid-body poses and velocities),
  :mod:`~graphsdg.sim.transforms` (world transforms), :mod:`~graphsdg.sim.bounds`
  (bounding boxes), :mod:`~graphsdg.sim.queries` (overlaps, ray casts, contacts).
* :mod:`~graphsdg.sim.placement`: surface and volume sampling behind
  ``rep.functional.randomizer.scatter_2d`` / ``scatter_3d``.
"""
