"""``rep.example``: the sample assets and textures Replicator's documentation uses (``omni.replicator.core.example``).

Replicator ships a folder of sample USD assets and one of textures with its extension; graphsdg points the
same names at real files of its built-in asset pack (``docs/assets.md``), so ``rep.create.from_usd(
rep.example.ASSETS[0])`` and ``rep.randomizer.texture(rep.example.TEXTURES)`` load and render:

* ``ASSETS_DIR`` / ``ASSETS``: the pack's YCB props (``/Isaac/Props/YCB/Axis_Aligned``), sorted;
* ``TEXTURES_DIR`` / ``TEXTURES``: the pack's ground textures (``/NVIDIA/Materials/vMaterials_2/Ground/textures``)
  and the base wood colour textures, sorted; ``UV_TEXTURES_DIR`` is the ground texture folder;
* ``MDL_JSON_EXAMPLE``: a material definition in ``rep.create.mdl_from_json``'s format.

The files are Replicator's in name and role, not in content (Replicator's own samples are not shipped).

Example:
    >>> import os
    >>> import graphsdg as rep
    >>> all(os.path.isfile(p) for p in rep.example.ASSETS + rep.example.TEXTURES)
    True
"""
from __future__ import annotations

import os

from graphsdg.assets.root import builtin_pack_root

_PACK = builtin_pack_root()
ASSETS_DIR = os.path.join(_PACK, "Isaac", "Props", "YCB", "Axis_Aligned").replace(os.sep, "/")
TEXTURES_DIR = os.path.join(_PACK, "NVIDIA", "Materials", "vMaterials_2", "Ground", "textures").replace(os.sep, "/")
UV_TEXTURES_DIR = TEXTURES_DIR
_WOOD_DIR = os.path.join(_PACK, "NVIDIA", "Materials", "Base", "Wood").replace(os.sep, "/")


def _files(folder: str, extensions: tuple[str, ...], recursive: bool = False) -> list[str]:
    """The files of ``folder`` with one of ``extensions``, sorted (an absent folder gives none)."""
    out = []
    for root, dirs, names in os.walk(folder):
        dirs.sort()
        out += [f"{root}/{n}".replace(os.sep, "/") for n in sorted(names) if n.lower().endswith(extensions)]
        if not recursive:
            break
    return sorted(out)


ASSETS: list[str] = _files(ASSETS_DIR, (".usd", ".usda", ".usdc"))
TEXTURES: list[str] = _files(TEXTURES_DIR, (".png", ".jpg", ".jpeg")) + _files(_WOOD_DIR, (".png", ".jpg"), True)

# a two-node OmniPBR graph in rep.create.mdl_from_json's layout (its shape only: graphsdg builds no MDL graphs)
MDL_JSON_EXAMPLE: dict = {
    "nodes": [
        {"name": "OmniPBR", "type": "OmniPBR.mdl::OmniPBR", "inputs": {"diffuse_color_constant": [0.8, 0.2, 0.2]}},
    ],
    "connections": [],
}

__all__ = ["ASSETS_DIR", "ASSETS", "TEXTURES_DIR", "TEXTURES", "UV_TEXTURES_DIR", "MDL_JSON_EXAMPLE"]
