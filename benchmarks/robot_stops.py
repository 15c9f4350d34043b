"""Energy scan of a robot's DOF joints with and without the joint stops (docs/robot.md 2.3).

An independent check of the stop design: it takes the *built scene* (site positions in
the world, the bonds' rest/tolerance as written to robot.yaml), turns the second body of
every DOF rigidly about its hinge axis by t in [-180, 180) degrees, and evaluates the
energy of every bond between the DOF's two bodies (hinge, stops, lock) with the kernel's
flat-bottom law ``U = k/2 max(0, |d - rest| - tol)^2``, plus, for a lever DOF, the
coupling's pair as one spring of stiffness k0 at the output's length (L0 or L1).  No
formula of mlc.robot.build is used: only the scene.

For each DOF and each output state it reports the energy minima (the equilibria of the
joint alone) and the barrier from the target to the nearest other minimum.  Without
stops (the stop bonds dropped) the lever DOF in state 1 has a second minimum at
t = 180 deg behind a barrier of k0/2 (p + q - L1)^2; with them the only minimum is the
target.

    python benchmarks/robot_stops.py OUT/robot.yaml [-o benchmarks/results/robot_stops.json]

Units: sigma, k0 sigma^2 (energies), degrees.
"""
from __future__ import annotations

import argparse
import json
import math
import sys

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np


def _rot(axis, a):
    axis = axis / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(a) * K + (1 - math.cos(a)) * K @ K


def scan_dof(scene, dm: dict, state: int, with_stops: bool = True, n: int = 1440):
    """Energy (k0 sigma^2) of DOF ``dm`` (an entry of meta.robot.dofs) against its turn t
    (deg, positive in the DOF's own sense: + for up, - for dn) with the output at
    ``state``.  Returns (t, U)."""
    b1, b2 = dm["bodies"]
    B1, B2 = scene.body(b1), scene.body(b2)
    name = dm["name"]
    O = B1.world(f"h_{name}_0")
    axis = B1.world(f"h_{name}_1") - O
    sgn = 1.0 if dm["side"] == "up" else -1.0
    rm = scene.meta["robot"]
    nz = np.asarray(rm["plane_normal"], float)
    if float(axis @ nz) < 0:
        axis = -axis
    springs = []                       # (site on b1 world, site on b2 world, k, rest, tol)
    for bd in scene.bonds:
        ends = {bd.a.split(".")[0], bd.b.split(".")[0]}
        if ends != {b1, b2}:
            continue
        if not with_stops and "_stop_" in bd.name:
            continue
        a, b = (bd.a, bd.b) if bd.a.startswith(b1 + ".") else (bd.b, bd.a)
        springs.append((scene.site_world(a), scene.site_world(b), bd.k, bd.rest, bd.tolerance))
    if dm.get("coupling") == "lever":
        # the chain's pair: one spring at the output's length (L0, L1 of the wires)
        g = rm["dof_geometry"]
        L = (g["actuated"] if state else g["rest"]) / g["gain"]
        springs.append((B1.world(f"lever_{name}"), B2.world(f"lever_{name}"), 1.0, L, 0.0))
    ts = np.linspace(-180.0, 180.0, n, endpoint=False)
    U = np.zeros(n)
    for i, t in enumerate(ts):
        R = _rot(axis, sgn * math.radians(t))
        for pa, pb, k, rest, tol in springs:
            d = float(np.linalg.norm(O + R @ (pb - O) - pa))
            U[i] += 0.5 * k * max(0.0, abs(d - rest) - tol) ** 2
    return ts, U


def minima(ts, U, floor: float = 1e-12):
    """Local minima of a periodic sampled curve: (t, U) of each basin's lowest point (flat
    bottoms count once)."""
    n = len(U)
    out = []
    for i in range(n):
        if U[i] <= U[i - 1] and U[i] < U[(i + 1) % n] or (U[i] < U[i - 1] and U[i] <= U[(i + 1) % n]):
            out.append((float(ts[i]), float(U[i])))
    return out


def barrier(ts, U, t_target: float, t_other: float) -> float:
    """The energy barrier (k0 sigma^2) from t_target to t_other along the shorter way round
    that does not... both ways round; the lower of the two saddles minus U(t_target)."""
    n = len(ts)
    i0 = int(np.argmin(np.abs(((ts - t_target) + 180) % 360 - 180)))
    i1 = int(np.argmin(np.abs(((ts - t_other) + 180) % 360 - 180)))
    fwd = [U[(i0 + j) % n] for j in range((i1 - i0) % n + 1)]
    bwd = [U[(i0 - j) % n] for j in range((i0 - i1) % n + 1)]
    return float(min(max(fwd), max(bwd)) - U[i0])


def scan_scene(scene, with_stops: bool = True) -> list[dict]:
    out = []
    for dm in scene.meta["robot"]["dofs"]:
        states = [0, 1] if dm.get("coupling") == "lever" else [int(dm.get("value", 0))]
        for st in states:
            ts, U = scan_dof(scene, dm, st, with_stops)
            target = 90.0 if st else 0.0
            mins = minima(ts, U)
            others = [(t, u) for t, u in mins if abs(((t - target) + 180) % 360 - 180) > 20]
            main_ = min(mins, key=lambda m: abs(((m[0] - target) + 180) % 360 - 180))
            e = {"dof": dm["name"], "coupling": dm.get("coupling"), "state": st, "target_deg": target,
                 "minimum_deg": main_[0], "U_target": main_[1],
                 "other_minima": [{"t_deg": t, "U": u, "barrier": barrier(ts, U, main_[0], t)} for t, u in others]}
            for t_probe in (-90.0, 180.0):
                e[f"U_at_{int(t_probe)}"] = float(U[int(np.argmin(np.abs(((ts - t_probe) + 180) % 360 - 180)))])
            out.append(e)
    return out


def main(argv=None) -> int:
    from mlc.scene.io import load_scene

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("-o", "--out")
    a = ap.parse_args(argv)
    sc = load_scene(a.scene)
    res = {"scene": a.scene, "with_stops": scan_scene(sc, True), "without_stops": scan_scene(sc, False),
           "units": "energies k0 sigma^2, angles degrees (turn in the DOF's own sense)"}
    for key in ("without_stops", "with_stops"):
        print(key)
        for e in res[key]:
            oth = ", ".join(f"{o['t_deg']:+.1f} deg (U {o['U']:.2e}, barrier {o['barrier']:.4f})" for o in e["other_minima"])
            print(f"  {e['dof']:7s} {e['coupling']:5s} state {e['state']}: minimum at {e['minimum_deg']:+.2f} deg "
                  f"U {e['U_target']:.1e}; U(-90) {e['U_at_-90']:.4f} U(180) {e['U_at_180']:.4f}; other minima: {oth or 'none'}")
    if a.out:
        with open(a.out, "w") as f:
            json.dump(res, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
