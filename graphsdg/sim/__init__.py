"""MuJoCo: the stage compiler, live sync, physics stepping and the timeline (the engine).

Isaac's user-facing physics API over it (prim views, scene queries, the timeline
interface) is one room up, in :mod:`graphsdg.physics`.

* :mod:`~graphsdg.sim.compiler`: USD -> MjSpec -> MjModel, one module per schema it
  reads (:mod:`~graphsdg.sim.gprims`, :mod:`~graphsdg.sim.materials`,
  :mod:`~graphsdg.sim.lights`, :mod:`~graphsdg.sim.rigid_bodies`,
  :mod:`~graphsdg.sim.colliders`, :mod:`~graphsdg.sim.masses`,
  :mod:`~graphsdg.sim.joints`, :mod:`~graphsdg.sim.physics_scene`, ...) into a
  :mod:`~graphsdg.sim.compiled_scene`; :mod:`~graphsdg.sim.scene`: edits synced
  live (each aspect by its module: :mod:`~graphsdg.sim.geom_poses`, ...), physics
  stepped and written back to the stage (:mod:`~graphsdg.sim.pose_write_back`).
* :mod:`~graphsdg.sim.timeline`: play / pause / stop, time, tick events.
* :mod:`~graphsdg.sim.bounds`: bounding boxes.
* :mod:`~graphsdg.sim.placement`: surface and volume sampling behind
  ``rep.functional.randomizer.scatter_2d`` / ``scatter_3d``.
"""
