"""Can a printed joint follow the scene's universal joints?  The turns each joint takes over
the poses the mesher checks, measured from the scene and its statics alone.

The scene's universal joint is one zero-length bond: a *ball* joint, free to turn about all
three axes.  The mesher prints a *cardan* (docs/printing.md): a joint part with a pin ``u``
in one body and a pin ``v`` in the other, square to it, which follows a relative turn ``M``
(rest frame) only when ``u . M v = 0``; the angle by which it misses is the *twist*
(90 degrees less the angle between the posed pins), which the printed part takes up in the
clearance of its holes only to about 7.6 degrees (``mlc.mesh.build._split_twist``).

For every universal joint of a compiled scene, over its mechanism's poses (the logic states
and the points on the way from rest, ``mlc.mesh.pipeline.state_poses``, as ``mlc stl``
poses them), this script reports:

* ``cone_deg``: the largest angle of the relative turn: what a ball-and-socket joint would
  have to allow;
* ``twist_deg``: the least largest twist of a cardan over the poses: the first pin ``u``
  on the hinge line of one of the two bodies that passes through the joint point (a
  connector chain's compound junction: the mesher's choice), else searched over the
  sphere; the second pin ``v`` searched every degree about ``u``;
* for a *branch* (several joints at one point of one body: a fan-out's pages), the largest
  turn of each page relative to the first page about the shared first pin ``u``
  (``page_turn_u_deg``): one joint part for all pages (the mesher's branch junction) turns
  about ``u`` once for all of them, so it cannot follow that turn at all.

No code of ``mlc.mesh.build`` is used: hinge lines, joint points and poses come from the
scene and its statics.

    python benchmarks/junction_kinematics.py [--case tetris] [-o benchmarks/results/junction_kinematics.json]

Units: degrees; seconds wall.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CASES = {"tetris": ("examples/tetris.tt", None), "expr": (None, "(a & b) | c"),
         # the README's robot: mlc compile examples/tetris.tt --robot examples/tetris.robot.yaml
         "tetris_robot": ("examples/tetris.tt", None)}
ROBOTS = {"tetris_robot": "examples/tetris.robot.yaml"}
#: twists a printed cardan takes in its holes' clearance: whole twist on one pin, shared (deg)
TWIST_ONE_PIN, TWIST_SHARED = 4.8, 7.6


def turns(scene, poses: dict) -> dict:
    """{body: (n_poses, 3, 3)} rest -> posed rotations (world) of every body."""
    from mlc.geometry.rotation import quat_to_matrix
    out = {}
    for i, b in enumerate(scene.bodies):
        R0 = b.rotation()
        out[b.name] = np.array([quat_to_matrix(q[i]) @ R0.T for _, q in poses.values()])
    return out


def hinge_lines(scene) -> dict:
    """{body: [(point, unit direction)]} of every hinge the body is on (sigma, rest)."""
    out: dict = {}
    for bonds in scene.joints().values():
        if bonds[0].kind != "hinge" or len(bonds) < 2:
            continue
        p0, p1 = scene.site_world(bonds[0].a), scene.site_world(bonds[1].a)
        d = (p1 - p0) / np.linalg.norm(p1 - p0)
        for ref in (bonds[0].a, bonds[0].b):
            out.setdefault(ref.split(".")[0], []).append((p0, d))
    return out


def host_pin(lines: dict, body: str, p, tol: float = 1e-6):
    """The direction of a hinge line of ``body`` through point ``p``, or None."""
    for q, d in lines.get(body, []):
        r = p - q
        if np.linalg.norm(r - (r @ d) * d) < tol:
            return d
    return None


def least_twist(M: np.ndarray, u, step_deg: float = 1.0) -> tuple[float, np.ndarray]:
    """min over v square to ``u`` of max over the poses of |u . M v| as an angle (deg), and that
    v.  ``M``: (n, 3, 3) relative turns in the rest frame."""
    e1 = np.cross(u, [1.0, 0, 0] if abs(u[0]) < 0.9 else [0, 1.0, 0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    a = np.radians(np.arange(0.0, 180.0, step_deg))
    V = np.outer(np.cos(a), e1) + np.outer(np.sin(a), e2)           # (k, 3)
    uM = np.einsum("j,njk->nk", u, M)                                 # (n, 3): u^T M
    worst = np.abs(uM @ V.T).max(axis=0)                              # (k,)
    i = int(np.argmin(worst))
    return math.degrees(math.asin(min(1.0, float(worst[i])))), V[i]


def sphere(n: int) -> np.ndarray:
    """``n`` near-uniform unit vectors on a half sphere (Fibonacci lattice)."""
    k = np.arange(n) + 0.5
    z = k / n
    phi = np.pi * (1 + 5 ** 0.5) * k
    r = np.sqrt(1 - z * z)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def analyse(scene, poses: dict) -> dict:
    D = turns(scene, poses)
    lines = hinge_lines(scene)
    joints, at = [], {}
    for jname, bonds in scene.joints().items():
        if bonds[0].kind != "universal":
            continue
        bd = bonds[0]
        C, O = bd.a.split(".")[0], bd.b.split(".")[0]
        p = 0.5 * (scene.site_world(bd.a) + scene.site_world(bd.b))
        M = np.einsum("nji,njk->nik", D[C], D[O])                    # D_C^T D_O
        ang = np.degrees(np.arccos(np.clip((np.trace(M, axis1=1, axis2=2) - 1) / 2, -1, 1)))
        u = host_pin(lines, C, p)
        kind = "compound"
        if u is None:
            u = host_pin(lines, O, p)
            if u is not None:          # the host is O: the same question with the roles swapped
                M = np.transpose(M, (0, 2, 1))
        if u is None:
            kind = "free"
            best = min((least_twist(M, x, 2.0)[0], i) for i, x in enumerate(sphere(400)))
            u = sphere(400)[best[1]]
        tw, v = least_twist(M, u)
        joints.append({"joint": jname, "bodies": [C, O], "kind": kind, "cone_deg": round(float(ang.max()), 3),
                       "twist_deg": round(tw, 3)})
        at.setdefault((C, tuple(np.round(p, 6))), []).append((jname, O, u))
    branches = []
    for (S, p), members in at.items():
        if len(members) < 2:
            continue
        first = members[0]
        u = first[2]
        worst = []
        for jn, O, _ in members[1:]:
            N = np.einsum("nji,njk->nik", D[first[1]], D[O])            # page vs first page
            # the turn's component about u (rotation vector, rest frame)
            w = np.array([[N_[2, 1] - N_[1, 2], N_[0, 2] - N_[2, 0], N_[1, 0] - N_[0, 1]] for N_ in N]) / 2
            ang = np.arccos(np.clip((np.trace(N, axis1=1, axis2=2) - 1) / 2, -1, 1))
            s = np.sin(ang)
            rv = np.where(s[:, None] > 1e-12, w * (ang / np.where(s > 1e-12, s, 1.0))[:, None], w)
            worst.append((round(float(np.degrees(np.abs(rv @ u)).max()), 3), jn))
        branches.append({"source": S, "joints": [m[0] for m in members],
                         "page_turn_u_deg": {jn: v for v, jn in worst},
                         "max_page_turn_u_deg": max(v for v, _ in worst)})
    tw = np.array([j["twist_deg"] for j in joints])
    cone = np.array([j["cone_deg"] for j in joints])
    summary = {
        "universal_joints": len(joints),
        "compound": sum(j["kind"] == "compound" for j in joints),
        "cone_deg": {"max": float(cone.max()), "p99": float(np.percentile(cone, 99)), "median": float(np.median(cone))},
        "twist_deg": {"max": float(tw.max()), "p99": float(np.percentile(tw, 99)), "median": float(np.median(tw)),
                      f"over_{TWIST_ONE_PIN}": int((tw > TWIST_ONE_PIN).sum()),
                      f"over_{TWIST_SHARED}": int((tw > TWIST_SHARED).sum())},
        "worst_twist": sorted(((j["twist_deg"], j["joint"]) for j in joints), reverse=True)[:12],
        "branches": len(branches),
        "max_page_turn_u_deg": max((b["max_page_turn_u_deg"] for b in branches), default=None),
    }
    return {"summary": summary, "joints": joints, "branches": branches}


def plot(data: dict, path: Path) -> Path:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    for a, key, lab in ((ax[0], "twist_deg", "cardan: least largest twist (deg)"),
                        (ax[1], "cone_deg", "ball joint: largest relative turn (deg)")):
        x = [j[key] for c in data["cases"].values() for j in c["joints"]]
        a.hist(x, bins=40, color="tab:blue")
        a.set_xlabel(lab)
        a.set_ylabel("universal joints")
        a.set_yscale("log")
    ax[0].axvline(TWIST_ONE_PIN, color="tab:orange", ls="--", label=f"{TWIST_ONE_PIN} deg: one pin's clearance")
    ax[0].axvline(TWIST_SHARED, color="tab:red", ls="--", label=f"{TWIST_SHARED} deg: shared by both pins")
    ax[0].legend(fontsize=8)
    fig.suptitle(", ".join(data["cases"]) + ": the scene's universal joints over the mesher's poses", fontsize=10)
    fig.tight_layout()
    png = path.with_suffix(".png")
    fig.savefig(png, dpi=110)
    return png


def main(argv=None) -> int:
    sys.path.insert(0, str(HERE))
    from gitstate import commit

    from mlc import pipeline
    from mlc.io.atomic import atomic_path
    from mlc.mesh.pipeline import split_mechanisms, state_poses, sub_scene
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", nargs="*", default=["tetris"], choices=list(CASES))
    ap.add_argument("-o", "--out", default=str(HERE / "results" / "junction_kinematics.json"))
    args = ap.parse_args(argv)
    data = {"benchmark": "junction_kinematics", "mlc_commit": commit(), "how": __doc__.split("\n\n")[1:4],
            "cases": {}}
    for case in args.case:
        path, expr = CASES[case]
        t0 = time.perf_counter()
        from mlc.circuit.build import CircuitOptions
        from mlc.robot.build import CIRCUIT_END_DROP, CIRCUIT_PRINT_LEANS
        opts = CircuitOptions(end_drop=CIRCUIT_END_DROP, print_leans=CIRCUIT_PRINT_LEANS) if case in ROBOTS else None     # as mlc compile --robot
        scene = pipeline.build(pipeline.compile_spec(pipeline.load(str(ROOT / path) if path else None, expr)),
                               options=opts).circuit.scene
        if case in ROBOTS:       # the circuit, the skeleton and the levers as one scene
            from mlc.commands.robot import robot_files
            scene, _ = robot_files(scene, str(ROOT / ROBOTS[case]))
        res = {"joints": [], "branches": [], "mechanisms": []}
        for m in split_mechanisms(scene):
            sub = sub_scene(scene, m.bodies, m.scene.name)
            if not any(b[0].kind == "universal" for b in sub.joints().values()):
                continue
            poses, note = state_poses(sub)
            r = analyse(sub, poses)
            res["joints"] += r["joints"]
            res["branches"] += r["branches"]
            res["mechanisms"].append({"name": m.scene.name, "bodies": len(m.bodies), "poses": list(poses),
                                      "note": note, "summary": r["summary"]})
            print(case, m.scene.name, json.dumps(r["summary"]), flush=True)
        res["seconds"] = round(time.perf_counter() - t0, 1)
        data["cases"][case] = res
    out = Path(args.out)
    with atomic_path(out) as tmp:
        Path(tmp).write_text(json.dumps(data, indent=1))
    print("wrote", out, plot(data, out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
