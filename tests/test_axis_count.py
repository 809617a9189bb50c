"""The axis count comes from the model (issue 62): no six-axis slice, loop, array or branch in the
packages outside the kinematic families and the compiled core. Each robot axis and external axis
reaches KRL's E6AXIS/E6POS through robot/axismap.py ``AxisMap`` (a seven-axis arm's redundancy as
E1); a count of Cartesian components is ``len(CART_KEYS)``, of A components ``len(ROBOT_KEYS)``,
and a count that is not about axes has a name (net/modbus.py ``MBAP_PREFIX``).

Run as a script, it prints every hit (``python tests/test_axis_count.py [ROOT]``).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: the packages (pyproject.toml's [tool.setuptools.packages.find])
PACKAGES = ("app", "krl", "recovery", "interp", "robot", "conformance", "net", "pendant", "audit")
#: where six axes are the subject itself: the kinematic families (robot/kinematics/: the arm's
#: six axes, the SCARA's four, the redundant arm's seven) and the compiled CP path of the six-axis
#: OPW core (robot/cartpath.py and its .pxd, robot/kinematics/compiled.py COMPILED_AXES), the
#: compiled VM loop's source and declarations, and ANTLR's generated parser
EXCLUDED = ("robot/kinematics/", "robot/cartpath.py", "robot/cartpath.pxd", "interp/vm/loop.py", "interp/vm/loop.pxd",
            "krl/syntax/generated/")
#: the six-axis shapes: (what, regular expression)
SHAPES = (
    ("slice", re.compile(r"\[:6\]|\[6:\]|\[:6,|\[0:6\]")),
    ("loop", re.compile(r"\brange\((?:0, ?)?6\)|\brange\(1, ?7\)")),
    ("array", re.compile(r"\b(?:zeros|ones|empty|full)\(6\b|\(6,\)|\[[^\[\]]*\] ?\* ?6\b")),
    ("branch", re.compile(r"(?<!:)(?:==|!=|<=|>=|<|>) ?6\b|(?<![\w.-])6 ?(?:==|!=|<=|>=|<(?!<)|>(?!>))")),
)


def hits(root: Path = REPO) -> list[str]:
    """``path:line: shape: text`` of every six-axis shape in the packages under `root`."""
    out = []
    for pkg in PACKAGES:
        for f in sorted((root / pkg).rglob("*")):
            if f.suffix not in (".py", ".pyx", ".pxd") or not f.is_file():
                continue
            rel = f.relative_to(root).as_posix()
            if rel.startswith(EXCLUDED):
                continue
            for n, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1):
                for what, rx in SHAPES:
                    if rx.search(line):
                        out.append(f"{rel}:{n}: {what}: {line.strip()}")
    return out


def test_the_shapes_find_what_they_name():
    """Each shape finds the forms the issue lists (the test can fail) and not a format width."""
    found = {what for what, rx in SHAPES for text in (
        "q = axes[:6]", "for i in range(6):", "for i in range(1, 7):", "a = np.zeros(6)",
        "v = [0.0] * 6", "if v.shape != (6,):", "if n == 6:", "if 1 <= idx <= 6:") if rx.search(text)}
    assert found == {"slice", "loop", "array", "branch"}
    assert not any(rx.search("f'{x:>6} {y:<6}'") for _, rx in SHAPES)
    assert not any(rx.search("x = 16; y = a[:60]; z = range(61)") for _, rx in SHAPES)


def test_no_six_axis_shape_outside_the_kinematic_families_and_the_compiled_core():
    found = hits()
    assert not found, "six-axis shapes (use robot/axismap.py or a named count):\n" + "\n".join(found)


if __name__ == "__main__":
    found = hits(Path(sys.argv[1]) if len(sys.argv) > 1 else REPO)
    print("\n".join(found))
    print(f"{len(found)} six-axis shapes")
