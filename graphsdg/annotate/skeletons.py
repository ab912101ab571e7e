"""Skeleton poses from ``UsdSkel``, in Replicator's ``skeleton_data`` layout.

Every ``UsdSkel.Skeleton`` on the stage is reported with its joints, parents,
rest pose (local translations and rotations, global translations), its
animated pose at the capture's time code (global translations, local
rotations), the joints' pixel positions, and per joint whether it is occluded:
a joint is visible when the pixel it projects to shows a mesh bound to the
skeleton (``UsdSkel.BindingAPI``). Otherwise its occlusion type is
``"BACKGROUND"`` (nothing drawn there, or outside the image) or the path of
the prim drawn in front of it. Per-joint arrays of all skeletons are
concatenated, with ``*Sizes`` arrays giving each skeleton's joint count.
Rotations are quaternions (w, x, y, z); positions are in stage units.
"""
from __future__ import annotations

import numpy as np
from pxr import Usd, UsdGeom, UsdSkel

from graphsdg.render.camera import CameraView


def _decompose(xforms) -> tuple[np.ndarray, np.ndarray]:
    """(translations (N, 3), rotations (N, 4) w x y z) of a Matrix4d array."""
    if len(xforms) == 0:
        return np.zeros((0, 3), np.float32), np.zeros((0, 4), np.float32)
    t, r, _ = UsdSkel.DecomposeTransforms(xforms)
    rot = np.array([[q.GetReal(), *q.GetImaginary()] for q in r], dtype=np.float32)
    return np.array(t, dtype=np.float32).reshape(-1, 3), rot


def _bound_meshes(stage: Usd.Stage, cache: UsdSkel.Cache) -> dict[str, set[str]]:
    """Skeleton path -> paths of the prims skinned by it."""
    out: dict[str, set[str]] = {}
    for prim in stage.Traverse():
        if not prim.IsA(UsdSkel.Root):
            continue
        cache.Populate(UsdSkel.Root(prim), Usd.PrimDefaultPredicate)
        for binding in cache.ComputeSkelBindings(UsdSkel.Root(prim), Usd.PrimDefaultPredicate):
            skel = str(binding.GetSkeleton().GetPrim().GetPath())
            out.setdefault(skel, set()).update(str(q.GetPrim().GetPath()) for q in binding.GetSkinningTargets())
    return out


def skeleton_data(stage: Usd.Stage, view: CameraView, time: Usd.TimeCode, geom_ids: np.ndarray,
                  geom_paths: list[str]) -> dict:
    """Replicator's ``skeleton_data`` dict for every skeleton on ``stage`` seen from ``view``."""
    cache = UsdSkel.Cache()
    bound = _bound_meshes(stage, cache)
    xf_cache = UsdGeom.XformCache(time)
    fields: dict[str, list] = {k: [] for k in (
        "skelName", "skelPath", "assetPath", "animationVariant", "skeletonParents", "restGlobalTranslations",
        "restLocalTranslations", "restLocalRotations", "globalTranslations", "localRotations", "translations2d",
        "skeletonJoints", "jointOcclusions", "occlusionTypes", "inView")}
    sizes: list[int] = []
    for prim in stage.Traverse():
        if not prim.IsA(UsdSkel.Skeleton):
            continue
        skel = UsdSkel.Skeleton(prim)
        query = cache.GetSkelQuery(skel)
        if not query:
            continue
        joints = [str(j) for j in query.GetJointOrder()]
        n = len(joints)
        to_world = np.array(xf_cache.GetLocalToWorldTransform(prim))
        rest_local = skel.GetRestTransformsAttr().Get(time) or query.ComputeJointLocalTransforms(time, True)
        rest_skel = query.ComputeJointSkelTransforms(time, True)
        posed_local = query.ComputeJointLocalTransforms(time)
        posed_world = query.ComputeJointWorldTransforms(xf_cache)   # at the cache's time
        rest_t, rest_r = _decompose(rest_local)
        rest_skel_t, _ = _decompose(rest_skel)
        rest_global = (np.c_[rest_skel_t, np.ones(n)] @ to_world)[:, :3].astype(np.float32)
        world_t, _ = _decompose(posed_world)
        _, local_r = _decompose(posed_local)
        uv, z = view.project(world_t.astype(np.float64)) if n else (np.zeros((0, 2)), np.zeros(0))
        occluded, kinds = _joint_occlusion(uv, z, view, geom_ids, geom_paths, bound.get(str(prim.GetPath()), set()))
        anim = query.GetAnimQuery()
        anim_prim = anim.GetPrim() if anim else None
        layer = anim_prim.GetPrimStack()[0].layer.identifier if anim_prim else ""
        variant_sets = prim.GetVariantSets()
        variant = next((variant_sets.GetVariantSelection(v) for v in variant_sets.GetNames()
                        if variant_sets.GetVariantSelection(v)), "None")
        fields["skelName"].append(prim.GetName())
        fields["skelPath"].append(str(prim.GetPath()))
        fields["assetPath"].append(layer if layer and not layer.startswith("anon:") else "")
        fields["animationVariant"].append(variant)
        fields["skeletonParents"].append(np.array(query.GetTopology().GetParentIndices(), dtype=np.int32))
        fields["restGlobalTranslations"].append(rest_global)
        fields["restLocalTranslations"].append(rest_t)
        fields["restLocalRotations"].append(rest_r)
        fields["globalTranslations"].append(world_t)
        fields["localRotations"].append(local_r)
        fields["translations2d"].append(uv.astype(np.float32))
        fields["skeletonJoints"].extend(joints)
        fields["jointOcclusions"].append(occluded)
        fields["occlusionTypes"].append(str(kinds))
        in_frame = (z > 0) & (uv[:, 0] >= 0) & (uv[:, 0] < view.width) & (uv[:, 1] >= 0) & (uv[:, 1] < view.height)
        fields["inView"].append(bool(in_frame.any()))
        sizes.append(n)
    out: dict = {"numSkeletons": len(sizes)}
    size_arr = np.array(sizes, dtype=np.int32)
    for key in ("skelName", "skelPath", "assetPath", "animationVariant", "skeletonJoints", "occlusionTypes"):
        out[key] = fields[key]
    widths = {"skeletonParents": None, "restGlobalTranslations": 3, "restLocalTranslations": 3,
              "restLocalRotations": 4, "globalTranslations": 3, "localRotations": 4, "translations2d": 2,
              "jointOcclusions": None}
    for key, width in widths.items():
        parts = fields[key]
        empty = np.zeros((0,) if width is None else (0, width),
                         dtype=np.int32 if key == "skeletonParents" else bool if key == "jointOcclusions"
                         else np.float32)
        out[key] = np.concatenate(parts) if parts else empty
        out[f"{key}Sizes"] = size_arr.copy()
    out["occlusionTypesSizes"] = size_arr.copy()
    out["inView"] = np.array(fields["inView"], dtype=bool)
    return out


def _joint_occlusion(uv: np.ndarray, z: np.ndarray, view: CameraView, geom_ids: np.ndarray, geom_paths: list[str],
                     skinned: set[str]) -> tuple[np.ndarray, list[str]]:
    occluded = np.ones(len(uv), dtype=bool)
    kinds: list[str] = []
    for k, ((u, v), zk) in enumerate(zip(uv, z)):
        x, y = int(np.floor(u)) if np.isfinite(u) else -1, int(np.floor(v)) if np.isfinite(v) else -1
        if zk <= 0 or not (0 <= x < view.width and 0 <= y < view.height) or geom_ids[y, x] < 0:
            kinds.append("BACKGROUND")
            continue
        shown = geom_paths[geom_ids[y, x]]
        if shown in skinned:
            occluded[k] = False
            kinds.append("None")
        else:
            kinds.append(shown)
    return occluded, kinds
