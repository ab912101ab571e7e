"""Static scan: which ``rep.*`` names and Isaac import statements of Isaac Sim's Replicator-using files resolve.

For every target of ``bench/isaac_tree.py`` (the standalone scripts and test
files of an Isaac Sim source tree that import ``omni.replicator.core``, with the
helper modules the scripts import beside them), it collects

* every maximal attribute chain rooted at a name bound to Replicator
  (``rep.functional.create.xform``; from-imported names count as chains), and
* every ``import X`` / ``from X import Y`` whose root is ``omni``, ``carb``,
  ``isaacsim``, ``pxr``, ``usdrt``, ``Semantics`` or ``warp``,

then resolves each under ``graphsdg.compat.isaac.install()`` (existence only:
behaviour is what ``bench/isaac_tree.py`` checks) and prints the share that
resolves, in scope and overall, with the names that do not.

Usage::

    python bench/isaac_scan.py /path/to/IsaacSim [--all] [--missing]
"""
from __future__ import annotations

import argparse
import ast
import importlib
import sys
import warnings
from collections import Counter, defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from isaac_tree import find_targets, imports_replicator, scope_of   # noqa: E402

ISAAC_ROOTS = ("omni", "carb", "isaacsim", "pxr", "usdrt", "Semantics", "warp")
REPLICATOR = "omni.replicator.core"


def replicator_bindings(tree: ast.AST) -> dict[str, str]:
    """Local names bound to Replicator or its parts -> their canonical ``rep.<path>`` form."""
    bound = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith(REPLICATOR) and alias.asname:
                    bound[alias.asname] = "rep" + alias.name[len(REPLICATOR):]
        elif isinstance(node, ast.ImportFrom) and node.module:
            if node.module == "omni.replicator":
                base = None
                for alias in node.names:
                    if alias.name == "core":
                        bound[alias.asname or "core"] = "rep"
            elif node.module.startswith(REPLICATOR):
                base = "rep" + node.module[len(REPLICATOR):]
                for alias in node.names:
                    bound[alias.asname or alias.name] = f"{base}.{alias.name}"
    return bound


def chains(tree: ast.AST, bound: dict[str, str]) -> set[str]:
    """Maximal attribute chains rooted at a Replicator-bound name, in canonical form."""
    found = set(v for v in bound.values() if v != "rep")
    inner = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Attribute):
            inner.add(id(node.value))
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and id(node) not in inner:
            parts = []
            current = node
            while isinstance(current, ast.Attribute):
                parts.append(current.attr)
                current = current.value
            if isinstance(current, ast.Name) and current.id in bound:
                found.add(".".join([bound[current.id], *reversed(parts)]))
    return found


def isaac_imports(tree: ast.AST) -> set[tuple[str, str]]:
    """``(module, name)`` pairs of Isaac-rooted imports (name ``""`` for a plain ``import module``)."""
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] in ISAAC_ROOTS:
                    found.add((alias.name, ""))
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            if node.module.split(".")[0] in ISAAC_ROOTS:
                for alias in node.names:
                    found.add((node.module, alias.name))
    return found


def resolves_chain(chain: str) -> bool:
    """Whether ``rep.a.b.c`` resolves by attribute access (or submodule import) from ``omni.replicator.core``."""
    obj = importlib.import_module(REPLICATOR)
    path = REPLICATOR
    for part in chain.split(".")[1:]:
        path = f"{path}.{part}"
        try:
            obj = getattr(obj, part)
        except AttributeError:
            try:
                obj = importlib.import_module(path)
            except ImportError:
                return False
    return True


def resolves_import(module: str, name: str) -> bool:
    """Whether ``from module import name`` (or ``import module``) succeeds under compat."""
    try:
        owner = importlib.import_module(module)
    except ImportError:
        return False
    except Exception:   # a module that raises on import does not resolve
        return False
    if not name or name == "*":
        return True
    if hasattr(owner, name):
        return True
    try:
        importlib.import_module(f"{module}.{name}")
        return True
    except Exception:
        return False


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("isaac", type=Path, help="Isaac Sim's source tree (the folder holding source/)")
    parser.add_argument("--missing", action="store_true", help="list the names that do not resolve")
    args = parser.parse_args(argv)
    source = args.isaac / "source"
    scripts, tests = find_targets(source)
    helpers = [p for p in (source / "standalone_examples").rglob("*_utils.py") if imports_replicator(p)]
    files = sorted(set(scripts) | set(tests) | set(helpers))
    per_file = {}
    for path in files:
        tree = ast.parse(path.read_text(errors="replace"))
        per_file[path] = (chains(tree, replicator_bindings(tree)), isaac_imports(tree))

    from graphsdg.compat import isaac
    isaac.install()
    from graphsdg.compat import extensions
    for ext in list(extensions.KNOWN):   # a scan sees every module, whether or not its extension is on
        extensions.get_extension_manager().set_extension_enabled(ext, True)
    warnings.simplefilter("ignore")
    chain_ok: dict[str, bool] = {}
    import_ok: dict[tuple[str, str], bool] = {}
    tallies = defaultdict(Counter)
    missing_chains, missing_imports = Counter(), Counter()
    for path, (file_chains, file_imports) in per_file.items():
        group = "in scope" if scope_of(str(path.relative_to(source))) == "in" else "out of scope"
        for chain in file_chains:
            if chain not in chain_ok:
                chain_ok[chain] = resolves_chain(chain)
            tallies[group]["chains"] += 1
            tallies[group]["chains ok"] += chain_ok[chain]
            if not chain_ok[chain] and group == "in scope":
                missing_chains[chain] += 1
        for item in file_imports:
            if item not in import_ok:
                import_ok[item] = resolves_import(*item)
            if not import_ok[item] and group == "in scope":
                missing_imports[item] += 1
    for group in ("in scope", "out of scope"):
        group_files = [p for p in per_file if (scope_of(str(p.relative_to(source))) == "in") == (group == "in scope")]
        distinct_chains = {c for p in group_files for c in per_file[p][0]}
        distinct_imports = {i for p in group_files for i in per_file[p][1]}
        ok_chains = sum(chain_ok[c] for c in distinct_chains)
        ok_imports = sum(import_ok[i] for i in distinct_imports)
        print(f"{group}: {len(group_files)} files; rep.* names {ok_chains}/{len(distinct_chains)} resolve "
              f"({100 * ok_chains / max(len(distinct_chains), 1):.1f} %); Isaac import statements "
              f"{ok_imports}/{len(distinct_imports)} ({100 * ok_imports / max(len(distinct_imports), 1):.1f} %)")
    if args.missing:
        print("\nin-scope rep.* names that do not resolve (files):")
        for chain, count in missing_chains.most_common():
            print(f"  {count:3d}  {chain}")
        print("\nin-scope import statements that do not resolve (files):")
        for (module, name), count in missing_imports.most_common():
            print(f"  {count:3d}  from {module} import {name}" if name else f"  {count:3d}  import {module}")
    isaac.uninstall()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
