"""Writing and reading the printable meshes: STL (whole assembly or one part) and 3MF.

Meshes go out through trimesh (STL).  3MF is written here with the standard library
(zip + XML, unit millimetre, one named ``object`` per part, one build ``item`` each) so it
needs no XML package beyond Python's; :func:`read_3mf` reads it back.  Every file is
written atomically (``mlc.io.atomic``): a failed export leaves no partial file.
"""
from __future__ import annotations

import io
import re
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import trimesh

from mlc.errors import MlcError
from mlc.io.atomic import atomic_path, write_bytes

_NS_3MF = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"


def to_trimesh(solid, T=None) -> trimesh.Trimesh:
    """A manifold3d solid as a trimesh (optionally transformed by the 4x4 ``T``)."""
    m = solid.to_mesh64() if hasattr(solid, "to_mesh64") else solid.to_mesh()
    v = np.asarray(m.vert_properties, dtype=np.float64)[:, :3]
    f = np.asarray(m.tri_verts, dtype=np.int64)
    if T is not None:
        v = v @ np.asarray(T)[:3, :3].T + np.asarray(T)[:3, 3]
    return trimesh.Trimesh(vertices=v, faces=f, process=False)


def part_meshes(asm, oriented: bool = True) -> list[tuple[str, trimesh.Trimesh]]:
    """``[(part name, mesh)]`` in the print frame (mm) when ``oriented``, else the model frame."""
    T = asm.orient if oriented else None
    return [(p.name, to_trimesh(p.solid, T)) for p in asm.parts]


def stl_bytes(meshes) -> bytes:
    if not meshes:
        raise MlcError("nothing to export: the assembly has no parts")
    whole = trimesh.util.concatenate([m for _, m in meshes])
    return whole.export(file_type="stl")


def threemf_bytes(meshes, title: str = "mlc") -> bytes:
    """A 3MF package (unit millimetre) with one named object per part."""
    out = io.BytesIO()
    parts = []
    for i, (name, m) in enumerate(meshes, start=1):
        v = np.asarray(m.vertices, float)
        f = np.asarray(m.faces, np.int64)
        verts = "".join(f'<vertex x="{x:.6g}" y="{y:.6g}" z="{z:.6g}"/>' for x, y, z in v.tolist())
        tris = "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in f.tolist())
        parts.append(f'<object id="{i}" type="model" name="{_xml(name)}"><mesh><vertices>{verts}</vertices>'
                     f'<triangles>{tris}</triangles></mesh></object>')
    items = "".join(f'<item objectid="{i}"/>' for i in range(1, len(meshes) + 1))
    model = (f'<?xml version="1.0" encoding="UTF-8"?>\n<model unit="millimeter" xml:lang="en-US" '
             f'xmlns="{_NS_3MF}"><metadata name="Title">{_xml(title)}</metadata>'
             f'<metadata name="Application">mlc</metadata>'
             f'<resources>{"".join(parts)}</resources><build>{items}</build></model>\n')
    types = ('<?xml version="1.0" encoding="UTF-8"?>\n<Types xmlns="http://schemas.openxmlformats.org/package/'
             '2006/content-types"><Default Extension="rels" ContentType="application/vnd.openxmlformats-'
             'package.relationships+xml"/><Default Extension="model" ContentType="application/vnd.ms-package.'
             '3dmanufacturing-3dmodel+xml"/></Types>\n')
    rels = ('<?xml version="1.0" encoding="UTF-8"?>\n<Relationships xmlns="http://schemas.openxmlformats.org/'
            'package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://'
            'schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>\n')
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=5) as z:
        z.writestr("[Content_Types].xml", types)
        z.writestr("_rels/.rels", rels)
        z.writestr("3D/3dmodel.model", model)
    return out.getvalue()


def _xml(s: str) -> str:
    return (str(s).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;"))


def read_3mf(path) -> list[tuple[str, trimesh.Trimesh]]:
    """The named objects of a 3MF file as meshes (in millimetres)."""
    try:
        with zipfile.ZipFile(path) as z:
            names = [n for n in z.namelist() if n.lower().endswith(".model")]
            if not names:
                raise MlcError("not a 3MF file: no 3D model inside", str(path))
            root = ET.fromstring(z.read(names[0]))
    except (zipfile.BadZipFile, ET.ParseError, OSError) as e:
        raise MlcError(f"cannot read 3MF: {e}", str(path)) from None
    ns = {"m": root.tag[1:].split("}")[0]} if root.tag.startswith("{") else {"m": ""}
    scale = {"millimeter": 1.0, "micron": 1e-3, "centimeter": 10.0, "meter": 1000.0, "inch": 25.4,
             "foot": 304.8}.get(root.get("unit", "millimeter"), 1.0)
    out = []
    q = (lambda t: f"m:{t}") if ns["m"] else (lambda t: t)
    for obj in root.iter(f"{{{ns['m']}}}object" if ns["m"] else "object"):
        mesh = obj.find(q("mesh"), ns)
        if mesh is None:
            continue
        v = np.array([[float(e.get("x")), float(e.get("y")), float(e.get("z"))]
                      for e in mesh.find(q("vertices"), ns)], float) * scale
        f = np.array([[int(e.get("v1")), int(e.get("v2")), int(e.get("v3"))]
                      for e in mesh.find(q("triangles"), ns)], np.int64).reshape(-1, 3)
        out.append((obj.get("name") or f"object_{obj.get('id')}", trimesh.Trimesh(v, f, process=False)))
    return out


def read_parts(path) -> list[tuple[str, trimesh.Trimesh]]:
    """The parts of an exported file: 3MF objects by name, or the connected pieces of an STL."""
    path = Path(path)
    if path.suffix.lower() == ".3mf":
        return read_3mf(path)
    try:
        m = trimesh.load(str(path), force="mesh")
    except Exception as e:  # trimesh raises many kinds
        raise MlcError(f"cannot read mesh: {e}", str(path)) from None
    if not isinstance(m, trimesh.Trimesh) or len(m.faces) == 0:
        raise MlcError("mesh file has no triangles", str(path))
    pieces = m.split(only_watertight=False)   # keep open pieces: they are errors to see
    return [(f"part_{i}", p) for i, p in enumerate(pieces)]


def safe_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)


def write_outputs(asm, stl=None, threemf=None, parts_dir=None, meshes=None) -> list[str]:
    """Write the requested files atomically; return the paths written.

    Every file is first built in memory, then all are renamed into place: an error while
    building any of them leaves none behind."""
    meshes = meshes if meshes is not None else part_meshes(asm)
    blobs: list[tuple[Path, bytes]] = []
    if stl:
        blobs.append((Path(stl), stl_bytes(meshes)))
    if threemf:
        blobs.append((Path(threemf), threemf_bytes(meshes, asm.scene.name)))
    if parts_dir:
        d = Path(parts_dir)
        if d.exists() and not d.is_dir():
            raise MlcError("--parts must be a directory", str(d))
        d.mkdir(parents=True, exist_ok=True)
        for name, m in meshes:
            blobs.append((d / f"{safe_name(name)}.stl", m.export(file_type="stl")))
    written = []
    # write every file to its temporary first; rename only when all are written
    from contextlib import ExitStack
    with ExitStack() as stack:
        for path, data in blobs:
            tmp = stack.enter_context(atomic_path(path))
            tmp.write_bytes(data)
            written.append(str(path))
    return written


__all__ = ["to_trimesh", "part_meshes", "stl_bytes", "threemf_bytes", "read_3mf", "read_parts",
           "write_outputs", "write_bytes"]
