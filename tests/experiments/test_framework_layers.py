"""The experiments package in layers: effects below the framework, the rigs above it.

``femast.effects`` (the effect contract and library) imports nothing of ``femast.experiments``;
the framework (``femast.experiments``: data, fits, noise, verdict, reports) imports no rig but
the registry, which registers the built-in ones on first use; every built-in rig
(``femast.experiments.rigs``) is written as a user's rig is, with the framework's public names
only, imported from the modules that define them (never from the package, whose ``__init__`` runs
the registry that imports the rigs: that would be an import circle).
"""

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import femast
import femast.experiments as fx

PKG = Path(femast.__file__).parent
PUBLIC_MODULES = {"femast.experiments.fe_cache", "femast.experiments.fe_reference"}


def _imports(path):
    """(module, names) of every import in a file, relative ones resolved."""
    tree = ast.parse(path.read_text())
    pkg = path.relative_to(PKG.parent).with_suffix("").parts[:-1]
    out = []
    for n in ast.walk(tree):
        if isinstance(n, ast.Import):
            out += [(a.name, ()) for a in n.names]
        elif isinstance(n, ast.ImportFrom):
            base = list(pkg[: len(pkg) - n.level + 1]) if n.level else []
            out.append((".".join(base + ([n.module] if n.module else [])), tuple(a.name for a in n.names)))
    return out


def test_effects_never_import_the_experiments():
    for p in sorted((PKG / "effects").rglob("*.py")):
        bad = [m for m, _ in _imports(p) if m.startswith("femast.experiments")]
        assert not bad, f"{p.relative_to(PKG)} imports {bad}: effects sit below the experiments framework"


def test_the_framework_imports_no_rig():
    for p in sorted((PKG / "experiments").glob("*.py")):
        bad = [
            m
            for m, names in _imports(p)
            if m.startswith("femast.experiments.rigs") or (m == "femast.experiments" and "rigs" in names)
        ]
        if p.name == "registry.py":  # registers them on first use: `from .rigs import BUILT_IN` inside a function
            assert bad == ["femast.experiments.rigs"], bad
        else:
            assert not bad, f"{p.relative_to(PKG)} imports the rigs {bad}"


def test_rigs_use_the_public_api_only():
    public = set(fx.__all__)
    for p in sorted((PKG / "experiments" / "rigs").glob("*.py")):
        for module, names in _imports(p):
            if module.startswith("femast.experiments.rigs") or not module.startswith("femast.experiments"):
                continue
            assert module != "femast.experiments", f"rigs/{p.name} imports the package (its registry imports the rigs)"
            if module in PUBLIC_MODULES:
                continue
            private = sorted(set(names) - public)
            assert not private, f"rigs/{p.name} imports {private} of {module}, not in femast.experiments.__all__"
            framework = importlib.import_module(module)
            assert all(getattr(framework, n) is getattr(fx, n) for n in names), (p.name, module, names)


def test_importing_effects_loads_no_experiment():
    code = "import sys, femast.effects; print(sorted(m for m in sys.modules if m.startswith('femast.experiments')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_the_builtin_rigs_are_registered_on_first_use():
    names = [e.name for e in fx.list_experiments()]
    assert names[:6] == ["mast-top", "latch-pull", "bay-torsion", "tip-cycle", "vibration", "platform-pose"]
    assert fx.get_experiment("latch-pull").model.__module__ == "femast.experiments.rigs.latch_pull"
