"""The building blocks shared by gates, connectors, circuits and robot bodies: a rigid
slab body, a hinge, a universal joint and a muscle, all in the scene IR.

Units: sigma (length), k0 (stiffness).  Every builder takes world points at build time;
a body's frame is parallel to the world frame with its origin at the centroid of its
slab material (where the WCA volume exclusion acts).
"""
from __future__ import annotations

import numpy as np

from mlc.geometry.rotation import frame_matrix, matrix_to_quat
from mlc.scene.model import Body, Bond, Box, Muscle

EX = np.array([1.0, 0.0, 0.0])
EY = np.array([0.0, 1.0, 0.0])
EZ = np.array([0.0, 0.0, 1.0])


def segment_box(p, q, axis, width: float, thickness: float) -> Box:
    """A slab from ``p`` to ``q`` (body-frame points), ``width`` along the hinge ``axis``
    and ``thickness`` across."""
    L = float(np.linalg.norm(np.asarray(q) - np.asarray(p)))
    return Box(np.array([L, width, thickness]), 0.5 * (np.asarray(p) + np.asarray(q)),
               matrix_to_quat(frame_matrix(np.asarray(q) - np.asarray(p), axis)))


def slab_body(name: str, segments, sites: dict, axis, width: float, thickness: float,
              axes=None) -> Body:
    """A rigid body made of straight slab segments (list of ``(p, q)`` world points at build
    time), each ``width`` wide along its hinge axis (``axes[i]``, default ``axis``) and
    ``thickness`` thick.  ``sites`` are world points; they are stored in the body frame."""
    lengths = np.array([np.linalg.norm(np.asarray(q) - np.asarray(p)) for p, q in segments])
    mids = np.array([0.5 * (np.asarray(p) + np.asarray(q)) for p, q in segments])
    centre = (lengths[:, None] * mids).sum(0) / lengths.sum()
    axes = axes or [axis] * len(segments)
    boxes = [segment_box(np.asarray(p) - centre, np.asarray(q) - centre, ax, width, thickness)
             for (p, q), ax in zip(segments, axes)]
    return Body(name, centre, np.array([1.0, 0, 0, 0]), boxes,
                {k: np.asarray(v, float) - centre for k, v in sites.items()})


def axis_sites(prefix: str, point, axis, width: float) -> dict:
    """The two ends ``prefix_0``, ``prefix_1`` of a hinge axis of length ``width`` centred on
    ``point`` (world points)."""
    point, axis = np.asarray(point, float), np.asarray(axis, float)
    return {f"{prefix}_0": point - 0.5 * width * axis, f"{prefix}_1": point + 0.5 * width * axis}


def hinge(name: str, body_a: str, body_b: str, site_a: str, site_b: str, k: float = 1.0,
          tolerance: float = 0.0) -> list[Bond]:
    """A hinge: two zero-rest bonds joining the axis ends ``site_a_{0,1}`` of ``body_a`` to
    ``site_b_{0,1}`` of ``body_b``."""
    return [Bond(f"{name}_{i}", f"{body_a}.{site_a}_{i}", f"{body_b}.{site_b}_{i}", k, 0.0, tolerance,
                 "hinge", name) for i in (0, 1)]


def universal_joint(name: str, a: str, b: str, k: float = 1.0, tolerance: float = 0.0) -> Bond:
    """A universal joint: one zero-rest bond between the sites ``a`` and ``b`` ("body.site")."""
    return Bond(name, a, b, k, 0.0, tolerance, "universal", name)


def muscle(name: str, input_name: str, a: str, b: str, rest: float, actuated: float, k: float = 1.0) -> Muscle:
    """A muscle between sites ``a`` and ``b``: length ``rest`` at input 0, ``actuated`` at 1."""
    return Muscle(name, input_name, a, b, rest, actuated, k)


__all__ = ["EX", "EY", "EZ", "axis_sites", "hinge", "muscle", "segment_box", "slab_body", "universal_joint"]
