"""The house rules of refsph/, checked on the source: no import cycle, no module importing another's private
name, no function of 80 lines or more, one spelling of equation numbers, every equation the README's code map
claims for a module cited in that module, and the layers: every module in exactly one, the equation modules and
the scenes importing nothing above them."""
import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "refsph"
MODULES = sorted(PKG.rglob("*.py"))


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def resolve(path: Path, node: ast.ImportFrom) -> str:
    """The absolute module an ImportFrom names (relative imports resolved)."""
    if node.level == 0:
        return node.module or ""
    base = module_name(path).split(".")
    if path.name != "__init__.py":
        base = base[:-1]
    base = base[:len(base) - node.level + 1]
    return ".".join(base + ([node.module] if node.module else []))


def imports(path: Path):
    """(imported refsph module, names imported from it) for every import in the file, at any depth."""
    tree = ast.parse(path.read_text())
    known = {module_name(p) for p in MODULES}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("refsph"):
                    yield a.name, []
        elif isinstance(node, ast.ImportFrom):
            mod = resolve(path, node)
            if not mod.startswith("refsph"):
                continue
            for a in node.names:                              # `from . import contact`: the module itself
                sub = f"{mod}.{a.name}"
                if sub in known:
                    yield sub, []
                else:
                    yield mod, [a.name]


def test_no_import_cycle():
    graph = {module_name(p): set() for p in MODULES}
    for p in MODULES:
        me = module_name(p)
        for mod, _ in imports(p):
            if mod in graph and mod != me and not me.startswith(mod + "."):   # a package's own __init__ is fine
                graph[me].add(mod)
    state, stack = {}, []

    def visit(m):
        state[m] = "open"
        stack.append(m)
        for n in sorted(graph[m]):
            if state.get(n) == "open":
                raise AssertionError("import cycle: " + " -> ".join(stack[stack.index(n):] + [n]))
            if n not in state:
                visit(n)
        stack.pop()
        state[m] = "done"

    for m in sorted(graph):
        if m not in state:
            visit(m)


# The layers, bottom to top. The equation modules stay flat (refsph.esph is Section 2.1) and import only each
# other; the scenes build set-ups from them; the run loop runs a scene; the tooling (crosscheck/, teaching/) sits
# on top (of the rest only cli.py imports it, to dispatch its commands). A new flat module must be added to one
# of the two lists by hand; a module in a folder takes the folder's layer.
EQUATION_MODULES = {f"refsph.{m}" for m in (
    "kernels", "esph", "tlsph", "material", "plasticity", "strength", "contact", "penalty", "self_contact", "thermal",
    "surface",
    "neighbours", "tensor", "state", "boundaries", "integrate", "stability", "paper_data")}
RUN_LOOP_MODULES = {"refsph", "refsph.simulate", "refsph.solvers", "refsph.reference", "refsph.coupling",
                    "refsph.cli", "refsph.io", "refsph.pfem_run"}   # refsph: the root; reference, coupling: parts of
#                                                   the TLSPH solver; pfem_run: the PFEM's run folders
FLAT_LAYERS = {"equations": EQUATION_MODULES, "run loop": RUN_LOOP_MODULES}
FOLDER_LAYERS = {"scenes": "refsph.scenes", "pfem": "refsph.pfem", "crosscheck": "refsph.crosscheck",
                 "teaching": "refsph.teaching"}
NOT_IMPORTED_BY = {                  # layer: the layers its modules must not import (unclassified modules neither)
    "equations": {"run loop", "scenes", "pfem", "crosscheck", "teaching"},
    "scenes": {"run loop", "pfem", "crosscheck", "teaching"},
    "pfem": {"run loop", "crosscheck", "teaching"},
}


def layers_of(module: str) -> list:
    return ([layer for layer, mods in FLAT_LAYERS.items() if module in mods]
            + [layer for layer, pkg in FOLDER_LAYERS.items() if module == pkg or module.startswith(pkg + ".")])


def test_every_module_in_exactly_one_layer():
    names = {module_name(p) for p in MODULES}
    wrong = {m: layers_of(m) for m in sorted(names) if len(layers_of(m)) != 1}
    assert not wrong, f"modules not in exactly one layer (place a new one in EQUATION_MODULES, ...): {wrong}"
    stale = sorted(m for mods in FLAT_LAYERS.values() for m in mods if m not in names)
    stale += sorted(pkg for pkg in FOLDER_LAYERS.values() if pkg not in names)
    assert not stale, f"layers name modules that do not exist: {stale}"


@pytest.mark.parametrize("layer", sorted(NOT_IMPORTED_BY))
def test_layer_imports_nothing_above_it(layer):
    bad = set()
    for p in MODULES:
        me = module_name(p)
        if layer not in layers_of(me):
            continue
        for mod, _ in imports(p):
            theirs = layers_of(mod)
            if not theirs or set(theirs) & NOT_IMPORTED_BY[layer]:
                bad.add(f"{p.relative_to(ROOT)} imports {mod} ({', '.join(theirs) or 'no layer'})")
    assert not bad, f"{layer} must not import {sorted(NOT_IMPORTED_BY[layer])}: {sorted(bad)}"


def test_no_private_name_imported_across_modules():
    bad = [f"{module_name(p)} imports {n} from {mod}" for p in MODULES for mod, names in imports(p)
           for n in names if n.startswith("_") and not n.endswith("__") and mod != module_name(p)]
    assert not bad, bad


def test_functions_are_short():
    long = []
    for p in MODULES:
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n >= 80:
                    long.append(f"{p.relative_to(ROOT)}:{node.lineno} {node.name} ({n} lines)")
    assert not long, long


def test_classes_are_small():
    """No class of ~150 lines or more (a class with one job fits on a screen or two)."""
    big = []
    for p in MODULES:
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.ClassDef) and node.end_lineno - node.lineno + 1 > 150:
                n = node.end_lineno - node.lineno + 1
                big.append(f"{p.relative_to(ROOT)}:{node.lineno} {node.name} ({n} lines)")
    assert not big, big


def private_attribute_uses(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, 'obj._name') for every read or write of another object's private attribute: ``x._name`` where x is
    not ``self`` or ``cls`` (dunder names and module-level private functions called as ``module._f`` count too)."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.endswith("__"):
            owner = node.value
            if not (isinstance(owner, ast.Name) and owner.id in ("self", "cls")):
                out.append((node.lineno, f"{ast.unparse(owner)}.{node.attr}"))
    return out


def test_no_access_to_another_objects_private_attributes():
    bad = [f"{p.relative_to(ROOT)}:{line} {what}" for p in MODULES
           for line, what in private_attribute_uses(ast.parse(p.read_text()))]
    assert not bad, bad


def test_the_private_attribute_check_can_fail():
    assert private_attribute_uses(ast.parse("def f(pairs):\n    return pairs._x_build\n")) == [(2, "pairs._x_build")]
    assert private_attribute_uses(ast.parse("class A:\n    def f(self):\n        return self._x\n")) == []


EQ_ANY = re.compile(r"\bEqs?\.\s*[(\d]")
EQ_GOOD = re.compile(r"\bEqs?\. \(\d+\)")


def test_one_spelling_of_equation_numbers():
    """Equations are cited as Eq. (n) / Eqs. (n)-(m), never Eq. n or Eqs. n-m."""
    bad = []
    for p in MODULES:
        for k, line in enumerate(p.read_text().splitlines(), 1):
            for m in EQ_ANY.finditer(line):
                if not EQ_GOOD.match(line, m.start()):
                    bad.append(f"{p.relative_to(ROOT)}:{k}: {line.strip()}")
    assert not bad, bad


CITATION = re.compile(r"\bEqs?\. (\(\d+\)(?:\s*(?:[-–,]|and)\s*\(\d+\))*)")


def cited(text: str) -> set:
    """Equation numbers cited in text: Eq. (n), Eqs. (a)-(b) (the whole range), Eqs. (a), (b)."""
    out = set()
    for m in CITATION.finditer(text):
        group = m.group(1)
        nums = [int(x) for x in re.findall(r"\((\d+)\)", group)]
        out.update(nums)
        for a, b in re.findall(r"\((\d+)\)\s*[-–]\s*\((\d+)\)", group):
            out.update(range(int(a), int(b) + 1))
    return out


def code_map():
    """{module path: equation numbers} from the README's code map."""
    text = (ROOT / "README.md").read_text()
    section = text.split("## Code map", 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = line.split("|")
        if len(cells) >= 4:
            for path in re.findall(r"`(refsph/[\w/]+\.py)`", cells[1]):
                rows[path] = cited(cells[2])
    return rows


def test_code_map_lists_every_module():
    rows = code_map()
    missing = [str(p.relative_to(ROOT)) for p in MODULES if str(p.relative_to(ROOT)) not in rows]
    assert not missing, f"modules missing from the README's code map: {missing}"


@pytest.mark.parametrize("path, claimed", sorted(code_map().items()))
def test_every_claimed_equation_is_cited(path, claimed):
    found = cited((ROOT / path).read_text())
    assert claimed <= found, f"{path}: the code map claims Eqs. {sorted(claimed - found)}, not cited in the code"
