"""Small scenes for the mesh tests, benchmarks and docs (sigma units).

* :func:`hinge_pair` -- two slabs on one hinge (axis along z at the origin).
* :func:`three_on_axis` -- three slabs on one axis (two pairwise hinge joints, like point c).
* :func:`ujoint_pair` -- two slabs joined by a universal joint at the origin, each also
  hinged to a ground slab so that its hinge direction is known.
* :func:`hinge_poses` -- poses of :func:`hinge_pair` with the second slab turned by angles.
"""
from __future__ import annotations

import numpy as np

from mlc.geometry.rotation import expmap, matrix_to_quat, quat_to_matrix
from mlc.scene.model import Body, Bond, Box, Muscle, Scene

W = 0.5      # slab width (along hinge axes)
T = 0.01     # slab thickness


def _slab(name, angle, length=1.0, origin=(0.0, 0.0, 0.0)):
    """A slab hinged (axis z) at ``origin``, pointing at ``angle`` (radians) from +x."""
    Rm = expmap(np.array([0, 0, 1.0]) * angle)
    q = matrix_to_quat(Rm)
    pos = np.asarray(origin, float) + Rm @ np.array([length / 2, 0, 0])
    sites = {"h0": np.array([-length / 2, 0, -W / 2]), "h1": np.array([-length / 2, 0, W / 2]),
             "tip": np.array([length / 2, 0, 0.0])}
    return Body(name, pos, q, [Box(np.array([length, T, W]))], sites)


def hinge_pair(angle: float = 2.0) -> Scene:
    a = _slab("A", np.pi)
    b = _slab("B", np.pi + angle)
    bonds = [Bond("h_0", "A.h0", "B.h0", kind="hinge", joint="h"),
             Bond("h_1", "A.h1", "B.h1", kind="hinge", joint="h")]
    muscles = [Muscle("m", "x", "A.tip", "B.tip", rest=1.0, actuated=1.5)]
    return Scene("hinge_pair", [a, b], bonds, muscles, [], ["x"], []).check()


def three_on_axis() -> Scene:
    bodies = [_slab("A", np.pi), _slab("B", np.pi + 2.0), _slab("C", np.pi - 2.0)]
    bonds = [Bond("ab_0", "A.h0", "B.h0", kind="hinge", joint="ab"),
             Bond("ab_1", "A.h1", "B.h1", kind="hinge", joint="ab"),
             Bond("ac_0", "A.h0", "C.h0", kind="hinge", joint="ac"),
             Bond("ac_1", "A.h1", "C.h1", kind="hinge", joint="ac")]
    return Scene("three_on_axis", bodies, bonds).check()


def ujoint_pair() -> Scene:
    """Slab C in the xy plane (hinge axes along z) meets slab O, which moves in the yz
    plane (hinge axes along x), at a universal joint at the origin (like point d)."""
    # C: from the origin along -y, width along z
    C = Body("C", np.array([0.0, -0.5, 0.0]), matrix_to_quat(expmap([0, 0, -np.pi / 2])),
             [Box(np.array([1.0, T, W]))],
             {"d": np.array([-0.5, 0, 0.0]), "g0": np.array([0.5, 0, -W / 2]), "g1": np.array([0.5, 0, W / 2])})
    # O: from the origin along +z tilted towards -y, width along x
    th = 0.35
    Rm = np.column_stack([[0, -np.sin(th), np.cos(th)], [0, np.cos(th), np.sin(th)], [-1.0, 0, 0]])
    if np.linalg.det(Rm) < 0:
        Rm[:, 1] *= -1
    O = Body("O", Rm @ np.array([0.5, 0, 0]), matrix_to_quat(Rm), [Box(np.array([1.0, T, W]))],
             {"d": np.array([-0.5, 0, 0.0]), "p0": np.array([0.5, 0, -W / 2]), "p1": np.array([0.5, 0, W / 2])})
    bonds = [Bond("u", "C.d", "O.d", kind="universal", joint="u")]
    return Scene("ujoint_pair", [C, O], bonds).check()


def hinge_poses(scene: Scene, angles: dict) -> dict:
    """Poses of :func:`hinge_pair` with body B turned about the hinge axis by ``angles[state]``."""
    out = {}
    pos = np.array([b.position for b in scene.bodies], float)
    quat = np.array([b.orientation for b in scene.bodies], float)
    for st, ang in angles.items():
        R = expmap(np.array([0, 0, 1.0]) * ang)
        p = pos.copy()
        q = quat.copy()
        p[1] = R @ pos[1]
        q[1] = matrix_to_quat(R @ quat_to_matrix(quat[1]))
        out[st] = (p, q)
    return out


def grid(scene: Scene, nx: int, ny: int, pitch) -> Scene:
    """``nx * ny`` copies of ``scene`` on a grid (names suffixed ``_i``): a benchmark assembly."""
    import copy
    bodies, bonds, muscles, probes, inputs, outputs = [], [], [], [], [], []
    k = 0
    for i in range(nx):
        for j in range(ny):
            off = np.array([i * pitch[0], j * pitch[1], 0.0])
            sfx = f"_{k}"
            for b in scene.bodies:
                bodies.append(Body(b.name + sfx, b.position + off, b.orientation.copy(), b.boxes,
                                   dict(b.sites)))
            ren = lambda ref: ref.split(".")[0] + sfx + "." + ref.split(".")[1]  # noqa: E731
            for x in scene.bonds:
                y = copy.copy(x)
                y.name, y.a, y.b = x.name + sfx, ren(x.a), ren(x.b)
                y.joint = (x.joint + sfx) if x.joint else None
                bonds.append(y)
            for x in scene.muscles:
                y = copy.copy(x)
                y.name, y.a, y.b, y.input = x.name + sfx, ren(x.a), ren(x.b), x.input + sfx
                muscles.append(y)
            for x in scene.probes:
                y = copy.copy(x)
                y.name, y.a, y.b, y.output = x.name + sfx, ren(x.a), ren(x.b), x.output + sfx
                probes.append(y)
            inputs += [n + sfx for n in scene.inputs]
            outputs += [n + sfx for n in scene.outputs]
            k += 1
    return Scene(f"{scene.name}_x{k}", bodies, bonds, muscles, probes, inputs, outputs).check()


__all__ = ["hinge_pair", "three_on_axis", "ujoint_pair", "hinge_poses", "grid", "gate_poses"]


_POSES: dict = {}


def gate_poses(name: str, signal: str = "expand") -> dict:
    """Equilibrium poses of every input state of a library gate (cached per process)."""
    key = (name, signal)
    if key not in _POSES:
        from mlc.gates.library import gate_scene
        from mlc.mesh.pipeline import state_poses
        _POSES[key] = state_poses(gate_scene(name, signal))[0]
    return _POSES[key]
