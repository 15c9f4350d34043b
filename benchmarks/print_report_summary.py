"""The checks of ``mlc stl`` printability reports side by side, from the report files that
``mlc stl --report`` wrote (for example the README's main job's ``out/circuit_print.json`` in two
sessions): each check's result, failure count, value, detail and the failures the report lists
(it lists at most 20); the blocking checks, and with ``--goals`` the goals too (``motion_clearance``,
``wall_thickness``, ``bed_contact``, ``supports``: their ``blocking`` field says which they are).

    python benchmarks/print_report_summary.py [--goals] [--notes TEXT] LABEL=COMMIT=REPORT.json [...] --out RESULTS.json

Nothing is measured here: the figures are the reports' own, and the results file names the
commit each report was made at (as its LABEL=COMMIT=PATH argument says)."""
import argparse
import json
from pathlib import Path

CHECKS = ("watertight", "part_count", "min_gap", "states", "retention", "features")
GOALS = ("motion_clearance", "wall_thickness", "bed_contact", "supports")


def summary(path: Path, goals: bool = False) -> dict:
    r = json.loads(Path(path).read_text())
    by = {c["name"]: c for c in r["checks"]}
    return {name: {"ok": by[name]["ok"], "blocking": by[name].get("blocking", True),
                   "failure_count": by[name].get("failure_count", 0),
                   "value": by[name].get("value"), "detail": by[name]["detail"],
                   "failures": by[name].get("failures", [])}
            for name in CHECKS + (GOALS if goals else ()) if name in by}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("reports", nargs="+", metavar="LABEL=COMMIT=REPORT.json")
    ap.add_argument("--out", required=True)
    ap.add_argument("--goals", action="store_true", help="the goals' checks too, not only the blocking ones")
    ap.add_argument("--notes", action="append", default=[], metavar="TEXT",
                    help="also the report's notes that contain this text (repeatable)")
    a = ap.parse_args()
    rows = []
    for arg in a.reports:
        label, commit, path = arg.split("=", 2)
        row = {"label": label, "commit": commit, "report": Path(path).name, "checks": summary(Path(path), a.goals)}
        if a.notes:
            row["notes"] = [n for n in json.loads(Path(path).read_text()).get("notes", []) if any(t in n for t in a.notes)]
        rows.append(row)
    Path(a.out).write_text(json.dumps({"benchmark": "print_report_summary", "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
