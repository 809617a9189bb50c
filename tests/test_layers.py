"""The import contract of docs/architecture.md ("Packages and layers") is the code's.

The table of that section lists each package, the packages of the project it imports itself
(``imports``) and the third-party packages it imports itself (``external``); the list of
interp's layers orders interp's parts. `.importlinter` is generated from both:

* one forbidden contract per package: every package of the project that its ``imports`` do not
  reach, directly or through the packages they import (no ``allow_indirect_imports``);
* one protected contract per third-party package: only the packages whose row names it may
  import it (``antlr4``: only ``krl.syntax`` and ``krl.ast``);
* one layers contract for interp.

And:

* the checked-in `.importlinter` must be exactly what the documentation generates (a stale
  file fails: ``python tests/test_layers.py --write`` regenerates it);
* each row is what its package imports, no more and no less (the import graph, grimp);
* `lint-imports` (import-linter) must keep every contract on the code as it is, and the
  antlr4 contract fails on an import of ANTLR outside krl/syntax and krl/ast.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path
import grimp
from importlinter.contracts.protected import ProtectedContract

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "architecture.md"
CONFIG = REPO / ".importlinter"
ROOTS = ("krl", "interp", "robot", "recovery", "conformance", "net", "pendant", "audit", "app")
#: the generated parser's own fallback import (``from KRLParser import KRLParser`` when the
#: generated visitor is run as a script): not a package anyone installs
GENERATED_SELF_IMPORTS = {"KRLParser"}


def _between(text: str, name: str) -> list[str]:
    m = re.search(rf"<!-- {name}:begin -->\n(.*?)<!-- {name}:end -->", text, re.S)
    if m is None:
        raise AssertionError(f"docs/architecture.md has no <!-- {name}:begin/end --> block")
    return [ln for ln in m.group(1).splitlines() if ln.strip()]


def documented() -> tuple[dict[str, list[str]], list[list[str]]]:
    """({package: packages of the project it imports}, interp's layers top to bottom) from the
    doc; ``["*"]`` for the row that may import every package."""
    allowed, _external, layers = documented_all()
    return allowed, layers


def documented_all() -> tuple[dict[str, list[str]], dict[str, list[str]], list[list[str]]]:
    """({package: project packages it imports}, {package: third-party packages it imports},
    interp's layers) from the doc."""
    text = DOC.read_text(encoding="utf-8")
    allowed: dict[str, list[str]] = {}
    external: dict[str, list[str]] = {}
    for row in _between(text, "layers")[2:]:            # header and rule first
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        package = cells[0].strip("`")
        allowed[package] = ["*"] if cells[2] == "every package" else re.findall(r"`([\w.]+)`", cells[2])
        external[package] = re.findall(r"`([\w.]+)`", cells[3]) if len(cells) > 3 else []
    layers = [re.findall(r"[\w.]+", ln.lstrip("- ").replace("`", "")) for ln in _between(text, "interp-layers")]
    return allowed, external, layers


def reach(allowed: dict[str, list[str]], package: str) -> set[str]:
    """The packages `package` may use: its ``imports``, and theirs, transitively."""
    seen: set[str] = set()
    work = [q for q in allowed[package] if q != "*"]
    while work:
        q = work.pop()
        if q not in seen:
            seen.add(q)
            work.extend(x for x in allowed[q] if x != "*")
    return seen


def generate() -> str:
    """The text of `.importlinter` that the documentation defines."""
    allowed, external, layers = documented_all()
    packages = list(allowed)
    out = ["# Generated from docs/architecture.md (\"Packages and layers\") by",
           "# python tests/test_layers.py --write; tests/test_layers.py keeps the two equal.",
           "[importlinter]",
           "root_packages =", *(f"    {r}" for r in ROOTS),
           "include_external_packages = True", ""]
    for package in packages:
        if allowed[package] == ["*"]:
            continue
        may = reach(allowed, package)
        forbidden = [p for p in packages if p != package and p not in may]
        out += [f"[importlinter:contract:{package}]",
                f"name = {package} imports only " + (", ".join(allowed[package]) or "no package of the project")
                + " (and what they import)",
                "type = forbidden",
                f"source_modules = {package}",
                "forbidden_modules =", *(f"    {p}" for p in forbidden), ""]
    importers: dict[str, list[str]] = {}
    for package in packages:
        for ext in external[package]:
            importers.setdefault(ext, []).append(package)
    for ext in sorted(importers):
        out += [f"[importlinter:contract:external-{ext}]",
                f"name = only {', '.join(importers[ext])} import {ext}",
                "type = protected",
                f"protected_modules = {ext}",
                "allowed_importers =", *(f"    {p}" for p in importers[ext]), ""]
    out += ["[importlinter:contract:interp-layers]",
            "name = interp's layers",
            "type = layers",
            "layers =", *(f"    {' | '.join(group)}" for group in layers), ""]
    return "\n".join(out)


def _graph():

    return grimp.build_graph(*ROOTS, include_external_packages=True, cache_dir=None)


def _owner(module: str, packages: list[str]) -> str | None:
    best = None
    for p in packages:
        if (module == p or module.startswith(p + ".")) and (best is None or len(p) > len(best)):
            best = p
    return best


def used(graph, packages: list[str]) -> tuple[dict[str, set[str]], dict[str, set[str]]]:
    """({package: project packages it imports}, {package: third-party packages it imports})
    from the import graph (module-level and function-level imports alike)."""
    std = set(sys.stdlib_module_names) | {"__future__"}
    direct: dict[str, set[str]] = {p: set() for p in packages}
    external: dict[str, set[str]] = {p: set() for p in packages}
    for m in graph.modules:
        owner = _owner(m, packages)
        if owner is None:
            continue
        for imp in graph.find_modules_directly_imported_by(m):
            other = _owner(imp, packages)
            top = imp.split(".")[0]
            if other is not None:
                if other != owner:
                    direct[owner].add(other)
            elif top not in ROOTS and top not in std and top not in GENERATED_SELF_IMPORTS:
                external[owner].add(top)
    return direct, external


def test_documented_imports_form_layers():
    """Every name in the table is a package of the table, and no package may import,
    directly or through others, itself: the table draws layers, not a tangle."""
    allowed, _ = documented()
    for package, names in allowed.items():
        assert all(n == "*" or n in allowed for n in names), (package, names)
    state: dict[str, int] = {}

    def visit(p: str, path: tuple[str, ...]) -> None:
        if state.get(p) == 2:
            return
        assert state.get(p) != 1, f"import cycle in docs/architecture.md: {' -> '.join(path + (p,))}"
        state[p] = 1
        for q in allowed[p]:
            if q != "*":
                visit(q, path + (p,))
        state[p] = 2

    for p in allowed:
        visit(p, ())


def test_every_package_of_the_project_is_in_the_table():
    allowed, _ = documented()
    found = set()
    for root in ROOTS:
        base = REPO / root
        if root != "krl":
            found.add(root)
            continue
        for child in base.iterdir():
            if child.name.startswith(("_", ".")) or child.name in ("templates", "__pycache__"):
                continue
            if child.suffix == ".py" or (child / "__init__.py").exists():
                found.add(f"krl.{child.stem}")
    assert found == set(allowed), f"not in the table: {sorted(found - set(allowed))}; " \
                                  f"no such package: {sorted(set(allowed) - found)}"


def test_importlinter_file_is_generated_from_the_doc():
    assert CONFIG.read_text(encoding="utf-8") == generate(), \
        ".importlinter is stale: run python tests/test_layers.py --write"
    assert "allow_indirect_imports" not in CONFIG.read_text(encoding="utf-8")


def test_each_row_is_what_its_package_imports():
    """No allow-list wider or narrower than the code: the table's ``imports`` and ``external``
    are exactly the packages each package imports itself."""
    allowed, external, _ = documented_all()
    packages = list(allowed)
    direct, ext = used(_graph(), packages)
    for p in packages:
        if allowed[p] != ["*"]:
            assert direct[p] == set(allowed[p]), \
                f"{p}: imports {sorted(direct[p])}, the table says {sorted(allowed[p])}"
        assert ext[p] == set(external[p]), f"{p}: imports {sorted(ext[p])}, the table says {sorted(external[p])}"


def test_antlr4_only_in_syntax_and_ast():
    """ANTLR is contained: only krl.syntax and krl.ast import antlr4, and the protected
    contract generated for it fails when any other module imports it."""

    graph = _graph()
    importers = {m for m in graph.find_modules_that_directly_import("antlr4")}
    assert importers and all(m.startswith(("krl.syntax.", "krl.ast.")) for m in importers), sorted(importers)
    assert "[importlinter:contract:external-antlr4]\nname = only krl.syntax, krl.ast import antlr4\n" \
           "type = protected\nprotected_modules = antlr4\nallowed_importers =\n    krl.syntax\n    krl.ast\n" \
        in generate()

    def check() -> bool:
        contract = ProtectedContract(name="antlr4", session_options={"root_packages": list(ROOTS)},
                                     contract_options={"protected_modules": ["antlr4"],
                                                       "allowed_importers": ["krl.syntax", "krl.ast"]})
        return contract.check(graph, verbose=False).kept

    assert check()
    graph.add_import(importer="krl.fmt.core", imported="antlr4", line_number=1, line_contents="import antlr4")
    assert not check()


def test_no_module_imports_itself_through_others():
    """The module import graph has no cycle (module-level and function-level imports alike):
    an import cycle hides the order modules depend on each other in."""
    graph = _graph()
    modules = sorted(m for m in graph.modules if m.split(".")[0] in ROOTS)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    cycles = []
    for start in modules:                # Tarjan's strongly connected components, iteratively
        if start in index:
            continue
        work = [(start, iter(sorted(graph.find_modules_directly_imported_by(start))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on.add(start)
        while work:
            v, it = work[-1]
            w = next((x for x in it if x.split(".")[0] in ROOTS), None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph.find_modules_directly_imported_by(w)))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    x = stack.pop()
                    on.discard(x)
                    comp.append(x)
                    if x == v:
                        break
                if len(comp) > 1:
                    cycles.append(sorted(comp))
    assert not cycles, cycles


def test_lint_imports_keeps_the_contract():
    lint = Path(sys.executable).with_name("lint-imports")
    proc = subprocess.run([str(lint), "--no-cache", "--config", str(CONFIG)], cwd=REPO,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]
    assert "broken" in proc.stdout and " 0 broken" in proc.stdout, proc.stdout[-2000:]


if __name__ == "__main__":
    if sys.argv[1:] == ["--write"]:
        CONFIG.write_text(generate(), encoding="utf-8")
        print(f"wrote {CONFIG}")
    else:
        print(generate(), end="")
