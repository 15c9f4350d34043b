"""Print poses in other configurations of the mechanism (issue 13, item 1), measured (not CI).

    python benchmarks/slicer_configs.py [--gates NAND,NOR] [--profiles fdm] [--signal expand]
                                        [--step 5] [--eval-step 10] [--no-slicer]

Can a configuration of a library gate other than rest -- any pose its printed joints reach, not
only a logic state -- with a suitable orientation raise bed contact towards 20 % of the footprint
and lower the support?  For each gate and profile:

1. the parts ``mlc stl`` prints (logic states, dense paths and their motion trims, as
   ``export_assembly`` builds them; orientation left as modelled: it is searched here);
2. the joint space of the printed parts (``mlc.mesh.configs.Kinematics``: every hinge axis keeps
   its bodies on one line, the universal joint its point and its crossed pins; muscles are not
   printed): its dimension at rest (``freedoms``), and how far every hinge axis turns from its rest
   direction over the reachable set (``axis_turn_deg``);
3. the reachable set: the input levers' hinge angles on a grid of ``--step`` degrees (up to 90
   degrees from rest), flood-filled from rest; a node is kept when the joints close there and
   half-way from its neighbour and no two parts come closer than the clearance (manifold3d
   ``min_gap``); refusals are counted by the pair of parts that met;
4. every reachable node on the ``--eval-step`` grid, and the ``--step`` neighbours of the best 3,
   in its best orientation among the world axes, every posed slab normal (both signs) and 60
   Fibonacci directions, scored by the report's own support model on a coarse grid, the best 2
   measured on the report's grid (``bed_stats``): contact fraction of the footprint, support
   fraction of the part volume, support between parts (mm^3);
5. ``lift``: for every slab turned flat (up = its normal, both signs), how high its lower face
   starts above the bed (mm): above its own part's lowest point (its knuckles, centred on the
   slab's mid-plane, reach R - t/2 below it) and above the whole print's lowest point, the least
   over the evaluated configurations;
6. PrusaSlicer 2.5 (``benchmarks/slicer_gates.py``'s slices: without supports, with supports,
   build plate only) on rest and on the best other configuration, each in its best orientation.

No random numbers (a grid and a Fibonacci lattice).  Lengths mm, angles degrees.  Results:
``benchmarks/results/slicer_configs.json``.
"""
from __future__ import annotations

import argparse
import collections
import json
import platform
import shutil
import sys
import tempfile
import time
import types
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from mlc.gates.library import GATE_NAMES, gate_scene  # noqa: E402
from mlc.geometry.rotation import quat_to_matrix, rotation_between  # noqa: E402
from mlc.mesh.build import Part, build_assembly, transform_solid  # noqa: E402
from mlc.mesh.configs import Clearance, Evaluator, Kinematics, scan  # noqa: E402
from mlc.mesh.pipeline import _dense_poses, state_poses  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402
from gitstate import commit as git_commit      # benchmarks/gitstate.py


def printed(scene, prof):
    """The parts ``mlc stl`` prints (export_assembly's build, without its checks)."""
    notes = []
    poses, _ = state_poses(scene)
    dense = _dense_poses(scene, prof, notes)
    return build_assembly(scene, prof, poses, motion_poses=dense)


def axis_turn(kin, configs) -> dict:
    """Largest angle (degrees) between each hinge axis, posed with its owner, and its rest
    direction, over ``configs``."""
    out = {}
    for ax in kin.asm.axes:
        i = kin.index[ax.bodies[0]]
        d = np.asarray(ax.direction, float)
        out[ax.name] = round(max(float(np.degrees(np.arccos(np.clip(abs((T[i][:3, :3] @ d) @ d), -1, 1))))
                                 for T in configs), 4)
    return out


def lifts(asm, kin, clear, T) -> dict:
    """For each slab turned flat (up = its posed normal, both signs): its lower face's height
    above its own part's lowest point and above the print's lowest point (mm)."""
    s, t = asm.profile.sigma_mm, asm.slab_thickness
    PT = clear.part_T(T)
    verts = {p.name: np.asarray(transform_solid(p.solid, P).to_mesh().vert_properties, float)[:, :3]
             for p, P in zip(asm.parts, PT)}
    allv = np.concatenate(list(verts.values()))
    own_l, all_l = [], []
    for k, b in enumerate(asm.scene.bodies):
        Rb = quat_to_matrix(b.orientation)
        for bx in b.boxes:
            R = Rb @ quat_to_matrix(bx.orientation)
            n = T[k][:3, :3] @ R[:, int(np.argmin(bx.size))]
            c = T[k][:3, :3] @ (s * (np.asarray(b.position, float) + Rb @ np.asarray(bx.center, float))) + T[k][:3, 3]
            for up in (n, -n):
                face = float(c @ up) - t / 2
                own_l.append(face - float((verts[b.name] @ up).min()))
                all_l.append(face - float((allv @ up).min()))
    return {"own_min": round(min(own_l), 3), "own_max": round(max(own_l), 3), "print_min": round(min(all_l), 3)}


def row_eval(node, step, r) -> dict:
    st = r["stats"]
    return {"angles_deg": [round(step * x, 2) for x in node], "up": [round(float(x), 4) for x in r["up"]],
            "contact_fraction": round(st.contact_fraction, 4), "support_fraction": round(st.support_fraction, 4),
            "support_inside_mm3": round(st.support_inside_mm3, 1), "footprint_mm2": round(st.footprint_mm2, 1),
            "contact_mm2": round(st.contact_mm2, 2), "coarse_best_contact": round(r["coarse_best_contact"], 4),
            "key": list(r["key"])}


def slice_config(exe, asm, clear, T, up, f, title, layer):
    from slicer_gates import pose_row
    PT = clear.part_T(T)
    posed = types.SimpleNamespace(parts=[Part(p.name, p.kind, transform_solid(p.solid, P)) for p, P in zip(asm.parts, PT)],
                                  profile=asm.profile)
    up = np.asarray(up, float)
    return pose_row(exe, posed, rotation_between(up, [0, 0, 1.0]), up, f, title, layer)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--signal", default="expand")
    ap.add_argument("--gates", default=",".join(GATE_NAMES))
    ap.add_argument("--profiles", default="fdm")
    ap.add_argument("--step", type=float, default=5.0)
    ap.add_argument("--eval-step", type=float, default=10.0)
    ap.add_argument("--no-slicer", action="store_true")
    ap.add_argument("-o", "--out", default=str(ROOT / "benchmarks/results/slicer_configs.json"))
    ap.add_argument("--append", action="store_true")
    a = ap.parse_args()
    exe = None if a.no_slicer else shutil.which("prusa-slicer")
    commit = git_commit()
    rows = json.loads(Path(a.out).read_text()).get("rows", []) if a.append and Path(a.out).exists() else []
    tmp = Path(tempfile.mkdtemp(prefix="mlc_configs_"))
    every = max(1, int(round(a.eval_step / a.step)))
    for g in a.gates.split(","):
        scene = gate_scene(g, a.signal)
        for pn in a.profiles.split(","):
            rows = [r for r in rows if not (r["gate"] == g and r["profile"] == pn and r["signal"] == a.signal)]
            prof = load_profile(pn, {"orient": "as_is"})
            t0 = time.perf_counter()
            asm = printed(scene, prof)
            t_build = time.perf_counter() - t0
            kin = Kinematics(asm)
            clear = Clearance(asm, kin)
            t0 = time.perf_counter()
            sc = scan(kin, clear, step_deg=a.step)
            t_scan = time.perf_counter() - t0
            reached = sc["reached"]
            ev = Evaluator(asm, clear)
            t0 = time.perf_counter()
            results = {}
            for node, T in reached.items():
                if all(x % every == 0 for x in node):
                    results[node] = ev(T)
            for node, _ in sorted(results.items(), key=lambda x: x[1]["key"])[:3]:
                for d in range(len(node)):
                    for sg in (-1, 1):
                        nb = tuple(x + (sg if q == d else 0) for q, x in enumerate(node))
                        if nb in reached and nb not in results:
                            results[nb] = ev(reached[nb])
            t_eval = time.perf_counter() - t0
            rest = tuple([0] * len(sc["keys"]))
            order = sorted(results, key=lambda n: (results[n]["key"], n != rest))
            best = order[0]
            other = next((n for n in order if n != rest), None)
            lift = [lifts(asm, kin, clear, reached[n]) for n in results]
            ang = np.array(list(reached), float) * a.step
            why = collections.Counter(v.rsplit(" ", 2)[0] for v in sc["refused"].values())
            row = {"gate": g, "signal": a.signal, "profile": pn, "commit": commit, "parts": len(asm.parts),
                   "build_s": round(t_build, 1), "scan_s": round(t_scan, 1), "eval_s": round(t_eval, 1),
                   "freedoms_at_rest": kin.freedoms(), "input_hinges": sc["keys"], "step_deg": a.step,
                   "reached": len(reached), "refused": len(sc["refused"]),
                   "refused_by": dict(why.most_common(6)),
                   "angle_range_deg": [[float(ang[:, k].min()), float(ang[:, k].max())] for k in range(ang.shape[1])],
                   "axis_turn_deg": axis_turn(kin, list(reached.values())),
                   "hinge_range_deg": {k: [round(min(kin.hinge_angles(T)[k] for T in reached.values()), 2),
                                           round(max(kin.hinge_angles(T)[k] for T in reached.values()), 2)]
                                       for k in kin.hinge_angles(kin.rest())},
                   "evaluated": len(results),
                   "lift_mm": {"own_min": min(x["own_min"] for x in lift), "own_max": max(x["own_max"] for x in lift),
                               "print_min": min(x["print_min"] for x in lift)},
                   "knuckle_R_mm": round(float(asm.axes[0].R), 3), "slab_mm": asm.slab_thickness,
                   "rest": row_eval(rest, a.step, results[rest]),
                   "best": row_eval(best, a.step, results[best]),
                   "best_other": row_eval(other, a.step, results[other]) if other is not None else None,
                   "max_contact": row_eval(max(results, key=lambda n: results[n]["stats"].contact_fraction), a.step,
                                           results[max(results, key=lambda n: results[n]["stats"].contact_fraction)]),
                   "min_support": row_eval(min(results, key=lambda n: results[n]["stats"].support_fraction), a.step,
                                           results[min(results, key=lambda n: results[n]["stats"].support_fraction)]),
                   "all": [row_eval(n, a.step, results[n]) for n in order]}
            if exe:
                from slicer_gates import LAYER
                row["prusa"] = {}
                for name, n in (("rest", rest), ("best_other", other)):
                    if n is None:
                        continue
                    r = slice_config(exe, asm, clear, reached[n], results[n]["up"], tmp / f"{g}_{pn}_{name}.3mf",
                                     f"{g}_{a.signal}", LAYER[pn])
                    row["prusa"][name] = {"angles_deg": [a.step * x for x in n], "up": r["up"],
                                          "prusa_support_mm3": r.get("prusa_support_mm3"),
                                          "prusa_support_on_print_mm3": r.get("prusa_support_on_print_mm3"),
                                          "first_layer_mm2": r["none"].get("first_layer_mm2"),
                                          "filament_mm3": r["none"].get("filament_mm3"),
                                          "sliced_without_supports": r["none"].get("ok"),
                                          "mlc_contact_fraction": r["mlc_bed"]["contact_fraction"],
                                          "mlc_support_fraction": r["mlc_bed"]["support_fraction"]}
            rows.append(row)
            b, o, mc = row["rest"], row["best_other"] or {}, row["max_contact"]
            print(f"{g:8s} {pn}: freedoms {row['freedoms_at_rest']}, reached {row['reached']} nodes "
                  f"(ranges {row['angle_range_deg']}), evaluated {row['evaluated']}; rest contact "
                  f"{100 * b['contact_fraction']:.2f} % support {100 * b['support_fraction']:.1f} %; best other "
                  f"{o.get('angles_deg')} contact {100 * o.get('contact_fraction', 0):.2f} % support "
                  f"{100 * o.get('support_fraction', 0):.1f} %; max contact {100 * mc['contact_fraction']:.2f} % at "
                  f"{mc['angles_deg']}; lift {row['lift_mm']}; {row.get('prusa')}", flush=True)
            Path(a.out).write_text(json.dumps({"machine": platform.platform(), "commit": commit,
                                               "note": "angles in degrees from rest (input levers' hinges); lengths mm; "
                                                       "fractions: contact of the footprint, support of the part volume",
                                               "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
