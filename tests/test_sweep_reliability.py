"""The reliability map (issue 11, item 4): the shipped specs load, and the plot's
probabilities and failure boundary follow from the table (no simulation: a hand-made
results table whose answers are known)."""
import csv
import json
from pathlib import Path

import pytest

from mlc.errors import MlcError
from mlc.sweep.plot import FAIL_P, reliability_map
from mlc.sweep.spec import load_spec

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "sweeps"


@pytest.mark.parametrize("name, runs, rows", [("reliability_gate", 420, 4), ("reliability_chain", 210, 2)])
def test_shipped_reliability_specs(name, runs, rows):
    spec = load_spec(str(EXAMPLES / f"{name}.yaml"))
    assert spec.plot == "reliability_map"
    assert len(spec.runs) == runs
    kts = sorted({r.params["kT"] for r in spec.runs})
    assert kts[0] == 1e-5 and kts[-1] >= 0.1            # from the paper's kT up to where it fails
    assert len({r.seed for r in spec.runs}) >= 3
    assert len({json.dumps(r.params["inputs"], sort_keys=True) for r in spec.runs}) == rows   # every input row


def _table(d: Path, cells):
    """cells: {(kT, tol): [(status, wrong), ...]} -> a results directory."""
    d.mkdir()
    cols = ["run_id", "index", "status", "error", "scene", "measure", "tolerance", "kT", "seed", "out_mean",
            "out_wrong", "samples", "wall_s"]
    with open(d / "results.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        i = 0
        for (kT, tol), runs in cells.items():
            for s, (status, wrong) in enumerate(runs):
                w.writerow([f"r{i}", i, status, "" if status == "ok" else "unstable", "gate", "steady", tol, kT, s,
                            1.0 if status == "ok" else "", wrong if status == "ok" else "",
                            100 if status == "ok" else "", 0.1])
                i += 1
    (d / "sweep.json").write_text(json.dumps({"name": "t", "scene": "gate", "measure": "steady",
                                              "plot": "reliability_map"}))
    return d


def test_reliability_map_probabilities_and_boundary(tmp_path):
    ok0 = [("ok", 0.0)] * 3
    cells = {
        (1e-5, 0.0): ok0, (1e-3, 0.0): [("ok", 0.0), ("ok", 0.01), ("ok", 0.02)],    # P = 1 %: fails (>=)
        (1e-1, 0.0): [("failed", None)] * 3,
        (1e-5, 0.1): ok0, (1e-3, 0.1): [("ok", 0.0), ("ok", 0.0), ("failed", None)],  # a failed run fails it
        (1e-1, 0.1): [("ok", 0.5)] * 3,
        (1e-5, 0.2): [("ok", 0.3)] * 3, (1e-3, 0.2): ok0, (1e-1, 0.2): ok0,      # fails at the first kT
    }
    d = _table(tmp_path / "run", cells)
    out = reliability_map(d, tmp_path / "map.png")
    assert (tmp_path / "map.png").stat().st_size > 1000
    by = {(r["kT"], r["tolerance"]): r for r in out["rows"]}
    assert by[(1e-3, 0.0)]["p_wrong"] == pytest.approx(0.01) and by[(1e-3, 0.0)]["fails"]
    assert by[(1e-3, 0.0)]["p_wrong_worst_run"] == pytest.approx(0.02)
    assert by[(1e-5, 0.0)]["p_wrong"] == 0 and by[(1e-5, 0.0)]["resolution"] == pytest.approx(1 / 300)
    assert by[(1e-1, 0.0)]["p_wrong"] is None and by[(1e-1, 0.0)]["failed_runs"] == 3
    assert by[(1e-3, 0.1)]["failed_runs"] == 1 and by[(1e-3, 0.1)]["fails"]
    b = {r["tolerance"]: r for r in out["boundary"]}
    assert b[0.0] == {"tolerance": 0.0, "last_ok_kT": 1e-5, "first_failing_kT": 1e-3}
    assert b[0.1]["first_failing_kT"] == 1e-3
    assert b[0.2] == {"tolerance": 0.2, "last_ok_kT": None, "first_failing_kT": 1e-5}
    assert out["fail_p"] == FAIL_P == 0.01


def test_reliability_map_needs_wrong_bit_columns(tmp_path):
    d = _table(tmp_path / "run", {(1e-5, 0.0): [("ok", 0.0)]})
    rows = (d / "results.csv").read_text().replace("out_wrong", "out_other")
    (d / "results.csv").write_text(rows)
    with pytest.raises(MlcError, match="wrong-bit"):
        reliability_map(d, tmp_path / "map.png")


def test_reliability_map_prefers_not_a_bit_over_wrong_bit(tmp_path):
    # a collapsed output (0.3 sigma for 1.0/1.5) reads 0 by the threshold ("right") but is no bit:
    # the map shows the {probe}_off column when the table has it
    d = _table(tmp_path / "run", {(1e-5, 0.0): [("ok", 0.0)] * 3})
    text = (d / "results.csv").read_text().splitlines()
    text = [text[0] + ",out_off"] + [line + ",0.4" for line in text[1:]]
    (d / "results.csv").write_text("\n".join(text) + "\n")
    out = reliability_map(d, tmp_path / "map.png")
    assert out["column"] == "out_off"
    assert out["rows"][0]["p_wrong"] == pytest.approx(0.4) and out["rows"][0]["fails"]


def test_steady_reports_not_a_bit_fraction():
    # a real run: the NAND gate in row 11 at the paper's temperature reads its bit all the time
    from mlc.sweep.measure import steady
    from mlc.sweep.scenes import gate
    from mlc.sweep.spec import MEASURE_PARAMS, SIM_PARAMS
    p = {**SIM_PARAMS, **MEASURE_PARAMS["steady"], "time": 1.0, "window": 0.5, "record": 0.01,
         "inputs": {"a": 1, "b": 1}}
    row, _ = steady(gate("NAND"), p, 0)
    assert row["out_wrong"] == 0.0 and row["out_off"] == 0.0 and row["samples"] >= 10
    assert abs(row["out_mean"] - 1.0) < 0.05
