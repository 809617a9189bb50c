"""The import contract of docs/architecture.md ("Packages and layers") is the code's.

The table of that section lists each package and the packages it may import; the list of
interp's layers orders interp's parts. `.importlinter` is generated from both (one forbidden
contract per package, direct imports; one layers contract for interp), and:

* the checked-in `.importlinter` must be exactly what the documentation generates (a stale
  file fails: ``python tests/test_layers.py --write`` regenerates it);
* `lint-imports` (import-linter) must keep every contract on the code as it is.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "architecture.md"
CONFIG = REPO / ".importlinter"
ROOTS = ("krl", "interp", "robot", "recovery", "conformance", "net")


def _between(text: str, name: str) -> list[str]:
    m = re.search(rf"<!-- {name}:begin -->\n(.*?)<!-- {name}:end -->", text, re.S)
    if m is None:
        raise AssertionError(f"docs/architecture.md has no <!-- {name}:begin/end --> block")
    return [ln for ln in m.group(1).splitlines() if ln.strip()]


def documented() -> tuple[dict[str, list[str]], list[list[str]]]:
    """({package: packages it may import}, interp's layers top to bottom) from the doc."""
    text = DOC.read_text(encoding="utf-8")
    allowed: dict[str, list[str]] = {}
    for row in _between(text, "layers")[2:]:            # header and rule first
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        package = cells[0].strip("`")
        allowed[package] = ["*"] if cells[2] == "every package" else re.findall(r"`([\w.]+)`", cells[2])
    layers = [re.findall(r"[\w.]+", ln.lstrip("- ").replace("`", "")) for ln in _between(text, "interp-layers")]
    return allowed, layers


def generate() -> str:
    """The text of `.importlinter` that the documentation defines."""
    allowed, layers = documented()
    packages = list(allowed)
    out = ["# Generated from docs/architecture.md (\"Packages and layers\") by",
           "# python tests/test_layers.py --write; tests/test_layers.py keeps the two equal.",
           "[importlinter]",
           "root_packages =", *(f"    {r}" for r in ROOTS), ""]
    for package in packages:
        if allowed[package] == ["*"]:
            continue
        forbidden = [p for p in packages if p != package and p not in allowed[package]]
        out += [f"[importlinter:contract:{package}]",
                f"name = {package} imports only " + (", ".join(allowed[package]) or "no package of the project"),
                "type = forbidden",
                f"source_modules = {package}",
                "forbidden_modules =", *(f"    {p}" for p in forbidden),
                "allow_indirect_imports = True", ""]
    out += ["[importlinter:contract:interp-layers]",
            "name = interp's layers",
            "type = layers",
            "layers =", *(f"    {' | '.join(group)}" for group in layers), ""]
    return "\n".join(out)


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
