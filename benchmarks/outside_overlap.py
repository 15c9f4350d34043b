"""Slab interpenetration of a posed scene by manifold3d's boolean intersection, independent
of mlc.verify.overlap (the oriented-box separating-axis test mlc reports).

Every box of every body becomes a manifold3d cube moved to its world pose; two boxes of
different bodies whose bounding spheres meet are intersected exactly (``A ^ B``), and the
intersection is kept unless all of it lies within ``near`` sigma of a joint the two bodies
share (the line through a hinge's sites, the point of a universal joint; a joint's bonds,
and joints sharing a site, merged): hinge contact, which mlc's test leaves out too.

Used by ``tests/test_verify_overlap.py`` (library gates) and ``benchmarks/robot_overlaps.py
--outside`` (a robot's rows), so that a clearance claim is confirmed by something other than
the code that makes it.  Units: sigma, sigma^3.
"""
from __future__ import annotations

import itertools

import numpy as np


def boolean_contacts(scene, pos, quat, near: float = 0.06, contact: list | None = None) -> list:
    """The pairs ``(body, body, volume, far)`` of different bodies of ``scene`` (at body
    positions ``pos`` (n, 3) and unit quaternions ``quat`` (n, 4), w first) whose boxes
    intersect with some of the intersection farther than ``near`` from every joint the two
    share (``far``: the farthest intersection vertex from the nearest shared joint; inf when
    they share none).  ``contact``: a one-element list raised to the farthest vertex of an
    intersection accepted as hinge contact."""
    import manifold3d as mf
    from scipy.spatial import cKDTree

    from mlc.geometry.rotation import quat_to_matrix

    names = [b.name for b in scene.bodies]
    index = {n: i for i, n in enumerate(names)}
    pos = np.asarray(pos, float)
    Rb = [quat_to_matrix(q) for q in np.asarray(quat, float)]

    def world(ref):
        b, site = ref.split(".", 1)
        i = index[b]
        return pos[i] + Rb[i] @ np.asarray(scene.bodies[i].sites[site], float)

    owner, centre, radius, solids = [], [], [], []
    for i, body in enumerate(scene.bodies):
        for bx in body.boxes:
            T = np.zeros((3, 4))
            T[:, :3] = Rb[i] @ quat_to_matrix(np.asarray(bx.orientation, float))
            T[:, 3] = pos[i] + Rb[i] @ np.asarray(bx.center, float)
            size = np.asarray(bx.size, float)
            owner.append(i)
            centre.append(T[:, 3].copy())
            radius.append(0.5 * float(np.linalg.norm(size)))
            solids.append((size, T))
    if not owner:
        return []
    centre, radius = np.array(centre), np.array(radius)

    parent: dict = {}

    def find(x):
        while parent.setdefault(x, x) != x:
            x = parent[x]
        return x

    joint_bonds = [bd for bd in scene.bonds if bd.kind in ("hinge", "universal") or bd.rest == 0.0]
    for bd in joint_bonds:                       # a joint's bonds (a hinge: two) and shared sites merge
        for r in (bd.a, bd.b):
            ra, rb = find(r), find(("joint", bd.joint or bd.name))
            if ra != rb:
                parent[ra] = rb
    groups: dict = {}
    for bd in joint_bonds:
        groups.setdefault(find(bd.a), set()).update((bd.a, bd.b))
    shared: dict = {}
    for refs in groups.values():
        pts = np.array([world(r) for r in sorted(refs)])
        for a, b in itertools.combinations(sorted({index[r.split(".")[0]] for r in refs}), 2):
            shared.setdefault((a, b), []).append(pts)

    cubes: dict = {}

    def cube(k):
        if k not in cubes:
            size, T = solids[k]
            cubes[k] = mf.Manifold.cube(list(size), True).transform(T.tolist())
        return cubes[k]

    bad = []
    contact = [0.0] if contact is None else contact
    for k, m in sorted(cKDTree(centre).query_pairs(2.0 * float(radius.max()))):
        i, j = owner[k], owner[m]
        if i == j or np.linalg.norm(centre[k] - centre[m]) > radius[k] + radius[m]:
            continue
        X = cube(k) ^ cube(m)
        if X.volume() <= 1e-12:
            continue
        V = np.asarray(X.to_mesh().vert_properties)[:, :3]
        far = np.inf
        for pts in shared.get((min(i, j), max(i, j)), []):
            D = np.linalg.norm(pts[:, None] - pts[None], axis=2)
            a, b = np.unravel_index(np.argmax(D), D.shape)
            if D[a, b] > 1e-9:
                u = (pts[b] - pts[a]) / D[a, b]
                w = V - pts[a]
                d = np.linalg.norm(w - np.outer(w @ u, u), axis=1)
            else:
                d = np.linalg.norm(V - pts[0], axis=1)
            far = min(far, float(d.max()))
        if not far <= near:
            bad.append((names[i], names[j], float(X.volume()), far))
        else:
            contact[0] = max(contact[0], far)
    return bad
