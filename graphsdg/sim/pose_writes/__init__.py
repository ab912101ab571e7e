"""Where a pose edit lands: the stage, MuJoCo, or the camera pose store. Authored on the stage, written into MuJoCo,
or kept beside the stage for a camera.

Replicator's write-to-fabric (``/exts/omni.replicator.core/enableWriteToFabric``) writes randomized values
without authoring USD. :mod:`.plan` picks, for one ``rep.functional.modify.pose`` call, the paths to try:

* the camera path (:mod:`.camera_poses`): cameras' local transforms kept by path, composed with the parent's
  pose at each render;
* the MuJoCo path (:mod:`.mujoco_poses`, with :mod:`.uniform_scales` for batches scaled by one factor per
  prim): gprims' poses and sizes written into the compiled model's arrays, for the prim lists
  :mod:`.targets` finds eligible;
* the USD path (:func:`graphsdg.stage.xform.set_local_pose`): ``xformOp`` s authored on the stage.

Display colours take the MuJoCo route the same way (:mod:`.colors`).
"""
