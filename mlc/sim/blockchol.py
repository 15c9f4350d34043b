"""The implicit scheme's step matrix ``D/h + H+`` as 6x6 blocks, one per body, and its
Cholesky factor with a symbolic structure computed once per scene.

Units as in :mod:`mlc.sim.kernels` (sigma, k0, gamma; h in gamma/k0).

:class:`mlc.sim.implicit.Implicit` builds ``H+ = G^T G`` from rows of ``G`` (its module doc
lists them).  Every row acts on at most two bodies, and which two is fixed by the scene's bonds
(a WCA contact aside, below), so the block pattern of ``H+`` is the scene's bond graph, whatever
the state.  Here that is used three ways:

* :func:`symbolic` orders the bodies once by minimum degree on the bond graph and lists the
  factor's pattern (the elimination graph's cliques: every block of ``L``, fill included) and,
  for each column, where each of its block products goes;
* :func:`assemble_bonds`, :func:`assemble_rot` and :func:`assemble_contacts` add each row's
  ``g g^T`` straight into those blocks (no sparse matrix is formed; a zero-length bond's three
  rows summed in closed form), and each row's noise ``g xi`` (scaled as the module doc of
  :mod:`mlc.sim.implicit` says) into a vector, in the row order of ``Implicit.rows``, so the same
  seed draws the same normals for the same row;
* :func:`factor` (right-looking block Cholesky) and :func:`solve` work on those blocks.

A WCA contact (centres within ``2 r0``) is a row between two bodies that need not be bonded:
``Implicit`` then computes the pattern again with that pair, and the pairs in its bodies'
neighbour lists, added (``symbolic``'s ``ei``, ``ej``), and keeps it for the rest of the run.
The rotational rows' eigenvectors come from Jacobi rotations (:func:`rot_eig`), not LAPACK:
the same ``H+``; with rotational noise, the same noise in law.

Cost, for a scene of N bodies in chains: the pattern's blocks and products grow with N (no
ordering, no sparse products, no Python loop per row in a step).  ``tests/test_sim_blockchol.py``
checks the blocks against ``G^T G`` from ``Implicit.rows``, the solve against SuperLU's, and a
short trajectory of each path against the other.
"""
from __future__ import annotations

import heapq
import math

import numpy as np
from numba import njit

from mlc.sim import kernels as K


class Pattern:
    """The block structure of one scene's step matrix and of its Cholesky factor.

    ``order[k]`` is the body eliminated k-th and ``pos`` its inverse; column k of ``L`` has its
    off-diagonal blocks at ``rowidx[colptr[k]:colptr[k+1]]`` (elimination indices, ascending);
    ``upd_tgt[upd_ptr[k]:upd_ptr[k+1]]`` is, for each pair a > b of those blocks in that order,
    the block that ``L_a L_b^T`` is subtracted from; ``bond_blk[s]`` is the block of bond s's
    two bodies (``bond_flip[s]``: stored as (j, i) rather than (i, j))."""

    def __init__(self, order, pos, colptr, rowidx, upd_ptr, upd_tgt, bond_blk, bond_flip, where):
        self.order, self.pos = order, pos
        self.colptr, self.rowidx = colptr, rowidx
        self.upd_ptr, self.upd_tgt = upd_ptr, upd_tgt
        self.bond_blk, self.bond_flip = bond_blk, bond_flip
        self.where = where               # (row, column) in elimination indices -> block
        self.N = len(order)
        self.nblk = len(rowidx)

    def holds(self, ci, cj) -> bool:
        """Whether the factor's pattern has a block for every body pair (ci[m], cj[m])."""
        a, b = self.pos[ci], self.pos[cj]
        return all((x, y) in self.where for x, y in zip(np.maximum(a, b).tolist(), np.minimum(a, b).tolist()))

    def pair_blk(self, ci, cj):
        """The block of each body pair (ci[m], cj[m]) (``holds`` must be true)."""
        a, b = self.pos[ci], self.pos[cj]
        return np.array([self.where[(x, y)] for x, y in zip(np.maximum(a, b).tolist(), np.minimum(a, b).tolist())],
                        np.int64)


def symbolic(N: int, bi, bj, ei=(), ej=()) -> Pattern:
    """The pattern for N bodies joined by rows between bodies ``bi[s]`` and ``bj[s]`` (every
    bond of the scene) and between ``ei[m]`` and ``ej[m]`` (WCA contacts met so far; not in
    ``bond_blk``).  Minimum degree (least current degree first, ties by body index), with
    the elimination graph kept explicitly: each eliminated body's neighbours become a clique, so
    its neighbour set is exactly its column of ``L``."""
    bi = np.asarray(bi, np.int64)
    bj = np.asarray(bj, np.int64)
    ei = np.asarray(ei, np.int64)
    ej = np.asarray(ej, np.int64)
    if np.any(bi == bj) or np.any(ei == ej):
        raise ValueError("a row on one body twice: the block assembly assumes two bodies")
    adj = [set() for _ in range(N)]
    for a, b in zip(bi.tolist() + ei.tolist(), bj.tolist() + ej.tolist()):
        adj[a].add(b)
        adj[b].add(a)
    heap = [(len(adj[i]), i) for i in range(N)]
    heapq.heapify(heap)
    done = np.zeros(N, bool)
    order = []
    cols = []
    while heap:
        d, i = heapq.heappop(heap)
        if done[i] or d != len(adj[i]):
            continue
        done[i] = True
        order.append(i)
        nb = adj[i]
        cols.append(nb)
        for a in nb:
            s = adj[a]
            s.discard(i)
            s |= nb
            s.discard(a)
            heapq.heappush(heap, (len(s), a))
        adj[i] = set()
    order = np.array(order, np.int64)
    pos = np.empty(N, np.int64)
    pos[order] = np.arange(N)
    colptr = np.zeros(N + 1, np.int64)
    rows = []
    for k, nb in enumerate(cols):
        r = sorted(int(pos[x]) for x in nb)
        rows.append(r)
        colptr[k + 1] = colptr[k] + len(r)
    rowidx = np.array([x for r in rows for x in r], np.int64)
    where = {}
    for k, r in enumerate(rows):
        for e, x in enumerate(r):
            where[(x, k)] = colptr[k] + e
    upd_ptr = np.zeros(N + 1, np.int64)
    tgt = []
    for k, r in enumerate(rows):
        for a in range(len(r)):
            for b in range(a):
                tgt.append(where[(r[a], r[b])])
        upd_ptr[k + 1] = len(tgt)
    upd_tgt = np.array(tgt, np.int64)
    pi, pj = pos[bi], pos[bj]
    flip = pi < pj                      # block (pos i, pos j) lives in column min(pi, pj)
    blk = np.array([where[(max(a, b), min(a, b))] for a, b in zip(pi.tolist(), pj.tolist())], np.int64)
    return Pattern(order, pos, colptr, rowidx, upd_ptr, upd_tgt, blk, flip.astype(np.bool_), where)


# -- assembly ------------------------------------------------------------------------------

@njit(cache=True)
def _normals(seed2, key, n):
    """The first n fresh normals for counter (seed2, key), as ``mlc.sim.implicit.normals`` draws them."""
    out = np.empty(n)
    for i in range((n + 1) // 2):
        x, y = K.gauss2(seed2, key, i)
        out[2 * i] = x
        if 2 * i + 1 < n:
            out[2 * i + 1] = y
    return out


@njit(cache=True)
def _row(p, q, gp, gq, flip, blk_e, diag, blk, pos, noisy, xi, rot, gamma, gamma_r, bvec):
    """Add a two-body row (gp on body p, gq on body q, 6 each) to the blocks and its noise."""
    dp = diag[pos[p]]
    dq = diag[pos[q]]
    B = blk[blk_e]
    for a in range(6):
        for b in range(6):
            dp[a, b] += gp[a] * gp[b]
            dq[a, b] += gq[a] * gq[b]
            if flip:
                B[a, b] += gq[a] * gp[b]
            else:
                B[a, b] += gp[a] * gq[b]
    if noisy:
        _noise(p, q, gp, gq, xi, rot, gamma, gamma_r, bvec)


@njit(cache=True)
def _noise(p, q, gp, gq, xi, rot, gamma, gamma_r, bvec):
    """A row's noise xi g, scaled without rotational noise by the square root of its share of
    translational mobility (mlc.sim.implicit's module doc)."""
    s = xi
    if not rot:
        gt = 0.0
        ga = 0.0
        for a in range(3):
            gt += (gp[a] * gp[a] + gq[a] * gq[a]) / gamma
            ga += (gp[a] * gp[a] + gq[a] * gq[a]) / gamma
            ga += (gp[a + 3] * gp[a + 3] + gq[a + 3] * gq[a + 3]) / gamma_r
        s = xi * math.sqrt(gt / max(ga, 1e-300))
    for a in range(6):
        bvec[p, a] += s * gp[a]
        bvec[q, a] += s * gq[a]


@njit(cache=True)
def _site_row(r0, r1, r2, ai, aj, gp, gq):
    """The row (r, a_i x r) on site i's body and -(r, a_j x r) on site j's."""
    gp[0], gp[1], gp[2] = r0, r1, r2
    gp[3] = ai[1] * r2 - ai[2] * r1
    gp[4] = ai[2] * r0 - ai[0] * r2
    gp[5] = ai[0] * r1 - ai[1] * r0
    gq[0], gq[1], gq[2] = -r0, -r1, -r2
    gq[3] = -(aj[1] * r2 - aj[2] * r1)
    gq[4] = -(aj[2] * r0 - aj[0] * r2)
    gq[5] = -(aj[0] * r1 - aj[1] * r0)


@njit(cache=True)
def _zero_bond(p, q, k, ai, aj, flip, blk_e, diag, blk, pos):
    """The three rows of a zero-length bond summed.  With X v = a x v (X^T = -X) and
    M = [I; X] (6 x 3): k M_i M_i^T on body p, k M_j M_j^T on q and -k M_i M_j^T between
    them, where X_i X_j^T = (a_i . a_j) I - a_j a_i^T."""
    dp = diag[pos[p]]
    dq = diag[pos[q]]
    B = blk[blk_e]
    x0, x1, x2 = ai[0], ai[1], ai[2]
    y0, y1, y2 = aj[0], aj[1], aj[2]
    xx = x0 * x0 + x1 * x1 + x2 * x2
    yy = y0 * y0 + y1 * y1 + y2 * y2
    xy = x0 * y0 + x1 * y1 + x2 * y2
    for m in range(3):
        dp[m, m] += k
        dq[m, m] += k
        dp[3 + m, 3 + m] += k * xx
        dq[3 + m, 3 + m] += k * yy
    # X as (row, column, entry): X[1,0] = a2, X[2,1] = a0, X[0,2] = a1 and minus their transposes
    for (m, n, ci) in ((1, 0, 2), (2, 1, 0), (0, 2, 1)):
        # diag blocks: [[kI, -kX], [kX, k(|a|^2 I - a a^T)]]
        dp[3 + m, n] += k * ai[ci]
        dp[3 + n, m] -= k * ai[ci]
        dp[m, 3 + n] -= k * ai[ci]
        dp[n, 3 + m] += k * ai[ci]
        dq[3 + m, n] += k * aj[ci]
        dq[3 + n, m] -= k * aj[ci]
        dq[m, 3 + n] -= k * aj[ci]
        dq[n, 3 + m] += k * aj[ci]
    for m in range(3):
        for n in range(3):
            dp[3 + m, 3 + n] -= k * ai[m] * ai[n]
            dq[3 + m, 3 + n] -= k * aj[m] * aj[n]
    # M[p, q] = -k [[I, -X_j], [X_i, (a_i.a_j) I - a_j a_i^T]]; stored transposed when flipped
    for m in range(3):
        _add(B, flip, m, m, -k)
        _add(B, flip, 3 + m, 3 + m, -k * xy)
        for n in range(3):
            _add(B, flip, 3 + m, 3 + n, k * aj[m] * ai[n])
    for (m, n, ci) in ((1, 0, 2), (2, 1, 0), (0, 2, 1)):
        _add(B, flip, m, 3 + n, k * aj[ci])          # -k (-X_j)[m, n]
        _add(B, flip, n, 3 + m, -k * aj[ci])
        _add(B, flip, 3 + m, n, -k * ai[ci])         # -k X_i[m, n]
        _add(B, flip, 3 + n, m, k * ai[ci])


@njit(cache=True, inline="always")
def _add(B, flip, r, c, v):
    if flip:
        B[c, r] += v
    else:
        B[r, c] += v


@njit(cache=True)
def assemble_bonds(ws, arm, sb, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp, uval, iz, isc,
                   bond_blk, bond_flip, pos, Dh, diag, blk, grad, noisy, seed2, key, rot, gamma, gamma_r, bvec):
    """Reset ``diag`` to diag(D/h) and ``blk`` to 0, then add every bond row of
    ``Implicit.rows`` (zero-length bonds' three axes, the others along the bond and, under
    tension, across it), in its row order; ``grad`` gets dE/dp at every site and ``bvec``
    (when ``noisy``) each row's noise ``sqrt(f) xi_r g`` (without the factor sqrt(kT)).
    Returns the number of rows."""
    N = diag.shape[0]
    for k in range(N):
        for a in range(6):
            for b in range(6):
                diag[k, a, b] = 0.0
    for b_ in range(N):
        k = pos[b_]
        for a in range(6):
            diag[k, a, a] = Dh[6 * b_ + a]
    blk[:] = 0.0
    grad[:] = 0.0
    if noisy:
        bvec[:] = 0.0
    nz = len(iz)
    # the others: which are outside their tolerance, which of those stretched
    ns = len(isc)
    e_ = np.zeros(ns)
    u_ = np.zeros((ns, 3))
    nrm = np.zeros(ns)
    act = np.zeros(ns, np.bool_)
    ten = np.zeros(ns, np.bool_)
    sg = np.zeros(ns)
    nact = 0
    nten = 0
    for m in range(ns):
        s = isc[m]
        i, j = sp_i[s], sp_j[s]
        rest = sp_rest0[s]
        if sp_inp[s] >= 0:
            rest += uval[sp_inp[s]] * (sp_rest1[s] - rest)
        d0 = ws[i, 0] - ws[j, 0]
        d1 = ws[i, 1] - ws[j, 1]
        d2 = ws[i, 2] - ws[j, 2]
        n_ = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        dev = n_ - rest
        e = abs(dev) - sp_tol[s]
        if e > 0 and n_ > 1e-300:
            act[m] = True
            nact += 1
            e_[m] = e
            nrm[m] = n_
            u_[m, 0], u_[m, 1], u_[m, 2] = d0 / n_, d1 / n_, d2 / n_
            sg[m] = 1.0 if dev > 0 else (-1.0 if dev < 0 else 0.0)
            if sp_k[s] * e * sg[m] / n_ > 0:
                ten[m] = True
                nten += 1
    r0 = 3 * nz
    ra = 0
    rt = 0
    xis = _normals(seed2, key, r0 + nact + 2 * nten if noisy else 0)
    gp = np.zeros(6)
    gq = np.zeros(6)
    # zero-length bonds: sqrt(k) times each axis (rows c * nz + n), the three rows' sum at once
    for n in range(nz):
        s = iz[n]
        i, j = sp_i[s], sp_j[s]
        _zero_bond(sb[i], sb[j], sp_k[s], arm[i], arm[j], bond_flip[s], bond_blk[s], diag, blk, pos)
        if noisy:
            sk = math.sqrt(sp_k[s])
            for c in range(3):
                _site_row(sk if c == 0 else 0.0, sk if c == 1 else 0.0, sk if c == 2 else 0.0, arm[i], arm[j], gp, gq)
                _noise(sb[i], sb[j], gp, gq, xis[c * nz + n], rot, gamma, gamma_r, bvec)
    for n in range(nz):
        s = iz[n]
        i, j = sp_i[s], sp_j[s]
        for a in range(3):
            g = sp_k[s] * (ws[i, a] - ws[j, a])
            grad[i, a] += g
            grad[j, a] -= g
    for m in range(ns):
        if not act[m]:
            continue
        s = isc[m]
        i, j = sp_i[s], sp_j[s]
        k = sp_k[s]
        u0, u1, u2 = u_[m, 0], u_[m, 1], u_[m, 2]
        g = k * e_[m] * sg[m]
        grad[i, 0] += g * u0
        grad[i, 1] += g * u1
        grad[i, 2] += g * u2
        grad[j, 0] -= g * u0
        grad[j, 1] -= g * u1
        grad[j, 2] -= g * u2
        sk = math.sqrt(k)
        _site_row(sk * u0, sk * u1, sk * u2, arm[i], arm[j], gp, gq)
        xi = xis[r0 + ra] if noisy else 0.0
        _row(sb[i], sb[j], gp, gq, bond_flip[s], bond_blk[s], diag, blk, pos, noisy, xi, rot, gamma, gamma_r, bvec)
        ra += 1
        if ten[m]:
            # two unit vectors across u, as Implicit.rows picks them
            hx, hy = (1.0, 0.0) if abs(u0) < 0.9 else (0.0, 1.0)
            t10 = u1 * 0.0 - u2 * hy
            t11 = u2 * hx - u0 * 0.0
            t12 = u0 * hy - u1 * hx
            tn = math.sqrt(t10 * t10 + t11 * t11 + t12 * t12)
            t10, t11, t12 = t10 / tn, t11 / tn, t12 / tn
            t20 = u1 * t12 - u2 * t11
            t21 = u2 * t10 - u0 * t12
            t22 = u0 * t11 - u1 * t10
            sq = math.sqrt(k * e_[m] * sg[m] / nrm[m])
            _site_row(sq * t10, sq * t11, sq * t12, arm[i], arm[j], gp, gq)
            xi = xis[r0 + nact + rt] if noisy else 0.0
            _row(sb[i], sb[j], gp, gq, bond_flip[s], bond_blk[s], diag, blk, pos, noisy, xi, rot, gamma, gamma_r, bvec)
            _site_row(sq * t20, sq * t21, sq * t22, arm[i], arm[j], gp, gq)
            xi = xis[r0 + nact + nten + rt] if noisy else 0.0
            _row(sb[i], sb[j], gp, gq, bond_flip[s], bond_blk[s], diag, blk, pos, noisy, xi, rot, gamma, gamma_r, bvec)
            rt += 1
    return r0 + nact + 2 * nten


@njit(cache=True)
def _eig3(A, lam, V):
    """Eigenvalues (ascending, into lam) and eigenvectors (columns of V) of the symmetric 3x3 A
    (overwritten) by cyclic Jacobi rotations A <- P^T A P (Numerical Recipes' convention)."""
    for a in range(3):
        for b in range(3):
            V[a, b] = 1.0 if a == b else 0.0
    for sweep in range(60):
        off = A[0, 1] * A[0, 1] + A[0, 2] * A[0, 2] + A[1, 2] * A[1, 2]
        dia = A[0, 0] * A[0, 0] + A[1, 1] * A[1, 1] + A[2, 2] * A[2, 2]
        if off <= 1e-36 * dia or off == 0.0:
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = A[p, q]
            if apq == 0.0:
                continue
            th = (A[q, q] - A[p, p]) / (2.0 * apq)
            t = 1.0 / (abs(th) + math.sqrt(th * th + 1.0))
            if th < 0.0:
                t = -t
            c = 1.0 / math.sqrt(t * t + 1.0)
            s = t * c
            for r in range(3):              # A <- A P
                arp, arq = A[r, p], A[r, q]
                A[r, p] = c * arp - s * arq
                A[r, q] = s * arp + c * arq
            for r in range(3):              # A <- P^T A
                apr, aqr = A[p, r], A[q, r]
                A[p, r] = c * apr - s * aqr
                A[q, r] = s * apr + c * aqr
            A[p, q] = 0.0
            A[q, p] = 0.0
            for r in range(3):              # V <- V P
                vrp, vrq = V[r, p], V[r, q]
                V[r, p] = c * vrp - s * vrq
                V[r, q] = s * vrp + c * vrq
    for a in range(3):
        lam[a] = A[a, a]
    for a in range(3):                      # ascending, as numpy's eigh
        m = a
        for b in range(a + 1, 3):
            if lam[b] < lam[m]:
                m = b
        if m != a:
            lam[a], lam[m] = lam[m], lam[a]
            for r in range(3):
                V[r, a], V[r, m] = V[r, m], V[r, a]


@njit(cache=True)
def rot_eig(grad, arm, sb, N, lam, vec):
    """Each body's rotational geometric stiffness ``Q = sum_s [(g a^T + a g^T)/2 - (g.a) I]``
    over its sites (``grad`` dE/dp at each site, ``arm`` its arm), as eigenpairs: lam (N, 3)
    ascending, vec (N, 3, 3) columns (what ``Implicit.rot_stiffness`` gets from numpy)."""
    Q = np.zeros((N, 3, 3))
    for s in range(sb.shape[0]):
        b = sb[s]
        ga = grad[s, 0] * arm[s, 0] + grad[s, 1] * arm[s, 1] + grad[s, 2] * arm[s, 2]
        for i in range(3):
            for j in range(3):
                Q[b, i, j] += 0.5 * (grad[s, i] * arm[s, j] + arm[s, i] * grad[s, j])
            Q[b, i, i] -= ga
    for b in range(N):
        _eig3(Q[b], lam[b], vec[b])


@njit(cache=True)
def assemble_rot(lam, vec, thresh, pos, diag, row0, noisy, seed2, key, rot, bvec):
    """Each body's rotational geometric stiffness: the positive eigenpairs of its 3x3 ``Q``
    (``lam`` (N, 3), ``vec`` (N, 3, 3) as numpy's eigh gives them), rows numbered from row0 in
    body-major order, as ``Implicit.rows``.  Such a row has no translational part, so without
    rotational noise its noise share is 0.  Returns the number of rows added."""
    N = lam.shape[0]
    nr = 0
    xis = np.empty(0)
    if noisy and rot:
        n = 0
        for b in range(N):
            for c in range(3):
                if lam[b, c] > thresh:
                    n += 1
        allx = _normals(seed2, key, row0 + n)
        xis = allx[row0:]
    for b in range(N):
        D = diag[pos[b]]
        for c in range(3):
            if lam[b, c] > thresh:
                sq = math.sqrt(lam[b, c])
                for a in range(3):
                    for a2 in range(3):
                        D[3 + a, 3 + a2] += lam[b, c] * vec[b, a, c] * vec[b, a2, c]
                if noisy and rot:
                    xi = xis[nr]
                    for a in range(3):
                        bvec[b, 3 + a] += xi * sq * vec[b, a, c]
                nr += 1
    return nr


@njit(cache=True)
def assemble_contacts(ci, cj, cv, cblk, cflip, pos, diag, blk, row0, noisy, seed2, key, bvec):
    """The WCA contacts' rows (``cv[m]`` on body ci[m]'s translation, minus it on cj[m]'s),
    numbered from row0 as ``Implicit.rows`` numbers them; translational only, so each row's noise
    share is 1."""
    n = len(ci)
    xis = _normals(seed2, key, row0 + n) if noisy else np.zeros(0)
    gp = np.zeros(6)
    gq = np.zeros(6)
    for m in range(n):
        for a in range(3):
            gp[a] = cv[m, a]
            gq[a] = -cv[m, a]
        xi = xis[row0 + m] if noisy else 0.0
        _row(ci[m], cj[m], gp, gq, cflip[m], cblk[m], diag, blk, pos, noisy, xi, True, 1.0, 1.0, bvec)


# -- factor and solve -----------------------------------------------------------------------

@njit(cache=True)
def _chol6(A):
    """In-place lower Cholesky factor of a 6x6 block; False when not positive definite."""
    for j in range(6):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        if not (s > 0.0):
            return False
        d = math.sqrt(s)
        A[j, j] = d
        for i in range(j + 1, 6):
            t = A[i, j]
            for k in range(j):
                t -= A[i, k] * A[j, k]
            A[i, j] = t / d
    for j in range(6):
        for i in range(j):
            A[i, j] = 0.0
    return True


@njit(cache=True)
def factor(diag, blk, colptr, rowidx, upd_ptr, upd_tgt):
    """Right-looking block Cholesky in place: ``diag[k]`` becomes L_kk, ``blk[e]`` the
    off-diagonal block of L.  Returns -1, or the column that was not positive definite."""
    N = diag.shape[0]
    for k in range(N):
        L = diag[k]
        if not _chol6(L):
            return k
        c0, c1 = colptr[k], colptr[k + 1]
        for e in range(c0, c1):
            B = blk[e]
            # B <- B L^-T: each row x of B solves L x^T = b^T
            for r in range(6):
                for j in range(6):
                    t = B[r, j]
                    for m in range(j):
                        t -= B[r, m] * L[j, m]
                    B[r, j] = t / L[j, j]
        m = upd_ptr[k]
        for a in range(c0, c1):
            Ba = blk[a]
            Da = diag[rowidx[a]]
            for r in range(6):
                for c in range(r + 1):
                    t = 0.0
                    for x in range(6):
                        t += Ba[r, x] * Ba[c, x]
                    Da[r, c] -= t
                    if c != r:
                        Da[c, r] -= t
            for b in range(c0, a):
                Bb = blk[b]
                T = blk[upd_tgt[m]]
                m += 1
                for r in range(6):
                    for c in range(6):
                        T[r, c] -= (Ba[r, 0] * Bb[c, 0] + Ba[r, 1] * Bb[c, 1] + Ba[r, 2] * Bb[c, 2]
                                    + Ba[r, 3] * Bb[c, 3] + Ba[r, 4] * Bb[c, 4] + Ba[r, 5] * Bb[c, 5])
    return -1


@njit(cache=True)
def solve(diag, blk, colptr, rowidx, order, rhs, out):
    """out = A^-1 rhs for the factored A (rhs, out: (N, 6) by body)."""
    N = diag.shape[0]
    y = np.empty((N, 6))
    for k in range(N):
        for a in range(6):
            y[k, a] = rhs[order[k], a]
    for k in range(N):
        L = diag[k]
        for a in range(6):
            t = y[k, a]
            for m in range(a):
                t -= L[a, m] * y[k, m]
            y[k, a] = t / L[a, a]
        for e in range(colptr[k], colptr[k + 1]):
            B = blk[e]
            r = rowidx[e]
            for a in range(6):
                t = 0.0
                for m in range(6):
                    t += B[a, m] * y[k, m]
                y[r, a] -= t
    for k in range(N - 1, -1, -1):
        for e in range(colptr[k], colptr[k + 1]):
            B = blk[e]
            r = rowidx[e]
            for a in range(6):
                t = 0.0
                for m in range(6):
                    t += B[m, a] * y[r, m]
                y[k, a] -= t
        L = diag[k]
        for a in range(5, -1, -1):
            t = y[k, a]
            for m in range(a + 1, 6):
                t -= L[m, a] * y[k, m]
            y[k, a] = t / L[a, a]
    for k in range(N):
        for a in range(6):
            out[order[k], a] = y[k, a]
