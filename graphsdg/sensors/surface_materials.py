"""What ray-cast sensors see of a surface: its reflectance and its non-visual material id.

Isaac Sim labels a material for its RTX sensors with three strings: a base material, a coating and an
attribute (``<prefix>:base``, ``<prefix>:coating``, ``<prefix>:attributes`` on the ``UsdShade.Material``;
the prefix is the setting ``/rtx/materialDb/nonVisualMaterialSemantics/prefix``, default
``omni:simready:nonvisual``). graphsdg reads them from the material bound to each drawn geom's gprim and
gives every geom:

* a *material id*: base index in bits 0-7, coating in 8-10, attribute in 11-15 (Isaac's 16-bit packing and
  index tables, :data:`BASES`, :data:`COATINGS`, :data:`ATTRIBUTES`);
* a *reflectance* in [0, 1] at the lidar's near-infrared wavelength: the base's value from
  :data:`BASE_REFLECTANCE` (graphsdg's table of typical diffuse reflectances near 905 nm), replaced by paint's
  (:data:`PAINT_REFLECTANCE`) under a paint coating, dimmed by :data:`CLEARCOAT_FACTOR` under a clear coat,
  and 1 for a retroreflective attribute. A surface with no non-visual labels reflects
  :data:`DEFAULT_REFLECTANCE`.

Example:
    >>> encode_material_id("aluminum", "paint", "emissive"), DEFAULT_REFLECTANCE
    (2305, 0.5)
    >>> reflectance_of("concrete", "none", "none"), reflectance_of("steel", "none", "retroreflective")
    (0.35, 1.0)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pxr import Usd

from graphsdg.base import settings_store as settings
from graphsdg.sim.scene import SimScene

PREFIX_SETTING = "/rtx/materialDb/nonVisualMaterialSemantics/prefix"
DEFAULT_PREFIX = "omni:simready:nonvisual"
DEFAULT_REFLECTANCE = 0.5
PAINT_REFLECTANCE = 0.6
CLEARCOAT_FACTOR = 0.9

#: base name -> index, in the order of Isaac's RTX non-visual material specification
BASES: dict[str, int] = {name: i for i, name in enumerate((
    "none", "aluminum", "steel", "oxidized_steel", "iron", "oxidized_iron", "silver", "brass", "bronze",
    "oxidized_Bronze_Patina", "tin", "plastic", "fiberglass", "carbon_fiber", "vinyl", "plexiglass", "pvc", "nylon",
    "polyester", "clear_glass", "frosted_glass", "one_way_mirror", "mirror", "ceramic_glass", "asphalt", "concrete",
    "leaf_grass", "dead_leaf_grass", "rubber", "wood", "bark", "cardboard", "paper", "fabric", "skin", "fur_hair",
    "leather", "marble", "brick", "stone", "gravel", "dirt", "mud", "water", "salt_water", "snow", "ice",
    "calibration_lambertion"))}
COATINGS: dict[str, int] = {"none": 0, "paint": 1, "clearcoat": 2, "paint_clearcoat": 3}
ATTRIBUTES: dict[str, int] = {"none": 0, "emissive": 1, "retroreflective": 2, "single_sided": 4,
                              "visually_transparent": 8}

#: graphsdg's near-infrared diffuse reflectance of each base (typical values; bases not listed reflect 0.5)
BASE_REFLECTANCE: dict[str, float] = {
    "aluminum": 0.75, "steel": 0.55, "oxidized_steel": 0.3, "iron": 0.5, "oxidized_iron": 0.25, "silver": 0.9,
    "brass": 0.6, "bronze": 0.5, "oxidized_Bronze_Patina": 0.3, "tin": 0.65, "plastic": 0.5, "fiberglass": 0.45,
    "carbon_fiber": 0.08, "vinyl": 0.4, "plexiglass": 0.1, "pvc": 0.45, "nylon": 0.55, "polyester": 0.55,
    "clear_glass": 0.08, "frosted_glass": 0.2, "one_way_mirror": 0.5, "mirror": 0.9, "ceramic_glass": 0.15,
    "asphalt": 0.08, "concrete": 0.35, "leaf_grass": 0.5, "dead_leaf_grass": 0.35, "rubber": 0.05, "wood": 0.45,
    "bark": 0.3, "cardboard": 0.7, "paper": 0.75, "fabric": 0.5, "skin": 0.45, "fur_hair": 0.35, "leather": 0.3,
    "marble": 0.6, "brick": 0.35, "stone": 0.35, "gravel": 0.3, "dirt": 0.25, "mud": 0.12, "water": 0.03,
    "salt_water": 0.03, "snow": 0.85, "ice": 0.3, "calibration_lambertion": 0.8}


#: lower-case spellings Isaac's older tables use for the same bases
BASE_ALIASES = {"oxidized_bronze_patina": "oxidized_Bronze_Patina"}


def base_name(name: str) -> str:
    """The table's spelling of base ``name`` (``oxidized_bronze_patina`` is ``oxidized_Bronze_Patina``)."""
    return BASE_ALIASES.get(name, name)


def decode_material_id(material_id: int) -> tuple[str, str, str]:
    """(base, coating, attribute) names of a 16-bit material id (``none`` for indices no name has)."""
    if isinstance(material_id, bool) or not float(material_id).is_integer() or not 0 <= material_id <= 0xFFFF:
        raise ValueError(f"Material ID {material_id} is outside valid uint16 range (0-65535)")
    value = int(material_id)

    def name_of(table: dict[str, int], index: int) -> str:
        return next((n for n, i in table.items() if i == index), "none")

    return (name_of(BASES, value & 0xFF), name_of(COATINGS, (value >> 8) & 0x7),
            name_of(ATTRIBUTES, (value >> 11) & 0x1F))


def encode_material_id(base: str, coating: str, attribute: str) -> int:
    """The 16-bit non-visual material id of (base, coating, attribute) (unknown names count as ``none``)."""
    return (BASES.get(base_name(base), 0) & 0xFF) | ((COATINGS.get(coating, 0) & 0x7) << 8) | \
        ((ATTRIBUTES.get(attribute, 0) & 0x1F) << 11)


def reflectance_of(base: str, coating: str, attribute: str) -> float:
    """The reflectance graphsdg gives (base, coating, attribute) (module docstring)."""
    if attribute == "retroreflective":
        return 1.0
    value = BASE_REFLECTANCE.get(base_name(base), DEFAULT_REFLECTANCE)
    if coating in ("paint", "paint_clearcoat"):
        value = PAINT_REFLECTANCE
    if coating in ("clearcoat", "paint_clearcoat"):
        value *= CLEARCOAT_FACTOR
    return float(value)


def label_attribute_names() -> list[str]:
    """The (base, coating, attribute) attribute names under the current prefix setting."""
    prefix = settings.get(PREFIX_SETTING) or DEFAULT_PREFIX
    return [f"{prefix}:base", f"{prefix}:coating", f"{prefix}:attributes"]


def material_labels(material: Usd.Prim) -> tuple[str, str, str] | None:
    """(base, coating, attribute) a material prim is labelled with, or None when it has no labels."""
    names = label_attribute_names()
    values = []
    for name in names:
        attr = material.GetAttribute(name)
        value = attr.Get() if attr else None
        values.append(str(value) if value else "none")
    return None if values == ["none", "none", "none"] and not material.GetAttribute(names[0]) else tuple(values)


@dataclass
class SurfaceTable:
    """Per geom of the compiled model: reflectance and material id (index -1 -> nothing hit)."""

    reflectance: np.ndarray   # float64 (ngeom + 1,)
    material_id: np.ndarray   # uint32 (ngeom + 1,)


_tables: dict[int, tuple[tuple, SurfaceTable]] = {}


def surface_table(sim: SimScene) -> SurfaceTable:
    """The surface table of ``sim``'s compiled model (rebuilt when the model, or the prefix setting, changes)."""
    compiled = sim.ensure_compiled()
    key = (sim.model_version, settings.get(PREFIX_SETTING), settings.generation())
    kept = _tables.get(id(sim))
    if kept is not None and kept[0] == key:
        return kept[1]
    ngeom = compiled.model.ngeom
    reflectance = np.full(ngeom + 1, DEFAULT_REFLECTANCE)
    material_id = np.zeros(ngeom + 1, dtype=np.uint32)
    reflectance[-1] = 0.0
    by_material: dict[str, tuple[float, int]] = {}
    stage = sim.stage
    for path, binding in compiled.geoms.items():
        if not binding.material:
            continue
        found = by_material.get(binding.material)
        if found is None:
            labels = material_labels(stage.GetPrimAtPath(binding.material))
            found = (reflectance_of(*labels), encode_material_id(*labels)) if labels else (DEFAULT_REFLECTANCE, 0)
            by_material[binding.material] = found
        ids = [binding.geom_id, *binding.parts]
        reflectance[ids], material_id[ids] = found
    table = SurfaceTable(reflectance=reflectance, material_id=material_id)
    _tables.clear()
    _tables[id(sim)] = (key, table)
    return table
