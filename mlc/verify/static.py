"""Static verification: the mechanical equilibrium of a scene in an input state.

For an input state (a bit string in ``scene.inputs`` order) the muscles take their
rest or actuated lengths and the body poses minimise the total bond energy

    E = sum_bonds k/2 max(0, | |d| - rest | - tol)^2 + sum_muscles k/2 (|d| - L)^2

(units: sigma, k0).  Poses are parametrised per body by a translation and a rotation
vector relative to the starting pose (R = exp(w) R0); body 0 is held fixed to remove
the six rigid-body modes.  The residual vector (zero-length bonds contribute their
3-vector, the others a scalar) is minimised by scipy's trust-region least squares
with the analytic, sparse Jacobian (dp/dw = -[R s]x J_l(w)).  The muscles are moved
from the starting state to the target in a few continuation steps so that the
solution stays on the mechanism's physical branch.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import least_squares

from mlc.errors import MlcError
from mlc.geometry.rotation import expmap, left_jacobian, matrix_to_quat, quat_to_matrix, skew
from mlc.scene.model import Scene

CONTINUATION_STEPS = 4


@dataclass
class Equilibrium:
    state: str
    pos: np.ndarray                 # (N, 3)
    quat: np.ndarray                # (N, 4)
    probes: dict                    # probe name -> length (sigma)
    max_joint_stretch: float        # largest |d| - rest - tol over the scene's bonds (sigma)
    max_muscle_strain: float        # largest | |d| - L | over the muscles (sigma)
    energy: float                   # k0 sigma^2
    iterations: int = 0
    rows: list = field(default_factory=list)


class _Problem:
    def __init__(self, scene: Scene, pos0, quat0):
        self.A = A = scene.arrays()
        self.N = len(pos0)
        self.pos0 = np.asarray(pos0, float)
        self.R0 = np.array([quat_to_matrix(q) for q in quat0])
        self.free = np.arange(1, self.N)                 # body 0 is pinned
        self.vec = (A.bond_rest == 0) & (A.bond_tol == 0)  # zero-length bonds: vector residual
        self.nb_vec = int(self.vec.sum())
        self.nb_sca = len(A.bond_i) - self.nb_vec
        self.m = 3 * self.nb_vec + self.nb_sca + len(A.muscle_i)

    def unpack(self, x):
        full = np.zeros((self.N, 6))
        full[self.free] = x.reshape(-1, 6)
        R = np.array([expmap(w) @ R0 for w, R0 in zip(full[:, 3:], self.R0)])
        return full, self.pos0 + full[:, :3], R

    def sites(self, x):
        A = self.A
        full, pos, R = self.unpack(x)
        rs = np.einsum("nij,nj->ni", R[A.site_body], A.site_local)     # R s per site
        return full, pos[A.site_body] + rs, rs

    def residuals(self, x, L_muscle):
        A = self.A
        _, p, _ = self.sites(x)
        out = []
        sk = np.sqrt(A.bond_k)
        d = p[A.bond_i] - p[A.bond_j]
        out.append((sk[self.vec, None] * d[self.vec]).ravel())
        if self.nb_sca:
            nv = ~self.vec
            r = np.linalg.norm(d[nv], axis=1) - A.bond_rest[nv]
            out.append(sk[nv] * np.sign(r) * np.maximum(0.0, np.abs(r) - A.bond_tol[nv]))
        dm = p[A.muscle_i] - p[A.muscle_j]
        out.append(np.sqrt(A.muscle_k) * (np.linalg.norm(dm, axis=1) - L_muscle))
        return np.concatenate(out)

    def jacobian(self, x, L_muscle):
        A = self.A
        full, p, rs = self.sites(x)
        # d p_site / d (t, w) of its body: [I, -[Rs]x J_l(w)]
        Jl = np.array([left_jacobian(w) for w in full[:, 3:]])
        blocks = np.zeros((len(A.site_body), 3, 6))
        blocks[:, :, :3] = np.eye(3)
        blocks[:, :, 3:] = -np.einsum("sij,sjk->sik", np.array([skew(v) for v in rs]), Jl[A.site_body])
        col_of_body = np.full(self.N, -1)
        col_of_body[self.free] = np.arange(len(self.free)) * 6
        rows, cols, vals = [], [], []

        def add(row0, site, coef):   # coef: (nrow, 3) left factor on dp_site
            c0 = col_of_body[A.site_body[site]]
            if c0 < 0:
                return
            blk = coef @ blocks[site]                    # (nrow, 6)
            r, c = np.meshgrid(np.arange(blk.shape[0]) + row0, np.arange(6) + c0, indexing="ij")
            rows.append(r.ravel()), cols.append(c.ravel()), vals.append(blk.ravel())

        row = 0
        sk = np.sqrt(A.bond_k)
        for b in np.nonzero(self.vec)[0]:
            add(row, A.bond_i[b], sk[b] * np.eye(3))
            add(row, A.bond_j[b], -sk[b] * np.eye(3))
            row += 3
        for b in np.nonzero(~self.vec)[0]:
            d = p[A.bond_i[b]] - p[A.bond_j[b]]
            n = np.linalg.norm(d)
            r = n - A.bond_rest[b]
            g = (sk[b] * d / n)[None, :] if (n > 0 and abs(r) > A.bond_tol[b]) else np.zeros((1, 3))
            add(row, A.bond_i[b], g)
            add(row, A.bond_j[b], -g)
            row += 1
        for mi in range(len(A.muscle_i)):
            d = p[A.muscle_i[mi]] - p[A.muscle_j[mi]]
            g = (np.sqrt(A.muscle_k[mi]) * d / max(np.linalg.norm(d), 1e-300))[None, :]
            add(row, A.muscle_i[mi], g)
            add(row, A.muscle_j[mi], -g)
            row += 1
        if rows:
            rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.m, 6 * len(self.free)))


def _state_bits(scene: Scene, state: str) -> np.ndarray:
    n = len(scene.inputs)
    if len(state) != n or set(state) - {"0", "1"}:
        raise MlcError(f"input state {state!r} is not {n} bits for inputs {scene.inputs}", "STATE")
    return np.array([int(c) for c in state], dtype=float)


def equilibrium(scene: Scene, state: str, start_state: str | None = None,
                steps: int = CONTINUATION_STEPS) -> Equilibrium:
    """Equilibrium of ``scene`` with its inputs in ``state``, reached by continuation from
    the scene's own poses, taken to be the equilibrium of ``start_state`` (default all 0)."""
    A = scene.arrays()
    target = _state_bits(scene, state)
    start = _state_bits(scene, start_state or "0" * len(scene.inputs))
    prob = _Problem(scene, A.pos, A.quat)
    x = np.zeros(6 * len(prob.free))
    L0, L1 = A.muscle_lengths(start), A.muscle_lengths(target)
    nit = 0
    path = [1.0] if np.allclose(L0, L1) else np.linspace(0, 1, steps + 1)[1:]
    for t in path:
        L = L0 + t * (L1 - L0)
        if prob.m == 0 or len(x) == 0:
            break
        dense = len(x) <= 600
        jac = (lambda y, L_: prob.jacobian(y, L_).toarray()) if dense else prob.jacobian
        res = least_squares(prob.residuals, x, jac=jac, args=(L,), method="trf",
                            x_scale=1.0, ftol=1e-15, xtol=1e-15, gtol=1e-15, max_nfev=200,
                            tr_solver="exact" if dense else "lsmr")
        x, nit = res.x, nit + res.nfev
    full, pos, R = prob.unpack(x)
    _, p, _ = prob.sites(x)
    quat = np.array([matrix_to_quat(r) for r in R])
    d = np.linalg.norm(p[A.bond_i] - p[A.bond_j], axis=1) if len(A.bond_i) else np.zeros(0)
    stretch = np.maximum(0.0, np.abs(d - A.bond_rest) - A.bond_tol) if len(d) else np.zeros(0)
    dm = np.linalg.norm(p[A.muscle_i] - p[A.muscle_j], axis=1) if len(A.muscle_i) else np.zeros(0)
    probes = {pr.name: float(np.linalg.norm(p[A.probe_i[i]] - p[A.probe_j[i]])) for i, pr in enumerate(scene.probes)}
    r = prob.residuals(x, L1) if prob.m else np.zeros(0)
    return Equilibrium(state, pos, quat, probes, float(stretch.max(initial=0.0)),
                       float(np.abs(dm - L1).max(initial=0.0)), float(0.5 * r @ r), nit)


def solve_states(scene: Scene) -> dict[str, Equilibrium]:
    """Equilibria of every input state, each reached by continuation from the rest pose."""
    return {s: equilibrium(scene, s) for s in scene.states()}


def verify_scene(scene: Scene, tol_length: float = 0.05, tol_stretch: float = 1e-3) -> list[dict]:
    """Check every input state against ``scene.truth_table``: one row per (state, probe) with
    the expected bit, measured length (sigma), margin to the threshold, ideal length and
    residual joint stretch.  ``ok`` needs the right bit, the length within ``tol_length``
    of the ideal rest/actuated length and the stretch below ``tol_stretch``."""
    if scene.truth_table is None:
        raise MlcError(f"scene {scene.name} has no truth table to verify against", scene.source or scene.name,
                       "add a truth_table mapping input bits to output bits")
    rows = []
    for state in scene.states():
        eq = equilibrium(scene, state)
        want = scene.truth_table.get(state)
        for pr in scene.probes:
            idx = scene.outputs.index(pr.output)
            bit = None if want is None or want[idx] == "-" else int(want[idx])
            L = eq.probes[pr.name]
            ideal = None if bit is None else (pr.actuated if bit else pr.rest)
            ok = (bit is None or (pr.bit(L) == bit and abs(L - ideal) <= tol_length)) and \
                eq.max_joint_stretch <= tol_stretch
            rows.append({"state": state, "output": pr.output, "expected": bit, "measured": L,
                         "bit": pr.bit(L), "ideal": ideal,
                         "margin": None if bit is None else float(pr.margin(L, bit)),
                         "error": None if ideal is None else float(abs(L - ideal)),
                         "joint_stretch": eq.max_joint_stretch, "muscle_strain": eq.max_muscle_strain,
                         "ok": bool(ok)})
    return rows
