"""mlc sweep (issue 11): specs, a small sweep on a two-worker local Dask cluster (resume,
same numbers on 1 and 2 workers, failed runs as rows), the plots, and bad input."""
import csv
import json
from pathlib import Path

import jsonschema
import pytest
import yaml

from mlc.cli import main
from mlc.io.schema import load_schema
from mlc.sweep.measure import run_task
from mlc.sweep.spec import load_spec

ROOT = Path(__file__).resolve().parents[1]

TINY = """\
scene: and_chain_and
measure: square_response
params: {units: 1, scheme: stiff, dt: 0.01, kT: 1.0e-5, cycles: 2, samples_per_cycle: 20, inputs: {hold: 1}}
grid:
  frequency: [2, 1]
runs:
  - {}
  - {scheme: euler, dt: 0.002}
  - {scheme: euler, dt: 9.0e-5}
seeds: 2
"""
# (the Euler runs at dt = 0.002 t0 are far beyond Euler's stability limit, about 1.5e-4 t0:
#  they must become failed rows; the Euler runs at 9e-5 t0 (its default here, half its limit) are the
#  scheme of the shipped Fig. 5D spec; the spec expands to 2 grid points x 3 entries x 2 seeds)


def _write(tmp_path, text, name="s.yaml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def _table(d):
    with open(d / "results.csv", newline="") as f:
        return list(csv.DictReader(f))


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


# (force_evals is left out: the integrator runs in compiled chunks of ~0.25 s of wall time and
#  the count can differ by one per chunk boundary on a loaded machine; the trajectory does not)
MEASURED = ("rms_dev", "rms_dev_all", "rms_dev_l1", "y_high", "y_low", "lag", "steps")


@pytest.fixture(scope="module")
def tiny_runs(tmp_path_factory):
    """The tiny sweep on 2 workers, then again on 1 worker; then a resume of the first."""
    from mlc.sweep.run import run_sweep
    tmp = tmp_path_factory.mktemp("sweep")
    spec_p = tmp / "tiny.yaml"
    spec_p.write_text(TINY)
    spec = load_spec(str(spec_p))
    a = run_sweep(spec, tmp / "two", workers=2, progress=False)
    b = run_sweep(spec, tmp / "one", workers=1, progress=False)
    return spec, tmp, a, b


def test_spec_expands_grid_runs_and_seeds(tmp_path):
    p = _write(tmp_path, TINY)
    s = load_spec(str(p))
    assert len(s.runs) == 2 * 3 * 2
    assert len({r.run_id for r in s.runs}) == 12
    assert sorted({r.params["scheme"] for r in s.runs}) == ["euler", "stiff"]
    assert {r.seed for r in s.runs} == {0, 1}
    # the id depends on the parameters and seed only, not on the order of the spec
    p2 = _write(tmp_path, TINY.replace("frequency: [2, 1]", "frequency: [1, 2]").replace(
        "runs:\n  - {}\n  - {scheme: euler, dt: 0.002}\n  - {scheme: euler, dt: 9.0e-5}\n",
        "runs:\n  - {scheme: euler, dt: 9.0e-5}\n  - {scheme: euler, dt: 0.002}\n  - {}\n"),
        "s2.yaml")
    assert {r.run_id for r in load_spec(str(p2)).runs} == {r.run_id for r in s.runs}


def test_sweep_two_workers_resume_and_reproducible(tiny_runs):
    spec, tmp, a, b = tiny_runs
    assert a["ran"] == 12 and a["skipped"] == 0 and b["ran"] == 12
    two, one = _table(tmp / "two"), _table(tmp / "one")
    assert [r["run_id"] for r in two] == [r.run_id for r in spec.runs]        # rows in the spec's order
    ok = [r for r in two if r["status"] == "ok"]
    failed = [r for r in two if r["status"] == "failed"]
    # the Euler runs at 13x its stability limit are failed rows naming the instability, not a crash
    # (messages name every row's status and error: a one-off failure on a loaded machine is then diagnosable)
    rows_msg = [(r["run_id"], r["scheme"], r["status"], r["error"][:200]) for r in two]
    assert len(ok) == 8 and len(failed) == 4, rows_msg
    assert all(r["scheme"] == "euler" and float(r["dt"]) == 0.002 for r in failed), rows_msg
    assert sum(r["scheme"] == "euler" for r in ok) == 4, rows_msg
    assert all("unstable" in r["error"] and "--dt" in r["error"] for r in failed), failed[0]["error"]
    # same spec, 1 or 2 workers: the same numbers, bit for bit (both schemes)
    for r1, r2 in zip(one, two):
        assert r1["run_id"] == r2["run_id"] and r1["status"] == r2["status"]
        for k in MEASURED:
            assert r1[k] == r2[k], (r1["run_id"], r1["scheme"], k, r1[k], r2[k])
    # the seeds differ (thermal noise), the drive frequencies too
    assert len({r["rms_dev"] for r in ok}) == 8
    for r in ok:
        assert 0.0 < float(r["rms_dev"]) < 1.0
    # beside the table: the spec and the versions
    assert (tmp / "two" / "spec.yaml").read_text() == spec.text
    meta = json.loads((tmp / "two" / "sweep.json").read_text())
    assert meta["versions"]["mlc"] and meta["versions"]["dask"] and meta["runs"] == 12
    assert len(list((tmp / "two" / "traces").glob("*.npz"))) == 8


def test_resume_skips_finished_runs(tiny_runs):
    from mlc.sweep.run import run_sweep
    spec, tmp, a, b = tiny_runs
    d = tmp / "one"
    before = _table(d)
    again = run_sweep(spec, d, workers=1, progress=False)
    assert again["ran"] == 0 and again["skipped"] == 12
    assert _table(d) == before
    # drop one finished row: only that run is run again, with the same numbers
    lines = (d / "results.csv").read_text().splitlines(keepends=True)
    dropped = before[1]
    (d / "results.csv").write_text("".join(lines[:2] + lines[3:]))
    third = run_sweep(spec, d, workers=1, progress=False)
    assert third["ran"] == 1 and third["skipped"] == 11
    after = _table(d)
    assert [r["run_id"] for r in after] == [r["run_id"] for r in before]
    assert {k: after[1][k] for k in MEASURED} == {k: dropped[k] for k in MEASURED}


def test_plot_response_grid(tiny_runs, capsys):
    spec, tmp, a, b = tiny_runs
    code, out, err = run(capsys, "sweep", "plot", tmp / "two", "-o", tmp / "grid.png", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert (tmp / "grid.png").stat().st_size > 1000 and (tmp / "grid.json").exists()
    rows = {(r["frequency"], r.get("scheme")): r for r in summary["rows"]}
    # failed runs are not plotted: the Euler lines are its runs at 9e-5 t0
    assert set(rows) == {(2.0, "stiff"), (1.0, "stiff"), (2.0, "euler"), (1.0, "euler")}
    t = _table(tmp / "two")
    mine = [float(r["rms_dev"]) for r in t if r["status"] == "ok" and r["frequency"] == "2" and r["scheme"] == "stiff"]
    assert rows[(2.0, "stiff")]["rms_dev_mean"] == pytest.approx(sum(mine) / 2)
    assert rows[(2.0, "stiff")]["seeds"] == 2


def test_steady_measure_and_signal_plot(tmp_path):
    """gate_chain + steady, one run in-process: every probe's mean, variance and wrong-bit fraction."""
    spec = load_spec(str(_write(tmp_path, """\
scene: gate_chain
measure: steady
params: {units: 2, tolerance: 0.02, inputs: {in: 1}, time: 1.0, dt: 0.05, fluct: true}
seeds: [7]
""")))
    (r,) = spec.runs
    res = run_task(r.task(spec.scene, spec.measure))
    assert res["status"] == "ok", res["error"]
    row = res["row"]
    for k in ("u0", "u1", "u2"):
        assert 1.3 < row[f"{k}_mean"] < 1.6 and 0 <= row[f"{k}_var"] < 0.01 and row[f"{k}_wrong"] == 0.0
    assert res["trace"] is None


def test_square_response_is_right_for_a_slow_drive():
    """Independent check of the measure: a 1-unit chain driven 100x slower than it relaxes follows
    the drive; its RMS deviation is then set by the edges (lag) and is small."""
    spec_text = {"run_id": "x", "index": 0, "scene": "and_chain_and", "measure": "square_response", "seed": 0}
    from mlc.sweep.spec import MEASURE_PARAMS, SIM_PARAMS
    from mlc.sweep.scenes import BUILDERS
    p = {**BUILDERS["and_chain_and"][1], **SIM_PARAMS, **MEASURE_PARAMS["square_response"]}
    p.update(units=1, frequency=0.02, cycles=2, samples_per_cycle=400, inputs={"hold": 1}, dt=0.05)
    res = run_task({**spec_text, "params": p})
    assert res["status"] == "ok", res["error"]
    r = res["row"]
    assert r["y_high"] > 0.97 and r["y_low"] < 0.03
    assert r["rms_dev"] < 0.2 and 0 < r["lag"] < 2.0


def test_shipped_specs_validate():
    for f in sorted((ROOT / "examples" / "sweeps").glob("*.yaml")):
        s = load_spec(str(f))
        assert s.runs
        jsonschema.validate(yaml.safe_load(f.read_text()), load_schema("sweep"))


BAD = [
    (TINY.replace("{scheme: euler, dt: 0.002}", "{scheme: euler, frequency: 2}"), ":8", "also in the grid"),
    ("scene: and_chain_ant\nmeasure: steady\nseeds: 1\n", ":1", "scene"),
    ("scene: gate\nmeasure: steady\nparams:\n  units: 3\nseeds: 1\n", ":4", "'units' does not apply"),
    ("scene: chain\nmeasure: steady\nparams:\n  kT: -1\nseeds: 1\n", ":4", "must be >= 0"),
    ("scene: chain\nmeasure: steady\ngrid:\n  tolerance: [0, 0.5]\nseeds: 1\n", ":4", "must be <= 0.3"),
    ("scene: chain\nmeasure: steady\nparams:\n  colour: red\nseeds: 1\n", ":4", "unknown key 'colour'"),
    ("scene: chain\nmeasure: steady\nparams:\n  inputs: {b: 1}\nseeds: 1\n", "", "no input 'b'"),
    ("scene: chain\nmeasure: steady\nseeds: [1, 1]\n", ":3", "twice"),
    ("scene: chain\nmeasure: steady\n", "", "seeds"),
    ("scene: and_chain_and\nmeasure: square_response\nparams:\n  dt: 0.5\n  frequency: 5\nseeds: 1\n", ":4",
     "quarter of the drive period"),
    # mlc simulate's step limit, before any run (each run failed alone, and mlc sweep exited 0)
    ("scene: gate\nmeasure: steady\nparams:\n  time: 10\n  dt: 1.0e-12\nseeds: 1\n", ":5",
     "dt 1e-12 t0 is 1e+13 steps over the run's 10 t0 (more than 1e+09) (use a larger dt"),
    ("scene: and_chain_and\nmeasure: square_response\nruns:\n  - {}\n  - {dt: 1.0e-9}\nseeds: 1\n", ":5",
     "6e+09 steps over the run's 6 t0"),
]


@pytest.mark.parametrize("text,line,words", BAD)
def test_bad_specs_are_one_clear_error(tmp_path, capsys, text, line, words):
    p = _write(tmp_path, text)
    out = tmp_path / "out"
    code, _, err = run(capsys, "sweep", p, "-o", out)
    assert code == 2, err
    assert err.startswith(f"mlc: error: {p}{line}") and err.count("\n") == 1, err
    assert words in err and "Traceback" not in err
    assert not out.exists()


def test_a_sweep_of_only_failed_runs_exits_1(tmp_path, capsys):
    """Each failed run is a row with its error; when every run failed, mlc sweep says so, exit 1."""
    bad = TINY.replace("runs:\n  - {}\n  - {scheme: euler, dt: 0.002}\n  - {scheme: euler, dt: 9.0e-5}\n",
                       "runs:\n  - {scheme: euler, dt: 0.002}\n").replace("seeds: 2", "seeds: 1")
    p = _write(tmp_path, bad)
    out = tmp_path / "out"
    code, stdout, err = run(capsys, "sweep", p, "-o", out, "--json", "--quiet")
    rows = _table(out)
    assert code == 1, err
    assert json.loads(stdout)["failed"] == 2 and [r["status"] for r in rows] == ["failed", "failed"]
    assert err.startswith("mlc: error: every run of the sweep failed (2 of 2), the first: --dt: unstable") \
        and err.count("\n") == 1 and "--retry-failed" in err, err


def test_unreachable_scheduler(tmp_path, capsys):
    p = _write(tmp_path, "scene: gate\nmeasure: steady\nparams: {time: 0.1}\nseeds: 1\n")
    out = tmp_path / "out"
    code, _, err = run(capsys, "sweep", p, "-o", out, "--scheduler", "tcp://127.0.0.1:9")
    assert code == 2 and "--scheduler" in err and "cannot reach" in err and err.count("\n") == 1, err
    assert not out.exists()


def test_not_a_results_table(tmp_path, capsys):
    p = _write(tmp_path, "scene: gate\nmeasure: steady\nparams: {time: 0.1}\nseeds: 1\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.csv").write_text("a,b\n1,2\n")
    code, _, err = run(capsys, "sweep", p, "-o", out)
    assert code == 2 and "not an mlc sweep results table" in err
    assert (out / "results.csv").read_text() == "a,b\n1,2\n"
    code, _, err = run(capsys, "sweep", "plot", tmp_path / "nowhere")
    assert code == 2 and "results directory" in err


@pytest.mark.parametrize("offset", [0.0, 0.0031])
def test_rms_of_a_first_order_response_matches_theory(offset):
    """Independent check of the RMS deviation: the exact periodic response of a first-order
    system (time constant tau) to a square wave of period P has mean square deviation
    (tau/P) tanh(P/(4 tau)) from the drive; sampled on a grid on or off the switching instants."""
    import math

    import numpy as np

    from mlc.sim.drive import Drive
    from mlc.sweep.measure import _rms
    tau, P = 0.4, 3.0
    d = Drive.square(P)
    t = np.arange(1601) * (P / 400) + offset      # 4 periods, on or off the switching instants
    # periodic regime: y relaxes towards u with tau; start of a high half at y = y0
    h = P / 2
    y0 = math.exp(-h / tau) / (1 + math.exp(-h / tau))            # y at a rising edge
    ph = t % P
    y = np.where(ph < h, 1 - (1 - y0) * np.exp(-ph / tau), (1 - y0) * np.exp(-(ph - h) / tau))
    ms = tau / P * math.tanh(P / (4 * tau))
    assert _rms(t, y, d, t >= P) == pytest.approx(math.sqrt(ms), rel=3e-3)
