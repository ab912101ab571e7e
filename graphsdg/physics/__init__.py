"""Isaac's user-facing physics API over the runtime's simulation, above the engine in sim/.

* :mod:`~graphsdg.physics.bodies` (``RigidPrim``: rigid-body poses and velocities),
  :mod:`~graphsdg.physics.articulations` (joint state, drives, switchable fixed joints),
  :mod:`~graphsdg.physics.world_pose` (setting any prim's world pose: ``XformPrim``);
* :mod:`~graphsdg.physics.queries`: overlaps, ray casts, contacts (PhysX's scene queries);
* :mod:`~graphsdg.physics.timeline`: the timeline interface (``omni.timeline``, ``rep.timeline``).
"""
