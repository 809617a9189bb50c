"""KUKA robots by model name: the catalogue of ``robot/data/catalogue.yaml`` (issue 64).

``--robot "KR 150 R3100-2"``, ``--robot KR150R3100_2`` (KUKA's ``$MODEL_NAME`` spelling, as a
backup's ``$robcor.dat`` holds it: ``#KR150R3100_2 C4 FLR``) and ``krl robot show`` resolve a model
here; ``krl robot list`` prints the catalogue with each value's source.

Each entry holds the values of a public robot description (kuka_experimental, kroshu's
kuka_robot_descriptions; the file's header cites them) in the terms of KUKA's machine data, and
:func:`arm_values` gives them to robot/mada.py (``load_robot``, ``catalogue_robot``), which builds the
model with ``machine_from_values`` exactly as a backup's ``$machine.dat`` is built: the kinematic family (robot/kinematics/families.py), the OPW
solution, the limits and the derived values follow from the same code. Provenance
(``MachineData.provenance``) names the description for every value the entry gives, and the rule
for every value derived.

**Machine data win.** A machine-data file of the project's robot library (robot/data/*.dat) whose
``$TRAFONAME`` names the same model is that model's robot (issue 60's KR 3 R540 data, for
instance): robot/mada.py ``catalogue_robot`` returns it, and ``krl robot list`` says so.

**Accelerations** are kroshu's joint-limits files' (``max_acceleration``: "calculated from the
worst-case ramp-up time to reach maximum velocity", its README) where one is published for the model,
else derived by robot/mada.py's rule (``RULES["max_acc_default"]``).

**Dynamic models** (issue 73 item 3): an entry's ``dynamics`` holds its description's link
inertials and joint efforts (robot/described_dynamics.py builds the model); an entry without says
why in ``no_dynamics`` where the rule of :func:`no_model_reason` does not; :func:`dynamics_line`
gives ``krl robot list`` each model's (identified, described, or none and why).

Units: mm and deg (deg/s, deg/s2). Errors: :class:`robot.madavalues.MachineDataError` for a name that is
no model of the catalogue (the message lists the close ones).
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import yaml

from .identified import identified_file
from .machine import library_robots
from .madavalues import MachineDataError
from krl.terminal import printable

CATALOGUE_FILE = Path(__file__).with_name("data") / "catalogue.yaml"

#: the public descriptions the entries cite: repo id -> (repository, licence)
REPOSITORIES = {
    "kuka_experimental": ("ros-industrial/kuka_experimental", "Apache-2.0 (support packages: BSD or Apache)"),
    "kroshu": ("kroshu/kuka_robot_descriptions", "Apache-2.0"),
}

#: the values KUKA's standard arm fixes (robot-model.md §4.3): every catalogue model is one
_STANDARD_ARM = "KUKA's standard arm (robot-model.md section 4.3): $TX3P3.B 90, $DH_4 alpha 90, $DH_5 alpha -90"
_AXIS_DIR = "KUKA's axis directions of the articulated arm (robot-model.md section 3, every corpus backup)"
#: path limits: every KR C4 backup of the corpus and ../shared/robots holds these
_PATH_LIMITS = "derived: the KR C4 path limits every backup of the corpus holds ($VEL_MA CP 3 m/s, ORI 400 deg/s; $ACC_MA CP 10 m/s2, ORI 1000 deg/s2)"


@dataclass(frozen=True)
class Model:
    """One model of the catalogue.

    Attributes:
        key: KUKA's ``$MODEL_NAME`` spelling (``KR150R3100_2``).
        name: the data sheet's name (``KR 150 R3100-2``).
        series: the product family (``KR QUANTEC``).
        source: where the values come from: ``repo path@commit``.
        also: other descriptions of the same model that agree (cited).
        geometry_mm: ``$TIRORO.Z``, ``$LENGTH_A``, ``$LENGTH_B``, ``$TX3P3.X``, ``$TX3P3.Z``,
            ``$TFLWP.Z`` (mm).
        limits_deg: ``($SOFTN_END, $SOFTP_END)`` of A1..A6.
        speeds_deg_s: axis speeds of A1..A6.
        note: what the entry says about its source.
        accelerations_deg_s2: the published axis accelerations of A1..A6 (kroshu's joint-limits
            file, rad/s2 there), or None where no file publishes them (robot/mada.py derives them).
        acc_source: where the accelerations come from: ``repo path@commit`` ("" without).
        dynamics: the description's link inertials, joint origins and efforts as it gives them
            (robot/described_dynamics.py turns them into the dynamic model), or None where no
            description publishes them.
        dyn_source: the description they come from: ``repo path@commit`` ("" without).
        no_dynamics: why a model without ``dynamics`` has none, where the entry says more than
            :func:`no_model_reason`'s rule (partial meshes, contradicting
            files); "" otherwise.
    """

    key: str
    name: str
    series: str
    source: str
    also: tuple[str, ...]
    geometry_mm: dict[str, float]
    limits_deg: tuple[tuple[float, float], ...]
    speeds_deg_s: tuple[float, ...]
    note: str = ""
    accelerations_deg_s2: tuple[float, ...] | None = None
    acc_source: str = ""
    dynamics: dict[str, Any] | None = None
    dyn_source: str = ""
    no_dynamics: str = ""


def _cite(src: dict[str, Any]) -> str:
    repo = REPOSITORIES.get(str(src.get("repo")), (str(src.get("repo")), ""))[0]
    return f"{repo} {src.get('path')}@{str(src.get('commit', ''))[:8]}"


@cache
def models() -> dict[str, Model]:
    """The catalogue: $MODEL_NAME spelling -> :class:`Model`, in the file's order."""
    doc = yaml.load(CATALOGUE_FILE.read_text(encoding="utf-8"), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    out = {}
    for key, m in doc["models"].items():
        out[key] = Model(key=key, name=str(m["name"]), series=str(m.get("series", "")),
                         source=_cite(m["source"]), also=tuple(_cite(a) for a in m.get("also", ())),
                         geometry_mm={k: float(v) for k, v in m["geometry_mm"].items()},
                         limits_deg=tuple((float(a), float(b)) for a, b in m["limits_deg"]),
                         speeds_deg_s=tuple(float(v) for v in m["speeds_deg_s"]), note=str(m.get("note", "")),
                         accelerations_deg_s2=(tuple(math.degrees(float(a)) for a in m["accelerations_rad_s2"])
                                               if "accelerations_rad_s2" in m else None),
                         acc_source=_cite(m["acc_source"]) if "acc_source" in m else "",
                         dynamics=m.get("dynamics"),
                         dyn_source=_cite(m["dynamics"]["source"]) if "dynamics" in m else "",
                         no_dynamics=str(m.get("no_dynamics", "")))
    return out


def model_key(text: str) -> str:
    """The ``$MODEL_NAME`` spelling of a model name: ``"KR 150 R3100-2"``, ``"KR150R3100_2"``,
    ``"#KR150R3100_2 C4 FLR"`` (a ``$MODEL_NAME``/``$TRAFONAME`` value: its first word) and
    ``"kr150_r3100_2"`` all give ``KR150R3100_2``."""
    t = str(text).strip().lstrip("#").upper()
    if re.match(r"^KR\d", t) and " " in t:          # $TRAFONAME/$MODEL_NAME: the model, then the controller
        t = t.split()[0]
    t = re.sub(r"\s+", "", t).replace("-", "_")
    return re.sub(r"(?<=\d)_(?=R\d)", "", t)        # kroshu's file names: kr150_r3100_2


def find(text: str) -> Model | None:
    """The model named `text` (any spelling :func:`model_key` reads), or None."""
    return models().get(model_key(text))


def lookup(text: str) -> Model:
    """:func:`find`, raising MachineDataError (with the close names) for an unknown model."""
    found = find(text)
    if found is None:
        close = difflib.get_close_matches(model_key(text), list(models()), n=3, cutoff=0.6)
        hint = f"; did you mean {', '.join(models()[k].name for k in close)}?" if close else \
            "; `krl robot list` shows the catalogue"
        raise MachineDataError(f"{text}: no KUKA model of that name in the catalogue{hint}")
    return found


def library_machine_data(model: Model) -> Path | None:
    """A machine-data file of the project's robot library (robot/data/*.dat) whose ``$TRAFONAME``
    names `model` (machine data win over a description), or None."""
    return library_file(model.key)


def library_file(key: str) -> Path | None:
    """A machine-data file of the project's robot library (robot/data/*.dat) whose ``$TRAFONAME``
    names the model of ``$MODEL_NAME`` spelling `key` (:func:`model_key`), or None."""
    for path in library_robots().values():
        if path.suffix.lower() != ".dat":
            continue
        head = path.read_text(encoding="latin-1", errors="replace")
        m = re.search(r'^\s*\$TRAFONAME\[\]\s*=\s*"([^"]*)"', head, re.M | re.I)
        if m and model_key(m.group(1)) == key:
            return path
    return None


def arm_values(trafo: str, g: dict[str, float], limits, speeds, source: str, trafo_source: str) -> dict[str, tuple[Any, str]]:
    """The machine-data values of KUKA's standard arm with the geometry `g` (mm: the keys of
    :attr:`Model.geometry_mm`), axis `limits` and `speeds` (deg, deg/s) from the description
    `source`, each with its source: variable -> (value, source). robot/mada.py ``build_cited``
    builds the model from them (this catalogue's entries, a URDF given to ``--robot``:
    robot/description.py)."""
    src = f"{source} (joint origins at A = 0)"
    lim = f"{source} (joint limits)"
    vel = f"{source} (joint velocities)"
    axes = range(1, len(limits) + 1)
    return {
        "$TRAFONAME": (trafo, trafo_source),
        "$KINCLASS": ("#STANDARD", _STANDARD_ARM),
        "$NUM_AX": (6, _STANDARD_ARM),
        "$TIRORO": (dict(X=0.0, Y=0.0, Z=g["TIRORO_Z"], A=0.0, B=0.0, C=0.0), src),
        "$LENGTH_A": (g["LENGTH_A"], src),
        "$LENGTH_B": (g["LENGTH_B"], src),
        "$TX3P3": (dict(X=g["TX3P3_X"], Y=0.0, Z=g["TX3P3_Z"], A=0.0, B=90.0, C=0.0), src),
        "$DH_4": (dict(DHART_A=0.0, DHART_D=0.0, DHART_ALPHA=90.0), _STANDARD_ARM),
        "$DH_5": (dict(DHART_A=0.0, DHART_D=0.0, DHART_ALPHA=-90.0), _STANDARD_ARM),
        "$TFLWP": (dict(X=0.0, Y=0.0, Z=g["TFLWP_Z"], A=0.0, B=0.0, C=0.0), src),
        "$AXIS_DIR": (dict(zip(axes, (-1, 1, 1, -1, -1, -1))), _AXIS_DIR),
        "$SOFTN_END": ({i: lo for i, (lo, _) in zip(axes, limits)}, lim),
        "$SOFTP_END": ({i: hi for i, (_, hi) in zip(axes, limits)}, lim),
        # the speeds as machine data carry them (rpm / |N/D| * 6 deg/s), N/D = 6: rpm = deg/s
        "$VEL_AXIS_MA": (dict(zip(axes, speeds)), vel),
        "$RAT_MOT_AX": ({i: {"N": 6, "D": 1} for i in axes}, vel),
        "$VEL_MA": ({"CP": 3.0, "ORI1": 400.0, "ORI2": 400.0}, _PATH_LIMITS),
        "$ACC_MA": ({"CP": 10.0, "ORI1": 1000.0, "ORI2": 1000.0}, _PATH_LIMITS),
    }


def catalogue_lines() -> list[str]:
    """The lines of ``krl robot list``: each model, its series, reach, axis limits and speeds,
    and the source of every value (the description; machine data of the library where they win)."""

    out = [f"{len(models())} KUKA robots (robot/data/catalogue.yaml); --robot takes the name or the $MODEL_NAME "
           f"spelling", ""]
    for m in models().values():
        g = m.geometry_mm
        reach = g["LENGTH_A"] + g["LENGTH_B"] + (g["TX3P3_X"] ** 2 + g["TX3P3_Z"] ** 2) ** 0.5
        lib = library_machine_data(m)
        out.append(f"{m.name:<20} {m.key:<16} {m.series}")
        out.append(f"    reach {reach:.0f} mm to the wrist point; $TIRORO.Z {g['TIRORO_Z']:g}, $LENGTH_A "
                   f"{g['LENGTH_A']:g}, $LENGTH_B {g['LENGTH_B']:g}, $TX3P3 X {g['TX3P3_X']:g} Z {g['TX3P3_Z']:g}, "
                   f"$TFLWP.Z {g['TFLWP_Z']:g} mm")
        out.append("    limits " + ", ".join(f"A{i + 1} {lo:g}..{hi:g}" for i, (lo, hi) in enumerate(m.limits_deg))
                   + " deg")
        out.append("    speeds " + ", ".join(f"{v:g}" for v in m.speeds_deg_s) + " deg/s")
        if m.accelerations_deg_s2 is not None:
            out.append("    accel  " + ", ".join(f"{a:.1f}" for a in m.accelerations_deg_s2)
                       + f" deg/s2 (worst-case ramp-up), source {printable(m.acc_source)}")
        else:
            out.append("    accel  derived: v / 0.2 s (no joint-limits file publishes them)")
        out.append(f"    source {printable(m.source)} (geometry, limits, speeds)"
                   + "".join(f"; agrees with {printable(a)}" for a in m.also))
        if m.note:
            out.append(f"    note   {printable(m.note)}")
        out.append(f"    dynamics {printable(dynamics_line(m, lib))}")
        if lib is not None:
            out.append(f"    machine data win: robot/data/{lib.name} ($TRAFONAME names this model)")
    return out


def dynamics_line(m: Model, lib: Path | None) -> str:
    """Where model `m`'s dynamic model comes from (issue 73 item 3; ``krl robot list``): identified
    from real recordings (the identified parameters of its library machine data `lib`,
    robot/identified.py), its description's published inertials, or none and why
    (:func:`no_model_reason`). ``krl robot show`` prints each value."""
    if lib is not None and identified_file(lib) is not None:
        return (f"identified from real recordings: robot/data/identified/{lib.stem}.yaml (links from the "
                f"description's collision meshes, masses and torques from the recorded gear torques)")
    if m.dynamics is not None:
        return f"described: {m.dyn_source} (link inertials, joint efforts)"
    return no_model_reason(m)


def no_model_reason(m: Model) -> str:
    """Why catalogue model `m` has no dynamic model (``krl robot show``, ``krl robot list``): its
    entry's ``no_dynamics`` where it says more, else what its description holds: kuka_experimental's
    xacros no ``<inertial>`` (or placeholders of 2 kg and 0.01 kg m2 per link), kroshu's files at the
    commit read none for this model."""
    why = m.no_dynamics or ("no description in reach publishes link inertials for it (kuka_experimental's xacros: "
                            "none or placeholders of 2 kg, 0.01 kg m2 per link; kroshu's files at the commits "
                            "read: none) and no complete set of its link meshes is in reach")
    return f"none: {why}; PTPs are planned with the axis accelerations alone"


__all__ = ["CATALOGUE_FILE", "Model", "arm_values", "catalogue_lines", "dynamics_line", "find", "library_machine_data",
           "lookup", "model_key", "models", "no_model_reason"]
