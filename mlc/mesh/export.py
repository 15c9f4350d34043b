"""Writing and reading the printable meshes: STL (whole assembly or one part) and 3MF.

Meshes go out through trimesh (STL).  3MF is written here with the standard library
(zip + XML, unit millimetre): one object, the assembly, whose named parts are volumes
(PrusaSlicer's ``Slic3r_PE_model.config``), so slicers keep the parts in place; it needs no
XML package beyond Python's; :func:`read_3mf` reads it back.  The files of one export are
written all or none (``mlc.io.outputs``): a failed export leaves no file behind.
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
from mlc.io.atomic import write_bytes

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
    """``[(part name, mesh)]`` in the print frame (mm) when ``oriented`` (each part in the printed
    configuration, ``asm.print_T``), else the model frame (rest)."""
    return [(p.name, to_trimesh(p.solid, asm.print_T(p.name) if oriented else None)) for p in asm.parts]


def stl_bytes(meshes) -> bytes:
    if not meshes:
        raise MlcError("nothing to export: the assembly has no parts")
    whole = trimesh.util.concatenate([m for _, m in meshes])
    return whole.export(file_type="stl")


def threemf_bytes(meshes, title: str = "mlc") -> bytes:
    """A 3MF package (unit millimetre): the whole assembly as **one object** whose named
    parts are *volumes*, so that a slicer keeps them where they are.

    The core 3MF model has one mesh object holding every part's triangles (each part a closed
    shell of its own; any 3MF reader sees the assembly in place).  The parts' names and their
    triangle ranges are in ``Metadata/Slic3r_PE_model.config``, the convention PrusaSlicer (and
    its forks, Orca and Bambu Studio) read to split an object into named volumes.  A 3MF with
    one object per part instead makes PrusaSlicer drop each part onto the bed on its own."""
    if not meshes:
        raise MlcError("nothing to export: the assembly has no parts")
    out = io.BytesIO()
    verts, tris, vols = [], [], []
    voff = toff = 0
    for name, m in meshes:
        v = np.asarray(m.vertices, float)
        f = np.asarray(m.faces, np.int64)
        verts.append("".join(f'<vertex x="{x:.6g}" y="{y:.6g}" z="{z:.6g}"/>' for x, y, z in v.tolist()))
        tris.append("".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in (f + voff).tolist()))
        vols.append((name, toff, toff + len(f) - 1))
        voff += len(v)
        toff += len(f)
    model = (f'<?xml version="1.0" encoding="UTF-8"?>\n<model unit="millimeter" xml:lang="en-US" '
             f'xmlns="{_NS_3MF}"><metadata name="Title">{_xml(title)}</metadata>'
             f'<metadata name="Application">mlc</metadata>'
             f'<resources><object id="1" type="model" name="{_xml(title)}"><mesh><vertices>{"".join(verts)}'
             f'</vertices><triangles>{"".join(tris)}</triangles></mesh></object></resources>'
             f'<build><item objectid="1"/></build></model>\n')
    cfg = ['<?xml version="1.0" encoding="UTF-8"?>\n<config>\n <object id="1" instances_count="1">\n'
           f'  <metadata type="object" key="name" value="{_xml(title)}"/>\n']
    for name, a, b in vols:
        cfg.append(f'  <volume firstid="{a}" lastid="{b}">\n'
                   f'   <metadata type="volume" key="name" value="{_xml(name)}"/>\n'
                   f'   <metadata type="volume" key="volume_type" value="ModelPart"/>\n  </volume>\n')
    cfg.append(" </object>\n</config>\n")
    types = ('<?xml version="1.0" encoding="UTF-8"?>\n<Types xmlns="http://schemas.openxmlformats.org/package/'
             '2006/content-types"><Default Extension="rels" ContentType="application/vnd.openxmlformats-'
             'package.relationships+xml"/><Default Extension="model" ContentType="application/vnd.ms-package.'
             '3dmanufacturing-3dmodel+xml"/><Default Extension="config" ContentType="text/xml"/></Types>\n')
    rels = ('<?xml version="1.0" encoding="UTF-8"?>\n<Relationships xmlns="http://schemas.openxmlformats.org/'
            'package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://'
            'schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>\n')
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=5) as z:
        z.writestr("[Content_Types].xml", types)
        z.writestr("_rels/.rels", rels)
        z.writestr("3D/3dmodel.model", model)
        z.writestr(SLIC3R_CONFIG, "".join(cfg))
    return out.getvalue()


SLIC3R_CONFIG = "Metadata/Slic3r_PE_model.config"


def _xml(s: str) -> str:
    return (str(s).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;"))


def read_3mf(path) -> list[tuple[str, trimesh.Trimesh]]:
    """The named parts of a 3MF file as meshes (in millimetres): the volumes of each object
    when the file lists them (``Metadata/Slic3r_PE_model.config``), else one mesh per object."""
    try:
        with zipfile.ZipFile(path) as z:
            names = [n for n in z.namelist() if n.lower().endswith(".model")]
            if not names:
                raise MlcError("not a 3MF file: no 3D model inside", str(path))
            root = ET.fromstring(z.read(names[0]))
            cfg = ET.fromstring(z.read(SLIC3R_CONFIG)) if SLIC3R_CONFIG in z.namelist() else None
    except (zipfile.BadZipFile, ET.ParseError, OSError) as e:
        raise MlcError(f"cannot read 3MF: {e}", str(path)) from None
    ns = {"m": root.tag[1:].split("}")[0]} if root.tag.startswith("{") else {"m": ""}
    scale = {"millimeter": 1.0, "micron": 1e-3, "centimeter": 10.0, "meter": 1000.0, "inch": 25.4,
             "foot": 304.8}.get(root.get("unit", "millimeter"), 1.0)
    volumes = {}
    if cfg is not None:
        for obj in cfg.iter("object"):
            vl = []
            for vol in obj.iter("volume"):
                nm = next((m.get("value") for m in vol.iter("metadata") if m.get("key") == "name"), None)
                vl.append((nm, int(vol.get("firstid")), int(vol.get("lastid"))))
            volumes[obj.get("id")] = vl
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
        name = obj.get("name") or f"object_{obj.get('id')}"
        vl = volumes.get(obj.get("id"))
        if not vl:
            out.append((name, trimesh.Trimesh(v, f, process=False)))
            continue
        for k, (nm, a, b) in enumerate(vl):
            sub = trimesh.Trimesh(v, f[a:b + 1], process=False)
            sub.remove_unreferenced_vertices()
            out.append((nm or f"{name}_{k}", sub))
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


def declare_outputs(outs, stl=None, threemf=None, parts_dir=None, options=("-o", "--3mf", "--parts")):
    """Declare the mesh files in an :class:`mlc.io.outputs.Outputs` (checked before any work):
    returns ``(stl, threemf, parts)``, each None when not asked for."""
    return (outs.file(stl, options[0], suffixes=(".stl",)),
            outs.file(threemf, options[1], suffixes=(".3mf",)),
            outs.directory(parts_dir, options[2]))


def write_staged(meshes, title: str, stl=None, threemf=None, parts=None) -> list[str]:
    """Write the meshes to outputs declared by :func:`declare_outputs` (staged: they reach their
    places when the ``Outputs`` block ends); return the final paths."""
    final = []
    if stl is not None:
        stl.write_bytes(stl_bytes(meshes))
        final.append(str(stl.path))
    if threemf is not None:
        threemf.write_bytes(threemf_bytes(meshes, title))
        final.append(str(threemf.path))
    if parts is not None:
        if not meshes:
            raise MlcError("nothing to export: the assembly has no parts")
        for name, m in meshes:
            fname = f"{safe_name(name)}.stl"
            parts.write_bytes(fname, m.export(file_type="stl"))
            final.append(str(parts.path / fname))
    return final


def write_outputs(asm, stl=None, threemf=None, parts_dir=None, meshes=None) -> list[str]:
    """Write the requested files, all or none (:mod:`mlc.io.outputs`); return the paths written.

    Every location is checked first (a file where the parts directory should go, a read-only
    directory, a wrong suffix are :class:`~mlc.errors.MlcError`); the files are staged and moved
    into place only when all are written."""
    from mlc.io.outputs import Outputs

    outs = Outputs()
    decl = declare_outputs(outs, stl, threemf, parts_dir)
    with outs:
        meshes = meshes if meshes is not None else part_meshes(asm)
        final = write_staged(meshes, asm.scene.name, *decl)
    return final


__all__ = ["to_trimesh", "part_meshes", "stl_bytes", "threemf_bytes", "read_3mf", "read_parts",
           "declare_outputs", "write_staged", "write_outputs", "write_bytes"]
