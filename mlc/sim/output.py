"""Simulation outputs: GSD trajectories (HOOMD-blue's format) and probe time series.

Each body is one GSD particle at its centre with its orientation; bodies with the
same slabs share a particle type whose shape (``particles/type_shapes``, GSD shape
visualisation spec) is a triangulated ``Mesh`` of all the body's boxes in the body
frame, so OVITO draws the slabs.  Probe series go to CSV (time in t0, one column per
probe, in sigma) and NPZ (arrays ``time`` and one per probe).  All writes are atomic.
"""
from __future__ import annotations

import json

import numpy as np

from mlc.geometry.rotation import quat_to_matrix
from mlc.io.atomic import atomic_path, write_text
from mlc.scene.model import Scene

# the 12 triangles of a box with corners numbered by bits (x, y, z), counterclockwise
# seen from outside (outward normals, as the GSD shape spec asks)
_BOX_TRI = [(0, 3, 2), (0, 1, 3), (4, 7, 5), (4, 6, 7), (0, 5, 1), (0, 4, 5),
            (2, 7, 6), (2, 3, 7), (0, 6, 4), (0, 2, 6), (1, 7, 3), (1, 5, 7)]


def body_mesh(body) -> tuple[np.ndarray, list]:
    """Vertices (body frame) and triangle indices of a body's boxes."""
    verts, faces = [], []
    for box in body.boxes:
        R = quat_to_matrix(box.orientation)
        half = 0.5 * np.asarray(box.size, float)
        base = len(verts)
        for c in range(8):
            corner = np.array([half[0] * (1 if c & 4 else -1), half[1] * (1 if c & 2 else -1),
                               half[2] * (1 if c & 1 else -1)])
            verts.append(np.asarray(box.center, float) + R @ corner)
        faces += [[base + a, base + b, base + c] for a, b, c in _BOX_TRI]
    return np.array(verts), faces


def body_types(scene: Scene):
    """(type names, typeid per body, type_shapes): bodies with identical boxes share a type."""
    keys, names, shapes, typeid = {}, [], [], []
    for b in scene.bodies:
        v, f = body_mesh(b)
        key = np.round(v, 9).tobytes()
        if key not in keys:
            keys[key] = len(names)
            names.append(b.name)
            shapes.append({"type": "Mesh", "vertices": v.tolist(), "indices": f})
        typeid.append(keys[key])
    return names, np.array(typeid, dtype=np.uint32), shapes


def write_gsd(path, scene: Scene, times, pos, quat, extra_log: dict | None = None) -> None:
    """Write frames ``pos`` (F,N,3), ``quat`` (F,N,4) at ``times`` (t0) to a GSD file."""
    import gsd.hoomd

    names, typeid, shapes = body_types(scene)
    pos = np.asarray(pos, float)
    quat = np.asarray(quat, float)
    ext = max(float(np.max(np.abs(pos))) if pos.size else 1.0, 1.0)
    L = 4.0 * ext + 4.0
    with atomic_path(path, suffix=".gsd") as tmp:
        with gsd.hoomd.open(str(tmp), "w") as f:
            for k in range(len(pos)):
                fr = gsd.hoomd.Frame()
                fr.configuration.step = k
                fr.configuration.box = [L, L, L, 0, 0, 0]
                fr.particles.N = len(scene.bodies)
                fr.particles.types = names
                fr.particles.typeid = typeid
                fr.particles.position = pos[k].astype(np.float32)
                fr.particles.orientation = quat[k].astype(np.float32)
                if k == 0:
                    fr.particles.type_shapes = shapes
                fr.log["mlc/time_t0"] = np.array([times[k]], dtype=np.float64)
                for key, val in (extra_log or {}).items():
                    fr.log[key] = np.asarray(val)
                f.append(fr)


def write_probes_csv(path, times, probes: dict) -> None:
    names = list(probes)
    lines = ["time_t0," + ",".join(names)]
    for k, t in enumerate(times):
        lines.append(f"{t:.9g}," + ",".join(f"{probes[n][k]:.9g}" for n in names))
    write_text(path, "\n".join(lines) + "\n")


def write_probes_npz(path, times, probes: dict, meta: dict | None = None) -> None:
    with atomic_path(path, suffix=".npz") as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, time=np.asarray(times), **{k: np.asarray(v) for k, v in probes.items()},
                     meta=np.array(json.dumps(meta or {})))
