"""Compiled (Numba) kernels of the Brownian-dynamics integrator.

Internal units: sigma (length), k0 (stiffness), gamma (drag), time in gamma/k0
(= 1e-3 t0).  Everything here works on contiguous arrays (see :mod:`mlc.sim.pack`);
the whole time loop (:func:`run_euler`, :func:`run_skrock`) is compiled, Python only
calls it once per chunk of steps.

Bodies: ``pos`` (N,3), ``quat`` (N,4) unit quaternions [w,x,y,z] body -> world.
Springs unify bonds and muscles: site indices ``sp_i``/``sp_j``, stiffness, rest
length ``rest0 + u(t) (rest1 - rest0)`` with ``u`` the drive value of input
``sp_inp`` (-1 = a plain bond), flat-bottom tolerance ``sp_tol``:
``U = k/2 max(0, |dist - rest| - tol)^2``.  WCA acts between body centres
(``U = 4 eps [(s/r)^12 - (s/r)^6] + eps`` for ``r < rc``) found through a Verlet
list (radius 1.5 rc) rebuilt through a hashed cell list; bonded body pairs are
excluded.

Random numbers are counter based (splitmix64 of seed, step, body, component):
the same seed gives the same trajectory, whatever the chunking or thread count.

Every kernel runs with ``prange`` loops; the serial variants are the same Python
functions compiled without ``parallel`` (see the bottom of this module).
"""
from __future__ import annotations

import math
import types

import numpy as np
from numba import njit, prange

# Parallel kernels (threads > 1) prefer OpenMP over TBB unless the user chose a layer (set by
# mlc/__init__.py for every process that imports mlc): with TBB, one advance() of many tiny
# parallel steps slows down as it runs (8 bodies, 2 threads, idle machine: 0.025 ms/step over
# 200 steps, 0.24 over 2000, 6.7 over 20000), while OpenMP stays at 0.0054 ms/step
# (docs/simulation.md, "Benchmarks", throughput).

# failure codes returned in status[0]
OK, STRETCH, WCA_CLOSE, DISPLACEMENT, NONFINITE, OVERFLOW = 0, 1, 2, 3, 4, 5
LMAX = 30          # deepest substep level of the stiff scheme: dt / 2^30

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_G = np.uint64(0x9E3779B97F4A7C15)
_H = np.uint64(0xD1B54A32D192ED03)
_S30 = np.uint64(30)
_S27 = np.uint64(27)
_S31 = np.uint64(31)
_S32 = np.uint64(32)
_MASK32 = np.uint64(0xFFFFFFFF)


@njit(cache=True)
def _mix(z):
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@njit(cache=True)
def gauss2(seed, step, idx):
    """Two independent standard normals for counter (seed, step, idx)."""
    z = _mix(np.uint64(seed) * _G + np.uint64(step) * _H + np.uint64(idx) * _M1 + np.uint64(1))
    z = _mix(z + _G)
    a = np.float64(z >> _S32)
    b = np.float64(z & _MASK32)
    u1 = (a + 1.0) * 2.3283064365386963e-10    # (0, 1]
    u2 = b * 2.3283064365386963e-10            # [0, 1)
    r = math.sqrt(-2.0 * math.log(u1))
    t = 6.283185307179586 * u2
    return r * math.cos(t), r * math.sin(t)


@njit(cache=True)
def drive_values(t, dkind, dpar, tab_t, tab_v, out):
    """Drive value u(t) of every input (0 = rest, 1 = actuated, fractions interpolate)."""
    for k in range(dkind.shape[0]):
        kind = dkind[k]
        p = dpar[k]
        if kind == 0:          # constant
            v = p[0]
        elif kind == 1:        # step at p[0] from p[1] to p[2]
            v = p[1] if t < p[0] else p[2]
        elif kind == 2:        # square wave: period p[0], duty p[1], start p[2], low p[3], high p[4]
            if t < p[2]:
                v = p[3]
            else:
                ph = ((t - p[2]) % p[0]) / p[0]
                v = p[4] if ph < p[1] else p[3]
        else:                  # piecewise-linear table rows p[0] .. p[0]+p[1]
            o = int(p[0])
            n = int(p[1])
            if t <= tab_t[o]:
                v = tab_v[o]
            elif t >= tab_t[o + n - 1]:
                v = tab_v[o + n - 1]
            else:
                v = tab_v[o]
                for m in range(o, o + n - 1):
                    if tab_t[m] <= t < tab_t[m + 1]:
                        w = (t - tab_t[m]) / (tab_t[m + 1] - tab_t[m])
                        v = tab_v[m] + w * (tab_v[m + 1] - tab_v[m])
                        break
        out[k] = v


@njit(cache=True)
def quat_exp_mul(wx, wy, wz, q0, q1, q2, q3):
    """exp(w) (as a unit quaternion) times q, normalised."""
    th = math.sqrt(wx * wx + wy * wy + wz * wz)
    if th < 1e-8:
        c = 1.0 - th * th / 8.0
        s = 0.5 - th * th / 48.0
    else:
        c = math.cos(0.5 * th)
        s = math.sin(0.5 * th) / th
    a0, a1, a2, a3 = c, s * wx, s * wy, s * wz
    r0 = a0 * q0 - a1 * q1 - a2 * q2 - a3 * q3
    r1 = a0 * q1 + a1 * q0 + a2 * q3 - a3 * q2
    r2 = a0 * q2 - a1 * q3 + a2 * q0 + a3 * q1
    r3 = a0 * q3 + a1 * q2 - a2 * q1 + a3 * q0
    n = 1.0 / math.sqrt(r0 * r0 + r1 * r1 + r2 * r2 + r3 * r3)
    return r0 * n, r1 * n, r2 * n, r3 * n


@njit(cache=True)
def _cell_key(cx, cy, cz, mask):
    h = (cx * 73856093) ^ (cy * 19349663) ^ (cz * 83492791)
    return h & mask


@njit(cache=True)
def build_cells(pos, h, head, nxt, cell):
    """Hashed cell list with cell size ``h`` (>= 2 rc); ``head`` has a power-of-two size."""
    mask = head.shape[0] - 1
    head[:] = -1
    for i in range(pos.shape[0]):
        cx = int(math.floor(pos[i, 0] / h))
        cy = int(math.floor(pos[i, 1] / h))
        cz = int(math.floor(pos[i, 2] / h))
        cell[i, 0] = cx
        cell[i, 1] = cy
        cell[i, 2] = cz
        k = _cell_key(cx, cy, cz, mask)
        nxt[i] = head[k]
        head[k] = i


@njit(cache=True)
def nlist_update(pos, rc, skin, head, nxt, cell, ex0, ex_list, nl0, nl, pos_nl, nlstate):
    """Verlet neighbour list of radius rc + skin (bonded pairs left out), rebuilt through
    the cell list when a body moved more than skin/2 since the last build.  Returns
    True when the list is valid; False when it overflowed ``nl`` (nlstate[2] counts
    overflows, nlstate[3] the size needed: the caller stops, grows ``nl`` and redoes the
    work).  nlstate[0] = list valid, nlstate[1] = builds."""
    N = pos.shape[0]
    need = nlstate[0] == 0.0
    if not need:
        lim2 = 0.25 * skin * skin
        for b in range(N):
            dx = pos[b, 0] - pos_nl[b, 0]
            dy = pos[b, 1] - pos_nl[b, 1]
            dz = pos[b, 2] - pos_nl[b, 2]
            if not (dx * dx + dy * dy + dz * dz <= lim2):
                need = True
                break
    if not need:
        return True
    rl = rc + skin
    h = 2.0 * rl
    build_cells(pos, h, head, nxt, cell)
    mask = head.shape[0] - 1
    rl2 = rl * rl
    cap = nl.shape[0]
    count = 0
    for b in range(N):
        nl0[b] = count
        px = pos[b, 0]
        py = pos[b, 1]
        pz = pos[b, 2]
        cx0 = cell[b, 0]
        cy0 = cell[b, 1]
        cz0 = cell[b, 2]
        ox = -1 if px - cx0 * h < 0.5 * h else 0
        oy = -1 if py - cy0 * h < 0.5 * h else 0
        oz = -1 if pz - cz0 * h < 0.5 * h else 0
        for ix in range(cx0 + ox, cx0 + ox + 2):
            for iy in range(cy0 + oy, cy0 + oy + 2):
                for iz in range(cz0 + oz, cz0 + oz + 2):
                    j = head[_cell_key(ix, iy, iz, mask)]
                    while j >= 0:
                        if j != b and cell[j, 0] == ix and cell[j, 1] == iy and cell[j, 2] == iz:
                            dx = px - pos[j, 0]
                            dy = py - pos[j, 1]
                            dz = pz - pos[j, 2]
                            if dx * dx + dy * dy + dz * dz < rl2:
                                excluded = False
                                for x in range(ex0[b], ex0[b + 1]):
                                    if ex_list[x] == j:
                                        excluded = True
                                        break
                                if not excluded:
                                    if count < cap:
                                        nl[count] = j
                                    count += 1
                        j = nxt[j]
    nl0[N] = count
    for b in range(N):
        pos_nl[b, 0] = pos[b, 0]
        pos_nl[b, 1] = pos[b, 1]
        pos_nl[b, 2] = pos[b, 2]
    nlstate[1] += 1.0
    if count > cap:
        nlstate[0] = 0.0
        nlstate[2] += 1.0
        nlstate[3] = max(nlstate[3], float(count))
        return False
    nlstate[0] = 1.0
    return True


def _eval_py(pos, quat, t, site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol,
             sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
             wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
             uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon):
    """Forces F and torques T at (pos, quat, t); monitor values into ``mon``:
    mon[0] max stretch ratio, mon[1] its spring, mon[2] min WCA distance, mon[3], mon[4]
    its bodies, mon[5] max WCA curvature |U''| (for the spectral bound)."""
    N = pos.shape[0]
    drive_values(t, dkind, dpar, tab_t, tab_v, uval)
    # sites in the world frame
    for b in prange(N):
        q0 = quat[b, 0]
        q1 = quat[b, 1]
        q2 = quat[b, 2]
        q3 = quat[b, 3]
        r00 = 1 - 2 * (q2 * q2 + q3 * q3)
        r01 = 2 * (q1 * q2 - q0 * q3)
        r02 = 2 * (q1 * q3 + q0 * q2)
        r10 = 2 * (q1 * q2 + q0 * q3)
        r11 = 1 - 2 * (q1 * q1 + q3 * q3)
        r12 = 2 * (q2 * q3 - q0 * q1)
        r20 = 2 * (q1 * q3 - q0 * q2)
        r21 = 2 * (q2 * q3 + q0 * q1)
        r22 = 1 - 2 * (q1 * q1 + q2 * q2)
        for s in range(bsite0[b], bsite0[b + 1]):
            lx = site_local[s, 0]
            ly = site_local[s, 1]
            lz = site_local[s, 2]
            ax = r00 * lx + r01 * ly + r02 * lz
            ay = r10 * lx + r11 * ly + r12 * lz
            az = r20 * lx + r21 * ly + r22 * lz
            arm[s, 0] = ax
            arm[s, 1] = ay
            arm[s, 2] = az
            ws[s, 0] = pos[b, 0] + ax
            ws[s, 1] = pos[b, 1] + ay
            ws[s, 2] = pos[b, 2] + az
    # springs: force on the i end
    for m in prange(sp_i.shape[0]):
        i = sp_i[m]
        j = sp_j[m]
        dx = ws[j, 0] - ws[i, 0]
        dy = ws[j, 1] - ws[i, 1]
        dz = ws[j, 2] - ws[i, 2]
        rest = sp_rest0[m]
        if sp_inp[m] >= 0:
            rest = rest + uval[sp_inp[m]] * (sp_rest1[m] - rest)
        tol = sp_tol[m]
        k = sp_k[m]
        bd = sp_bound[m]
        if rest == 0.0 and tol == 0.0:
            c = k
            # stretch ratio squared (no sqrt on the hot path); mon[0] takes the root
            ratio[m] = (dx * dx + dy * dy + dz * dz) / (bd * bd)
        else:
            dist = math.sqrt(dx * dx + dy * dy + dz * dz)
            dev = dist - rest
            e = abs(dev) - tol
            if e > 0.0 and dist > 1e-300:
                c = k * e / dist
                if dev < 0.0:
                    c = -c
            else:
                c = 0.0
            ratio[m] = e * abs(e) / (bd * bd)        # signed square of e / bound
        fsp[m, 0] = c * dx
        fsp[m, 1] = c * dy
        fsp[m, 2] = c * dz
    # gather per body, then WCA through the Verlet list.  A list that overflowed its buffer
    # leaves WCA out and nlstate[2] > 0: the caller grows the list and redoes the step.
    nlok = True
    if wca_eps > 0.0:
        nlok = nlist_update(pos, wca_rc, 0.5 * wca_rc, head, nxt, cell, ex0, ex_list, nl0, nl, pos_nl, nlstate)
    rc2 = wca_rc * wca_rc
    s2 = wca_s * wca_s
    for b in prange(N):
        fx = 0.0
        fy = 0.0
        fz = 0.0
        tx = 0.0
        ty = 0.0
        tz = 0.0
        for ee in range(end0[b], end0[b + 1]):
            m = end_sp[ee]
            sg = end_sign[ee]
            gx = sg * fsp[m, 0]
            gy = sg * fsp[m, 1]
            gz = sg * fsp[m, 2]
            s = sp_i[m] if sg > 0 else sp_j[m]
            ax = arm[s, 0]
            ay = arm[s, 1]
            az = arm[s, 2]
            fx += gx
            fy += gy
            fz += gz
            tx += ay * gz - az * gy
            ty += az * gx - ax * gz
            tz += ax * gy - ay * gx
        dm = np.inf
        dp = -1
        if wca_eps > 0.0 and nlok:
            px = pos[b, 0]
            py = pos[b, 1]
            pz = pos[b, 2]
            for x in range(nl0[b], nl0[b + 1]):
                j = nl[x]
                dx = px - pos[j, 0]
                dy = py - pos[j, 1]
                dz = pz - pos[j, 2]
                r2 = dx * dx + dy * dy + dz * dz
                if r2 < rc2:
                    ir2 = s2 / r2
                    ir6 = ir2 * ir2 * ir2
                    # F = -dU/dr rhat = 24 eps (2 (s/r)^12 - (s/r)^6) / r^2 * d
                    c = 24.0 * wca_eps * (2.0 * ir6 * ir6 - ir6) / r2
                    fx += c * dx
                    fy += c * dy
                    fz += c * dz
                    r = math.sqrt(r2)
                    if r < dm:
                        dm = r
                        dp = j
        F[b, 0] = fx
        F[b, 1] = fy
        F[b, 2] = fz
        T[b, 0] = tx
        T[b, 1] = ty
        T[b, 2] = tz
        dmin[b] = dm
        dpart[b] = dp
    # reductions (serial, cheap)
    mr = -np.inf
    mi = -1
    for m in range(ratio.shape[0]):
        if not (ratio[m] <= mr):
            if ratio[m] != ratio[m] or ratio[m] > mr:
                mr = ratio[m]
                mi = m
                if mr != mr:
                    break
    md = np.inf
    ma = -1
    for b in range(N):
        if dmin[b] < md:
            md = dmin[b]
            ma = b
    mon[0] = math.sqrt(mr) if mr >= 0.0 else (-math.sqrt(-mr) if mr > -np.inf else mr)
    mon[1] = mi
    mon[2] = md
    mon[3] = ma
    mon[4] = dpart[ma] if ma >= 0 else -1
    if md < wca_rc:
        ir2 = s2 / (md * md)
        ir6 = ir2 * ir2 * ir2
        mon[5] = 24.0 * wca_eps * (26.0 * ir6 * ir6 - 7.0 * ir6) / (md * md)
    else:
        mon[5] = 0.0


def _spectral_py(site_body, arm, sp_i, sp_j, sp_k, end0, end_sp, end_sign, sp_tmp, mob_t, mob_r, v, w, iters):
    """Power iteration for the largest eigenvalue of the mobility-weighted bond Hessian
    M^1/2 (sum_springs k J^T J) M^1/2 (every spring counted as a zero-rest, active bond:
    an upper bound of the true spectrum up to geometric-stiffness terms).  ``v`` (N,6)
    is the warm start and is updated; returns the Rayleigh quotient."""
    N = v.shape[0]
    lam = 0.0
    st = math.sqrt(mob_t)
    sr = math.sqrt(mob_r)
    for it in range(iters):
        nrm = 0.0
        for b in range(N):
            for c in range(6):
                nrm += v[b, c] * v[b, c]
        nrm = math.sqrt(nrm)
        if nrm == 0.0:
            return 0.0
        for b in prange(N):
            for c in range(6):
                v[b, c] /= nrm
        for m in prange(sp_i.shape[0]):
            i = sp_i[m]
            j = sp_j[m]
            bi = site_body[i]
            bj = site_body[j]
            # delta d = (v_j + w_j x a_j) - (v_i + w_i x a_i), scaled by M^1/2
            d0 = 0.0
            d1 = 0.0
            d2 = 0.0
            for side in range(2):
                sgn = 1.0 if side == 0 else -1.0
                s = j if side == 0 else i
                bb = bj if side == 0 else bi
                ux = st * v[bb, 0]
                uy = st * v[bb, 1]
                uz = st * v[bb, 2]
                ox = sr * v[bb, 3]
                oy = sr * v[bb, 4]
                oz = sr * v[bb, 5]
                d0 += sgn * (ux + oy * arm[s, 2] - oz * arm[s, 1])
                d1 += sgn * (uy + oz * arm[s, 0] - ox * arm[s, 2])
                d2 += sgn * (uz + ox * arm[s, 1] - oy * arm[s, 0])
            sp_tmp[m, 0] = sp_k[m] * d0
            sp_tmp[m, 1] = sp_k[m] * d1
            sp_tmp[m, 2] = sp_k[m] * d2
        for b in prange(N):
            fx = 0.0
            fy = 0.0
            fz = 0.0
            tx = 0.0
            ty = 0.0
            tz = 0.0
            for ee in range(end0[b], end0[b + 1]):
                m = end_sp[ee]
                sg = -end_sign[ee]     # body at the j end gets +f, i end -f
                gx = sg * sp_tmp[m, 0]
                gy = sg * sp_tmp[m, 1]
                gz = sg * sp_tmp[m, 2]
                s = sp_i[m] if end_sign[ee] > 0 else sp_j[m]
                ax = arm[s, 0]
                ay = arm[s, 1]
                az = arm[s, 2]
                fx += gx
                fy += gy
                fz += gz
                tx += ay * gz - az * gy
                ty += az * gx - ax * gz
                tz += ax * gy - ay * gx
            w[b, 0] = st * fx
            w[b, 1] = st * fy
            w[b, 2] = st * fz
            w[b, 3] = sr * tx
            w[b, 4] = sr * ty
            w[b, 5] = sr * tz
        lam = 0.0
        for b in range(N):
            for c in range(6):
                lam += v[b, c] * w[b, c]
        for b in prange(N):
            for c in range(6):
                v[b, c] = w[b, c]
    return lam


@njit(cache=True)
def _site_world(pos, quat, b, lx, ly, lz):
    """World position of the body-frame point (lx, ly, lz) of body b."""
    q0 = quat[b, 0]
    q1 = quat[b, 1]
    q2 = quat[b, 2]
    q3 = quat[b, 3]
    x = pos[b, 0] + (1 - 2 * (q2 * q2 + q3 * q3)) * lx + 2 * (q1 * q2 - q0 * q3) * ly + 2 * (q1 * q3 + q0 * q2) * lz
    y = pos[b, 1] + 2 * (q1 * q2 + q0 * q3) * lx + (1 - 2 * (q1 * q1 + q3 * q3)) * ly + 2 * (q2 * q3 - q0 * q1) * lz
    z = pos[b, 2] + 2 * (q1 * q3 - q0 * q2) * lx + 2 * (q2 * q3 + q0 * q1) * ly + (1 - 2 * (q1 * q1 + q2 * q2)) * lz
    return x, y, z


@njit(cache=True)
def _record(n, t, rec_every, rec_phase, rec, nrec, probe_i, probe_j, site_body, site_local,
            frame_every, frame_phase, fpos, fquat, nfr, pos, quat):
    """Record the probe lengths (when (n + rec_phase) is a multiple of ``rec_every``) and a
    frame (likewise with ``frame_every``) of the state (pos, quat); returns ``(nrec, nfr)``."""
    if rec_every > 0 and (n + rec_phase) % rec_every == 0 and nrec < rec.shape[0]:
        rec[nrec, 0] = t
        for p in range(probe_i.shape[0]):
            i = probe_i[p]
            j = probe_j[p]
            xi, yi, zi = _site_world(pos, quat, site_body[i], site_local[i, 0], site_local[i, 1], site_local[i, 2])
            xj, yj, zj = _site_world(pos, quat, site_body[j], site_local[j, 0], site_local[j, 1], site_local[j, 2])
            rec[nrec, 1 + p] = math.sqrt((xj - xi) ** 2 + (yj - yi) ** 2 + (zj - zi) ** 2)
        nrec += 1
    if frame_every > 0 and (n + frame_phase) % frame_every == 0 and nfr < fpos.shape[0]:
        fpos[nfr] = pos
        fquat[nfr] = quat
        nfr += 1
    return nrec, nfr


@njit(cache=True)
def _due(n, every, phase):
    return every > 0 and (n + phase) % every == 0


@njit(cache=True)
def _failed(mon, wca_min, status, step):
    """Read the stability monitor: on a failure write (code, step, culprits) into ``status``
    and return True."""
    if not (mon[0] <= 1.0):
        status[0] = STRETCH if mon[0] == mon[0] else NONFINITE
        status[1] = step
        status[2] = int(mon[1])
        return True
    if mon[2] < wca_min:
        status[0] = WCA_CLOSE
        status[1] = step
        status[2] = int(mon[3])
        status[3] = int(mon[4])
        return True
    return False


def _euler_py(pos, quat, t_start, t_k0, step0, nsteps, dt, kT, gamma, gamma_r, rot_noise, seed,
              site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp, sp_bound,
              end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v, wca_eps, wca_s, wca_rc, wca_min,
              ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate, max_disp, max_rot,
              probe_i, probe_j, rec_every, rec_phase, rec, frame_every, frame_phase, fpos, fquat,
              uval, ws, arm, fsp, ratio, dmin, dpart, F, T, disp, mon, status):
    """Euler-Maruyama for ``nsteps`` steps; returns the number of steps done.
    Stops early with status[0] != OK (status[1] = step, status[2..] = culprit).  The
    per-step motion monitor looks at the deterministic part (drift) only: noise alone,
    however large, is never an instability."""
    N = pos.shape[0]
    amp = math.sqrt(2.0 * kT * dt / gamma)
    amp_r = math.sqrt(2.0 * kT * dt / gamma_r) if rot_noise else 0.0
    mt = dt / gamma
    mr = dt / gamma_r
    nrec = 0
    nfr = 0
    for n in range(nsteps):
        t = t_start + (t_k0 + n) * dt
        step = step0 + n
        _eval(pos, quat, t, site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol,
              sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
              wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
              uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
        if nlstate[2] > 0.0:
            status[0] = OVERFLOW
            status[1] = step
            return n
        nrec, nfr = _record(n, t, rec_every, rec_phase, rec, nrec, probe_i, probe_j, site_body, site_local,
                            frame_every, frame_phase, fpos, fquat, nfr, pos, quat)
        if _failed(mon, wca_min, status, step):
            return n
        for b in prange(N):
            xi0, xi1 = gauss2(seed, step, 2 * b)
            xi2, xi3 = gauss2(seed, step, 2 * b + 1)
            fx = mt * F[b, 0]
            fy = mt * F[b, 1]
            fz = mt * F[b, 2]
            wx = mr * T[b, 0]
            wy = mr * T[b, 1]
            wz = mr * T[b, 2]
            # squared drift ratios: <= 1 exactly when the ratios are
            disp[b] = max((fx * fx + fy * fy + fz * fz) / (max_disp * max_disp),
                          (wx * wx + wy * wy + wz * wz) / (max_rot * max_rot))
            if rot_noise:
                e0, e1 = gauss2(seed, step, 2 * N + 2 * b)
                wx += amp_r * xi3
                wy += amp_r * e0
                wz += amp_r * e1
            pos[b, 0] += fx + amp * xi0
            pos[b, 1] += fy + amp * xi1
            pos[b, 2] += fz + amp * xi2
            q0, q1, q2, q3 = quat_exp_mul(wx, wy, wz, quat[b, 0], quat[b, 1], quat[b, 2], quat[b, 3])
            quat[b, 0] = q0
            quat[b, 1] = q1
            quat[b, 2] = q2
            quat[b, 3] = q3
        worst = 0.0
        wb = -1
        for b in range(N):
            if not (disp[b] <= worst):
                worst = disp[b]
                wb = b
                if worst != worst:
                    break
        if not (worst <= 1.0):
            status[0] = DISPLACEMENT if worst == worst else NONFINITE
            status[1] = step
            status[2] = wb
            return n + 1
    return nsteps


@njit(cache=True)
def _normals3(seed, key, b, rot, out):
    """Three (or six with ``rot``) standard normals for counter (seed, key, body b) into out[0:6]."""
    a0, a1 = gauss2(seed, key, 3 * b)
    a2, a3 = gauss2(seed, key, 3 * b + 1)
    out[0] = a0
    out[1] = a1
    out[2] = a2
    if rot:
        a4, a5 = gauss2(seed, key, 3 * b + 2)
        out[3] = a3
        out[4] = a4
        out[5] = a5
    else:
        out[3] = 0.0
        out[4] = 0.0
        out[5] = 0.0


@njit(cache=True)
def _least_level(seed, step, lev_min, lev_span):
    """The fluctuation mode's random least substep level of macro step ``step``: lev_min + r,
    r uniform in [0, lev_span), from a counter keyed by (seed, step) (not by the noise's keys)."""
    r = _mix(np.uint64(seed) * _H + np.uint64(step) * _G + _M2) % np.uint64(lev_span)
    return min(lev_min + int(r), LMAX)


@njit(cache=True)
def brownian_at(seed, step, k, lev, b, rot, out, z):
    """Standard Brownian path of macro step ``step``, body ``b``, at the dyadic point
    u = k / 2^lev of the step (B(0) = 0, Var B(u) = u), into out[0:6] (3 components, 6 with
    ``rot``).  Levy's construction: B(1) and the midpoint of every dyadic interval (heap
    index H, the root interval H = 1) come from counter-based normals keyed by
    (seed, step * 2^31 + H); the midpoint is the mean of the ends plus sqrt(width/4) times
    its normal.  So the value at a point does not depend on which other points were
    visited: refining a substep keeps the Brownian path (no conditioning on the noise)."""
    while lev > 0 and (k & 1) == 0:
        k >>= 1
        lev -= 1
    key0 = np.uint64(step) * np.uint64(2147483648)
    if k == 0:
        for c in range(6):
            out[c] = 0.0
        return
    _normals3(seed, key0, b, rot, out)        # B(1)
    if lev == 0:
        return
    ba0, ba1, ba2, ba3, ba4, ba5 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    bb0, bb1, bb2, bb3, bb4, bb5 = out[0], out[1], out[2], out[3], out[4], out[5]
    a = 0
    H = 1
    w = 1.0
    for j in range(1, lev + 1):
        _normals3(seed, key0 + np.uint64(H), b, rot, z)
        sd = 0.5 * math.sqrt(w)
        m0 = 0.5 * (ba0 + bb0) + sd * z[0]
        m1 = 0.5 * (ba1 + bb1) + sd * z[1]
        m2 = 0.5 * (ba2 + bb2) + sd * z[2]
        m3 = 0.5 * (ba3 + bb3) + sd * z[3]
        m4 = 0.5 * (ba4 + bb4) + sd * z[4]
        m5 = 0.5 * (ba5 + bb5) + sd * z[5]
        if j == lev:
            out[0] = m0
            out[1] = m1
            out[2] = m2
            out[3] = m3
            out[4] = m4
            out[5] = m5
            return
        kj = k >> (lev - j)
        if kj == 2 * a:
            bb0, bb1, bb2, bb3, bb4, bb5 = m0, m1, m2, m3, m4, m5
            a = 2 * a
            H = 2 * H
        else:
            ba0, ba1, ba2, ba3, ba4, ba5 = m0, m1, m2, m3, m4, m5
            a = 2 * a + 1
            H = 2 * H + 1
        w *= 0.5


@njit(cache=True)
def stages_for(h, rho, eta):
    """SK-ROCK stage count: the smallest s >= 2 with (2 - 4 eta/3) s^2 >= h rho."""
    s = int(math.ceil(math.sqrt(h * rho / (2.0 - 4.0 * eta / 3.0))))
    return s if s >= 2 else 2


def _sk_step_py(pos, quat, t, h, gamma, gamma_r, noisy, s, eta,
                site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp, sp_bound,
                end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v, wca_eps, wca_s, wca_rc,
                ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate, uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon,
                K0, K1, K2, Qn, qn):
    """One SK-ROCK step of size h with s stages from (pos, quat) and the noise increment
    Qn (N, 6: translation, rotation vector); F, T must hold the forces at (pos, quat, t).
    Orientations enter the stages as rotation vectors theta (q = exp(theta) q_n) in the
    chart of the step's start orientation, with theta' = J_l(theta)^-1 omega.  Leaves the
    new state in (pos, quat) and its chart coordinates (r, theta) in K1."""
    N = pos.shape[0]
    for b in prange(N):
        for c in range(3):
            K0[b, c] = pos[b, c]
            K0[b, 3 + c] = 0.0
        for c in range(4):
            qn[b, c] = quat[b, c]
    # Chebyshev coefficients: T_j(w0), U_j(w0); T_s' = s U_{s-1}
    w0 = 1.0 + eta / (s * s)
    tjm1 = 1.0
    tj = w0
    ujm1 = 1.0
    uj = 2.0 * w0
    for j in range(2, s + 1):
        tjm1, tj = tj, 2.0 * w0 * tj - tjm1
        ujm1, uj = uj, 2.0 * w0 * uj - ujm1
    w1 = tj / (s * ujm1)
    mu1 = w1 / w0
    nu1 = s * w1 / 2.0
    ka1 = s * w1 / w0
    # first evaluation point X_n + nu1 Q
    for b in prange(N):
        for c in range(6):
            K2[b, c] = K0[b, c] + nu1 * Qn[b, c]
    if noisy:
        _stage_f(K2, qn, pos, quat)
        _eval(pos, quat, t, site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol,
              sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
              wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
              uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
    for b in prange(N):
        fr = _rot_rate(K2[b, 3], K2[b, 4], K2[b, 5], T[b, 0] / gamma_r, T[b, 1] / gamma_r, T[b, 2] / gamma_r)
        for c in range(3):
            K1[b, c] = K0[b, c] + mu1 * h * F[b, c] / gamma + ka1 * Qn[b, c]
            K1[b, 3 + c] = K0[b, 3 + c] + mu1 * h * fr[c] + ka1 * Qn[b, 3 + c]
    # stages 2..s: K_j = mu_j h f(K_{j-1}) + nu_j K_{j-1} + kappa_j K_{j-2}
    tjm2 = 1.0
    tjm1 = w0
    for j in range(2, s + 1):
        tj = 2.0 * w0 * tjm1 - tjm2
        muj = 2.0 * w1 * tjm1 / tj
        nuj = 2.0 * w0 * tjm1 / tj
        kaj = -tjm2 / tj
        _stage_f(K1, qn, pos, quat)
        _eval(pos, quat, t, site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol,
              sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
              wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
              uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
        for b in prange(N):
            fr = _rot_rate(K1[b, 3], K1[b, 4], K1[b, 5], T[b, 0] / gamma_r, T[b, 1] / gamma_r,
                           T[b, 2] / gamma_r)
            for c in range(3):
                K2[b, c] = muj * h * F[b, c] / gamma + nuj * K1[b, c] + kaj * K0[b, c]
                K2[b, 3 + c] = muj * h * fr[c] + nuj * K1[b, 3 + c] + kaj * K0[b, 3 + c]
        for b in prange(N):
            for c in range(6):
                K0[b, c] = K1[b, c]
                K1[b, c] = K2[b, c]
        tjm2 = tjm1
        tjm1 = tj
    _stage_f(K1, qn, pos, quat)


def _skrock_py(pos, quat, t_start, t_k0, step0, nsteps, dt, kT, gamma, gamma_r, rot_noise, seed,
               site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp, sp_bound,
               end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v, wca_eps, wca_s, wca_rc, wca_min,
               ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate, max_disp, max_rot,
               probe_i, probe_j, rec_every, rec_phase, rec, frame_every, frame_phase, fpos, fquat,
               uval, ws, arm, fsp, ratio, dmin, dpart, F, T, disp, mon, status,
               eta, rho_safety, rho_every, rho_iters, pv, pw, sp_tmp, fixed_s, stages_out,
               K0, K1, K2, Qn, qn, xs, qs, accept, rot_acc, disp_acc, arm_max,
               Bc, Bn, zb, ppos, pquat, post, lev_min, lev_span):
    """SK-ROCK (Abdulle, Almuslimani & Vilmart 2018) with damping ``eta``, ``nsteps``
    macro steps of size dt.  The number of stages s is the smallest with
    (2 - 4 eta/3) s^2 >= h rho, rho = power-iteration estimate (times ``rho_safety``,
    refreshed every ``rho_every`` steps) plus the WCA curvature bound.

    Adaptive substeps on a dyadic grid: a substep covers [k, k+1] dt/2^l and its noise is
    the increment of one Brownian path per macro step built by Levy's construction
    (:func:`brownian_at`), so a rejected substep is refined into halves of the *same*
    noise (a Brownian bridge), never redrawn: step-size control does not condition the
    noise.  A substep is redone at level l+1 when its end state has a bond beyond
    ``accept`` of its stretch bound, centres inside ``wca_min``, a body whose drift
    (displacement less its noise increment) exceeds max_disp/max_rot, or (accuracy) a
    drift beyond ``disp_acc`` (+ 3 |noise| for bodies whose noise a bond absorbs) or a
    rotational drift beyond ``rot_acc`` or that over ``arm_max``.  After an easy substep
    the level drops again where the grid allows; never below ``lev_min`` (a level set from
    the rotational noise variance).  With ``lev_span`` > 1 (the fluctuation mode with noise)
    each macro step also gets a random least level lev_min + r, r uniform in [0, lev_span),
    from a counter keyed by (seed, step) and independent of the noise: a mode whose h lambda
    sits at an interior Chebyshev extremum at one level (|R| = 1 without damping: it neither
    relaxes nor takes noise) is away from it at the others, so no mode of the spectrum stays
    frozen.  A substep rejected at level LMAX is a genuine
    instability (status set).  With ``post`` the recorded states are post-processed:
    X + Q'/(2s), Q' a fresh noise increment of the current substep size (exact stationary
    variance of linear modes for eta = 0), (h, s) of the last accepted substep, and the
    displacement alarm gets the accuracy test's noise allowance (no redo selected by the
    noise of a body whose stiff bond absorbs it).  stages_out: [0] force evaluations, [1] last s,
    [2] last rho, [3] rejected substeps, [4] the substep size to go on with, [5] the spectral
    estimate (both kept between calls, so the trajectory does not depend on the chunking),
    [6], [7] the last accepted substep's h and s (for the post-processor)."""
    N = pos.shape[0]
    nrec = 0
    nfr = 0
    rho_b = stages_out[5]          # kept between calls: refreshes depend on the global step only
    full = 1 << LMAX
    amp_dt = math.sqrt(2.0 * kT * dt / gamma)
    amp_dt_r = math.sqrt(2.0 * kT * dt / gamma_r) if rot_noise else 0.0
    noisy = amp_dt > 0.0 or amp_dt_r > 0.0
    # fluctuation mode with noise: the displacement alarm gets the accuracy test's noise
    # allowance (a body held by a stiff bond absorbs its noise, so its drift is of the noise's
    # size); without it, the alarm redid substeps chosen by their noise (a selection bias:
    # +9 % on bonded pairs at kT = 1e-2, dt = 0.01 t0)
    predict = post and noisy
    h_last = stages_out[4]
    lev = lev_min
    if h_last > 0.0:
        lev = int(round(math.log2(dt / h_last)))
        lev = min(max(lev, lev_min), LMAX)
    _eval(pos, quat, t_start + t_k0 * dt, site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol,
          sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
          wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
          uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
    stages_out[0] += 1
    if nlstate[2] > 0.0:
        status[0] = OVERFLOW
        status[1] = step0
        return 0
    for n in range(nsteps):
        t = t_start + (t_k0 + n) * dt
        step = step0 + n
        # F, T, ws, arm, mon hold the state at (pos, quat, t)
        if fixed_s <= 0 and (step % rho_every == 0 or rho_b == 0.0):
            it = rho_iters if rho_b == 0.0 else max(3, rho_iters // 8)
            rho_b = _spectral(site_body, arm, sp_i, sp_j, sp_k, end0, end_sp, end_sign, sp_tmp,
                              1.0 / gamma, 1.0 / gamma_r, pv, pw, it) * rho_safety
            stages_out[5] = rho_b
        rho = rho_b + 2.0 * mon[5] / gamma
        stages_out[2] = rho
        # the macro step starts at twice the last accepted substep, not below its least level;
        # with random levels, a step that ended at the previous step's least level starts at its own
        lmin = lev_min
        if lev_span > 1:
            lmin = _least_level(seed, step, lev_min, lev_span)
            if step > 0 and lev <= _least_level(seed, step - 1, lev_min, lev_span):
                lev = lmin
        lev = max(lev - 1, lmin)
        if _due(n, rec_every, rec_phase) or _due(n, frame_every, frame_phase):
            if post and noisy:
                # the stiff modes' variance deficit is that of the last substep taken (h, s)
                if stages_out[6] > 0.0:
                    h0 = stages_out[6]
                    s0 = int(stages_out[7])
                else:
                    h0 = dt / (1 << lev)
                    s0 = fixed_s if fixed_s > 0 else stages_for(h0, rho, eta)
                c = math.sqrt(h0 / dt) / (2.0 * s0)
                pkey = np.uint64(step) * np.uint64(2147483648) + np.uint64(2147483647)
                for b in prange(N):
                    z = np.empty(6)
                    _normals3(seed, pkey, b, rot_noise, z)
                    for cc in range(3):
                        ppos[b, cc] = pos[b, cc] + c * amp_dt * z[cc]
                    q0, q1, q2, q3 = quat_exp_mul(c * amp_dt_r * z[3], c * amp_dt_r * z[4], c * amp_dt_r * z[5],
                                                  quat[b, 0], quat[b, 1], quat[b, 2], quat[b, 3])
                    pquat[b, 0] = q0
                    pquat[b, 1] = q1
                    pquat[b, 2] = q2
                    pquat[b, 3] = q3
                nrec, nfr = _record(n, t, rec_every, rec_phase, rec, nrec, probe_i, probe_j, site_body, site_local,
                                    frame_every, frame_phase, fpos, fquat, nfr, ppos, pquat)
            else:
                nrec, nfr = _record(n, t, rec_every, rec_phase, rec, nrec, probe_i, probe_j, site_body, site_local,
                                    frame_every, frame_phase, fpos, fquat, nfr, pos, quat)
        if _failed(mon, wca_min, status, step):
            return n
        # adaptive substeps on the dyadic grid of [t, t + dt]; u in units of dt / 2^LMAX
        u = 0
        for b in range(N):
            for c in range(6):
                Bc[b, c] = 0.0
        while u < full:
            h = dt / (1 << lev)
            rho = rho_b + 2.0 * mon[5] / gamma          # WCA curvature at the substep start
            s = fixed_s if fixed_s > 0 else stages_for(h, rho, eta)
            stages_out[1] = s
            for b in prange(N):
                for c in range(3):
                    xs[b, c] = pos[b, c]
                for c in range(4):
                    qs[b, c] = quat[b, c]
            if noisy:
                kend = (u >> (LMAX - lev)) + 1
                for b in prange(N):
                    brownian_at(seed, step, kend, lev, b, rot_noise, Bn[b], zb[b])
                    for c in range(3):
                        Qn[b, c] = amp_dt * (Bn[b, c] - Bc[b, c])
                        Qn[b, 3 + c] = amp_dt_r * (Bn[b, 3 + c] - Bc[b, 3 + c])
            else:
                for b in range(N):
                    for c in range(6):
                        Qn[b, c] = 0.0
            _sk_step(pos, quat, t + u * (dt / full), h, gamma, gamma_r, noisy, s, eta,
                     site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp,
                     sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v, wca_eps, wca_s, wca_rc,
                     ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate, uval, ws, arm, fsp, ratio, dmin, dpart,
                     F, T, mon, K0, K1, K2, Qn, qn)
            _eval(pos, quat, t + (u + (full >> lev)) * (dt / full), site_body, site_local, bsite0, sp_i, sp_j,
                  sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar,
                  tab_t, tab_v, wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
                  uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
            stages_out[0] += s + 1
            if nlstate[2] > 0.0:
                status[0] = OVERFLOW
                status[1] = step
                return n
            # drift = displacement less the noise increment, in translation and rotation
            dmax = 0.0
            amax = 0.0
            worst = 0.0
            wb = -1
            md = max_disp
            mr = max_rot
            if predict:
                # a body held by a stiff bond absorbs its noise, so its drift is of the noise's
                # size: the displacement alarm gets the same allowance as the accuracy test
                md += 3.0 * math.sqrt(3.0) * amp_dt * math.sqrt(1.0 / (1 << lev))
                mr += 3.0 * math.sqrt(3.0) * amp_dt_r * math.sqrt(1.0 / (1 << lev))
            for b in range(N):
                ex = pos[b, 0] - xs[b, 0] - Qn[b, 0]
                ey = pos[b, 1] - xs[b, 1] - Qn[b, 1]
                ez = pos[b, 2] - xs[b, 2] - Qn[b, 2]
                v = ex * ex + ey * ey + ez * ez
                if not (v <= dmax):
                    dmax = v
                rx = K1[b, 3] - Qn[b, 3]
                ry = K1[b, 4] - Qn[b, 4]
                rz = K1[b, 5] - Qn[b, 5]
                a2 = rx * rx + ry * ry + rz * rz
                if not (a2 <= amax):
                    amax = a2
                w = max(v / (md * md), a2 / (mr * mr))
                if not (w <= worst):
                    worst = w
                    wb = b
            dmax = math.sqrt(dmax)
            amax = math.sqrt(amax)
            # accept when bonds stay inside their bounds, no WCA core is entered, no drift explodes
            # and the substep drifted < disp_acc and turned (less its noise) < rot_acc (rotations
            # count by the arc of the farthest site, arm_max).  For bodies held by stiff bonds the
            # noise is absorbed, so their drift is of the noise's size: allow 3 |Q| on top.
            dlim = disp_acc + 3.0 * math.sqrt(3.0) * amp_dt * math.sqrt(1.0 / (1 << lev))
            alim = min(rot_acc, dlim / arm_max) if arm_max > 0.0 else rot_acc
            ok = (mon[0] <= accept) and (mon[2] >= wca_min) and (worst <= 1.0)
            accurate = (dmax <= dlim) and (amax <= alim)
            if ok and (accurate or lev >= LMAX):
                u += full >> lev
                stages_out[6] = h
                stages_out[7] = s
                for b in range(N):
                    for c in range(6):
                        Bc[b, c] = Bn[b, c]
                if dmax < 0.5 * dlim and amax < 0.5 * alim and lev > lmin and ((u >> (LMAX - lev)) & 1) == 0:
                    lev -= 1
                stages_out[4] = dt / (1 << lev)         # the level to go on with (kept between calls)
                continue
            # reject: back to the substep start, refine into halves of the same Brownian increment
            stages_out[3] += 1
            if lev >= LMAX:
                if not (mon[0] <= 1.0):
                    status[0] = STRETCH if mon[0] == mon[0] else NONFINITE
                    status[2] = int(mon[1])
                elif mon[2] < wca_min:
                    status[0] = WCA_CLOSE
                    status[2] = int(mon[3])
                    status[3] = int(mon[4])
                else:
                    status[0] = DISPLACEMENT if worst == worst else NONFINITE
                    status[2] = wb
                status[1] = step
                return n + 1
            for b in prange(N):
                for c in range(3):
                    pos[b, c] = xs[b, c]
                for c in range(4):
                    quat[b, c] = qs[b, c]
            _eval(pos, quat, t + u * (dt / full), site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0,
                  sp_rest1, sp_tol, sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
                  wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
                  uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
            stages_out[0] += 1
            if nlstate[2] > 0.0:
                status[0] = OVERFLOW
                status[1] = step
                return n
            lev += 1
    return nsteps


@njit(cache=True)
def _rot_rate(t0, t1, t2, w0, w1, w2):
    """d theta/dt = J_l(theta)^-1 omega for q = exp(theta) q_n and world angular velocity omega."""
    th2 = t0 * t0 + t1 * t1 + t2 * t2
    # K w and K K w with K = [theta]x
    a0 = t1 * w2 - t2 * w1
    a1 = t2 * w0 - t0 * w2
    a2 = t0 * w1 - t1 * w0
    b0 = t1 * a2 - t2 * a1
    b1 = t2 * a0 - t0 * a2
    b2 = t0 * a1 - t1 * a0
    if th2 < 1e-6:
        c = 1.0 / 12.0 + th2 / 720.0
    else:
        th = math.sqrt(th2)
        c = 1.0 / th2 - (1.0 + math.cos(th)) / (2.0 * th * math.sin(th))
    return (w0 - 0.5 * a0 + c * b0, w1 - 0.5 * a1 + c * b1, w2 - 0.5 * a2 + c * b2)


def _stage_f_py(K, qn, pos, quat):
    """Set the configuration (pos, quat) of a stage K = (r, theta) in the chart of qn."""
    for b in prange(K.shape[0]):
        pos[b, 0] = K[b, 0]
        pos[b, 1] = K[b, 1]
        pos[b, 2] = K[b, 2]
        q0, q1, q2, q3 = quat_exp_mul(K[b, 3], K[b, 4], K[b, 5], qn[b, 0], qn[b, 1], qn[b, 2], qn[b, 3])
        quat[b, 0] = q0
        quat[b, 1] = q1
        quat[b, 2] = q2
        quat[b, 3] = q3


# -- compiled variants: serial (plain loops) and parallel (prange over bodies/springs) ----------
def _variant(fn, name, env, parallel):
    g = dict(globals())
    g.update(env)
    f = types.FunctionType(fn.__code__, g, name, fn.__defaults__, fn.__closure__)
    f.__qualname__ = name
    f.__module__ = __name__
    f.__doc__ = fn.__doc__
    return njit(cache=True, parallel=parallel)(f)


_serial = {}
_parallel = {}
for _tbl, _par, _suf in ((_serial, False, "_s"), (_parallel, True, "_p")):
    _tbl["eval"] = _variant(_eval_py, "eval" + _suf, {}, _par)
    _tbl["spectral"] = _variant(_spectral_py, "spectral" + _suf, {}, _par)
    _tbl["stage_f"] = _variant(_stage_f_py, "stage_f" + _suf, {}, _par)
    _env = {"_eval": _tbl["eval"], "_spectral": _tbl["spectral"], "_stage_f": _tbl["stage_f"]}
    _tbl["sk_step"] = _variant(_sk_step_py, "sk_step" + _suf, _env, _par)
    _env["_sk_step"] = _tbl["sk_step"]
    _tbl["euler"] = _variant(_euler_py, "euler" + _suf, _env, _par)
    _tbl["skrock"] = _variant(_skrock_py, "skrock" + _suf, _env, _par)


def kernels(parallel: bool) -> dict:
    """The compiled kernels: ``eval``, ``spectral``, ``euler``, ``skrock``."""
    return _parallel if parallel else _serial
