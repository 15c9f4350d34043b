"""Unit quaternions ``[w, x, y, z]`` (scalar first, as HOOMD-blue and GSD) and the SO(3)
exponential map used by the static solver and the integrator."""
from __future__ import annotations

import numpy as np


def quat_to_matrix(q) -> np.ndarray:
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def matrix_to_quat(m) -> np.ndarray:
    """Rotation matrix to unit quaternion with w >= 0 (Shepperd's method)."""
    m = np.asarray(m, dtype=float)
    t = np.trace(m)
    if t > 0:
        s = 2.0 * np.sqrt(1.0 + t)
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        q = np.empty(4)
        q[0] = (m[k, j] - m[j, k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (m[j, i] + m[i, j]) / s
        q[1 + k] = (m[k, i] + m[i, k]) / s
    q = np.asarray(q, dtype=float)
    q /= np.linalg.norm(q)
    return q if q[0] >= 0 else -q


def skew(v) -> np.ndarray:
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def expmap(w) -> np.ndarray:
    """Rotation matrix exp([w]x) of a rotation vector ``w`` (Rodrigues)."""
    w = np.asarray(w, dtype=float)
    th = np.linalg.norm(w)
    K = skew(w)
    if th < 1e-8:
        return np.eye(3) + K + 0.5 * K @ K
    return np.eye(3) + np.sin(th) / th * K + (1 - np.cos(th)) / th**2 * K @ K


def left_jacobian(w) -> np.ndarray:
    """J_l(w) with exp(w + d) = exp(J_l(w) d) exp(w) to first order in d."""
    w = np.asarray(w, dtype=float)
    th = np.linalg.norm(w)
    K = skew(w)
    if th < 1e-6:
        return np.eye(3) + 0.5 * K + K @ K / 6.0
    return np.eye(3) + (1 - np.cos(th)) / th**2 * K + (th - np.sin(th)) / th**3 * K @ K


def rotation_between(u, v) -> np.ndarray:
    """The smallest rotation matrix taking unit vector ``u`` to unit vector ``v``."""
    u = np.asarray(u, float) / np.linalg.norm(u)
    v = np.asarray(v, float) / np.linalg.norm(v)
    c = float(np.dot(u, v))
    ax = np.cross(u, v)
    s = np.linalg.norm(ax)
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        perp = np.cross(u, [1.0, 0, 0])
        if np.linalg.norm(perp) < 1e-6:
            perp = np.cross(u, [0, 1.0, 0])
        return expmap(np.pi * perp / np.linalg.norm(perp))
    return expmap(ax / s * np.arctan2(s, c))


def cross3(a, b) -> np.ndarray:
    """``np.cross`` of two 3-vectors, bit for bit (the same products and differences, each
    rounded once), without its general-shape overhead: the builders call it for every slab."""
    a0, a1, a2 = np.asarray(a, float).tolist()
    b0, b1, b2 = np.asarray(b, float).tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def frame_matrix(x_axis, y_axis) -> np.ndarray:
    """Rotation whose columns are the orthonormalised ``x_axis``, ``y_axis`` and their cross."""
    x = np.asarray(x_axis, float)
    x = x / np.linalg.norm(x)
    y = np.asarray(y_axis, float)
    y = y - np.dot(y, x) * x
    y /= np.linalg.norm(y)
    return np.array((x, y, cross3(x, y))).T
