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
