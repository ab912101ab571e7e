"""Reading MDL material-instance modules: ``.mdl`` files that export OmniPBR with fixed arguments.

Isaac Sim's environment materials (``Simple_Warehouse/Materials/MI_*.mdl``)
are MDL modules of this form::

    mdl 1.6;
    import ::OmniPBR::OmniPBR;

    export material MI_CardBoxB_05(*)
    = ::OmniPBR::OmniPBR(
        diffuse_texture: texture_2d("./Textures/CardBoxB_05_BaseColor.png", ::tex::gamma_srgb),
        reflection_roughness_constant: 0.85f
    );

A material whose MDL shader names such a file (``info:mdl:sourceAsset``) is
rendered with those arguments as its OmniPBR inputs (inputs authored on the
shader win). :func:`read_module` parses the subset that material instances use:
``color(r, g, b)``, ``float2(a, b)``, numbers (``0.5f``), ``true`` / ``false``
and ``texture_2d("path"[, gamma])`` arguments of ``OmniPBR``. Texture paths
are resolved against the module's folder. Anything else raises
:class:`MdlModuleError` naming the file and what it could not read.

Example:
    >>> text = 'mdl 1.6; export material M(*) = OmniPBR(metallic_constant: 1.0f);'
    >>> parse_module(text, "/x/M.mdl")["M"].arguments
    {'metallic_constant': 1.0}
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

from pxr import Usd, UsdShade

from graphsdg.assets.nucleus import find_local, is_nucleus_url

#: the base materials whose arguments graphsdg maps (OmniPBR's inputs; see graphsdg.stage.materials)
SUPPORTED_BASES = ("OmniPBR",)

_COMMENTS = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_MATERIAL = re.compile(r"export\s+material\s+(\w+)\s*\(\s*\*?\s*\)\s*=\s*([\w:]+)\s*\(", re.S)
_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?[fFdD]?$")
_CALL = re.compile(r"^([\w:]+)\s*\((.*)\)$", re.S)


class MdlModuleError(ValueError):
    """An ``.mdl`` file graphsdg cannot read as a material instance."""


@dataclass(frozen=True)
class MdlMaterialInstance:
    """One exported material of a module: its name, the material it instantiates and the arguments given."""

    name: str
    base: str                                         # e.g. "OmniPBR"
    arguments: dict[str, Any] = field(default_factory=dict)   # textures as absolute file paths


def _split_top_level(text: str, sep: str = ",") -> list[str]:
    """``text`` split at ``sep`` outside brackets and string literals."""
    parts, depth, quote, start = [], 0, False, 0
    for i, ch in enumerate(text):
        if ch == '"':
            quote = not quote
        elif not quote and ch in "([{":
            depth += 1
        elif not quote and ch in ")]}":
            depth -= 1
        elif not quote and depth == 0 and ch == sep:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p.strip() for p in parts if p.strip()]


def _matching_paren(text: str, open_index: int) -> int:
    depth, quote = 0, False
    for i in range(open_index, len(text)):
        ch = text[i]
        if ch == '"':
            quote = not quote
        elif not quote and ch == "(":
            depth += 1
        elif not quote and ch == ")":
            depth -= 1
            if depth == 0:
                return i
    return -1


def _value(expr: str, folder: str, where: str) -> Any:
    """The Python value of one argument expression (see the module docstring for what is read)."""
    expr = expr.strip()
    if expr in ("true", "false"):
        return expr == "true"
    if _NUMBER.match(expr):
        return float(expr.rstrip("fFdD"))
    call = _CALL.match(expr)
    if call:
        func = call.group(1).split("::")[-1]
        args = _split_top_level(call.group(2))
        if func in ("color", "float2", "float3", "float4") and args:
            values = tuple(_value(a, folder, where) for a in args)
            if not all(isinstance(v, float) for v in values):
                raise MdlModuleError(f"{where}: {func}(...) takes numbers, got {expr!r}")
            return values[0] if len(values) == 1 and func == "color" else values
        if func == "texture_2d" and args and args[0].startswith('"') and args[0].endswith('"'):
            rel = args[0][1:-1]
            if rel.startswith("/"):
                raise MdlModuleError(f"{where}: texture {rel!r} is relative to the MDL search path; graphsdg reads "
                                     f"textures relative to the module ('./Textures/...')")
            return os.path.normpath(os.path.join(folder, rel)) if rel else None
    raise MdlModuleError(f"{where}: cannot read the argument value {expr!r} (graphsdg reads numbers, true/false, "
                         f"color(...), float2(...) and texture_2d(\"file\", ...))")


def parse_module(text: str, path: str) -> dict[str, MdlMaterialInstance]:
    """The material instances exported by the MDL source ``text`` of the file ``path``, by name."""
    source = _COMMENTS.sub(" ", text)
    if not re.match(r"\s*mdl\s+\d+\.\d+\s*;", source):
        raise MdlModuleError(f"{path}: not an MDL module (it must start with 'mdl <version>;')")
    folder = os.path.dirname(os.path.abspath(path))
    found: dict[str, MdlMaterialInstance] = {}
    for match in _MATERIAL.finditer(source):
        name, base = match.group(1), match.group(2).split("::")[-1]
        close = _matching_paren(source, match.end() - 1)
        if close < 0:
            raise MdlModuleError(f"{path}: material {name}: unbalanced parentheses in its argument list")
        arguments = {}
        for item in _split_top_level(source[match.end():close]):
            key, sep, expr = item.partition(":")
            if not sep or not re.fullmatch(r"\w+", key.strip()):
                raise MdlModuleError(f"{path}: material {name}: expected 'parameter: value', got {item!r}")
            arguments[key.strip()] = _value(expr, folder, f"{path}: material {name}: {key.strip()}")
        found[name] = MdlMaterialInstance(name=name, base=base, arguments=arguments)
    if not found:
        raise MdlModuleError(f"{path}: exports no material of the form 'export material NAME(*) = BASE(...)'")
    return found


@lru_cache(maxsize=256)
def _read_cached(path: str, mtime_ns: int) -> dict[str, MdlMaterialInstance]:
    with open(path, encoding="utf-8") as f:
        return parse_module(f.read(), path)


def read_module(path: str) -> dict[str, MdlMaterialInstance]:
    """The material instances of the ``.mdl`` file at ``path`` (parsed once per file version)."""
    if not os.path.isfile(path):
        raise FileNotFoundError(f"MDL module {path!r} does not exist")
    return _read_cached(os.path.abspath(path), os.stat(path).st_mtime_ns)


def module_file(shader: UsdShade.Shader) -> str | None:
    """The ``.mdl`` file an MDL shader's ``info:mdl:sourceAsset`` names, if it is a file on disk.

    An ``omniverse://`` URL is read where graphsdg keeps its local copy (the asset pack or a Nucleus
    mirror, :mod:`graphsdg.assets.nucleus`). A bare name such as ``OmniPBR.mdl`` (a module of the MDL
    search path) gives None.
    """
    asset = shader.GetSourceAsset("mdl")
    if not asset or not asset.path or not asset.path.lower().endswith(".mdl"):
        return None
    if asset.resolvedPath and os.path.isfile(asset.resolvedPath):
        return asset.resolvedPath
    path = asset.path
    if is_nucleus_url(path):
        local = find_local(path)                 # an omniverse:// URL read from the pack or a mirror
        return local if local and os.path.isfile(local) else None
    if os.path.isabs(path):
        return path if os.path.isfile(path) else None
    if "://" in path or os.sep not in path and "/" not in path:
        return None
    attr = shader.GetPrim().GetAttribute("info:mdl:sourceAsset")
    for spec in attr.GetPropertyStack(Usd.TimeCode.Default()):
        if spec.HasDefaultValue():
            candidate = os.path.normpath(spec.layer.ComputeAbsolutePath(path))
            return candidate if os.path.isfile(candidate) else None
    return None


def instance_arguments(shader: UsdShade.Shader) -> dict[str, Any]:
    """The OmniPBR arguments fixed by the material-instance module an MDL shader runs ({} if none).

    The exported material is the shader's ``info:mdl:sourceAsset:subIdentifier``, or the module's only
    one. A module that instantiates something other than OmniPBR raises :class:`MdlModuleError`.
    """
    path = module_file(shader)
    if path is None:
        return {}
    instances = read_module(path)
    name = shader.GetSourceAssetSubIdentifier("mdl") or ""
    if name not in instances:
        if len(instances) != 1 or name:
            raise MdlModuleError(f"{path}: the shader {shader.GetPath()} asks for material {name!r}; the module "
                                 f"exports {sorted(instances)}")
        name = next(iter(instances))
    inst = instances[name]
    if inst.base not in SUPPORTED_BASES:
        raise MdlModuleError(f"{path}: material {name} instantiates {inst.base}; graphsdg renders instances of "
                             f"{', '.join(SUPPORTED_BASES)} only")
    return dict(inst.arguments)


def material_name(path: str) -> str:
    """The material an ``.mdl`` file is named for: its single export, else its file stem."""
    instances = read_module(path)
    stem = os.path.splitext(os.path.basename(path))[0]
    return stem if stem in instances or len(instances) != 1 else next(iter(instances))


__all__ = ["MdlMaterialInstance", "MdlModuleError", "SUPPORTED_BASES", "instance_arguments", "material_name",
           "module_file", "parse_module", "read_module"]

