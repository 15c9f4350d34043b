"""Which cells the wall check counts as "at least the minimum wall thick", three ways, against a
brute-force opening.

    python benchmarks/mesh_walls_cover.py [--gates NAND:expand:mjp ...] [--out FILE]

``mlc.mesh.walls.thin_walls`` covers the cells within ``r = min_wall / 2`` of a ball centre.  A
cell near the threshold depth (the *band*) is measured from the surface: ``_ball`` searches, from
the cell along the line away from the nearest surface point, for a ball of radius
``need = r (1 - WALL_TOL)``, moving up to three times by at most a cell.  Where it finds one, the
rule of session 37/38 (``cell``, committed) covers the cells within ``r`` of the **cell the search
started from**; the patch left uncommitted in session 38 (``found``) covers those within ``r`` of
**the centre it found**; ``found_grown`` (tried here) covers those within
``r + (D - need)`` of it (a ball of radius ``D >= need`` there holds a ball of radius ``need``
anywhere within ``D - need`` of its centre: every cell it covers is covered by the definition).

Each rule's covered cells are computed on the grid ``thin_walls`` uses (the steps before the
regions, copied from ``mlc/mesh/walls.py`` with the rule as a switch), and wherever two rules
differ the cell is judged by a **brute-force opening** that does not use ``_ball``: the part's
exact inside distance (``walls._Surface``, distance to the nearest triangle) sampled every
``h / 5`` mm in every grid cell within ``r + 5 h`` of the cells in question (a ball the search
found is within three cells of its band cell).  A cell is *surely
covered* when a sample with distance ``>= need`` lies within ``r`` of it, *surely uncovered* when
no sample with distance ``>= need - e`` lies within ``r + e`` (``e`` = half a sample diagonal,
the most a sample is from a point between them; the distance changes by at most as much); in
between it is left undecided.  Per part and rule: the cells it covers wrongly (surely uncovered)
and those it leaves uncovered wrongly (surely covered), counted over the cells where the rules
differ (where they agree, none of them is judged), and how far past the opening the farthest
wrongly covered cell lies (``covered_wrongly_past_mm``, at least: its distance to the nearest sample with
a ball of ``need - e``, less ``e`` and ``r``) and how far inside it the deepest wrongly uncovered
one (``left_uncovered_wrongly_inside_mm``: ``r`` less its distance to a sample with a ball of
``need``).  ``thin_walls`` (the committed rule) is
recorded beside: regions, thicknesses, volumes.

``fin_sweep``: a 2 mm cube with a fin 0.4 mm thick (thinner than any ball), 1.4 mm wide (its
ends inside the face) or 2 mm (its ends flush with two faces of the cube), standing 0.24 to
0.52 mm out of one face, at mjp's 0.6 mm, four random grid offsets a length: the thin regions the
committed rule finds (``regions_cell``) and those the patch finds (``regions_found``, the patch
applied to this checkout's ``walls.py``), beside what the definition gives for the exact opening
(``thin_wall_by_definition``).

Cases: ``plate``, a 2 mm cube with a 0.55 mm plate (1 mm out, 1.4 mm wide) on one face, at
mjp's 0.6 mm minimum wall; and the parts of library gates as ``export_assembly`` builds them
(``--gates``, default ``NAND:expand:mjp``).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from gitstate import commit  # noqa: E402  (benchmarks/gitstate.py)
from mlc.io.atomic import atomic_path  # noqa: E402
from mlc.mesh import walls as W  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"
RULES = ("cell", "found", "found_grown")


def coverage(solid, min_wall: float, rule: str):
    """The covered cells of ``solid`` by ``rule`` (steps 1-4 of ``thin_walls``), with the grid,
    its origin and spacing and the surface."""
    from scipy.spatial import cKDTree
    from mlc.mesh.printability import _mesh_arrays
    h = min_wall / 8
    grid, lo = W.voxelize(solid, h)
    V, F = _mesh_arrays(solid)
    r = min_wall / 2
    need = r * (1 - W.WALL_TOL)
    edge = (np.sqrt(3) - 1) * r + 1.01 * h
    R = int(np.ceil(max(r, edge) / h)) + 3
    depth = W._edt_upto(grid, R) * h
    centres = depth >= r + 2 * h
    band = grid & ~centres & (depth >= r - 0.87 * h)
    if band.any():
        cov = (W._edt_upto(~centres, R) * h <= r + 1e-9) & grid if centres.any() else np.zeros_like(grid)
        far = grid & ~cov & ((W._edt_upto(~cov, R) * h > edge) if cov.any() else True)
        band &= (W._edt_upto(~far, int(np.ceil((r + edge + h) / h)) + 1) * h <= r + edge + h) if far.any() else False
    surf = W._Surface(V, F, grid, lo, h)
    found, Df = np.zeros((0, 3)), np.zeros(0)
    if band.any():
        ib = np.argwhere(band)
        D, Cb = W._ball(surf, lo + h * ib, h, need)
        ok = D >= need
        if rule == "cell":
            centres[tuple(ib[ok].T)] = True
        else:
            found, Df = Cb[ok], D[ok]
    covered = (W._edt_upto(~centres, R) * h <= r + 1e-9) & grid
    if len(found):
        cand = np.argwhere(grid & ~covered)
        P = lo + h * cand
        if rule == "found":
            d, _ = cKDTree(found).query(P, distance_upper_bound=r + 1e-9)
            hit = d <= r + 1e-9
        else:       # found_grown: within r + (D - need) of a found centre (D - need capped at a cell)
            extra = np.minimum(Df - need, h)
            tree = cKDTree(found)
            hit = np.zeros(len(P), bool)
            for i, near in enumerate(tree.query_ball_point(P, r + h + 1e-9)):
                if near:
                    near = np.asarray(near)
                    hit[i] = bool((np.linalg.norm(found[near] - P[i], axis=1) <= r + extra[near] + 1e-9).any())
        covered[tuple(cand[hit].T)] = True
    return covered, grid, lo, h, surf


def brute(surf, grid, lo, h, cells, r, need):
    """(surely covered, surely uncovered, distance to the nearest sample with a ball of need, that
    to the nearest with one of need - e, less e) for each of ``cells`` (grid indices), by the
    inside distance sampled every h / 5 in the grid cells within r + 5 h of them."""
    from scipy.spatial import cKDTree
    k = 5
    hf = h / k
    e = hf * np.sqrt(3) / 2
    mask = np.zeros(grid.shape, bool)
    mask[tuple(cells.T)] = True
    near = (W._edt_upto(~mask, int(np.ceil(r / h)) + 6) * h <= r + 5 * h) & grid
    off = (np.arange(k) - (k - 1) / 2) * hf
    O = np.stack(np.meshgrid(off, off, off, indexing="ij"), -1).reshape(-1, 3)
    nc = np.argwhere(near)
    hi_pts, lo_pts = [], []
    for s in range(0, len(nc), 20000):
        G = (lo + h * nc[s:s + 20000])[:, None, :] + O[None]
        G = G.reshape(-1, 3)
        D, _, ins = surf.inside(G)
        hi_pts.append(G[ins & (D >= need)])
        lo_pts.append(G[ins & (D >= need - e)])
    P = lo + h * cells
    hi_pts, lo_pts = np.concatenate(hi_pts), np.concatenate(lo_pts)
    d1 = cKDTree(hi_pts).query(P)[0] if len(hi_pts) else np.full(len(P), np.inf)
    d2 = cKDTree(lo_pts).query(P)[0] if len(lo_pts) else np.full(len(P), np.inf)
    return d1 <= r, d2 > r + e, d1, d2 - e


def judge(name: str, solid, min_wall: float) -> dict:
    t0 = time.perf_counter()
    cov = {}
    for rule in RULES:
        c, grid, lo, h, surf = coverage(solid, min_wall, rule)
        cov[rule] = c
    differ = np.zeros(grid.shape, bool)
    for a in RULES:
        for b in RULES:
            differ |= cov[a] != cov[b]
    cells = np.argwhere(differ)
    r = min_wall / 2
    need = r * (1 - W.WALL_TOL)
    row = {"part": name, "min_wall_mm": min_wall, "grid_mm": h, "inside_cells": int(grid.sum()),
           "cells_where_rules_differ": int(len(cells))}
    if len(cells):
        sc, su, d1, d2 = brute(surf, grid, lo, h, cells, r, need)
        row["surely_covered"], row["surely_uncovered"] = int(sc.sum()), int(su.sum())
        for rule in RULES:
            c = cov[rule][tuple(cells.T)]
            cw, lw = c & su, ~c & sc
            # how far past the opening a wrongly covered cell lies at least (its distance to the
            # nearest sample with a ball of need - e, less e and r), and how far inside it a
            # wrongly uncovered one (r less its distance to a sample with a ball of need)
            row[rule] = {"covered": int(c.sum()), "covered_wrongly": int(cw.sum()),
                         "left_uncovered_wrongly": int(lw.sum()),
                         "covered_wrongly_past_mm": round(float((d2[cw] - r).max()), 4) if cw.any() else None,
                         "left_uncovered_wrongly_inside_mm": round(float((r - d1[lw]).max()), 4) if lw.any() else None}
    else:
        for rule in RULES:
            row[rule] = {"covered": 0, "covered_wrongly": 0, "left_uncovered_wrongly": 0,
                         "covered_wrongly_past_mm": None, "left_uncovered_wrongly_inside_mm": None}
    row["thin_walls_committed"] = [
        {"thickness_mm": round(w.thickness_mm, 4), "volume_mm3": round(w.volume_mm3, 4),
         "thinnest_mm": None if w.thinnest_mm is None else round(w.thinnest_mm, 4)}
        for w in W.thin_walls(name, solid, min_wall)]
    row["seconds"] = round(time.perf_counter() - t0, 1)
    return row


#: the patch of session 38 (``found``) as applied to ``thin_walls``, for the fin sweep
PATCH = ((
    """        D, _ = _ball(surf, lo + h * ib, h, r * (1 - WALL_TOL))
        ok = D >= r * (1 - WALL_TOL)
        centres[tuple(ib[ok].T)] = True
""", """        D, Cb = _ball(surf, lo + h * ib, h, r * (1 - WALL_TOL))
        found = Cb[D >= r * (1 - WALL_TOL)]
    else:
        found = np.zeros((0, 3))
"""), (
    """    rest = grid & ~covered
    if not rest.any():
        return []
""", """    if len(found):
        from scipy.spatial import cKDTree
        cand = np.argwhere(grid & ~covered)
        d, _ = cKDTree(found).query(lo + h * cand, distance_upper_bound=r + 1e-9)
        covered[tuple(cand[d <= r + 1e-9].T)] = True
    rest = grid & ~covered
    if not rest.any():
        return []
"""))


def patched_walls():
    """``mlc.mesh.walls`` with the session-38 patch applied (a module of its own)."""
    import importlib.util
    import tempfile
    src = Path(W.__file__).read_text()
    for a, b in PATCH:
        assert src.count(a) == 1, "walls.py changed: the patch no longer applies"
        src = src.replace(a, b)
    path = Path(tempfile.mkdtemp(prefix="walls_found_")) / "walls_found.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("walls_found", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["walls_found"] = mod        # (the dataclass looks its module up)
    spec.loader.exec_module(mod)
    return mod


def fin(L: float, t: float = 0.4, width: float = 1.4, off=(0.0, 0.0, 0.0)):
    """A 2 mm cube with a fin ``t`` thick and ``width`` wide standing ``L`` out of the middle of one
    face (``width`` 2: the fin's ends flush with two faces of the cube)."""
    import manifold3d as mf
    blk = mf.Manifold.cube([2.0, 2.0, 2.0]).translate([-2.0, -1.0, -1.0])
    f = mf.Manifold.cube([L + 0.1, t, width]).translate([-0.1, -t / 2, -width / 2])
    return (blk + f).translate(list(off))


def fin_sweep(min_wall: float = 0.6, seeds: int = 4) -> list:
    """Thin regions of a fin near the threshold length, by the committed rule and the patch, at
    ``seeds`` random grid offsets a length.  The fin is thinner than any ball, so the opening
    covers ``r - need`` of it past the cube's face; by the definition (a region reaching deeper
    than the corner rounding plus a cell from what is covered) it is a thin wall when
    ``L - (r - need) > (sqrt 3 - 1) r + 1.01 h``."""
    pw = patched_walls()
    r = min_wall / 2
    need = r * (1 - W.WALL_TOL)
    h = min_wall / 8
    edge = (np.sqrt(3) - 1) * r + 1.01 * h
    rng = np.random.default_rng(0)
    rows = []
    for width in (1.4, 2.0):
        for L in np.round(np.arange(0.24, 0.521, 0.02), 3):
            cell, found = [], []
            for _ in range(seeds):
                m = fin(float(L), width=width, off=rng.uniform(0, h, 3))
                cell.append(len(W.thin_walls("fin", m, min_wall)))
                found.append(len(pw.thin_walls("fin", m, min_wall)))
            rows.append({"fin_mm": float(L), "fin_thickness_mm": 0.4, "fin_width_mm": width,
                         "thin_wall_by_definition": bool(L - (r - need) > edge),
                         "regions_cell": cell, "regions_found": found})
    return rows


def plate():
    import manifold3d as mf
    blk = mf.Manifold.cube([2.0, 2.0, 2.0]).translate([-2.0, -1.0, -1.0])
    fin = mf.Manifold.cube([1.1, 0.55, 1.4]).translate([-0.1, -0.275, -0.7])
    return (blk + fin).translate([0.013, 0.031, 0.047])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gates", nargs="*", default=["NAND:expand:mjp"])
    ap.add_argument("--out", default=str(RESULTS / "mesh_walls_cover.json"))
    args = ap.parse_args()
    rows = []
    r = judge("plate", plate(), 0.6)
    r["case"] = "plate"
    rows.append(r)
    print(json.dumps(r), flush=True)
    from mlc.gates.library import gate_scene
    from mlc.mesh.pipeline import export_assembly
    from mlc.mesh.profiles import load_profile
    for spec in args.gates:
        g, s, p = spec.split(":")
        profile = load_profile(p)
        asm, _ = export_assembly(gate_scene(g, s), profile)
        for part in asm.parts:
            r = judge(part.name, part.solid, float(profile.min_wall))
            r["case"] = spec
            rows.append(r)
            print(json.dumps(r), flush=True)
    sweep = fin_sweep()
    for r in sweep:
        print(json.dumps(r), flush=True)
    out = {"benchmark": "mesh_walls_cover", "commit": commit(), "python": platform.python_version(),
           "cpus": os.cpu_count(), "load_average": [round(x, 2) for x in os.getloadavg()], "rows": rows, "fin_sweep": sweep}
    with atomic_path(Path(args.out)) as t:
        Path(t).write_text(json.dumps(out, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
