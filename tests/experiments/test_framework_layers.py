"""The experiments in layers: effects below the framework, the rigs above it.

``femast.effects`` (the effect contract and library) imports nothing of ``femast.experiments``;
the framework (``femast.experiments``: data, fits, noise, verdict, reports, the registry) imports
no rig: the registry finds the built-in ones through their entry point, on first use; every
built-in rig (``femast.rigs``) is written as a user's rig is, with the framework's public names only.
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
    for p in sorted((PKG / "experiments").rglob("*.py")):
        if p.parent.name == "rigs":  # the old paths of the rigs (femast/_moved.py)
            continue
        bad = [m for m, names in _imports(p) if m.startswith("femast.rigs") or (m == "femast" and "rigs" in names)]
        assert not bad, f"{p.relative_to(PKG)} imports the rigs {bad}"


def test_rigs_use_the_public_api_only():
    public = set(fx.__all__)
    for p in sorted((PKG / "rigs").glob("*.py")):
        for module, names in _imports(p):
            if not module.startswith("femast.experiments"):
                continue
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
    assert fx.get_experiment("latch-pull").model.__module__ == "femast.rigs.latch_pull"


MY_RIGS = '''
"""An installed package of rigs: its experiments, named by an entry point of the femast.experiments group."""
from femast.experiments import Column, Experiment, Parameter

def model(params, data, effects, options):
    return {"u_m": data["F_N"] / params["k"]}

EXPERIMENTS = (Experiment(
    name="my-spring", title="a spring of my own",
    columns=(Column("F_N", "N", "applied force"), Column("u_m", "m", "measured extension")),
    channels=("u_m",), parameters=(Parameter("k", "N/m", 1e4, 1.0, 1e8, "spring stiffness"),),
    model=model, error_unit="m"),)
'''


def test_an_installed_package_registers_its_experiments_by_entry_point(tmp_path, monkeypatch):
    from importlib.metadata import EntryPoint

    import pytest

    from femast.errors import FemastError
    from femast.experiments import registry
    from femast.rigs import BUILT_IN

    (tmp_path / "my_rigs_pkg.py").write_text(MY_RIGS)
    monkeypatch.syspath_prepend(str(tmp_path))
    femast_own = list(registry.entry_points(group=registry.ENTRY_POINTS))

    def installed(*entries):
        monkeypatch.setattr(registry, "entry_points", lambda group: list(entries))
        monkeypatch.setattr(registry, "_EXPERIMENTS", {})
        monkeypatch.setattr(registry, "_BUILTIN_LOADED", False)

    try:
        # another package's entry point listed first: femast's own rigs still come first
        installed(EntryPoint("my-rigs", "my_rigs_pkg:EXPERIMENTS", registry.ENTRY_POINTS), *femast_own)
        names = [e.name for e in registry.list_experiments()]
        assert names == [r.EXPERIMENT.name for r in BUILT_IN] + ["my-spring"]
        assert registry.get_experiment("my-spring").title == "a spring of my own"
        # a package whose experiments do not load is named, with the reason
        installed(*femast_own, EntryPoint("broken", "no_such_rigs_pkg:EXPERIMENTS", registry.ENTRY_POINTS))
        with pytest.raises(FemastError, match=r"entry point 'broken = no_such_rigs_pkg:EXPERIMENTS'.*ModuleNotFound"):
            registry.list_experiments()
        # femast's metadata without its entry point (installed before the rigs moved): say to reinstall
        installed()
        with pytest.raises(FemastError, match=r"built-in experiments are not registered.*reinstall femast"):
            registry.get_experiment("mast-top")
    finally:
        sys.modules.pop("my_rigs_pkg", None)
