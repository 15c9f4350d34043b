"""How much faster could the Tetris robot's fold run with its stiff joints as exact constraints?
(issue 10 item 6: the speed goal, 4 rows x 3 seeds in 120 s on one core, missed 8.7 times at the
verifier's defaults; docs/robot.md 3.4 "needs the joints as constraints").  A bound, measured
before anything is built: no constrained integrator exists in mlc.

The stiff scheme's (SK-ROCK's) stages per step grow as sqrt(h rho), rho the largest rate of the
linearised drift M F (M the mobility: 1/gamma, 1/gamma_r for every body).  Today rho is set by the
joints (hinges and universal joints, zero-length bonds of K = 100 k0).  As exact constraints they
would leave only the soft terms (muscles, the skeleton's bonds, the junction stops, WCA), whose
largest rate on the constraints' tangent space is rho_c = max eig of P A_soft P, with
A = M^1/2 (sum_springs k J^T J) M^1/2 (every spring a zero-rest active bond: the same upper bound
as the integrator's own estimate, mlc.sim.kernels._spectral_py) and P the orthogonal projector
onto the null space of the constraints' Jacobian G M^1/2.  The stages would fall by
sqrt(rho / rho_c); every stage would then also project onto the constraints (at least one sparse
solve with G M G^T, its factorisation refreshed at least once a step), so the best speed-up is

    S = sqrt(rho / rho_c) * t_eval / (t_eval + t_solve + t_factor / s_c)

with t_eval one force evaluation, s_c the constrained stage count of a step at the verifier's
dt.  This leaves out what would make it worse (Newton iterations of a nonlinear projection, the
stops as unilateral constraints when engaged, the step-size control) and so is an upper bound.

Independent check: rho of the full scene from scipy's Lanczos (eigsh) on the assembled sparse
matrix, against the integrator's own power iteration (``Simulation.rho``), two implementations.

    python benchmarks/robot_constraint_bound.py OUT/robot.yaml [--stages 842 --dt 0.8]

Writes benchmarks/results/robot_constraint_bound.json and .png.  Units: internal time
(gamma / k0; 1 t0 = 1000 of it) for rates, seconds for times.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from gitstate import commit

RESULTS = Path(__file__).resolve().parent / "results"
JOINT_KINDS = ("hinge", "universal")


def _rows(sim, springs):
    """Sparse J (3 rows a spring, 6 columns a body: v then w) of the site separations
    d = (v_j + w_j x a_j) - (v_i + w_i x a_i), at the current arms."""
    rows, cols, vals = [], [], []
    for r, m in enumerate(springs):
        for sgn, s in ((1.0, sim.sp_j[m]), (-1.0, sim.sp_i[m])):
            b = int(sim.site_body[s])
            a = sim.arm[s]
            # v + w x a = v - [a]x w
            ax = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
            for c in range(3):
                rows += [3 * r + c] * 4
                cols += [6 * b + c, 6 * b + 3, 6 * b + 4, 6 * b + 5]
                vals += [sgn, -sgn * ax[c, 0], -sgn * ax[c, 1], -sgn * ax[c, 2]]
    return sp.csr_matrix((vals, (rows, cols)), shape=(3 * len(springs), 6 * sim.N))


def _stiffness(sim, springs, msq):
    J = _rows(sim, springs) @ msq
    k = np.repeat(sim.sp_k[springs], 3)
    return (J.T @ sp.diags(k) @ J).tocsr()


def _lmax(op_or_mat, n, seed=0):
    v0 = np.random.default_rng(seed).standard_normal(n)
    return float(spla.eigsh(op_or_mat, k=1, which="LA", v0=v0, tol=1e-6, maxiter=20000,
                            return_eigenvectors=False)[0])


def measure(scene_path: str, stages: float, dt: float) -> dict:
    from mlc.scene.io import load_scene
    from mlc.sim.integrator import SimOptions, Simulation

    scene = load_scene(scene_path)
    sim = Simulation(scene, options=SimOptions(scheme="stiff", kT=0.0))
    sim._eval()
    rho_kernel = sim.rho()
    wca = 2.0 * sim.mon[5] / sim.gamma
    n = 6 * sim.N
    msq = sp.diags(np.tile(np.r_[np.full(3, (1.0 / sim.gamma) ** 0.5), np.full(3, (1.0 / sim.gamma_r) ** 0.5)], sim.N))
    kinds = [b.kind for b in scene.bonds] + ["muscle"] * len(scene.muscles)
    nb = len(scene.bonds)
    joint = np.array([m < nb and kinds[m] in JOINT_KINDS and sim.sp_rest0[m] == 0.0 and sim.sp_tol[m] == 0.0
                      and sim.sp_k[m] >= 10.0 for m in range(len(kinds))])
    stop = np.array([m < nb and not joint[m] and sim.sp_tol[m] > 0.0 for m in range(len(kinds))])
    every = np.arange(len(kinds))
    A_full = _stiffness(sim, every, msq)
    t = time.process_time()
    rho_full = _lmax(A_full, n) + wca
    t_lanczos = time.process_time() - t

    G = (_rows(sim, np.nonzero(joint)[0]) @ msq).tocsc()
    GG = (G @ G.T).tocsc()
    eps = 1e-10 * float(GG.diagonal().max())
    reg = (GG + eps * sp.identity(GG.shape[0])).tocsc()
    t = time.process_time()
    reps = 3
    for _ in range(reps):
        lu = spla.splu(reg, permc_spec="MMD_AT_PLUS_A")
    t_factor = (time.process_time() - t) / reps
    rhs = np.random.default_rng(1).standard_normal(GG.shape[0])
    t = time.process_time()
    for _ in range(20):
        lu.solve(rhs)
    t_solve = (time.process_time() - t) / 20

    def project(v):
        return v - G.T @ lu.solve(G @ v)

    # how well the regularised solve projects: |G P v| / |G v| on random vectors
    rng = np.random.default_rng(2)
    leak = max(float(np.linalg.norm(G @ project(x)) / np.linalg.norm(G @ x))
               for x in rng.standard_normal((3, n)))

    out = {}
    for label, sel in (("stops free", ~joint & ~stop), ("stops engaged", ~joint)):
        A_s = _stiffness(sim, np.nonzero(sel)[0], msq)
        op = spla.LinearOperator((n, n), matvec=lambda v, A_s=A_s: project(A_s @ project(v)), dtype=float)
        rho_c = _lmax(op, n) + wca
        out[label] = {"rho_c": rho_c, "soft_springs": int(sel.sum())}

    # one force evaluation (the integrator's kernel, warm)
    sim._eval()
    t = time.process_time()
    reps = 200
    for _ in range(reps):
        sim._eval_once()
    t_eval = (time.process_time() - t) / reps

    res = {"bodies": sim.N, "springs": len(kinds), "joint_constraints": int(joint.sum()),
           "junction_stops": int(stop.sum()), "constraint_rows": int(G.shape[0]),
           "ggt_nonzeros": int(GG.nnz), "lu_nonzeros": int(lu.L.nnz + lu.U.nnz),
           "rho_kernel": rho_kernel, "rho_lanczos": rho_full, "wca_term": wca,
           "lanczos_cpu_s": round(t_lanczos, 2), "projection_leak": leak,
           "t_eval_s": t_eval, "t_factor_s": t_factor, "t_solve_s": t_solve,
           "stages_per_step_now": stages, "dt_t0": dt, "cases": {}}
    for label, c in out.items():
        ratio = (rho_full / c["rho_c"]) ** 0.5
        s_c = max(1.0, stages / ratio)
        per_stage = t_eval + t_solve + t_factor / s_c
        res["cases"][label] = {**c, "stage_ratio": ratio, "stages_per_step": s_c,
                               "cost_per_stage_over_eval": per_stage / t_eval,
                               "speedup_bound": ratio * t_eval / per_stage,
                               "speedup_bound_no_factor": ratio * t_eval / (t_eval + t_solve),
                               "speedup_bound_free_projection": ratio}
    return res


def plot(res: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    labels, vals = [], []
    for case, c in res["cases"].items():
        for key, name in (("speedup_bound_free_projection", "projection\nfree"),
                          ("speedup_bound_no_factor", "+1 solve\na stage"),
                          ("speedup_bound", "+1 factorisation\na step")):
            labels.append(f"{case}\n{name}")
            vals.append(c[key])
    ax.bar(range(len(vals)), vals, color=["#4c72b0", "#55a868", "#c44e52"] * 2)
    ax.axhline(res["goal_factor"], color="k", ls="--", lw=1)
    ax.text(len(vals) - 0.5, res["goal_factor"], f" goal: {res['goal_factor']:.1f}x", va="bottom", ha="right")
    ax.set_xticks(range(len(vals)))
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_ylabel("speed-up over the spring joints (upper bound)")
    ax.set_yscale("log")
    ax.set_title(f"Tetris robot, joints as exact constraints: best case ({res['bodies']} bodies, commit {res['commit']})",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--stages", type=float, default=842.0,
                    help="SK-ROCK stages of a full step now (robot_speed_profile_jointk100_s35.json: 842 at dt 0.8)")
    ap.add_argument("--dt", type=float, default=0.8)
    ap.add_argument("--goal-factor", type=float, default=8.7,
                    help="how many times too slow the verifier's 12 runs are (robot_verify_speed.json, setting D)")
    ap.add_argument("-o", "--out", default=str(RESULTS / "robot_constraint_bound.json"))
    a = ap.parse_args()
    res = measure(a.scene, a.stages, a.dt)
    res.update({"what": "upper bound on the speed-up of the Tetris robot's fold with its K = 100 joints as exact "
                        "constraints (benchmarks/robot_constraint_bound.py docstring)",
                "scene": a.scene, "goal_factor": a.goal_factor, "commit": commit(),
                "machine": f"{platform.machine()}, {os.cpu_count()} cores (shared)",
                "units": "rates in internal 1/time (1 t0 = 1000); times CPU s",
                "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())})
    out = Path(a.out)
    out.write_text(json.dumps(res, indent=1) + "\n")
    plot(res, out.with_suffix(".png"))
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
