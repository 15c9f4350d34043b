"""Reuse across congruent parts: one exact test per shape pair and relative pose.

A compiled circuit is mostly connector half units: thousands of slabs of one design, each in
its own place and orientation.  The exact tests of the mesher (manifold3d intersection volume,
``min_gap``) and the final trims depend only on the two parts' shapes *in their own frames* and
on their relative pose, so a result found for one pair holds for every congruent pair in the
same relative pose.  :class:`Congruence` keys

* a part's shape by its mesh in its own frame (:func:`mlc.mesh.spatial.part_frames`): the
  vertices, expressed in that frame and rounded to :data:`SHAPE_Q` mm, sorted (so the order in
  which manifold3d lists them does not matter), with the triangle count and the volume;
* a relative pose by the 3x4 matrix taking one frame into the other, rotation rounded to
  :data:`ROT_Q` and translation to :data:`POS_Q` mm.

A cached result is reused only for an equal key: parts equal to within 1e-4 mm, poses equal to
within about 1e-6 mm over a part -- far below the tolerances of the tests themselves
(``VOL_EPS = 1e-6 mm^3``, the clearance).  Rounding can only split one class in two (a miss,
computed again), never merge shapes that differ by more than the rounding.
"""
from __future__ import annotations

import hashlib

import numpy as np

SHAPE_Q = 1e-4    # mm: vertex rounding of a shape key
ROT_Q = 1e-7      # rotation matrix entries
POS_Q = 1e-6      # mm: translation


def shape_key(solid, F) -> bytes:
    """Key of ``solid``'s shape in the frame ``F`` (4x4, mm): equal for congruent solids posed
    the same way in their frames."""
    m = solid.to_mesh()
    V = np.asarray(m.vert_properties, float)[:, :3]
    if len(V) == 0:
        return b"empty"
    L = (V - F[:3, 3]) @ F[:3, :3]
    q = np.round(L / SHAPE_Q).astype(np.int64)
    q = q[np.lexsort(q.T[::-1])]
    h = hashlib.blake2b(q.tobytes(), digest_size=16)
    h.update(np.int64(len(m.tri_verts)).tobytes())
    h.update(np.int64(round(float(solid.volume()) / SHAPE_Q)).tobytes())
    return h.digest()


def pose_key(M) -> bytes:
    """Key of a rigid 4x4 transform (rotation and translation rounded)."""
    M = np.asarray(M, float)
    r = np.round(M[:3, :3] / ROT_Q).astype(np.int64)
    t = np.round(M[:3, 3] / POS_Q).astype(np.int64)
    return r.tobytes() + t.tobytes()


def points_key(P, F, q: float = 1e-5) -> bytes:
    """Key of a point set (rows of ``P``, mm) in the frame ``F``, in the given order."""
    P = np.asarray(P, float).reshape(-1, 3)
    L = (P - F[:3, 3]) @ F[:3, :3]
    return hashlib.blake2b(np.round(L / q).astype(np.int64).tobytes(), digest_size=16).digest()


class Congruence:
    """Shape keys of an assembly's parts (by current solid) and caches of exact results."""

    def __init__(self, frames):
        self.frames = [np.asarray(F, float) for F in frames]
        self._keys: dict[int, tuple] = {}      # part index -> (solid, key)
        self.results: dict = {}                 # (what, keys..., pose keys) -> result
        self.hits = 0
        self.misses = 0

    def key(self, i: int, solid) -> bytes:
        got = self._keys.get(i)
        if got is not None and got[0] is solid:
            return got[1]
        k = shape_key(solid, self.frames[i])
        self._keys[i] = (solid, k)
        return k

    def rel(self, i: int, j: int, Ti=None, Tj=None) -> bytes:
        """Pose key of part j's frame seen from part i's frame, with the parts moved by the 4x4
        ``Ti`` and ``Tj`` (None: at rest)."""
        Wi = self.frames[i] if Ti is None else np.asarray(Ti) @ self.frames[i]
        Wj = self.frames[j] if Tj is None else np.asarray(Tj) @ self.frames[j]
        return pose_key(np.linalg.solve(Wi, Wj))

    def rel_many(self, pairs, Ts) -> list:
        """:meth:`rel` of every pair ``(i, j)`` of ``pairs`` with the parts moved by ``Ts`` (one 4x4
        per part), the matrices solved at once (a compiled circuit's states check asks for 150 000)."""
        if not len(pairs):
            return []
        P = np.asarray(pairs, int)
        idx = np.unique(P)
        W = np.asarray(Ts, float)[idx] @ np.asarray([self.frames[k] for k in idx])
        at = {int(k): n for n, k in enumerate(idx)}
        A = W[[at[int(k)] for k in P[:, 0]]]
        B = W[[at[int(k)] for k in P[:, 1]]]
        M = np.linalg.solve(A, B)
        r = np.round(M[:, :3, :3] / ROT_Q).astype(np.int64)
        t = np.round(M[:, :3, 3] / POS_Q).astype(np.int64)
        return [r[k].tobytes() + t[k].tobytes() for k in range(len(P))]

    def lookup(self, key, compute):
        if key in self.results:
            self.hits += 1
            return self.results[key]
        self.misses += 1
        v = compute()
        self.results[key] = v
        return v


__all__ = ["Congruence", "points_key", "pose_key", "shape_key"]
