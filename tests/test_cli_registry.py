"""The `krl` subcommands are declared once (app/__init__.py SUBCOMMANDS: name -> the module that
defines it) and loaded on first use: the table names every command of every stage's ``commands``
list and no other, and a command that does not move the arm starts without the simulator."""

from __future__ import annotations

import importlib
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import click
import pytest
from click.testing import CliRunner

from app import SUBCOMMANDS, SUMMARIES, main, subcommand

REPO = Path(__file__).resolve().parents[1]
#: ``commands = [...]`` or ``commands: list = ...`` at a module's top level (column 0)
_TOP_LEVEL_COMMANDS = re.compile(r"^commands\s*(:[^=]*)?=", re.M)


def _modules_with_commands() -> set[str]:
    """Every module of the shipped packages (pyproject.toml) that assigns ``commands`` at its top
    level (column 0), read from the sources (not from what the table imports)."""
    include = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]["find"]["include"]
    out = set()
    for pkg in {p.split(".")[0].rstrip("*") for p in include}:
        for path in (REPO / pkg).rglob("*.py"):
            if "generated" in path.parts:
                continue
            if _TOP_LEVEL_COMMANDS.search(path.read_text(encoding="utf-8")):
                rel = path.relative_to(REPO).with_suffix("")
                parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
                out.add(".".join(parts))
    return out


def _loaded_after(argv: list[str], cwd: Path) -> set[str]:
    """The modules a fresh process holds after ``krl ARGV`` exited 0."""
    probe = ("import sys\n"
             "from app import main\n"
             "try:\n"
             f"    main({argv!r})\n"
             "except SystemExit as e:\n"
             "    assert e.code == 0, e.code\n"
             "print(' '.join(sys.modules))\n")
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=cwd, timeout=120)
    assert res.returncode == 0, res.stderr
    return set(res.stdout.splitlines()[-1].split())


def test_the_table_names_each_stage_module_and_each_of_its_commands():
    assert set(SUBCOMMANDS.values()) == _modules_with_commands()
    for module_name in set(SUBCOMMANDS.values()):
        listed = {c.name for c in importlib.import_module(module_name).commands}
        assert listed == {n for n, m in SUBCOMMANDS.items() if m == module_name}, module_name
    for name in SUBCOMMANDS:
        assert subcommand(name).name == name
    assert subcommand("no-such-command") is None


def test_help_lists_every_subcommand_and_an_unknown_one_is_a_usage_error():
    res = CliRunner().invoke(main, ["--help"])
    assert res.exit_code == 0
    listed = {line.split()[0] for line in res.output.split("Commands:", 1)[1].splitlines() if line.strip()}
    assert listed == set(SUBCOMMANDS)
    res = CliRunner().invoke(main, ["chek", "x.src"])
    assert res.exit_code == 2 and "No such command 'chek'" in res.output


def test_help_lists_each_summary_as_click_would_without_importing_a_subcommand(tmp_path):
    """SUMMARIES holds each command's first sentence (what click shows of its help); `krl --help`
    prints what click's own listing prints (it imports every subcommand), at two widths, and
    imports no module of a subcommand."""
    assert set(SUMMARIES) == set(SUBCOMMANDS)
    for name, module_name in SUBCOMMANDS.items():
        cmd = subcommand(name)
        assert SUMMARIES[name] == cmd.get_short_help_str(10**6), name
    for width in (60, 200):
        eager = click.Group("krl", commands={n: subcommand(n) for n in SUBCOMMANDS})
        ctx = click.Context(main, info_name="krl", terminal_width=width, max_content_width=width)
        ours, theirs = ctx.make_formatter(), ctx.make_formatter()
        main.format_commands(ctx, ours)
        eager.format_commands(ctx, theirs)
        assert ours.getvalue() == theirs.getvalue() and "Commands:" in ours.getvalue(), width
    loaded = _loaded_after(["--help"], tmp_path)
    assert not set(SUBCOMMANDS.values()) & loaded, sorted(set(SUBCOMMANDS.values()) & loaded)


def test_check_does_not_load_the_simulator(tmp_path):
    """`krl check` of a module: none of the simulator's or the interpreters' modules, nor numpy and
    scipy, are imported (robot/__init__.py's promise; was 0.3 s of CPU at each start)."""
    (tmp_path / "demo.src").write_text("DEF demo()\n  INT i\n  i = 1\nEND\n")
    loaded = {m.split(".")[0] for m in _loaded_after(["check", str(tmp_path / "demo.src")], tmp_path)}
    assert not loaded & {"numpy", "scipy", "mujoco", "robot", "interp"}, sorted(loaded)


@pytest.mark.parametrize("command", [["graph", "--format", "text"], ["diff"]])
def test_graph_and_diff_do_not_load_the_simulator(tmp_path, command):
    """`krl graph` and `krl diff` read the backups and no run: none of the simulator's modules,
    nor numpy, scipy and MuJoCo, are imported (app/changes.py; `krl report`'s runs are
    app/report.py's). They did through `krl report` in the same module and the logbook's
    message table (interp/runtime/kssmessages.py importing every native): 4.8 -> 3.0 s of CPU
    for `krl graph` of the palletizer backup."""
    (tmp_path / "demo.src").write_text("DEF demo()\n  INT i\n  i = 1\nEND\n")
    args = command + [str(tmp_path / "demo.src")] * (2 if command == ["diff"] else 1)
    loaded = {m.split(".")[0] for m in _loaded_after(args, tmp_path)}
    assert not loaded & {"numpy", "scipy", "mujoco", "robot"}, sorted(loaded)
