"""The layout holds (issue 24): packages in one order, each importing only packages below it; no
import cycle and no import hidden in a function outside the command line; the README's layout table
is the real tree; every module, class and public function says what it is for; modules stay small."""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: The packages, lowest first: a package may import only packages of an earlier row (or itself).
LAYERS = (
    ("elastokin.core",),                                       # foundation
    ("elastokin.cluster",),                                    # where runs execute (Dask)
    ("elastokin.bushings",),                                   # bushing laws
    ("elastokin.bushings.bench",),                             # the bushing test bench
    ("elastokin.tyres",),                                      # tyre property files and laws
    ("elastokin.vehicle", "elastokin.vehicle.model"),          # the vehicle model
    ("elastokin.vehicle.scenarios",),                          # what the car is made to do
    ("elastokin.vehicle.simulation",),                         # running it
    ("elastokin.recordings",),                                 # recorded runs and measured data
    ("elastokin.analysis",),                                   # metrics and comparison
    ("elastokin.sweeps",),                                     # sweeps over vehicle parameters
    ("elastokin.diagnosis",),                                  # causes, virtual rigs, diagnoses
    ("elastokin.presentation",),                               # plots, replay, tables, reports
    ("elastokin.api",),                                        # the Python API
    ("elastokin.cli",),                                        # the command line
    ("elastokin",),                                            # the package's front door: the API re-exported
)
LAYER = {package: i for i, row in enumerate(LAYERS) for package in row}
SETUPTOOLS = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
#: The shipped data's packages: folders of files, no modules.
DATA_PACKAGES = {"elastokin.models": "models", "elastokin.scenarios": "scenarios", "elastokin.data": "data"}
#: Where each package's folder is: the repository's own top-level folders mapped into the one package.
FOLDERS = {"elastokin": "elastokin", "elastokin.bushings": "bushings", "elastokin.vehicle": "vehicle"}
#: Compiled kernels may be long: one function is one compiled unit.
COMPILED_KERNELS = {"bushings/kernel.py"}
MAX_LINES = 450


def _modules() -> dict[str, Path]:
    """Every module of the packages, by dotted name (a package by its own name)."""
    out = {}
    for package, folder in FOLDERS.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            parts = path.relative_to(ROOT / folder).with_suffix("").parts
            out[".".join((package, *(parts[:-1] if parts[-1] == "__init__" else parts)))] = path
    return out


MODULES = _modules()
TREES = {name: ast.parse(path.read_text(), str(path)) for name, path in MODULES.items()}


def package_of(module: str) -> str:
    return module if MODULES[module].name == "__init__.py" else module.rpartition(".")[0]


def _imports(tree: ast.Module) -> list[tuple[ast.AST, str]]:
    """(node, imported project module) of every import in the tree, wherever it stands."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in MODULES else node.module
                     for a in node.names]
        else:
            continue
        for name in names:
            while name and name not in MODULES:
                name = name.rpartition(".")[0]
            if name:
                out.append((node, name))
    return out


EDGES = {(m, target) for m, tree in TREES.items() for _, target in _imports(tree) if target != m}


def test_every_package_has_its_place_in_the_order():
    packages = {package_of(m) for m in MODULES}
    assert packages == set(LAYER), f"not in LAYERS: {sorted(packages - set(LAYER))}; gone: {sorted(set(LAYER) - packages)}"


def test_packages_import_only_packages_below_them():
    upward = sorted(f"{a} imports {b}" for a, b in EDGES
                    if package_of(a) != package_of(b) and LAYER[package_of(b)] >= LAYER[package_of(a)])
    assert not upward, "\n".join(upward)


def test_no_import_cycle():
    """No cycle between modules, counting every import (also within a package and in functions)."""
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for a, b in EDGES:
        graph[a].add(b)
    state: dict[str, int] = {}
    cycles = []

    def visit(node: str, trail: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycles.append(" -> ".join(trail[trail.index(nxt):] + [node, nxt]) if nxt in trail else f"{node} -> {nxt}")
            elif nxt not in state:
                visit(nxt, trail + [node])
        state[node] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [])
    assert not cycles, "\n".join(cycles)


def test_imports_stand_at_the_top_of_modules_except_in_the_command_line():
    """Deferred imports are the command line's and the front door's alone (`vsim --help` and `import
    elastokin.core` need not load MuJoCo: the package re-exports the API when it is first asked for);
    elsewhere an import inside a function would hide a dependency."""
    top_level = {m: {id(n) for n in tree.body} for m, tree in TREES.items()}
    hidden = sorted(f"{MODULES[m].relative_to(ROOT)}:{node.lineno}" for m, tree in TREES.items()
                    for node, _ in _imports(tree) if id(node) not in top_level[m] and package_of(m) not in ("elastokin.cli", "elastokin"))
    assert not hidden, "\n".join(hidden)


def test_the_wheel_packages_every_package_and_the_shipped_data():
    """pyproject.toml lists the packages (a wheel carries no other), all under the one import package,
    and maps the repository's bushings/, vehicle/, models/, scenarios/ and data/ into it, where
    elastokin.core.shipped looks for the data in an installed copy."""
    packages = {m for m, path in MODULES.items() if path.name == "__init__.py"}
    assert sorted(SETUPTOOLS["packages"]) == sorted(packages | set(DATA_PACKAGES))
    assert {p.split(".")[0] for p in SETUPTOOLS["packages"]} == {"elastokin"}
    assert SETUPTOOLS["package-dir"] == {**{p: f for p, f in FOLDERS.items() if p != "elastokin"}, **DATA_PACKAGES}


def _readme_table() -> dict[str, tuple[str, str]]:
    text = (ROOT / "README.md").read_text()
    section = text.split("## Layout", 1)[1].split("\n## ", 1)[0]
    return {p: (purpose, modules) for p, purpose, modules in
            re.findall(r"^\| `([\w.]+)` \| (.+?) \| (.+?) \|$", section, flags=re.M)}


def test_the_readme_layout_table_is_the_tree():
    """One row per package, in the order of LAYERS, with the first line of the package's docstring and
    its modules (or subpackages)."""
    table = _readme_table()
    assert list(table) == [p for row in LAYERS for p in row]
    for package, (purpose, listed) in table.items():
        assert purpose == ast.get_docstring(TREES[package]).splitlines()[0], package
        modules = sorted(m.rpartition(".")[2] for m in MODULES if m.rpartition(".")[0] == package
                         and MODULES[m].name != "__init__.py")
        subpackages = sorted(m for m in MODULES if m.rpartition(".")[0] == package and MODULES[m].name == "__init__.py")
        expected = ", ".join(f"`{m}`" for m in modules) or "(" + ", ".join(f"`{m}`" for m in subpackages) + ")"
        assert listed == expected, package


def _public(body: list[ast.stmt]) -> list[ast.ClassDef | ast.FunctionDef]:
    """Public classes and functions of a module or class body, with the public methods of public classes."""
    out = []
    for node in body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)) and not node.name.startswith("_"):
            out.append(node)
            if isinstance(node, ast.ClassDef):
                out += _public(node.body)
    return out


def test_every_module_class_and_public_function_says_what_it_is_for():
    missing = [f"{MODULES[m].relative_to(ROOT)}: module" for m, tree in TREES.items() if not ast.get_docstring(tree)]
    missing += [f"{MODULES[m].relative_to(ROOT)}:{node.lineno}: {node.name}" for m, tree in TREES.items()
                for node in _public(tree.body) if not ast.get_docstring(node)]
    assert not missing, "\n".join(missing)


def test_modules_are_small():
    long = {str(p.relative_to(ROOT)): n for p in MODULES.values()
            if (n := len(p.read_text().splitlines())) > MAX_LINES and str(p.relative_to(ROOT)) not in COMPILED_KERNELS}
    assert not long, long


_NO_MUJOCO = """
import sys
class Refuse:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "mujoco":
            raise ImportError("MuJoCo must not be loaded to " + WHAT)
sys.meta_path.insert(0, Refuse())
from elastokin.cli.main import main
for WHAT, argv in COMMANDS:
    assert main(argv) == 0, WHAT
assert "mujoco" not in sys.modules
"""


def test_measured_data_is_imported_compared_plotted_and_diagnosed_without_mujoco(tmp_path):
    """`vsim rig import`, `compare`, `plot`, `bushing run --plot` and a bench-level `diagnose` run with
    MuJoCo made unimportable."""
    example = ROOT / "data" / "examples" / "kc_import"
    bench = tmp_path / "bench"
    _small_bench_dataset(bench)
    rig = [str(example / "kc_pumping.csv"), "--meta", str(example / "META.yaml")]
    commands = [
        ("import a rig CSV", ["rig", "import", *rig, "-o", str(tmp_path / "a.mcap")]),
        ("import it again", ["rig", "import", *rig, "-o", str(tmp_path / "b.mcap")]),
        ("compare two runs", ["compare", str(tmp_path / "a.mcap"), str(tmp_path / "b.mcap"), "-o", str(tmp_path / "c")]),
        ("plot a run", ["plot", str(tmp_path / "a.mcap"), "-o", str(tmp_path / "p")]),
        ("run and plot a bench", ["bushing", "run", str(ROOT / "models" / "bushings" / "benches" / "bisine.yaml"),
                                  "-o", str(tmp_path / "bisine.csv"), "--plot", str(tmp_path / "bp")]),
        ("diagnose bench data", ["diagnose", str(bench), "--bushing-set", "fig5_9", "-o", str(tmp_path / "d")]),
    ]
    code = f"COMMANDS = {commands!r}\n" + _NO_MUJOCO
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert (tmp_path / "d" / "report.md").is_file() and (tmp_path / "c" / "comparison.json").is_file()
    # the Mullins softening hidden in the bench dataset named with its magnitude
    verdict = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    assert verdict["cause"] == "mullins", verdict["ranking"][:3]
    fitted = verdict["parameters"]["mullins"]
    assert abs(fitted["value"] - 0.15) <= max(4.0 * fitted["std"], 0.25 * 0.15), fitted


def _small_bench_dataset(directory: Path) -> None:
    """Four short tests of fig5_9 with a little Mullins softening, written as a measured bench dataset."""
    from elastokin.bushings.bench.campaign import CAMPAIGN
    from elastokin.diagnosis.virtual_bench import measure_bench, parse_truth

    truth = parse_truth({"level": "bench", "baseline": "fig5_9", "effects": [{"cause": "mullins", "mullins": 0.15}],
                         "seed": 1}, "truth.yaml")
    tests = tuple(t for t in CAMPAIGN if t.name in ("triangle_2mm_slow", "triangle_1mm_slow", "sine_1hz_1mm",
                                                    "triangle_2mm_10mm_s"))
    measure_bench(truth, directory, tests=tests)
