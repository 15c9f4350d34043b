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

# failure codes returned in status[0]
OK, STRETCH, WCA_CLOSE, DISPLACEMENT, NONFINITE = 0, 1, 2, 3, 4

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
    True when the list is valid; False when it overflowed ``nl`` (the caller then uses
    the cell list, just built; nlstate[2] counts overflows, nlstate[3] the size needed).
    nlstate[0] = list valid, nlstate[1] = builds."""
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
    # gather per body, then WCA through the Verlet list (or the cell list if it overflowed)
    nlok = True
    if wca_eps > 0.0:
        nlok = nlist_update(pos, wca_rc, 0.5 * wca_rc, head, nxt, cell, ex0, ex_list, nl0, nl, pos_nl, nlstate)
    mask = head.shape[0] - 1
    h = 2.0 * (wca_rc + 0.5 * wca_rc)      # the cell size nlist_update builds with
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
                    c = 24.0 * wca_eps * (2.0 * ir6 * ir6 - ir6) / r2
                    fx += c * dx
                    fy += c * dy
                    fz += c * dz
                    r = math.sqrt(r2)
                    if r < dm:
                        dm = r
                        dp = j
        elif wca_eps > 0.0:
            px = pos[b, 0]
            py = pos[b, 1]
            pz = pos[b, 2]
            # the 2x2x2 block of cells (size 2 (rc + skin)) nearest to the body
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
                                r2 = dx * dx + dy * dy + dz * dz
                                if r2 < rc2:
                                    excluded = False
                                    for x in range(ex0[b], ex0[b + 1]):
                                        if ex_list[x] == j:
                                            excluded = True
                                            break
                                    if not excluded:
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
                            j = nxt[j]
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
def _record(n, t, rec_every, rec, nrec, probe_i, probe_j, ws, frame_every, fpos, fquat, nfr, pos, quat):
    """Record the probe lengths (every ``rec_every`` steps) and a frame (every ``frame_every``)
    at step ``n``; returns the new counts ``(nrec, nfr)``."""
    if rec_every > 0 and n % rec_every == 0 and nrec < rec.shape[0]:
        rec[nrec, 0] = t
        for p in range(probe_i.shape[0]):
            dx = ws[probe_j[p], 0] - ws[probe_i[p], 0]
            dy = ws[probe_j[p], 1] - ws[probe_i[p], 1]
            dz = ws[probe_j[p], 2] - ws[probe_i[p], 2]
            rec[nrec, 1 + p] = math.sqrt(dx * dx + dy * dy + dz * dz)
        nrec += 1
    if frame_every > 0 and n % frame_every == 0 and nfr < fpos.shape[0]:
        fpos[nfr] = pos
        fquat[nfr] = quat
        nfr += 1
    return nrec, nfr


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


def _euler_py(pos, quat, t_start, step0, nsteps, dt, kT, gamma, gamma_r, rot_noise, seed,
              site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp, sp_bound,
              end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v, wca_eps, wca_s, wca_rc, wca_min,
              ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate, max_disp, max_rot,
              probe_i, probe_j, rec_every, rec, frame_every, fpos, fquat,
              uval, ws, arm, fsp, ratio, dmin, dpart, F, T, disp, mon, status):
    """Euler-Maruyama for ``nsteps`` steps; returns the number of steps done.
    Stops early with status[0] != OK (status[1] = step, status[2..] = culprit)."""
    N = pos.shape[0]
    amp = math.sqrt(2.0 * kT * dt / gamma)
    amp_r = math.sqrt(2.0 * kT * dt / gamma_r) if rot_noise else 0.0
    mt = dt / gamma
    mr = dt / gamma_r
    nrec = 0
    nfr = 0
    for n in range(nsteps):
        t = t_start + n * dt
        step = step0 + n
        _eval(pos, quat, t, site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol,
              sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
              wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
              uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
        nrec, nfr = _record(n, t, rec_every, rec, nrec, probe_i, probe_j, ws, frame_every, fpos, fquat, nfr,
                            pos, quat)
        if _failed(mon, wca_min, status, step):
            return n
        for b in prange(N):
            xi0, xi1 = gauss2(seed, step, 2 * b)
            xi2, xi3 = gauss2(seed, step, 2 * b + 1)
            dx = mt * F[b, 0] + amp * xi0
            dy = mt * F[b, 1] + amp * xi1
            dz = mt * F[b, 2] + amp * xi2
            wx = mr * T[b, 0]
            wy = mr * T[b, 1]
            wz = mr * T[b, 2]
            if rot_noise:
                e0, e1 = gauss2(seed, step, 2 * N + 2 * b)
                wx += amp_r * xi3
                wy += amp_r * e0
                wz += amp_r * e1
            pos[b, 0] += dx
            pos[b, 1] += dy
            pos[b, 2] += dz
            q0, q1, q2, q3 = quat_exp_mul(wx, wy, wz, quat[b, 0], quat[b, 1], quat[b, 2], quat[b, 3])
            quat[b, 0] = q0
            quat[b, 1] = q1
            quat[b, 2] = q2
            quat[b, 3] = q3
            # squared displacement ratios: <= 1 exactly when the ratios are
            disp[b] = max((dx * dx + dy * dy + dz * dz) / (max_disp * max_disp),
                          (wx * wx + wy * wy + wz * wz) / (max_rot * max_rot))
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


def _sk_step_py(pos, quat, t, h, kT, gamma, gamma_r, rot_noise, seed, key, s, eta,
                site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp, sp_bound,
                end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v, wca_eps, wca_s, wca_rc,
                ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate, uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon,
                K0, K1, K2, Qn, qn):
    """One SK-ROCK step of size h with s stages from (pos, quat); F, T must hold the
    forces at (pos, quat, t).  Orientations enter the stages as rotation vectors theta
    (q = exp(theta) q_n) in the chart of the step's start orientation, with
    theta' = J_l(theta)^-1 omega.  Leaves the new state in (pos, quat)."""
    N = pos.shape[0]
    amp = math.sqrt(2.0 * kT * h / gamma)
    amp_r = math.sqrt(2.0 * kT * h / gamma_r) if rot_noise else 0.0
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
    # noise increment Q; first evaluation point X_n + nu1 Q
    for b in prange(N):
        xi0, xi1 = gauss2(seed, key, 2 * b)
        xi2, xi3 = gauss2(seed, key, 2 * b + 1)
        Qn[b, 0] = amp * xi0
        Qn[b, 1] = amp * xi1
        Qn[b, 2] = amp * xi2
        if rot_noise:
            e0, e1 = gauss2(seed, key, 2 * N + 2 * b)
            Qn[b, 3] = amp_r * xi3
            Qn[b, 4] = amp_r * e0
            Qn[b, 5] = amp_r * e1
        else:
            Qn[b, 3] = 0.0
            Qn[b, 4] = 0.0
            Qn[b, 5] = 0.0
        for c in range(6):
            K2[b, c] = K0[b, c] + nu1 * Qn[b, c]
    if amp > 0.0 or amp_r > 0.0:
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


def _skrock_py(pos, quat, t_start, step0, nsteps, dt, kT, gamma, gamma_r, rot_noise, seed,
               site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp, sp_bound,
               end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v, wca_eps, wca_s, wca_rc, wca_min,
               ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate, max_disp, max_rot,
               probe_i, probe_j, rec_every, rec, frame_every, fpos, fquat,
               uval, ws, arm, fsp, ratio, dmin, dpart, F, T, disp, mon, status,
               eta, rho_safety, rho_every, rho_iters, pv, pw, sp_tmp, fixed_s, stages_out,
               K0, K1, K2, Qn, qn, xs, qs, accept, rot_acc, disp_acc, arm_max):
    """SK-ROCK (Abdulle, Almuslimani & Vilmart 2018) with damping ``eta``, ``nsteps``
    macro steps of size dt.  The number of stages s is the smallest with
    (2 - 4 eta/3) s^2 >= h rho, rho = power-iteration estimate (times ``rho_safety``,
    refreshed every ``rho_every`` steps) plus the WCA curvature bound.

    Transients (a muscle switching, a large rotation) are resolved by adaptive substeps:
    a substep whose end state has a bond beyond ``accept`` of its stretch bound, centres
    inside ``wca_min``, a body moved more than max_disp/max_rot, or (accuracy) a body
    drifted (displacement less noise) more than ``disp_acc`` or turned by more than
    ``rot_acc`` or ``disp_acc/arm_max`` rad, is redone with half the step (fresh
    counter-based noise); after an easy substep the step doubles again, up to dt.  A
    substep rejected at dt/2^20 is a genuine instability (status set).  stages_out:
    [0] force evaluations, [1] last s, [2] last rho, [3] rejected substeps, [4] the
    last accepted substep (carried over between calls)."""
    N = pos.shape[0]
    nrec = 0
    nfr = 0
    rho_b = 0.0
    h_last = stages_out[4]
    h_min = dt / 1048576.0
    _eval(pos, quat, t_start, site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol,
          sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
          wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
          uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
    stages_out[0] += 1
    for n in range(nsteps):
        t = t_start + n * dt
        step = step0 + n
        # F, T, ws, mon hold the state at (pos, quat, t)
        nrec, nfr = _record(n, t, rec_every, rec, nrec, probe_i, probe_j, ws, frame_every, fpos, fquat, nfr,
                            pos, quat)
        if _failed(mon, wca_min, status, step):
            return n
        if fixed_s <= 0 and (n % rho_every == 0 or rho_b == 0.0):
            it = rho_iters if rho_b == 0.0 else max(3, rho_iters // 8)
            rho_b = _spectral(site_body, arm, sp_i, sp_j, sp_k, end0, end_sp, end_sign, sp_tmp,
                              1.0 / gamma, 1.0 / gamma_r, pv, pw, it) * rho_safety
        rho = rho_b + 2.0 * mon[5] / gamma
        stages_out[2] = rho
        # adaptive substeps within the macro step [t, t + dt]
        tt = 0.0
        h = min(dt, 2.0 * h_last) if h_last > 0.0 else dt
        counter = 0
        while tt < dt * (1.0 - 1e-12):
            if h > dt - tt:
                h = dt - tt
            if fixed_s > 0:
                s = fixed_s
            else:
                s = int(math.ceil(math.sqrt(h * rho / (2.0 - 4.0 * eta / 3.0))))
                if s < 2:
                    s = 2
            stages_out[1] = s
            # substep start (F, T, mon are fresh for it)
            for b in prange(N):
                for c in range(3):
                    xs[b, c] = pos[b, c]
                for c in range(4):
                    qs[b, c] = quat[b, c]
            key = np.uint64(step) * np.uint64(1048576) + np.uint64(counter)
            counter += 1
            _sk_step(pos, quat, t + tt, h, kT, gamma, gamma_r, rot_noise, seed, key, s, eta,
                     site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1, sp_tol, sp_inp,
                     sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v, wca_eps, wca_s, wca_rc,
                     ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate, uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon,
                     K0, K1, K2, Qn, qn)
            _eval(pos, quat, t + tt + h, site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1,
                  sp_tol, sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
                  wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
                  uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
            stages_out[0] += s + 1
            # drift (displacement less the noise increment), displacement and rotation of the substep
            dmax = 0.0
            amax = 0.0
            worst = 0.0
            wb = -1
            for b in range(N):
                dx = pos[b, 0] - xs[b, 0]
                dy = pos[b, 1] - xs[b, 1]
                dz = pos[b, 2] - xs[b, 2]
                d2 = dx * dx + dy * dy + dz * dz
                ex = dx - Qn[b, 0]
                ey = dy - Qn[b, 1]
                ez = dz - Qn[b, 2]
                v = ex * ex + ey * ey + ez * ez
                if not (v <= dmax):
                    dmax = v
                dq = abs(quat[b, 0] * qs[b, 0] + quat[b, 1] * qs[b, 1] + quat[b, 2] * qs[b, 2]
                         + quat[b, 3] * qs[b, 3])
                ang = 2.0 * math.acos(min(1.0, dq))
                if not (ang <= amax):
                    amax = ang
                w = max(math.sqrt(d2) / max_disp, ang / max_rot)
                if not (w <= worst):
                    worst = w
                    wb = b
            dmax = math.sqrt(dmax)
            # accept when bonds stay inside their bounds, no WCA core is entered, and the substep
            # drifted < disp_acc and turned < rot_acc (rotations count by the arc of the farthest
            # site, arm_max).  For bodies held by stiff bonds the noise is absorbed, so
            # "displacement less noise" is of the noise's size: allow 3 |Q| on top.
            dlim = disp_acc + 3.0 * math.sqrt(3.0) * math.sqrt(2.0 * kT * h / gamma)
            alim = min(rot_acc, dlim / arm_max) if arm_max > 0.0 else rot_acc
            ok = (mon[0] <= accept) and (mon[2] >= wca_min) and (worst <= 1.0)
            accurate = (dmax <= dlim) and (amax <= alim)
            if ok and (accurate or h <= h_min):
                tt += h
                h_last = h
                stages_out[4] = h
                if dmax < 0.5 * dlim and amax < 0.5 * alim:
                    h = 2.0 * h
                continue
            # reject: back to the substep start with half the step
            stages_out[3] += 1
            if h <= h_min:
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
            _eval(pos, quat, t + tt, site_body, site_local, bsite0, sp_i, sp_j, sp_k, sp_rest0, sp_rest1,
                  sp_tol, sp_inp, sp_bound, end0, end_sp, end_sign, dkind, dpar, tab_t, tab_v,
                  wca_eps, wca_s, wca_rc, ex0, ex_list, head, nxt, cell, nl0, nl, pos_nl, nlstate,
                  uval, ws, arm, fsp, ratio, dmin, dpart, F, T, mon)
            stages_out[0] += 1
            h = 0.5 * h
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
