"""What holds a library gate's print off the bed, measured (issue 13, item 1; not CI).

    python benchmarks/slicer_bed_levels.py [--gates NAND,NOR] [--profiles fdm] [--signal expand]

With the model's z up (the pose ``orient: auto`` keeps for every library gate in fdm,
benchmarks/results/slicer_gates.json), the slabs of the lever loop (core_ab, the input levers,
core_cd) stand on edge and every hinge of that loop runs along z, so no configuration of the
mechanism moves any of them along z (benchmarks/results/slicer_configs.json: every hinge axis
turns 0 degrees over the reachable set).  For the parts ``mlc stl`` prints (the same build as
``benchmarks/slicer_configs.py``), in the rest configuration, up = z, this records:

* each part's lowest point above the print's lowest point (mm);
* for every distinct such level L: the section of all parts at L + half the first layer, as a
  fraction of the footprint -- the bed contact the print would have if nothing hung below L;
* the report's support figures per part (``bed_stats``: overhang mm^2, support mm^3, of it on
  other parts), to say which parts the support is for.

Lengths mm, areas mm^2, volumes mm^3.  No random numbers.  Results:
``benchmarks/results/slicer_bed_levels.json``.
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import manifold3d as mf  # noqa: E402

from mlc.gates.library import GATE_NAMES, gate_scene  # noqa: E402
from mlc.mesh.build import _orientation, transform_solid  # noqa: E402
from mlc.mesh.checks import bed_checks  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402
from slicer_configs import printed  # noqa: E402
from gitstate import commit as git_commit      # benchmarks/gitstate.py


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--signal", default="expand")
    ap.add_argument("--gates", default=",".join(GATE_NAMES))
    ap.add_argument("--profiles", default="fdm")
    ap.add_argument("-o", "--out", default=str(ROOT / "benchmarks/results/slicer_bed_levels.json"))
    a = ap.parse_args()
    commit = git_commit()
    rows = []
    for g in a.gates.split(","):
        scene = gate_scene(g, a.signal)
        for pn in a.profiles.split(","):
            prof = load_profile(pn, {"orient": "as_is"})
            t0 = time.perf_counter()
            asm = printed(scene, prof)
            asm.orient = _orientation(asm)            # the model's z up, centred, on the bed
            bed_checks(asm)
            st = asm.bed
            sol = [(p.name, transform_solid(p.solid, asm.orient)) for p in asm.parts if not p.solid.is_empty()]
            fp = mf.CrossSection.batch_boolean([s.project() for _, s in sol], mf.OpType.Add).area()
            half = 0.5 * min(0.2, prof.min_wall / 2)
            low = {n: round(float(np.asarray(s.bounding_box())[2]), 3) for n, s in sol}
            levels = []
            for L in sorted(set(low.values())):
                sec = mf.CrossSection.batch_boolean([s.slice(L + half) for _, s in sol], mf.OpType.Add).area()
                levels.append({"level_mm": L, "parts_from_here": sorted(n for n, z in low.items() if z == L),
                               "section_mm2": round(float(sec), 1), "fraction_of_footprint": round(float(sec / fp), 4)})
            row = {"gate": g, "signal": a.signal, "profile": pn, "commit": commit, "seconds": round(time.perf_counter() - t0, 1),
                   "footprint_mm2": round(float(fp), 1), "contact_fraction": round(st.contact_fraction, 4),
                   "support_fraction": round(st.support_fraction, 4), "support_mm3": round(st.support_mm3, 1),
                   "support_inside_mm3": round(st.support_inside_mm3, 1), "lowest_mm": low, "levels": levels,
                   "per_part": {n: {"overhang_mm2": v[0], "support_mm3": v[1], "on_other_parts_mm3": v[2]}
                                for n, v in st.per_part.items()}}
            rows.append(row)
            best = max(levels, key=lambda x: x["fraction_of_footprint"])
            print(f"{g:8s} {pn}: contact {100 * row['contact_fraction']:.2f} %; lowest {low}; at "
                  f"{best['level_mm']} mm the section is {100 * best['fraction_of_footprint']:.1f} % of the footprint; "
                  f"support {100 * row['support_fraction']:.1f} %", flush=True)
            Path(a.out).write_text(json.dumps({"machine": platform.platform(), "commit": commit,
                                               "note": "model's z up, rest configuration; lengths mm",
                                               "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
