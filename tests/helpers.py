"""Shared test helpers (tests/ is on sys.path under pytest's default import mode)."""
import os
from pathlib import Path

import pytest

from mlc.errors import MlcError

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden" / "front"


def check_golden(name: str, text: str) -> None:
    """Compare ``text`` with tests/golden/front/NAME (rewrite it with MLC_UPDATE_GOLDEN=1)."""
    path = GOLDEN / name
    if os.environ.get("MLC_UPDATE_GOLDEN"):
        path.write_text(text)
    assert path.exists(), f"missing golden file {path}; run with MLC_UPDATE_GOLDEN=1"
    assert text == path.read_text()


def assert_parse_error(parse, text: str, filename: str, where: str, words: str) -> None:
    """``parse(text, filename)`` must raise one MlcError located at ``filename:where`` containing ``words``."""
    with pytest.raises(MlcError) as e:
        parse(text, filename)
    msg = str(e.value)
    assert msg.startswith(f"{filename}:{where}:") or msg.startswith(f"{filename}:{where} "), msg
    assert words in msg, msg


def random_aig(seed: int, n_in: int = 20, n_and: int = 400, n_out: int = 12, window: int = 40):
    """A seeded random AIG: mostly local fanins (the last ``window`` nodes: reconvergence), some
    far ones, outputs on every third of the last nodes."""
    import random

    from mlc.logic.aig import AIG
    rng = random.Random(seed)
    g = AIG([f"i{i}" for i in range(n_in)])
    lits = [g.input_lit(i) for i in range(n_in)]
    while g.num_ands() < n_and:
        a = rng.choice(lits[-window:]) if rng.random() < 0.7 else rng.choice(lits)
        b = rng.choice(lits[-window:]) if rng.random() < 0.7 else rng.choice(lits)
        r = g.and_(a ^ rng.randint(0, 1), b ^ rng.randint(0, 1))
        if r > 1 and (r >> 1) > n_in and r not in lits:
            lits.append(r & ~1)
    for k in range(n_out):
        g.add_output(f"o{k}", lits[-1 - 3 * k] ^ (k & 1))
    return g.cleanup()


def downward_faces(solid):
    """The downward faces of a manifold3d ``solid``: (normal z, area, centroid (n, 3)) of each
    triangle whose normal points down (z < 0, area > 0)."""
    import numpy as np
    m = solid.to_mesh()
    V = np.asarray(m.vert_properties, float)[:, :3]
    F = np.asarray(m.tri_verts, np.int64)
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    n = np.cross(B - A, C - A)
    area = 0.5 * np.linalg.norm(n, axis=1)
    nz = n[:, 2] / np.maximum(2 * area, 1e-12)
    keep = (nz < -1e-9) & (area > 1e-9)
    return nz[keep], area[keep], ((A + B + C) / 3)[keep]


def web_sections(asm, min_wall, owner=None):
    """The webs of the owner of a three-body hinge (a gate's hinge c; ``owner``: that body's name
    when the assembly holds several gates): every piece of a section normal to the axis in the
    middle of the other bodies' knuckles, near the axis and not the pin, with the diameter of the
    largest disc in it (manifold3d slices, Clipper2 offsets to 0.001 mm; as
    benchmarks/mesh_gates.py's section_webs), independent of mlc.mesh.walls."""
    import numpy as np

    from mlc.mesh.build import _perp_frame
    (c,) = [ax for ax in asm.axes if len(ax.bodies) == 3 and owner in (None, ax.owner)]
    E = np.asarray(c.direction, float)
    R = _perp_frame(E).T
    M = np.hstack([R, (-R @ np.asarray(c.origin, float))[:, None]])
    local = asm.part(c.owner).solid.transform(M.tolist())
    out = []
    for bn, ivs in c.intervals.items():
        if bn == c.owner:
            continue
        for a0, a1 in ivs:
            for piece in local.slice(0.5 * (a0 + a1)).decompose():
                x0, y0, x1, y1 = piece.bounds()
                if x0 <= 0 <= x1 and y0 <= 0 <= y1:
                    continue
                if np.hypot(max(x0, 0, -x1), max(y0, 0, -y1)) > c.rho + 2 * min_wall:
                    continue
                out.append(largest_disc(piece))
    return out


def largest_disc(section) -> float:
    """The diameter (mm) of the largest disc in a manifold3d ``CrossSection``: the largest inward
    offset (Clipper2, round joins) that leaves it non-empty, bisected to 0.001 mm (up to 4 mm)."""
    import manifold3d as mf

    lo, hi = 0.0, 2.0
    while hi - lo > 5e-4:
        r = 0.5 * (lo + hi)
        lo, hi = (lo, r) if section.offset(-r, mf.JoinType.Round).is_empty() else (r, hi)
    return 2 * lo


def posed_gaps(a, b, transforms, n=300_000, bound=None):
    """The gap (mm) between two manifold3d solids ``a`` and ``b`` in each of ``transforms`` (pairs
    ``(Ta, Tb)`` of rigid 4x4 transforms of each, ``None``: as built), measured outside mlc and
    manifold3d: trimesh's seeded surface samples of each (``n``), nearest pairs by a scipy k-d tree.
    An upper bound of the true gap (the samples' spacing); near 0 where the two surfaces cross; inf
    over ``bound`` (mm) when one is given."""
    import numpy as np
    import trimesh
    from scipy.spatial import cKDTree

    def surf(solid, seed):
        m = solid.to_mesh()
        tm = trimesh.Trimesh(np.asarray(m.vert_properties)[:, :3], np.asarray(m.tri_verts), process=False)
        return trimesh.sample.sample_surface(tm, n, seed=seed)[0]

    def moved(p, T):
        return p if T is None else p @ T[:3, :3].T + T[:3, 3]
    pa, pb = surf(a, 1), surf(b, 2)
    return [float(cKDTree(moved(pb, Tb)).query(moved(pa, Ta), distance_upper_bound=np.inf if bound is None
                                                 else bound)[0].min()) for Ta, Tb in transforms]


def part_gaps(asm, a, b, poses, n=200_000):
    """:func:`posed_gaps` of the assembly's parts ``a`` and ``b`` in each of ``poses`` (``{name:
    (pos, quat)}``, posed by the assembly's part transforms): ``{name: gap}`` (mm; inf over 1 mm)."""
    Ts = {k: asm.part_transforms(*pq) for k, pq in poses.items()}
    gaps = posed_gaps(asm.part(a).solid, asm.part(b).solid, [(T[a], T[b]) for T in Ts.values()], n, bound=1.0)
    return dict(zip(Ts, gaps))


def load_piece(name: str):
    """A piece of a compiled circuit or robot as stored in tests/data_mesh (NAME.yaml, its scene,
    and NAME_poses.npz, the print poses it was cut with): ``(scene, {pose: (pos, quat)})``."""
    import numpy as np

    from mlc.scene.io import load_scene

    data = ROOT / "tests" / "data_mesh"
    z = np.load(data / f"{name}_poses.npz")
    return load_scene(data / f"{name}.yaml"), {str(k): (p, q) for k, p, q in zip(z["names"], z["pos"], z["quat"])}


def mesh_piece(name: str, walls: bool = True, **flags):
    """A piece of a compiled circuit or robot (tests/data_mesh: NAME.yaml and NAME_poses.npz),
    built at mjp with mlc.mesh.build's flags set as given (restored after), and its report:
    ``(assembly, report)``."""
    from mlc.mesh import build as B
    from mlc.mesh.checks import check_assembly
    from mlc.mesh.profiles import load_profile

    sc, poses = load_piece(name)
    with B.flags(**flags):
        asm = B.build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    return asm, check_assembly(asm, walls=walls)
