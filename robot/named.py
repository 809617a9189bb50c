"""The robot a KRC backup without machine data names in its ``$config.dat`` (issue 72).

A KR C4 backup exported without ``R1/Mada`` still names its robot where WorkVisual writes the
cell's machines: ``MACHINE_DEF[1]={NAME[] "KR 10 R1440-2",...}`` (KUKA's ``MACHINE_DEF_T``;
krl.workspace ``config_robot`` reads it, the one rule of ``krl report``'s cover too).
:func:`named_robot` gives that name, where it is written and the catalogue's model of it
(robot/catalogue.py: the public descriptions of ../shared/robots) and the project's robot
library's machine data of it (robot/data/*.dat whose ``$TRAFONAME`` names it: they win), or
neither; robot/mada.py ``named_machine`` makes the robot driven: the named model, else the
stand-in, saying which.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from krl.parsecache import load_file
from krl.project import config_file
from krl.workspace import config_robot

from . import catalogue


@dataclass(frozen=True)
class Named:
    """The robot a backup names: ``name`` as written (``KR 10 R1440-2``), ``where`` it is written
    (``.../R1/System/$config.dat:415 MACHINE_DEF[1]``), ``model``, the catalogue's model of that
    name, and ``library``, the robot library's machine data of it (each None when absent)."""

    name: str
    where: str
    model: catalogue.Model | None
    library: Path | None = None

    @property
    def known(self) -> bool:
        """True when the catalogue or the robot library has the named robot."""
        return self.model is not None or self.library is not None

    def note(self, driven: str) -> str:
        """What the run, ``krl robot show`` and the report say of it, given the name of the robot
        `driven`: the named model itself, or the stand-in in its place."""
        head = f"{self.name}, the robot the backup names ({self.where})"
        if self.known:
            return head
        return (f"{head}, is neither in the catalogue (krl robot list) nor in the robot library: "
                f"the {driven} stands in")


    def cover(self, driven: str) -> str:
        """What ``krl report``'s cover says after the robot's name, given the robot(s) the runs
        drive in its place (`driven`)."""
        head = "named by $config.dat MACHINE_DEF[1]"
        if self.known:
            return head
        return f"{head}; neither in the catalogue nor in the robot library: the runs drive the {driven} in its place"

    @classmethod
    def of(cls, name: str, where: str) -> "Named":
        """The robot named `name` (written at `where`), with the catalogue's and the robot
        library's model of it."""
        return cls(name, where, catalogue.find(name), catalogue.library_file(catalogue.model_key(name)))


def named_robot(root: str | Path) -> Named | None:
    """The robot the ``$config.dat`` of the backup or program folder rooted at `root`
    (krl.project ``config_file``: its System folder's, else one lying flat at its top) names in
    ``MACHINE_DEF[1]`` (krl.workspace ``config_robot``: a KUKA model's name), or None (no
    ``$config.dat``, no model named there). Never raises for bad input: a file that does not
    parse names nothing."""
    cfg = config_file(Path(root))       # System/$config.dat, or one lying flat at the top (issue 85)
    if cfg is None:
        return None
    try:
        st = os.stat(cfg, follow_symlinks=False)
    except OSError:
        return None
    key = (str(cfg), st.st_size, st.st_mtime_ns)
    if key not in _NAMED:
        found = config_robot([load_file(cfg)])
        if len(_NAMED) >= _NAMED_SIZE:
            _NAMED.clear()
        _NAMED[key] = None if found is None else Named.of(found[0], f"{found[1]}:{found[2]} MACHINE_DEF[1]")
    return _NAMED[key]


#: ($config.dat path, size, modification time) -> what it names: each run of a backup's program
#: asks (interp/run.py ``robot_for``), and reading the file is 10-40 ms; this process's answers
_NAMED: dict[tuple, Named | None] = {}
_NAMED_SIZE = 256


__all__ = ["Named", "named_robot"]
