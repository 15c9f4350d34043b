"""What the coarse ``motion_clearance`` check (issue 13, session 65: ``COARSE_CLEARANCE``,
``mlc.mesh.checks._CoarseClearance``) finds and costs on compiled circuits and robots, which have no
dense poses: the clearance between parts that share no joint, in the states check's poses.

For each case (a compiled scene's largest mechanism, posed by ``mlc.mesh.pipeline.state_poses``,
or a ``tests/data_mesh`` piece by name with its stored print poses) the parts are built once at
mjp as ``mlc stl`` builds them (``build_assembly(..., reuse=True)``), then checked
(``check_assembly(..., walls=False)``) ``--repeat`` times with ``COARSE_CLEARANCE`` off and on,
alternating, so that both see the same machine load, each from the congruence caches the build
left (a check caches the booleans and gaps it measured, so a second check would be cheaper).  Each check records its wall time and the
time spent measuring the clearance (a wrapped timer); with the flag on, the ``motion_clearance``
result: passed, the smallest gap, the pairs closer than the clearance and in which poses.  The
ratio on / off is of the medians.

    python benchmarks/coarse_clearance.py --piece circuit_g3 --piece robot_g2 \\
        -o benchmarks/results/coarse_clearance_s65.json

Writes the JSON and a bar plot next to it (``.png``).  Units: seconds, mm."""
from __future__ import annotations

import argparse
import json
import re
import sys
from collections import Counter
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy (mlc/__init__.py)

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))
from fine_gaps_cost import _load  # noqa: E402  (the same cases: a scene's largest mechanism or a piece)
from gitstate import commit  # noqa: E402  (benchmarks/gitstate.py)
from case_plot import case_bars  # noqa: E402

from mlc.io.atomic import atomic_path  # noqa: E402
from mlc.mesh import build as B  # noqa: E402
from mlc.mesh import checks as C  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402


def _where(name: str):
    """``(kind, group, unit)`` of a part by its name: a chain's slab (``w_b_0_58_AB``, ``rc_u4_dn_0_DA``:
    its wire and half unit), a chain's joint part (``w_b_0_j59_lo``: half way to the unit before) or
    end (``w_y_3_end_lo``), a gate's part (``g3_a_lo``: its gate), else other."""
    m = re.match(r"^(.*)_(\d+|w\d+|pg)_(AB|BC|CD|DA)$", name)
    if m:
        u = m.group(2)
        return "chain", m.group(1), float(u) if u.isdigit() else u
    m = re.match(r"^(.*)_j(\d+)_(lo|hi)$", name)
    if m:
        return "chain", m.group(1), int(m.group(2)) - 0.5
    m = re.match(r"^(.*)_end_(lo|hi)$", name)
    if m:
        return "chain", m.group(1), "end"
    m = re.match(r"^(g\d+)_", name)
    return ("gate", m.group(1), None) if m else ("other", name, None)


def kind_of(pair: str) -> str:
    """Which kind of pair ``"a - b"`` is: a part of a branch tree's source, pages or stubs in it; two
    parts of one chain at most one junction apart, or farther; of two chains; within one gate, of two
    gates, a gate and a chain; or other."""
    a, b = pair.split(" - ")
    if any(re.search(r"^src_|_p\d+(_|$)|_stub_", x) for x in (a, b)):
        return "a branch tree (source, pages, stubs)"
    (ka, ga, ua), (kb, gb, ub) = _where(a), _where(b)
    if ka == kb == "chain" and ga == gb:
        near = not (isinstance(ua, float) and isinstance(ub, float)) or abs(ua - ub) <= 1.5
        return "one chain, neighbouring half units" if near else "one chain, farther apart"
    if ka == kb == "chain":
        return "two chains"
    if ka == kb == "gate":
        return "within a gate" if ga == gb else "two gates"
    if {ka, kb} == {"gate", "chain"}:
        return "a gate and a chain"
    return "other"


def _check(asm, coarse: bool, cache) -> dict:
    """One check of ``asm``, with its congruence caches as the build left them (``cache``): each
    check measures what ``mlc stl``'s one check would, not the pairs an earlier check cached."""
    cong = getattr(asm, "congruence", None)
    if cong is not None:
        cong.results, cong._keys = dict(cache[0]), dict(cache[1])
    spent = [0.0]
    orig = C._CoarseClearance.pose

    def timed(self, *a, **k):
        t0 = time.perf_counter()
        try:
            return orig(self, *a, **k)
        finally:
            spent[0] += time.perf_counter() - t0
    C._CoarseClearance.pose = timed
    old = C.COARSE_CLEARANCE
    C.COARSE_CLEARANCE = coarse
    try:
        t0 = time.perf_counter()
        rep = C.check_assembly(asm, walls=False)
        wall = time.perf_counter() - t0
    finally:
        C._CoarseClearance.pose = orig
        C.COARSE_CLEARANCE = old
    mc = rep.check("motion_clearance")
    out = {"coarse": coarse, "check_s": round(wall, 3), "clearance_s": round(spent[0], 3)}
    if coarse:
        pairs = sorted({f.split(": ")[1] for f in mc.failures})
        out.update({"ok": mc.ok, "blocking": mc.blocking, "smallest_mm": mc.value, "detail": mc.detail,
                    "pairs": pairs, "kinds": dict(Counter(kind_of(p) for p in pairs).most_common()),
                    "poses_short": len(mc.failures), "failures": mc.failures[:200]})
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", action="append", default=[], help="a compiled scene (circuit.yaml, robot.yaml)")
    ap.add_argument("--piece", action="append", default=[], help="a tests/data_mesh piece by name")
    ap.add_argument("--repeat", type=int, default=2, help="checks of each kind per case (alternating)")
    ap.add_argument("-o", "--out", required=True)
    args = ap.parse_args(argv)
    cases = []
    for scene, piece in [(s, None) for s in args.scene] + [(None, p) for p in args.piece]:
        label, sc, poses = _load(scene, piece)
        t0 = time.perf_counter()
        asm = B.build_assembly(sc, load_profile("mjp"), poses, reuse=True)
        build_s = time.perf_counter() - t0
        cong = getattr(asm, "congruence", None)
        cache = (dict(cong.results), dict(cong._keys)) if cong is not None else None
        runs = []
        for _ in range(args.repeat):
            for coarse in (False, True):
                r = _check(asm, coarse, cache)
                print(label, {k: v for k, v in r.items() if k not in ("failures", "detail", "pairs")}, flush=True)
                runs.append(r)

        def med(coarse, key):
            return float(np.median([r[key] for r in runs if r["coarse"] is coarse]))
        on = [r for r in runs if r["coarse"]]
        cases.append({"case": label, "bodies": len(sc.bodies), "parts": len(asm.parts), "poses": len(poses),
                      "build_s": round(build_s, 3), "runs": runs,
                      "check_s_off": med(False, "check_s"), "check_s_on": med(True, "check_s"),
                      "clearance_s": med(True, "clearance_s"),
                      "clearance_share": med(True, "clearance_s") / med(True, "check_s"),
                      "check_ratio": med(True, "check_s") / med(False, "check_s"),
                      "ok": on[-1]["ok"], "smallest_mm": on[-1]["smallest_mm"], "pairs": on[-1]["pairs"],
                      "kinds": on[-1]["kinds"],
                      "same_every_run": all(r["failures"] == on[-1]["failures"] for r in on)})
    out = {"benchmark": "coarse_clearance", "commit": commit(), "profile": "mjp", "repeat": args.repeat,
           "cases": cases}
    with atomic_path(args.out) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")
    case_bars(args.out, cases, [([c["check_ratio"] for c in cases], "")],
              "check time with COARSE_CLEARANCE / without", ref=1.0,
              notes=[f"{len(c['pairs'])} pairs < c" for c in cases])
    return 0


if __name__ == "__main__":
    sys.exit(main())
