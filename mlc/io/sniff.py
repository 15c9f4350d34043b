"""Recognise a mesh file by its bytes before handing it to a mesh library.

trimesh guesses: given bytes that are neither binary nor ASCII STL it tries a text
decoder (needing the optional ``charset_normalizer``) or returns an empty mesh.  These
checks give one clear error instead, and read only the first bytes of a large file.
"""
from __future__ import annotations

import os
import zipfile
from pathlib import Path

from mlc.errors import MlcError

_STL_HEADER = 80
_STL_TRIANGLE = 50            # 12 floats (normal, 3 vertices) and a 2-byte attribute


def check_mesh_file(path, max_triangles: int | None = None) -> str:
    """Return ``"stl-binary"``, ``"stl-ascii"`` or ``"3mf"``; raise MlcError for anything else.

    A binary STL is 80 header bytes, a little-endian uint32 triangle count N and exactly
    50 N bytes of triangles; an ASCII STL is text starting with ``solid`` and containing
    ``facet``; a 3MF is a ZIP archive.  ``max_triangles`` refuses larger binary files
    before they are loaded."""
    p = Path(path)
    try:
        size = os.stat(p).st_size
        if p.is_dir():
            raise MlcError("mesh file is a directory", str(p), "give an .stl or .3mf file")
        with open(p, "rb") as f:
            head = f.read(4096)
    except FileNotFoundError:
        raise MlcError("mesh file not found", str(p)) from None
    except OSError as e:
        raise MlcError(f"cannot read mesh file: {e.strerror}", str(p)) from None
    if p.suffix.lower() == ".3mf" or head[:4] == b"PK\x03\x04":
        if not zipfile.is_zipfile(p):
            raise MlcError("not a 3MF file (a 3MF is a ZIP archive)", str(p), "give an .stl or .3mf file")
        return "3mf"
    if size >= _STL_HEADER + 4:
        n = int.from_bytes(head[_STL_HEADER:_STL_HEADER + 4], "little")
        if size == _STL_HEADER + 4 + _STL_TRIANGLE * n:
            if n == 0:
                raise MlcError("binary STL with no triangles", str(p))
            if max_triangles is not None and n > max_triangles:
                raise MlcError(f"mesh has {n} triangles, too many to draw (limit {max_triangles})", str(p))
            return "stl-binary"
    text = head.lstrip()
    if text[:5].lower() == b"solid":
        try:
            head.decode("ascii")
        except UnicodeDecodeError:
            raise MlcError("not an STL file: starts like ASCII STL but contains binary bytes", str(p),
                           "give a binary or ASCII STL, or a 3MF file") from None
        if b"facet" not in head and size <= len(head):
            raise MlcError("ASCII STL with no triangles (no 'facet')", str(p))
        return "stl-ascii"
    raise MlcError(f"not an STL or 3MF file (binary STL needs {_STL_HEADER + 4} + 50 x N bytes, "
                   f"ASCII STL starts with 'solid')", str(p), "give an .stl or .3mf file")
