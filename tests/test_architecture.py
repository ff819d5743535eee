"""The layout holds: imports run one way down the pipeline, no circle of files or folders, nothing imported
inside a function but heavy third-party libraries, and no face name shared with a subpackage.

The graph is read from the source (every import, those inside functions too; ``if TYPE_CHECKING:`` blocks
left out), as a reader of the code sees it.
"""
from __future__ import annotations

import ast
import collections
import functools
from pathlib import Path

import pytest

import gearsym

ROOT = Path(gearsym.__file__).resolve().parent
BENCH = ROOT.parent / "bench"

#: the stages from the bottom up (docs/architecture.md): a module may import its own stage and those below
LAYERS = [
    {"errors", "version", "files", "units", "checks", "options", "parameters", "records"},
    {"geometry"},
    {"model"},
    {"system", "registry"},
    {"reduction"},
    {"scales"},
    {"codegen", "derivation"},
    {"analysis", "data"},
    {"sweep", "periodic", "stability"},
    {"fit", "physical"},
    {"figures"},
    {"verbs", "loading", "cached", "opening", "jobs", "fmu"},
    {"reproduce"},
    {"cli", "__init__"},
]
RANK = {unit: i for i, layer in enumerate(LAYERS) for unit in layer}
#: heavy third-party libraries: the only imports a function may hold (start-up of a cached model stays fast)
HEAVY = {"sympy", "pint", "casadi", "matplotlib", "scipy", "numba", "jitcode", "dask", "distributed", "tqdm",
         "fmpy", "gearsym_geometry_native"}


def modules(root: Path) -> dict[str, Path]:
    out = {}
    for p in sorted(root.rglob("*.py")):
        name = ".".join(p.relative_to(root.parent).with_suffix("").parts)
        out[name[: -len(".__init__")] if name.endswith(".__init__") else name] = p
    return out


def _import_nodes(tree: ast.AST, inside: bool = False):
    """Every import statement of ``tree`` with whether it is inside a function, those under ``if TYPE_CHECKING``
    left out (one pass over the tree)."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node, inside
        yield from _import_nodes(node, inside or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)))


def imports(root: Path) -> tuple[tuple[str, str, bool], ...]:
    """(importer, imported module, inside a function?) for every import of the package's own modules (the files
    read and parsed once for all the tests of this file)."""
    return _imports(root)


@functools.cache
def _imports(root: Path) -> tuple[tuple[str, str, bool], ...]:
    return tuple(_each_import(root))


@functools.cache
def _parsed(path: Path) -> ast.AST:
    return ast.parse(path.read_text())


def _each_import(root: Path):
    mods = modules(root)
    for name, path in mods.items():
        tree = _parsed(path)
        package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        for node, inside in _import_nodes(tree):
            if isinstance(node, ast.ImportFrom):
                base = ".".join((package[: len(package) - node.level + 1] if node.level else [])
                                + ([node.module] if node.module else []))
                targets = [f"{base}.{a.name}" for a in node.names] + [base]
            else:
                targets = [a.name for a in node.names]
            for target in targets:
                while target and target not in mods:
                    target = target.rpartition(".")[0]
                if target and target != name:
                    yield name, target, inside
                    break


def circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected parts with more than one member (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = []
            while True:
                w = stack.pop()
                on.discard(w)
                part.append(w)
                if w == v:
                    break
            if len(part) > 1:
                out.append(sorted(part))

    for v in list(edges):
        if v not in index:
            visit(v)
    return out


def unit(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


@pytest.mark.slow
@pytest.mark.parametrize("root", [ROOT, BENCH], ids=["gearsym", "bench"])
def test_no_file_and_no_folder_imports_itself_round_a_circle(root):
    files, folders = collections.defaultdict(set), collections.defaultdict(set)
    for a, b, _ in imports(root):
        files[a].add(b)
        fa, fb = ".".join(a.split(".")[:2]), ".".join(b.split(".")[:2])
        if fa != fb and fb != root.name:  # (a package's own face is its parent: not a folder of its own)
            folders[fa].add(fb)
    assert circles(files) == []
    assert circles(folders) == []


@pytest.mark.parametrize("root", [ROOT, BENCH], ids=["gearsym", "bench"])
def test_functions_import_no_module_of_the_project(root):
    inside = [f"{a} -> {b}" for a, b, within in imports(root) if within]
    assert inside == []


def test_imports_run_down_the_pipeline():
    against = [f"{a} -> {b}" for a, b, _ in imports(ROOT)
               if unit(b) != "__init__" and RANK[unit(b)] > RANK[unit(a)]]
    assert against == []
    assert {unit(m) for m in modules(ROOT)} <= set(RANK), "a new top-level module: give it its stage in LAYERS"


def test_functions_import_only_heavy_libraries():
    light = []
    for name, path in modules(ROOT).items():
        tree = _parsed(path)
        for f in ast.walk(tree):
            if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for node in ast.walk(f):
                    if isinstance(node, ast.Import):
                        light += [f"{name}: {a.name}" for a in node.names if a.name.split(".")[0] not in HEAVY]
                    elif isinstance(node, ast.ImportFrom) and node.level == 0 and \
                            node.module.split(".")[0] not in HEAVY:
                        light.append(f"{name}: {node.module}")
    assert light == []


def test_no_module_swaps_its_class_and_no_face_name_is_a_subpackage():
    source = (ROOT / "__init__.py").read_text()
    assert "__class__" not in source
    subpackages = {p.name for p in ROOT.iterdir() if (p / "__init__.py").is_file()}
    top_modules = {p.stem for p in ROOT.glob("*.py")}
    assert set(gearsym.__all__) & (subpackages | top_modules) == set()


def test_the_faces_verbs_are_made_from_modules_below_them():
    """gearsym.VERBS names the low-level verbs' modules, which verbs.py imports by name: they sit below it."""
    for name, module in gearsym.VERBS.items():
        assert module in modules(ROOT) and RANK[unit(module)] < RANK["verbs"], f"{name}: {module}"
        assert callable(getattr(gearsym, name)) and name in gearsym.__all__


DOC = ROOT.parent / "docs" / "architecture.md"
#: the picture's name of a unit whose module name is no mermaid id
PICTURE_NAMES = {"face": "__init__"}


def picture(text: str) -> tuple[list[set[str]], list[tuple[str, str]]]:
    """The stages (subgraph sN, bottom up) and the arrows of docs/architecture.md's picture of the stages."""
    block = next(b for b in text.split("```mermaid")[1:] if "%% the stages" in b).split("```")[0]
    stages: dict[int, set[str]] = {}
    arrows, inside = [], None
    for line in block.splitlines():
        line = line.strip()
        if line.startswith("subgraph "):
            inside = int(line.split()[1].removeprefix("s"))
            stages[inside] = set()
        elif line == "end":
            inside = None
        elif "-->" in line:
            a, b = (part.strip() for part in line.split("-->"))
            arrows.append((PICTURE_NAMES.get(a, a), PICTURE_NAMES.get(b, b)))
        elif inside is not None and line:
            node = line.split("[")[0].strip()
            stages[inside].add(PICTURE_NAMES.get(node, node))
    return [stages[i] for i in sorted(stages)], arrows


def test_the_picture_of_the_stages_is_the_code():
    """docs/architecture.md draws LAYERS (its stages, bottom up, with the same units) and only arrows that are
    imports the code makes, none of them up the picture."""
    stages, arrows = picture(DOC.read_text())
    assert stages == LAYERS
    made = {(unit(a), unit(b)) for a, b, _ in imports(ROOT)}
    assert [f"{a} --> {b}" for a, b in arrows if (a, b) not in made] == [], "an arrow no import makes"
    assert [f"{a} --> {b}" for a, b in arrows if RANK[a] < RANK[b]] == [], "an arrow up the picture"
