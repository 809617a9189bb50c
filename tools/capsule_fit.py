"""The capsule radii of robot/capsules.py, measured on the public collision meshes of KUKA robots and
fitted (issue 64).

For each description with meshes (read in place under ../shared/robots/descriptions, loaded as
``krl run --robot`` loads it: robot/description.py puts each mesh in the model's link frame), at
A = 0: the capsule axes of the model (robot/mjcf.py: the base column from the foot to the A1 origin,
then each link from its joint origin to the next, the last to the flange), every vertex of each
mesh's convex hull given to the nearest axis, and per group (base; arm = A1..A3; wrist = A4..A6)
the 90th percentile of those vertices' distances to their axis. A group is measured only where the
vertices given to it come from meshes of its own links (the KR 6 R900 sixx publishes link_2 and
link_4 only: no base). Then ``r = C[group] * (reach / 1 m) ** P`` is fitted by least squares on the
logarithms, one P for all groups.

Usage::

    python tools/capsule_fit.py [DESCRIPTION.xacro ...]   (default: the three of ../shared with meshes)

Prints each robot's reach and group radii, the fit (P, C) and each radius the fit gives.
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

REPO = Path(__file__).resolve().parents[1]
DESCRIPTIONS = REPO.parent / "shared" / "robots" / "descriptions" / "kuka_experimental"
DEFAULT = ("kuka_kr3_support/urdf/kr3r540.xacro", "kuka_kr6_support/urdf/kr6r900sixx.xacro",
           "kuka_kr150_support/urdf/kr150r3100_2.xacro")
GROUPS = {"base": ("base_link",), "arm": ("link_1", "link_2", "link_3"), "wrist": ("link_4", "link_5", "link_6")}
PERCENTILE = 90.0


def _segment_distance(V: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    n = float(ab @ ab)
    if n < 1e-12:
        return np.linalg.norm(V - a, axis=1)
    u = np.clip((V - a) @ ab / n, 0.0, 1.0)
    return np.linalg.norm(V - (a + u[:, None] * ab), axis=1)


def measure(path: Path) -> tuple[float, dict[str, float]]:
    """(reach mm, {group: radius mm}) of the description at `path` (groups without their meshes left out)."""
    # importable once sys.path holds the checkout (main puts it there; the nightly test runs in it)
    from robot.mada import load_robot  # noqa: PLC0415

    m = load_robot(path)
    meshes = m.raw.get("meshes", {})
    frames, T = {"base_link": np.eye(4)}, np.eye(4)
    for j in m.joints:
        O = np.eye(4)
        O[:3, :3] = Rotation.from_euler("xyz", j.origin_rpy_rad).as_matrix()
        O[:3, 3] = j.origin_mm
        T = T @ O
        frames[j.child] = T
    names = ["base_link", *(j.child for j in m.joints)]
    axes = []
    for i, n in enumerate(names):
        a = frames[n][:3, 3]
        if i + 1 < len(names):
            b = frames[names[i + 1]][:3, 3]
        else:
            b = (frames[n] @ np.r_[np.asarray(m.flange_pos_mm, dtype=float), 1.0])[:3]
        axes.append((np.zeros(3) if i == 0 else a, b))
    verts, owner = [], []
    for n in names:
        if n in meshes:
            hull = trimesh.load(io.BytesIO(meshes[n]), file_type="stl").convex_hull
            V = np.asarray(hull.vertices) * 1000.0
            verts.append(V @ frames[n][:3, :3].T + frames[n][:3, 3])
            owner += [n] * len(V)
    V, owner = np.vstack(verts), np.array(owner)
    D = np.stack([_segment_distance(V, a, b) for a, b in axes], axis=1)
    nearest = D.argmin(axis=1)
    out = {}
    for g, links in GROUPS.items():
        ks = [names.index(n) for n in links]
        sel = np.isin(nearest, ks)
        if not any(n in meshes for n in links) or not set(owner[sel]) & set(links):
            continue
        out[g] = float(np.percentile(D[sel][:, ks].min(axis=1), PERCENTILE))
    return float(m.reach_wrist_point_mm), out


def fit(rows: list[tuple[float, dict[str, float]]]) -> tuple[float, dict[str, float]]:
    """(P, {group: C}) of ``r = C * (reach / 1 m) ** P`` by least squares on the logarithms."""
    groups = sorted({g for _, radii in rows for g in radii})
    A, y = [], []
    for reach, radii in rows:
        for g, r in radii.items():
            A.append([1.0 if g == h else 0.0 for h in groups] + [np.log(reach / 1000.0)])
            y.append(np.log(r))
    sol = np.linalg.lstsq(np.array(A), np.array(y), rcond=None)[0]
    return float(sol[-1]), {g: float(np.exp(c)) for g, c in zip(groups, sol[:-1])}


def main(argv: list[str]) -> int:
    paths = [Path(a) for a in argv] or [DESCRIPTIONS / p for p in DEFAULT]
    rows = []
    for p in paths:
        reach, radii = measure(p)
        rows.append((reach, radii))
        print(f"{p.name}: reach {reach:.0f} mm, " + ", ".join(f"{g} {r:.0f}" for g, r in radii.items()))
    P, C = fit(rows)
    print(f"fit: P {P:.4f}, C " + ", ".join(f"{g} {c:.2f}" for g, c in C.items()))
    for (reach, radii), p in zip(rows, paths):
        print(f"  {p.name}: " + ", ".join(f"{g} {r:.0f} -> {C[g] * (reach / 1000.0) ** P:.0f}" for g, r in radii.items()))
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(REPO))
    sys.exit(main(sys.argv[1:]))
