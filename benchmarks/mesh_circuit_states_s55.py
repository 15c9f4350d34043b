"""Before/after summary of two ``mlc stl`` reports of the README's Tetris circuit (session 55).

    python benchmarks/mesh_circuit_states_s55.py --before BEFORE.json --after AFTER.json \
        [--after-time TIME_V.log] [--before-commit HASH] [--after-commit HASH] \
        [--out benchmarks/results/mesh_circuit_states_s55.json]

Each report is what ``mlc stl circuit.yaml -o x.stl --3mf x.3mf --report x.json --force`` writes
(mjp, the default profile).  Kept per check: ok, value, limit, blocking and the failure count; for
``states`` the failures themselves (at most 40) sorted into the three kinds of session 55: two
neighbouring half units of one chain, a branch page against a chain's slab, a half unit against a
joint part (any other pair is "other").  The report's own seconds, and the wall clock and peak RSS
of ``/usr/bin/time -v`` where given.  Writes the JSON atomically."""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PAIR = re.compile(r"state (\S+): (\S+) intersects (\S+) \(([0-9.e+-]+) mm\^3\)")


def kind(a: str, b: str) -> str:
    """Session 55's kinds of a states failure between parts ``a`` and ``b``."""
    joint = re.compile(r"w_.*_(j\d+|end)_(lo|hi)$")
    page = re.compile(r"w_[a-z]+_p\d")
    if joint.match(a) or joint.match(b):
        return "half unit against a joint part"
    if page.match(a) or page.match(b):
        return "branch page against a chain's slab"
    ca, cb = (re.match(r"(w_[a-z]+_\d+)_", x) for x in (a, b))
    if ca and cb and ca.group(1) == cb.group(1):
        return "neighbouring half units of one chain"
    return "other"


def summary(path: str) -> dict:
    r = json.load(open(path))
    out = {"seconds": r.get("seconds"), "ok": r.get("ok"), "parts": len(r.get("parts", [])), "checks": {}}
    for c in r["checks"]:
        row = {k: c.get(k) for k in ("ok", "value", "limit", "blocking")}
        row["failure_count"] = c.get("failure_count", len(c.get("failures", [])))
        if c["name"] == "states":
            fails = c.get("failures", [])
            row["detail"] = c.get("detail")
            by: dict = {}
            for f in fails:
                m = PAIR.search(f)
                if m:
                    k = kind(m.group(2), m.group(3))
                    e = by.setdefault(k, {"count": 0, "mm3": 0.0})
                    e["count"] += 1
                    e["mm3"] = round(e["mm3"] + float(m.group(4)), 6)
            row["by_kind"] = by
            row["failures"] = fails[:40]
        out["checks"][c["name"]] = row
    return out


def time_v(path: str) -> dict:
    txt = open(path).read()
    wall = re.search(r"Elapsed \(wall clock\) time.*: (\S+)", txt)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", txt)
    return {"wall": wall.group(1) if wall else None,
            "peak_rss_gb": round(int(rss.group(1)) / 2 ** 20, 2) if rss else None}


def main(argv=None) -> int:
    from mlc.io.atomic import atomic_path
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--before-time")
    ap.add_argument("--after-time")
    ap.add_argument("--before-commit")
    ap.add_argument("--after-commit")
    ap.add_argument("--note", default="")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "mesh_circuit_states_s55.json"))
    a = ap.parse_args(argv)
    res = {"benchmark": "mesh_circuit_states_s55", "profile": "mjp", "note": a.note,
           "command": "mlc stl circuit.yaml -o x.stl --3mf x.3mf --report x.json --force"}
    for side in ("before", "after"):
        s = summary(getattr(a, side))
        s["commit"] = getattr(a, f"{side}_commit")
        if getattr(a, f"{side}_time"):
            s["time"] = time_v(getattr(a, f"{side}_time"))
        res[side] = s
    with atomic_path(a.out) as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1) + "\n")
    print(json.dumps({k: {n: (c["ok"], c["value"], c["failure_count"]) for n, c in res[k]["checks"].items()}
                      for k in ("before", "after")}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
