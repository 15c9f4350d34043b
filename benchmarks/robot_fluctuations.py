"""How each integrator samples a folded robot's joint-angle fluctuations at kT = 1e-5 (issue 10,
item 6; docs/robot.md 3.4, "Session 49"): Euler-Maruyama at its default step (half its
stability limit) against the stiff scheme (SK-ROCK) and the linearly implicit scheme at the
verifier's step, from the static equilibrium of one row.

The locked DOFs (a lock bond at the lever tips) fluctuate fast (their correlation time is a few
10^-3 t0), so Euler, which cannot follow a fold (10^8 steps), can sample them: ``--euler-time``
t0 after ``--euler-burn`` t0, every ``--euler-every`` t0.  The other schemes run ``--time`` t0
after ``--burn`` t0 and are sampled every step.  The soft DOFs (those the muscles turn) decorrelate
over tens of t0: Euler's short run does not sample them, so only the locked DOFs are compared.
``--rot-noise`` adds a run of the implicit scheme with rotational noise, whose harmonic modes
have Boltzmann's variance exactly at any step (docs/simulation.md): the paper's model has no
rotational noise ("the rotational noise in a particle orientation arises from the translational
diffusion of the particles bonded to it"), so that run is a bound, not the reference.

    python benchmarks/robot_fluctuations.py OUT/robot.yaml [--row 01] [--burn 50] [--time 200]
        [--euler-burn 0.2] [--euler-time 1.0] [--euler-every 0.002] [--rot-noise] [-o OUT.json]

Writes benchmarks/results/robot_fluctuations.json (or ``-o``) and its .png.  Units: degrees, t0,
CPU seconds.  Euler's run dominates (160 s of CPU for 1.2 t0 of the 524-body per-lever robot).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.io.atomic import atomic_path

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "robot_fluctuations.json"


def sample(scene, row, pos, quat, scheme, dt, burn, T, every, rot_noise=False, seed=1) -> dict:
    """DOF angles (degrees) every ``every`` t0 over ``T`` t0 after ``burn`` t0 from (pos, quat)."""
    from mlc.robot.verify import ROBOT_DISP_ACC, dof_angles
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation
    drives = {i: Drive.constant(int(b)) for i, b in zip(scene.inputs, row)}
    sim = Simulation(scene, drives, SimOptions(scheme=scheme, kT=1e-5, seed=seed, dt=dt, disp_acc=ROBOT_DISP_ACC,
                                               rot_noise=rot_noise), pos=pos.copy(), quat=quat.copy())
    c0 = time.process_time()
    sim.run(burn, quiet=True)
    ang = []
    for _ in range(int(round(T / every))):
        sim.run(every, quiet=True)
        ang.append(dof_angles(scene, sim.pos, sim.quat))
    ang = np.asarray(ang)
    return {"scheme": scheme, "rot_noise": rot_noise, "dt": sim.dt, "burn_t0": burn, "time_t0": T, "every_t0": every,
            "samples": len(ang), "cpu_s": round(time.process_time() - c0, 1),
            "std_deg": np.round(ang.std(axis=0, ddof=1), 4).tolist(), "mean_deg": np.round(ang.mean(axis=0), 3).tolist()}


def plot(res: dict, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = res["dofs"]
    fig, ax = plt.subplots(figsize=(9, 4))
    w = 0.8 / len(res["runs"])
    for k, (label, r) in enumerate(res["runs"].items()):
        ax.bar(np.arange(len(names)) + k * w, r["std_deg"], w, label=label)
    ax.set_xticks(np.arange(len(names)) + 0.4 - w / 2, [n + (" (locked)" if n in res["locked"] else "")
                                                       for n in names], rotation=30, fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("DOF angle std (deg)")
    ax.set_title(f"{res['bodies']}-body robot, row {res['row']}, kT = 1e-5, from the static equilibrium "
                 f"(Euler's run samples only the locked DOFs)", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(out.with_suffix(".png")) as tmp:
        fig.savefig(tmp, dpi=110, format="png")


def main(argv=None) -> int:
    sys.path.insert(0, str(HERE))
    from gitstate import commit

    from mlc.robot.verify import ROBOT_DT, verify_robot_static
    from mlc.scene.io import load_scene
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?")
    ap.add_argument("--row", default="01")
    ap.add_argument("--burn", type=float, default=50.0)
    ap.add_argument("--time", type=float, default=200.0)
    ap.add_argument("--euler-burn", type=float, default=0.2)
    ap.add_argument("--euler-time", type=float, default=1.0)
    ap.add_argument("--euler-every", type=float, default=0.002)
    ap.add_argument("--rot-noise", action="store_true")
    ap.add_argument("--plot", action="store_true", help="only redraw the PNG from the JSON")
    ap.add_argument("-o", "--out", type=Path, default=OUT)
    a = ap.parse_args(argv)
    if a.plot:
        plot(json.loads(a.out.read_text()), a.out)
        return 0
    if not a.scene:
        ap.error("give the robot scene (mlc compile ... --robot ... -o OUT: OUT/robot.yaml)")
    sc = load_scene(a.scene)
    rm = sc.meta["robot"]
    names = [d["name"] for d in rm["dofs"]]
    locked = [d["name"] for d in rm["dofs"] if d.get("coupling") == "lock"]
    st = verify_robot_static(sc, [a.row], keep_poses=True)
    pos, quat = st.poses[a.row]
    res = {"scene": str(a.scene), "bodies": len(sc.bodies), "row": a.row, "kT": 1e-5, "dofs": names, "locked": locked,
           "runs": {}, "commit": commit(), "machine": {"platform": platform.platform(), "cpus": os.cpu_count()}}
    todo = [("stiff", "stiff", ROBOT_DT, a.burn, a.time, ROBOT_DT, False),
            ("implicit", "implicit", ROBOT_DT, a.burn, a.time, ROBOT_DT, False)]
    if a.rot_noise:
        todo.append(("implicit, rotational noise", "implicit", ROBOT_DT, a.burn, a.time, ROBOT_DT, True))
    todo.append(("euler", "euler", None, a.euler_burn, a.euler_time, a.euler_every, False))
    for label, scheme, dt, burn, T, every, rot in todo:
        r = sample(sc, a.row, pos, quat, scheme, dt, burn, T, every, rot)
        res["runs"][label] = r
        print(f"{label}: {r['cpu_s']} s CPU, locked DOFs' std (deg) "
              + ", ".join(f"{n} {s:.3f}" for n, s in zip(names, r["std_deg"]) if n in locked), flush=True)
    e = res["runs"]["euler"]["std_deg"]
    res["locked_std_over_euler"] = {label: {n: round(r["std_deg"][j] / e[j], 3) for j, n in enumerate(names) if n in locked}
                                    for label, r in res["runs"].items() if label != "euler"}
    a.out.parent.mkdir(exist_ok=True)
    with atomic_path(a.out) as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1))
    plot(res, a.out)
    print(json.dumps(res["locked_std_over_euler"]))
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
