"""Regenerate the pictures of docs/printing.md.

    python benchmarks/mesh_figures.py

docs/img/nand_print.png: the printable NAND gate (profile mjp, sigma = 5 mm) as printed,
and posed at the equilibrium of input state 11 (both muscles actuated) -- the same parts,
moved by their hinges.
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mlc.gates.library import gate_scene  # noqa: E402
from mlc.mesh.build import build_assembly  # noqa: E402
from mlc.mesh.examples import gate_poses  # noqa: E402
from mlc.mesh.export import to_trimesh  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402
from mlc.mesh.render import render_panels  # noqa: E402


def main() -> int:
    poses = gate_poses("NAND", "expand")
    asm = build_assembly(gate_scene("NAND", "expand"), load_profile("mjp"), poses)
    rest = [(p.name, to_trimesh(p.solid, asm.orient)) for p in asm.parts]
    T = asm.part_transforms(*poses["11"])
    moved = [(p.name, to_trimesh(p.solid, asm.orient @ T[p.name])) for p in asm.parts]
    out = ROOT / "docs" / "img" / "nand_print.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    render_panels([("NAND, profile mjp (sigma 5 mm): as printed, inputs 00", rest),
                   ("the same parts at the equilibrium of inputs 11", moved)], out, elev=24, azim=-62)
    print(f"wrote {out.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
