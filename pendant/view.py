"""The program view's data: the programs a workspace offers, a module's text, its taught points
(in $WORLD, mm/deg, for the 3D view) and the robot the page draws.

Files are read through krl/source.py (decoded in their own encoding, size-limited) and the data
lists through the front end (robot/datalist.py); nothing here runs KRL.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from krl.limits import MAX_WEB_FILE_BYTES
from robot.axismap import AxisMap, CART_KEYS, EXT_KEYS, ROBOT_KEYS
from interp.realprograms import programs_of
from krl.files import walk
from krl.source import read_source
from robot.datalist import DataListError, read_data_list
from robot.frames import frame_to_matrix
from krl.project import backup_of, system_folder
from robot.urdf import build_urdf
from robot.capsules import capsule_radii
from robot.mjcf import robot_meshes
import base64
from interp.run import cell_of, is_auto
from robot.controller import Controller
from krl.ast import nodes as N
from robot.stimuli import parse_start
from interp.scene import start_axes

POINT_KEYS = ("X", "Y", "Z")


def programs(root: Path) -> list[str]:
    """The runnable programs of the workspace (interp/realprograms.py ``programs_of``: a
    backup's entry points; else every .src with a main routine), relative to ``root``."""

    out = []
    for p in programs_of(root):
        try:
            out.append(str(Path(p).relative_to(root)))
        except ValueError:
            continue
    return out


def modules(root: Path) -> list[str]:
    """Every program file (.src) of the workspace, relative to ``root`` (the navigator's view:
    any of them can be selected)."""

    out = [e.rel for e in walk(root) if e.kind == "file" and e.rel.lower().endswith(".src")]
    return sorted(out, key=str.lower)[:5000]


def module_view(path: Path, root: Path) -> dict:
    """``{path, lines, points}``: the text of ``path`` (lines as str) and the taught points of
    its data list (the .dat beside it, any case)."""

    src = read_source(path, max_bytes=MAX_WEB_FILE_BYTES)
    text = getattr(src, "text", None) or ""
    dat = _data_list_of(path)
    return {"path": str(path), "label": str(path.relative_to(root)),
            "lines": text.splitlines(), "points": taught_points(dat, root) if dat is not None else [],
            "dat": str(dat) if dat is not None else None}


def _data_list_of(path: Path) -> Path | None:
    if path.suffix.lower() == ".dat":
        return path
    for p in path.parent.iterdir():
        if p.is_file() and p.stem.lower() == path.stem.lower() and p.suffix.lower() == ".dat":
            return p
    return None


def taught_points(dat: Path, root: Path) -> list[dict]:
    """The points of the data list ``dat`` (at most 5000), each ``{name, line, ext}`` and either
    ``frame`` (X..C mm/deg in its base), ``base`` (the base number its FDAT names) and ``world``
    (its position in $WORLD, mm: through ``BASE_DATA[n]`` of the backup's $config.dat; $WORLD when
    none), for an E6POS/POS/FRAME, or ``axes`` (A1..A6, deg) for an E6AXIS/AXIS. ``ext`` maps each
    external axis component the point holds (``E1``..``E6`` of an E6POS/E6AXIS, mm or deg) to its
    value: the page's list of points shows them (issue 64). A base measured on an external
    kinematic (``MACHINE_FRAME_DAT``) is placed as a fixed ``BASE_DATA[n]``: the point's world
    position at its E is not computed here."""

    try:
        values = read_data_list(dat)
    except DataListError:
        return []
    bases = _base_data(root)
    out = []
    for name, dv in values.items():
        v = dv.value
        if not isinstance(v, dict):
            continue
        if all(k in v and isinstance(v[k], (int, float)) for k in POINT_KEYS):
            frame = [float(v.get(k, 0.0) or 0.0) for k in ("X", "Y", "Z", "A", "B", "C")]
            fdat = values.get("F" + name[1:] if name.startswith("X") else "F" + name)
            base_no = 0
            if fdat is not None and isinstance(fdat.value, dict):
                b = fdat.value.get("BASE_NO")
                base_no = b if isinstance(b, int) and not isinstance(b, bool) else 0
            base = bases.get(base_no, (0.0,) * 6)
            T = frame_to_matrix(*base) @ frame_to_matrix(*frame)
            out.append({"name": dv.name, "line": dv.line, "frame": frame, "base": base_no,
                        "world": [round(float(x), 3) for x in np.asarray(T)[:3, 3]], "ext": _ext(v)})
        elif all(k in v for k in ROBOT_KEYS):
            out.append({"name": dv.name, "line": dv.line,
                        "axes": [float(v[k]) for k in ROBOT_KEYS], "ext": _ext(v)})
        if len(out) >= 5000:
            break
    return out


def _ext(v: dict) -> dict[str, float]:
    """The external axis components E1..E6 a point's value holds (numbers only)."""
    return {k: float(v[k]) for k in EXT_KEYS if isinstance(v.get(k), (int, float)) and not isinstance(v.get(k), bool)}


def _base_data(root: Path) -> dict[int, tuple]:
    """``BASE_DATA[n]`` of the workspace's $config.dat (n -> X..C), {} when there is none."""

    base = backup_of(root) or root
    folder = system_folder(base)
    if folder is None:
        return {}
    cfg = next((p for p in folder.iterdir() if p.name.lower() == "$config.dat"), None)
    if cfg is None:
        return {}
    try:
        dv = read_data_list(cfg).get("BASE_DATA")
    except DataListError:
        return {}
    out = {}
    if dv is not None and isinstance(dv.value, dict):
        for n, f in dv.value.items():
            if isinstance(f, dict):
                out[int(n)] = tuple(float(f.get(k, 0.0) or 0.0) for k in ("X", "Y", "Z", "A", "B", "C"))
    return out


def robot_view(machine, inputs: str | None = None) -> dict:
    """The robot the page draws: its URDF (``krl robot export``'s, robot/urdf.py: with external
    kinematics its root is ``$WORLD``, so ``robroot`` is then null), $ROBROOT (X..C mm/deg), the
    joint names (A1..An, then ``joint_e<n>`` of E1..Em), for each the index of its value in the
    position's axes (KRL's order, robot/axismap.py) and its unit (``deg`` or ``mm``), the jog keys'
    names (``A1``.., ``E1``..), the cell's bodies (:func:`cell_view`), ``capsules``: the radii (m)
    of the links' capsules the collision check uses (robot/capsules.py: ``base``, ``arm``,
    ``wrist``; the page draws the links with them), and ``start``: where it stands before a program
    is selected (:func:`start_position`)."""

    amap = AxisMap.of(machine)
    joints = [j.name for j in machine.joints] + [f"joint_e{e.number}" for e in machine.external_axes]
    robroot = [0.0] * len(CART_KEYS) if machine.external_kinematics else list(machine.robroot_frame)
    return {"name": machine.name, "urdf": build_urdf(machine), "robroot": robroot,
            "joints": joints, "axis_index": list(amap.krl_index), "units": [amap.unit(k) for k in amap.model_keys],
            "keys": list(amap.model_keys), "cell": cell_view(inputs), "meshes": _meshes(machine),
            "capsules": {g: r / 1000.0 for g, r in capsule_radii(machine.reach_wrist_point_mm).items()},
            "start": start_position(machine, inputs)}


def _meshes(machine) -> dict[str, str]:
    """The robot's link meshes (a description's, robot/description.py): link -> STL (metres, in
    the link's frame of the URDF the page draws) in base64; {} for a robot of machine data."""

    return {link: base64.b64encode(data).decode("ascii") for link, data in robot_meshes(machine).items()}


def cell_view(inputs: str | None) -> dict | None:
    """The cell file's geometry as the page draws it (robot/collision.py): ``bodies`` (name, shape
    box/cylinder/mesh, size mm, frame X..C in $WORLD, an STL's bytes in base64), ``tool`` (the
    same, its frame on the flange) and ``floor`` (its Z, or null); None without geometry."""
    if not inputs:
        return None

    if is_auto(inputs):
        return None
    try:
        geo = cell_of(inputs).geometry
    except Exception:  # noqa: BLE001 - a cell file the run refuses shows no cell (the run says why)
        return None
    if geo is None:
        return None

    def body(b) -> dict:
        out = {"name": b.name, "shape": b.shape, "size": list(b.size), "frame": list(b.frame)}
        if b.shape == "mesh":
            out["stl"] = base64.b64encode(b.mesh).decode("ascii")
        return out
    return {"bodies": [body(b) for b in geo.bodies], "tool": body(geo.tool) if geo.tool is not None else None,
            "floor": geo.floor}


def start_position(machine, inputs: str | None = None) -> dict | None:
    """The position panel's data before a program is selected: the axes a run starts at
    (interp/run.py ``make_runtime``: the cell file's ``start:`` when it gives the axes, else
    ``$AXIS_HOME[1]``, the machine data's home; a start named by a point of the program is known
    only once the program is selected) and ``$POS_ACT`` there with ``$TOOL`` and ``$BASE`` null,
    as before the program's BAS sets them: ``{axes, pos, base, tool}`` as pendant/state.py's
    ``position``. None when the robot cannot be placed (the page then shows no position)."""

    try:
        cell = cell_of(inputs) if inputs and not is_auto(inputs) else None
        ctl = Controller(machine, stimuli=cell, mujoco=False)
        where = cell.start if cell is not None else None
        if where is not None:

            if not isinstance(parse_start(where), N.Name):

                ctl.place(start_axes(ctl.model, lambda name: None, where))
        pos = ctl.actual.pos_act()
    except Exception:  # noqa: BLE001 - a robot the model cannot place shows no start position
        return None
    null = dict.fromkeys(("X", "Y", "Z", "A", "B", "C"), 0.0)
    return {"axes": [round(float(v), 4) for v in ctl.actual.axis_act()],
            "pos": {k: round(float(v), 3) for k, v in pos.items()}, "base": null, "tool": null}


__all__ = ["module_view", "programs", "robot_view", "taught_points"]
