"""The implicit scheme's block Cholesky (mlc/sim/blockchol.py) against the reference path it
replaces: the rows of G from ``Implicit.rows`` with SuperLU (scipy), and numpy's eigh."""
import numpy as np
import pytest
import scipy.sparse as sp

from mlc.sim import blockchol as BC
from mlc.sim.implicit import _LU
from mlc.sim.integrator import SimOptions, Simulation
from mlc.sim.testscenes import bonded_pairs, chain_scene, tongs_scene


def _nand():
    from mlc.gates.library import gate_scene

    return gate_scene("NAND")


def _sim(sc, drives, seed=3, kT=1e-3, rot_noise=False):
    sim = Simulation(sc, drives, SimOptions(scheme="implicit", kT=kT, seed=seed, dt=0.05, rot_noise=rot_noise))
    sim.run(0.2)                     # away from rest: bonds stretched, muscles moving
    sim._eval()
    return sim


def _dense(imp, h):
    """D/h + H+ from the block factor's input, as a dense 6N x 6N matrix (before factor())."""
    P = imp._pat
    N = imp.N
    A = np.zeros((6 * N, 6 * N))
    for k in range(N):
        b = P.order[k]
        A[6 * b:6 * b + 6, 6 * b:6 * b + 6] = imp._diag[k]
        for e in range(P.colptr[k], P.colptr[k + 1]):
            r = P.order[P.rowidx[e]]
            A[6 * r:6 * r + 6, 6 * b:6 * b + 6] = imp._blk[e]
            A[6 * b:6 * b + 6, 6 * r:6 * r + 6] = imp._blk[e].T
    return A


def _compare(sim, rot_noise):
    """The block path's matrix, noise and solve against rows() + SuperLU at the sim's state."""
    imp = sim._imp
    h = 37.0
    key = np.uint64(12345)
    seed2 = np.uint64(99)
    G = imp.rows()
    ref = (G.T @ G + sp.diags(imp.D / h)).toarray()
    imp._block(h, True, seed2, key, rot_noise)      # the pattern and buffers (factorised: assembled again below)
    P = imp._pat
    nrow = BC.assemble_bonds(sim.ws, sim.arm, imp.sb, sim.sp_i, sim.sp_j, sim.sp_k, sim.sp_rest0, sim.sp_rest1,
                             sim.sp_tol, sim.sp_inp, sim.uval, imp.iz, imp.isc, P.bond_blk, P.bond_flip, P.pos,
                             imp.D / h, imp._diag, imp._blk, imp._grad, True, seed2, key, rot_noise,
                             float(sim.gamma), float(sim.gamma_r), imp._bvec)
    bond_noise = imp._bvec.copy()
    BC.rot_eig(imp._grad, sim.arm, imp.sb, imp.N, imp._lam, imp._vec)
    thresh = 1e-14 * max(1.0, float(np.abs(imp._lam).max()))
    nrot = BC.assemble_rot(imp._lam, imp._vec, thresh, P.pos, imp._diag, nrow, True, seed2, key, rot_noise, imp._bvec)
    ci, cj, cv = imp.contacts()
    if len(ci):
        BC.assemble_contacts(ci, cj, cv, P.pair_blk(ci, cj), P.pos[ci] < P.pos[cj], P.pos, imp._diag, imp._blk,
                             nrow + nrot, True, seed2, key, imp._bvec)
    assert nrow + nrot + len(ci) == G.shape[0]      # the same rows, so the same normals per row
    A = _dense(imp, h)
    assert np.abs(A - ref).max() <= 1e-9 * np.abs(ref).max()
    ref_noise = _LU(imp, G, None, seed2, key, rot_noise).noise()
    if rot_noise:
        # the rotational rows' eigenvectors are Jacobi's, not LAPACK's (the same up to sign, or
        # basis for a repeated eigenvalue: the same H+, checked above, the same noise in law);
        # the bond rows' noise is the reference's, normal for normal
        ref_noise = _LU(imp, G[:nrow], None, seed2, key, rot_noise).noise()
        got = bond_noise
    else:
        got = imp._bvec
    assert np.abs(got - ref_noise).max() <= 1e-9 * max(1.0, np.abs(ref_noise).max())
    assert np.abs(ref_noise).max() > 0
    # the factor solves what SuperLU solves
    block = imp._block(h, False, seed2, key, rot_noise)
    rhs = np.random.default_rng(0).normal(size=(imp.N, 6))
    x = block.solve(rhs)
    x_ref = imp.solve(G, h).solve(rhs.ravel()).reshape(imp.N, 6)
    assert np.abs(x - x_ref).max() <= 1e-9 * np.abs(x_ref).max()
    return len(ci)


@pytest.mark.parametrize("make,drives", [(lambda: tongs_scene(3, k=100.0), {"a": 1}),
                                         (lambda: chain_scene(12, tol=0.05, universal=True), {}),
                                         (_nand, {"a": 1, "b": 0})])
@pytest.mark.parametrize("rot_noise", [False, True])
def test_blocks_noise_and_solve_match_rows_and_superlu(make, drives, rot_noise):
    assert _compare(_sim(make(), drives, rot_noise=rot_noise), rot_noise) == 0


def test_a_wca_contact_joins_the_pattern_and_matches_the_reference():
    sc = bonded_pairs(3)
    sim = Simulation(sc, {}, SimOptions(scheme="implicit", kT=1e-3, seed=0, dt=0.05))
    sim._eval()
    sim._imp._block(1.0, False, np.uint64(0), np.uint64(0), False)
    nblk = sim._imp._pat.nblk
    # body 2 (the second pair) moved to 0.15 sigma of body 1: a contact between unbonded bodies
    sim.pos[2] = sim.pos[1] + [0.15, 0.02, 0.0]
    sim._eval()
    assert sim.dmin.min() < 2 * sim.opt.wca_r0
    assert _compare(sim, False) == 1
    assert sim._imp._pat.nblk == nblk + 1
    assert (1, 2) in sim._imp._extra


def test_a_trajectory_is_the_reference_paths():
    sc = _nand()
    out = {}
    for backend in ("superlu", "block"):
        sim = Simulation(sc, {"a": 1, "b": 1}, SimOptions(scheme="implicit", kT=1e-5, seed=7, dt=0.2))
        sim._imp.backend = backend
        sim.run(6.0)
        out[backend] = (sim.pos.copy(), sim.stages_out[0])
    assert out["block"][1] == out["superlu"][1]               # the same steps split
    assert np.abs(out["block"][0] - out["superlu"][0]).max() < 1e-8
    assert np.abs(out["block"][0] - sc_pos(sc)).max() > 1e-3  # the gate moved


def sc_pos(sc):
    return np.array([b.position for b in sc.bodies])


def test_eig3_matches_numpy_including_repeated_eigenvalues():
    rng = np.random.default_rng(1)
    mats = [rng.normal(size=(3, 3)) for _ in range(200)]
    mats = [0.5 * (m + m.T) for m in mats]
    mats += [np.diag([2.0, 2.0, -1.0]), np.zeros((3, 3)), np.eye(3) * 1e-20,
             np.outer([1.0, 2, 3], [1.0, 2, 3])]
    for m in mats:
        lam = np.zeros(3)
        V = np.zeros((3, 3))
        BC._eig3(m.copy(), lam, V)
        ref = np.linalg.eigvalsh(m)
        scale = max(1.0, np.abs(ref).max())
        assert np.abs(lam - ref).max() <= 1e-12 * scale
        assert np.abs(V @ np.diag(lam) @ V.T - m).max() <= 1e-12 * scale
        assert np.abs(V.T @ V - np.eye(3)).max() <= 1e-12


def test_symbolic_pattern_holds_every_bond_and_its_fill():
    # a ring of 6 bodies: eliminating one joins its two neighbours (fill)
    bi = np.arange(6)
    bj = (bi + 1) % 6
    P = BC.symbolic(6, bi, bj)
    L = np.zeros((6, 6), bool)
    for k in range(6):
        for e in range(P.colptr[k], P.colptr[k + 1]):
            assert P.rowidx[e] > k
            L[P.rowidx[e], k] = True
    for a, b in zip(P.pos[bi], P.pos[bj]):
        assert L[max(a, b), min(a, b)]
    assert L.sum() == 6 + 3                 # a ring of n by minimum degree: n - 3 fill blocks
    with pytest.raises(ValueError):
        BC.symbolic(2, [0], [0])
