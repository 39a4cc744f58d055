"""The layout's rules, read from the tree's own imports (lazy ones inside functions included, and
the package ``__init__`` that importing a submodule runs): every package and root module of femast
imports only units below it (:data:`LEVELS`), there is no import circle between its modules, the
analysis keeps its own rules (one Newton loop, no files in the loop, the results writer owned by
the output observer), modules and classes stay small, and the old module paths are thin modules
that warn.  docs/architecture.md and CONTRIBUTING.md describe the layout."""

import ast
import re
import sys
from pathlib import Path

import pytest

import femast as fm

PKG = Path(__file__).resolve().parents[1] / "femast"
ROOT = PKG.parent

# ------------------------------------------------------------------------------ the tree's imports
MODULES = {}  # dotted name -> file, every module of femast
for _p in PKG.rglob("*.py"):
    _parts = list(_p.relative_to(ROOT).with_suffix("").parts)
    MODULES[".".join(_parts[:-1] if _parts[-1] == "__init__" else _parts)] = _p


def _module_of(name):
    """The femast module a dotted name lives in (``femast.analysis.Analysis`` -> ``femast.analysis``)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _imports(path):
    """Module names a file imports (relative ones resolved against femast/), with the imported
    names appended (``from femast import progress`` gives ``femast`` and ``femast.progress``)."""
    tree = ast.parse(path.read_text())
    pkg = path.relative_to(ROOT).with_suffix("").parts[:-1]
    names = set()
    for n in ast.walk(tree):
        if isinstance(n, ast.Import):
            names |= {a.name for a in n.names}
        elif isinstance(n, ast.ImportFrom):
            base = list(pkg[: len(pkg) - n.level + 1]) if n.level else []
            mod = ".".join(base + ([n.module] if n.module else []))
            names |= {mod} | {f"{mod}.{a.name}" for a in n.names}
    return names


def _module_imports(path):
    """The femast modules that importing the file ``path`` runs: the modules it imports (a name
    imported from a package counts as that package unless it is a submodule) and their packages'
    ``__init__`` (not the file's own packages, which are already running)."""
    tree = ast.parse(path.read_text())
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    me = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
    pkg = me.split(".") if path.name == "__init__.py" else me.split(".")[:-1]
    out = set()
    for n in ast.walk(tree):
        if isinstance(n, ast.Import):
            out |= {_module_of(a.name) for a in n.names if a.name.split(".")[0] == "femast"}
        elif isinstance(n, ast.ImportFrom):
            mod = ".".join((pkg[: len(pkg) - n.level + 1] if n.level else []) + ([n.module] if n.module else []))
            if mod.split(".")[0] == "femast":
                out |= {f"{mod}.{a.name}" if f"{mod}.{a.name}" in MODULES else _module_of(mod) for a in n.names}
    own = {".".join(me.split(".")[:k]) for k in range(1, me.count(".") + 1)}
    parents = {".".join(m.split(".")[:k]) for m in out if m for k in range(1, m.count(".") + 1)}
    return {m for m in out | (parents - own) if m and m != me and m in MODULES}


#: the old paths of moved modules and packages (femast/_moved.py): three-line modules at the top of the layout
OLD_PATH_MODULES = {m for m, p in MODULES.items() if re.search(r"\bmoved(?:_package)?\(__name__", p.read_text())}


def _unit(module):
    """The layout unit of a module: its top package, a root module, ``femast`` (the package's own
    ``__init__``: the public API), or ``old paths`` (a root module left where a module moved from)."""
    parts = module.split(".")
    if module in OLD_PATH_MODULES:
        return "old paths"
    return parts[1] if len(parts) > 1 else "femast"


GRAPH = {m: _module_imports(p) for m, p in MODULES.items()}

# ------------------------------------------------------------------------------ the layering
#: the units from the bottom up: a unit imports only units of lower levels (docs/architecture.md)
LEVELS = [
    {"errors", "_moved", "text"},
    {"rotations", "progress", "numba_cache", "examples"},
    {"jit"},  # the kernels' compile notice and set-up helpers
    {"worker_main"},
    {"workers"},  # the one executor of worker processes
    {"elements"},
    {"testing", "model"},
    {"post"},
    {"analysis"},
    {"femast"},  # the public API: femast/__init__.py
    {"modal", "latch_identification"},
    {"verification"},
    {"adam", "guyed"},
    {"effects"},
    {"experiments"},
    {"rigs"},  # the built-in rigs: above the framework, registered through its entry point
    {"studies"},
    {"cli_experiments", "warmup"},
    {"cli"},
    {"old paths"},
]
LEVEL = {u: k for k, units in enumerate(LEVELS) for u in units}
#: the crossings of the layering that remain: (unit, unit it imports) -> why, and who removes it
CROSSINGS = {}


def test_every_unit_of_the_tree_has_a_level():
    units = {_unit(m) for m in MODULES}
    assert units == set(LEVEL), (
        f"units without a level: {sorted(units - set(LEVEL))}; gone: {sorted(set(LEVEL) - units)}"
    )


def test_no_unit_imports_a_unit_above_it():
    bad = []
    for module, imported in sorted(GRAPH.items()):
        u = _unit(module)
        for m in sorted(imported):
            v = _unit(m)
            if v != u and LEVEL[v] >= LEVEL[u] and (u, v) not in CROSSINGS:
                bad.append(f"{MODULES[module].relative_to(ROOT)} imports {m}")
    assert not bad, "imports upwards or sideways (docs/architecture.md, LEVELS):\n" + "\n".join(bad)


def test_the_listed_crossings_still_exist():
    # a crossing that was removed is struck off the list, so that it cannot come back unnoticed
    seen = {(_unit(m), _unit(i)) for m, imported in GRAPH.items() for i in imported}
    assert not set(CROSSINGS) - seen, f"crossings that are gone: {sorted(set(CROSSINGS) - seen)}"


def _circles(graph):
    """The strongly connected components of more than one module (Tarjan), as sets."""
    index, low, stack, on, out = {}, {}, [], set(), []
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = set()
            while True:
                w = stack.pop()
                on.discard(w)
                comp.add(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(frozenset(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_circle():
    # modules and the package __init__ that importing them runs, imports inside functions included
    graph = {m: {i for i in imp if (_unit(m), _unit(i)) not in CROSSINGS} for m, imp in GRAPH.items()}
    circles = _circles(graph)
    assert not circles, "import circles: " + "; ".join(" <-> ".join(sorted(c)) for c in circles)


def _folder(module):
    """The folder a module lives in (``femast/analysis/control``), or the module itself for femast's root
    modules and package ``__init__`` (each is a unit of :data:`LEVELS` of its own)."""
    folder = MODULES[module].parent.relative_to(ROOT).as_posix()
    return module if folder == "femast" else folder


def _folder_graph():
    """Folder -> the folders its modules import (old paths left out: they import their new path by name)."""
    graph = {}
    for m, imported in GRAPH.items():
        if m not in OLD_PATH_MODULES:
            graph.setdefault(_folder(m), set()).update(
                _folder(i) for i in imported if i not in OLD_PATH_MODULES and _folder(i) != _folder(m)
            )
    return graph


#: circles between folders that remain, each with the change that removes it
FOLDER_CIRCLES = {}


def test_no_import_circle_between_folders():
    # each folder read as one node: a subpackage sits wholly above or below its parent's modules
    # (analysis/control below the Newton loop and the step loop, which import its strategies)
    circles = [c for c in _circles(_folder_graph()) if c not in FOLDER_CIRCLES]
    assert not circles, "import circles between folders: " + "; ".join(" <-> ".join(sorted(c)) for c in circles)
    assert not set(FOLDER_CIRCLES) - set(_circles(_folder_graph())), "a listed folder circle is gone: strike it off"


def test_the_control_strategies_import_nothing_else_of_the_analysis():
    control = {m: imp for m, imp in GRAPH.items() if m.startswith("femast.analysis.control")}
    assert control
    for m, imported in control.items():
        above = {i for i in imported if _unit(i) == "analysis" and not i.startswith("femast.analysis.control")}
        assert not above, f"{m} imports {sorted(above)}"


def test_the_framework_imports_no_rig_and_finds_them_by_their_entry_point():
    # the built-in rigs sit above the experiments framework; the registry finds them as it finds an
    # installed package of rigs: the entry point group femast.experiments (pyproject.toml)
    from importlib.metadata import entry_points

    framework = {m: imp for m, imp in GRAPH.items() if _unit(m) == "experiments"}
    assert framework and not [m for m, imp in framework.items() if {_unit(i) for i in imp} & {"rigs"}]
    assert '[project.entry-points."femast.experiments"]\nfemast = "femast.rigs:EXPERIMENTS"' in (
        (ROOT / "pyproject.toml").read_text()
    )
    installed = [ep for ep in entry_points(group="femast.experiments") if ep.dist and ep.dist.name == "femast"]
    assert [ep.value for ep in installed] == ["femast.rigs:EXPERIMENTS"], "reinstall: pip install -e ."
    from femast.experiments import list_experiments
    from femast.rigs import BUILT_IN

    assert [e.name for e in list_experiments()][: len(BUILT_IN)] == [r.EXPERIMENT.name for r in BUILT_IN]


def test_the_circle_finder_finds_a_lazy_circle():
    # the reader sees imports inside functions and the package __init__ an import runs
    graph = {"a.x": {"a.y"}, "a.y": {"a"}, "a": {"a.x"}, "b": {"a.x"}}
    assert _circles(graph) == [frozenset({"a", "a.x", "a.y"})]


def _sizes():
    """(path under femast/, module lines, [(class, lines)]) of every module of femast."""
    out = []
    for p in sorted(PKG.rglob("*.py")):
        src = p.read_text()
        tree = ast.parse(src)
        classes = [(n.name, n.end_lineno - n.lineno + 1) for n in ast.walk(tree) if isinstance(n, ast.ClassDef)]
        out.append((p.relative_to(PKG).as_posix(), len(src.splitlines()), classes))
    return out


MODULE_LINES, CLASS_LINES = 500, 300
# the few modules / classes allowed past the limits ("~500", "~300"), each with its ceiling and why
# an entry "path" or "path:Class" -> (ceiling, reason)
SIZE_EXCEPTIONS = {  # the formatter (ruff, one statement per line) lengthened these; each is to be split by concept
    "analysis/system.py:System": (340, "numbering, assembly and update in one class, to be split"),
    "elements/cable_latch.py:CableLatchFamily": (340, "the family's set-up, to be split from its state handling"),
    "experiments/noise.py": (550, "the estimators, to be split from the noise report"),
    "model/model.py:Model": (350, "the script verbs, to be split from the model's containers"),
}


def test_modules_and_classes_are_small():
    for name, lines, classes in _sizes():
        limit = SIZE_EXCEPTIONS.get(name, (MODULE_LINES,))[0]
        assert lines <= limit, f"femast/{name}: {lines} lines (limit {limit}); split it by concept"
        for cls, n in classes:
            limit = SIZE_EXCEPTIONS.get(f"{name}:{cls}", (CLASS_LINES,))[0]
            assert n <= limit, f"femast/{name}: class {cls} has {n} lines (limit {limit})"


def test_every_size_exception_is_still_needed():
    # a module or class back under the limit is struck off the list, so that it cannot grow back unnoticed
    sizes = {}
    for name, lines, classes in _sizes():
        sizes[name] = lines
        sizes.update({f"{name}:{cls}": n for cls, n in classes})
    unneeded = [k for k in SIZE_EXCEPTIONS if sizes.get(k, 0) <= (CLASS_LINES if ":" in k else MODULE_LINES)]
    assert not unneeded, f"back under the limit (strike them off SIZE_EXCEPTIONS): {unneeded}"


def test_one_newton_loop():
    # the only code that solves K du = r inside an increment is newton.py
    solving = [p.name for p in (PKG / "analysis").glob("*.py") if "solver.solve(" in p.read_text()]
    assert solving == ["newton.py"]


def test_the_loop_knows_nothing_of_files():
    loop = [PKG / "analysis" / n for n in ("newton.py", "stepping.py", "system.py", "state.py")]
    for path in loop + sorted((PKG / "analysis" / "control").glob("*.py")):
        src = path.read_text()
        assert "ResultsWriter" not in src and "results import" not in src, path.name


def test_elements_and_post_processing_never_import_the_analysis():
    for module, imported in GRAPH.items():
        if _unit(module) in ("elements", "post"):
            assert not {m for m in imported if _unit(m) == "analysis"}, module


def test_only_the_output_observer_imports_the_results_writer():
    for module, imported in GRAPH.items():
        if module.startswith("femast.analysis.") and module not in (
            "femast.analysis.output",
            "femast.analysis.analysis",
        ):
            bad = {m for m in imported if _unit(m) == "post"}
            assert not bad, f"{module} imports the results writer ({bad}): only output.py may"


OLD_TO_NEW = [
    ("femast.results", "femast.post.results"),
    ("femast.vtk", "femast.post.vtk"),
    ("femast.render", "femast.post.render"),
    ("femast.plotstyle", "femast.post.plotstyle"),
    ("femast.sections", "femast.model.sections"),
    ("femast.amplitudes", "femast.model.amplitudes"),
    ("femast.constraints", "femast.model.constraints"),
    ("femast.thermal", "femast.model.thermal"),
    ("femast.validation", "femast.model.validation"),
    ("femast.model_arrays", "femast.model.arrays"),
    ("femast.assembly", "femast.analysis.assembly"),
    ("femast.dofs", "femast.analysis.dofs"),
    ("femast.reduction", "femast.analysis.reduction"),
    ("femast.configuration", "femast.analysis.configuration"),
    ("femast.solvers.control", "femast.analysis.control"),
    ("femast.solvers.linear", "femast.analysis.linalg.linear"),
    ("femast.analysis.solvers.control", "femast.analysis.control"),
    ("femast.analysis.solvers.arclength", "femast.analysis.control.arclength"),
    ("femast.analysis.solvers.stabilize", "femast.analysis.control.stabilize"),
    ("femast.analysis.solvers.convergence", "femast.analysis.convergence"),
    ("femast.analysis.solvers.linear", "femast.analysis.linalg.linear"),
    ("femast.analysis.solvers.ordering", "femast.analysis.linalg.ordering"),
    ("femast.analysis.solvers.banded", "femast.analysis.linalg.banded"),
    ("femast.analysis.solvers.backends", "femast.analysis.linalg.backends"),
    ("femast.analysis.solvers.dense", "femast.analysis.linalg.dense"),
    ("femast.analysis.controls", "femast.analysis.control"),
    ("femast.analysis.viscous", "femast.analysis.control.stabilize"),
    ("femast.latch", "femast.elements.latch_law"),
    ("femast.mass", "femast.modal.mass"),
    ("femast.modal_output", "femast.modal.output"),
    ("femast.frequency_step", "femast.modal.step"),
    ("femast.references", "femast.verification.references"),
    ("femast.guyed.shroud", "femast.elements.shroud_law"),
    ("femast.verification_arclength", "femast.verification.arclength"),
    ("femast.verification_modal", "femast.verification.modal"),
] + [
    (f"femast.experiments.rigs.{m}", f"femast.rigs.{m}")
    for m in (
        "bay_torsion",
        "joint_test",
        "latch_pull",
        "mast_top",
        "platform_pose",
        "synthetic",
        "tip_cycle",
        "vibration",
    )
]


def _forget(name):
    """Drop ``name`` from sys.modules so that importing it runs its module again (and warns)."""
    import sys

    sys.modules.pop(name, None)
    parent, _, leaf = name.rpartition(".")
    if parent in sys.modules and leaf in vars(sys.modules[parent]):
        delattr(sys.modules[parent], leaf)


@pytest.mark.parametrize("old, new", OLD_TO_NEW)
def test_an_old_import_path_warns_and_gives_the_moved_module(old, new):
    import importlib
    import sys

    _forget(old)
    with pytest.warns(DeprecationWarning, match=rf"{re.escape(old)} has moved to {re.escape(new)}.*femast 0\.3"):
        mod = importlib.import_module(old)
    assert mod is importlib.import_module(new) and sys.modules[old] is sys.modules[new]
    assert mod.__name__ == new
    parent, _, leaf = old.rpartition(".")
    assert getattr(importlib.import_module(parent), leaf) is mod  # from femast import results


def test_an_old_package_path_warns_and_gives_the_new_package_names():
    import importlib

    import femast.rigs

    _forget("femast.experiments.rigs")
    with pytest.warns(DeprecationWarning, match=r"femast\.experiments\.rigs has moved to femast\.rigs.*femast 0\.3"):
        from femast.experiments.rigs import BUILT_IN, mast_top
    assert BUILT_IN is femast.rigs.BUILT_IN and mast_top is femast.rigs.mast_top
    # a module of the old package is the new module, never a second copy loaded under the old name
    _forget("femast.experiments.rigs.synthetic")
    with pytest.warns(
        DeprecationWarning, match=r"femast\.experiments\.rigs\.synthetic has moved to femast\.rigs\.synthetic"
    ):
        old = importlib.import_module("femast.experiments.rigs.synthetic")
    assert old is importlib.import_module("femast.rigs.synthetic")
    assert not [m for m in sys.modules.values() if getattr(m, "__file__", "") == old.__file__ and m is not old]


def test_the_old_paths_are_plain_modules_not_an_import_hook():
    import sys

    assert not [f for f in sys.meta_path if type(f).__module__.startswith("femast")]
    for old, _ in OLD_TO_NEW:
        rel = old.replace("femast.solvers.", "femast.analysis.solvers.").split(".")[1:]  # femast.solvers: that folder
        path = PKG.joinpath(*rel).with_suffix(".py")
        assert path.is_file() or (PKG.joinpath(*rel) / "__init__.py").is_file(), old


def test_old_names_resolve_to_the_same_objects():
    for old in ("femast.results", "femast.sections", "femast.solvers.control"):
        _forget(old)
    with pytest.warns(DeprecationWarning):
        from femast.solvers.control import LoadControl as OldControl

        from femast.results import Results as OldResults
        from femast.sections import circular_tube as old_tube

    from femast.analysis.control import LoadControl
    from femast.model.sections import circular_tube
    from femast.post.results import Results

    assert (OldResults, old_tube, OldControl) == (Results, circular_tube, LoadControl)
    assert fm.results.Results is Results and fm.Results is Results
    # the modules that became packages re-export the names the old module had
    from femast.modal import Modes, modal_analysis
    from femast.model import Model, Step, dof_index
    from femast.verification import Check, references

    assert Model is fm.Model and Step.__module__ == "femast.model.step" and dof_index("uz") == 2
    assert Modes.__module__ == "femast.modal.modes" and modal_analysis.__module__ == "femast.modal.modes"
    assert Check.__module__ == "femast.verification.cases"
    _forget("femast.references")
    with pytest.warns(DeprecationWarning, match="femast.references has moved"):
        assert references is fm.references  # the old top-level module, through femast's __getattr__
    with pytest.raises(AttributeError, match="no attribute 'nonexistent'"):
        _ = fm.nonexistent


#: femast modules that exist only as old paths (femast/_moved.py)
OLD_PATH_FILES = {MODULES[m] for m in OLD_PATH_MODULES}


def test_the_project_imports_no_old_path():
    old = tuple(o for o, _ in OLD_TO_NEW) + ("femast.solvers", "femast.analysis.solvers", "femast.experiments.rigs")
    root = PKG.parent
    pattern = re.compile(r"^\s*(?:from|import)\s+(femast(?:\.\w+)+)", re.M)
    offenders = []
    for p in (
        sorted(PKG.rglob("*.py")) + sorted((root / "tests").rglob("*.py")) + sorted((root / "benchmarks").rglob("*.py"))
    ):
        if p in OLD_PATH_FILES or p == Path(__file__).resolve():
            continue
        mods = {m for m in _imports(p) if m.startswith("femast.")}
        offenders += [
            f"{p.relative_to(root)}: {m}" for m in mods if m in old or m.startswith(tuple(o + "." for o in old))
        ]
    for p in sorted((root / "docs").rglob("*.md")):
        for m in pattern.findall(p.read_text()):
            if m in old or m.startswith(tuple(o + "." for o in old)):
                offenders.append(f"{p.relative_to(root)}: {m}")
    assert not offenders, "old import paths (use the new ones, femast/_moved.py): " + ", ".join(offenders)


def test_a_numba_kernel_of_a_moved_module_is_compiled_from_its_new_file():
    from femast.analysis.configuration import update_configuration

    # numba keys its cache on the source file: the kernel is loaded once, from the new path
    assert update_configuration.py_func.__code__.co_filename.endswith("femast/analysis/configuration.py")
