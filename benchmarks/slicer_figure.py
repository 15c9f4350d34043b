"""The picture of docs/printing.md "On the bed": a gate as laid out on the bed (print frame).

    python benchmarks/slicer_figure.py [GATE] [PROFILE]

Writes docs/img/print_bed_<gate>_<profile>.png: the parts in the print frame of the profile
(the orientation the 3MF and STL are written in), over a grey plate at z = 0.
"""
from __future__ import annotations

import sys
from pathlib import Path

import trimesh

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mlc.gates.library import gate_scene  # noqa: E402
from mlc.mesh.build import build_assembly  # noqa: E402
from mlc.mesh.examples import gate_poses  # noqa: E402
from mlc.mesh.export import part_meshes  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402
from mlc.mesh.render import render_panels  # noqa: E402


def main(argv) -> int:
    gate = argv[0] if argv else "NAND"
    pn = argv[1] if len(argv) > 1 else "fdm"
    prof = load_profile(pn)
    asm = build_assembly(gate_scene(gate, "expand"), prof, gate_poses(gate, "expand"))
    meshes = part_meshes(asm)
    lo = min(m.bounds[0][0] for _, m in meshes), min(m.bounds[0][1] for _, m in meshes)
    hi = max(m.bounds[1][0] for _, m in meshes), max(m.bounds[1][1] for _, m in meshes)
    pad = 0.15 * max(hi[0] - lo[0], hi[1] - lo[1])
    bed = trimesh.creation.box([hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad, 0.02 * pad])
    bed.apply_translation([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, -0.01 * pad])
    out = ROOT / "docs" / "img" / f"print_bed_{gate.lower()}_{pn}.png"
    render_panels([(f"{gate} (expanding muscles), profile {pn}, orient {prof.orient}: on the bed",
                    meshes + [("bed", bed)])], out, elev=14, azim=-60, size=(8.0, 6.0))
    print(f"wrote {out.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
