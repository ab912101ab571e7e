"""Isaac compat area: the writers of ``isaacsim.replicator.writers`` besides PoseWriter, and its helpers.

``DOPEWriter``, ``YCBVideoWriter``, ``PytorchWriter`` and ``PytorchListener`` are graphsdg's own
(:mod:`graphsdg.io.writers`), registered with the writer registry like every built-in writer; the ``dope``
and ``pose`` annotators they read are :mod:`graphsdg.annotate.object_poses`. ``scripts.utils`` is
:mod:`graphsdg.io.camera_models` (projection for the pinhole, OpenCV pinhole and fisheye-polynomial camera
models, truncation, image-space points, pose matrices) plus ``get_mesh_vertices_relative_to``
(:func:`graphsdg.io.object_models.mesh_points_in_frame`). ``DataVisualizationWriter`` is not provided.
"""
from __future__ import annotations

import sys
import types

from graphsdg.compat.modules import CompatModule
from graphsdg.io import camera_models
from graphsdg.io.object_models import mesh_points_in_frame
from graphsdg.io.writer import WriterRegistry
from graphsdg.io.writers import DOPEWriter, PoseWriter, PytorchListener, PytorchWriter, YCBVideoWriter

NAME = "isaacsim.replicator.writers"
EXTENSIONS = {NAME: (NAME,)}
_HINT = "DataVisualizationWriter is not provided in graphsdg's compat mode (PoseWriter's debug images draw boxes)."


def get_mesh_vertices_relative_to(mesh_prim, coord_prim):
    """The mesh's points (N, 3) in ``coord_prim``'s frame, in metres."""
    return mesh_points_in_frame(mesh_prim, coord_prim)


def invert_fisheye_polynomial(theta, poly_coeffs, max_iterations: int = 10, tolerance: float = 1e-6):
    """The pixel radius of the fisheye polynomial's angle ``theta``; no convergence is reported through
    ``carb.log_warn``, as in Isaac."""
    return camera_models.invert_fisheye_polynomial(theta, poly_coeffs, max_iterations, tolerance,
                                                   warn=lambda message: sys.modules["carb"].log_warn(message))


def register_writers() -> None:
    """Register the extension's writers (graphsdg registers them already; registering again changes nothing)."""
    for cls in (DOPEWriter, PoseWriter, PytorchWriter, YCBVideoWriter):
        WriterRegistry.register(cls, category="default")


def modules() -> list[types.ModuleType]:
    """The extension's package (merged with PoseWriter's), ``scripts``, ``scripts.writers`` and ``scripts.utils``."""
    writers = dict(DOPEWriter=DOPEWriter, PoseWriter=PoseWriter, PytorchListener=PytorchListener,
                   PytorchWriter=PytorchWriter, YCBVideoWriter=YCBVideoWriter)
    utils = {name: getattr(camera_models, name) for name in (
        "project_point_to_screen", "project_pinhole", "project_pinhole_opencv", "project_fisheye_polynomial",
        "calculate_truncation_ratio_simple", "get_image_space_points",
        "get_transform_with_normalized_rotation", "tf_matrix_from_pose", "pose_from_tf_matrix")}
    utils_module = CompatModule(f"{NAME}.scripts.utils", camera_models.__doc__ or "",
                                get_mesh_vertices_relative_to=get_mesh_vertices_relative_to,
                                invert_fisheye_polynomial=invert_fisheye_polynomial, **utils)
    writers_module = CompatModule(f"{NAME}.scripts.writers", hint=_HINT, register_writers=register_writers,
                                  **writers)
    return [CompatModule(NAME, hint=_HINT, **writers),
            CompatModule(f"{NAME}.scripts", hint=_HINT, utils=utils_module, writers=writers_module, **writers),
            writers_module, utils_module,
            CompatModule(f"{NAME}.scripts.writers.dope_writer", DOPEWriter=DOPEWriter),
            CompatModule(f"{NAME}.scripts.writers.ycb_video_writer", YCBVideoWriter=YCBVideoWriter),
            CompatModule(f"{NAME}.scripts.writers.pytorch_writer", PytorchWriter=PytorchWriter),
            CompatModule(f"{NAME}.scripts.writers.pytorch_listener", PytorchListener=PytorchListener),
            CompatModule(f"{NAME}.scripts.writers.pose_writer", PoseWriter=PoseWriter)]
