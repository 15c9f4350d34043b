"""The blocking checks of ``mlc stl`` printability reports side by side, from the report files
that ``mlc stl --report`` wrote (for example the README's main job's ``out/circuit_print.json``
in two sessions): each check's result, failure count, value, detail and the failures the report
lists (it lists at most 20).

    python benchmarks/print_report_summary.py LABEL=COMMIT=REPORT.json [...] --out RESULTS.json

Nothing is measured here: the figures are the reports' own, and the results file names the
commit each report was made at (as its LABEL=COMMIT=PATH argument says)."""
import argparse
import json
from pathlib import Path

CHECKS = ("watertight", "part_count", "min_gap", "states", "retention", "features")


def summary(path: Path) -> dict:
    r = json.loads(Path(path).read_text())
    by = {c["name"]: c for c in r["checks"]}
    return {name: {"ok": by[name]["ok"], "failure_count": by[name].get("failure_count", 0),
                   "value": by[name].get("value"), "detail": by[name]["detail"],
                   "failures": by[name].get("failures", [])} for name in CHECKS if name in by}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("reports", nargs="+", metavar="LABEL=COMMIT=REPORT.json")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    rows = []
    for arg in a.reports:
        label, commit, path = arg.split("=", 2)
        rows.append({"label": label, "commit": commit, "report": Path(path).name, "checks": summary(Path(path))})
    Path(a.out).write_text(json.dumps({"benchmark": "print_report_summary", "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
