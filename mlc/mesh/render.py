"""``mlc draw --mesh X.stl -o X.png``: a shaded picture of printable meshes (matplotlib).

Each part (3MF object, or connected piece of an STL) gets its own colour; faces are
shaded by a fixed light so hinges and knuckles read in a still image."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mlc.errors import MlcError
from mlc.io.atomic import atomic_path

_PALETTE = ["#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860", "#da8bc3", "#8c8c8c",
            "#ccb974", "#64b5cd"]


def render_parts(meshes, out_png, title: str | None = None, elev: float = 28, azim: float = -58,
                 size=(7.0, 6.0), max_faces: int = 400_000) -> None:
    """Render ``[(name, trimesh)]`` to a PNG file (written atomically)."""
    if not meshes:
        raise MlcError("nothing to draw: the mesh has no parts")
    render_panels([(title, meshes)], out_png, elev=elev, azim=azim, size=size, max_faces=max_faces)


def render_panels(panels, out_png, elev: float = 28, azim: float = -58, size=None,
                  max_faces: int = 400_000) -> None:
    """Render several ``(title, [(name, trimesh)])`` panels side by side into one PNG."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    total = sum(len(m.faces) for _, meshes in panels for _, m in meshes)
    if total > max_faces:
        raise MlcError(f"mesh has {total} triangles, too many to draw (limit {max_faces})")
    size = size or (6.5 * len(panels), 6.0)
    fig = plt.figure(figsize=size, dpi=130)
    light = np.array([0.35, -0.45, 0.82])
    light /= np.linalg.norm(light)
    for k, (title, meshes) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), k + 1, projection="3d")
        allt, allc = [], []
        for i, (name, m) in enumerate(meshes):
            tris = np.asarray(m.vertices)[np.asarray(m.faces)]
            n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
            nn = np.linalg.norm(n, axis=1, keepdims=True)
            n = n / np.where(nn > 0, nn, 1)
            shade = 0.3 + 0.7 * np.clip(n @ light, 0, 1)
            base = np.array(matplotlib.colors.to_rgb(_PALETTE[i % len(_PALETTE)]))
            allt.append(tris)
            allc.append(np.clip(base[None, :] * shade[:, None], 0, 1))
        tris = np.concatenate(allt)
        # one collection: matplotlib sorts its faces by depth, so parts occlude each other properly
        ax.add_collection3d(Poly3DCollection(tris, facecolors=np.concatenate(allc), edgecolors="none",
                                             linewidths=0))
        lo = tris.reshape(-1, 3).min(0)
        hi = tris.reshape(-1, 3).max(0)
        c = (lo + hi) / 2
        r = float(np.max(hi - lo)) / 2 or 1.0
        ax.set_xlim(c[0] - r, c[0] + r)
        ax.set_ylim(c[1] - r, c[1] + r)
        ax.set_zlim(c[2] - r, c[2] + r)
        ax.set_box_aspect((1, 1, 1))
        ax.view_init(elev=elev, azim=azim)
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_zlabel("z (mm)")
        ax.set_title(title or f"{len(meshes)} parts, {hi[0] - lo[0]:.1f} x {hi[1] - lo[1]:.1f} x "
                              f"{hi[2] - lo[2]:.1f} mm")
    out_png = Path(out_png)
    with atomic_path(out_png, suffix=".png") as tmp:
        fig.savefig(tmp, format="png", bbox_inches="tight")
    plt.close(fig)


def render_mesh(path, out_png, **kw) -> None:
    """Render an STL or 3MF file (``mlc draw --mesh path -o out_png``)."""
    from mlc.mesh.export import read_parts

    path = Path(path)
    if not path.exists():
        raise MlcError("mesh file not found", str(path))
    meshes = read_parts(path)
    kw.setdefault("title", f"{path.name}: {len(meshes)} parts")
    render_parts(meshes, out_png, **kw)
