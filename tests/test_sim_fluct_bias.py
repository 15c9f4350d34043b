"""The fluctuation mode's bias beyond linear theory, as `mlc simulate --json` reports it
(``variance_bias.pair_ratio_measured``): the table in the package is the benchmark's
(benchmarks/results/sim_fluct_bias.json), and the goal of issue 12 (bond-length variance
within 5 % of exact in the fluctuation mode) holds, with another seed, at points where the
benchmark meets it, including points where it failed before the session-10 fixes (kT = 1e-3,
dt = 5 t0: +21 %; kT = 1e-2, dt = 0.01 and 0.2 t0: +10 %) and before the session-13 stage rule
(kT = 1e-3, dt = 0.2 t0: +40 %, the pair's mode on an interior Chebyshev extremum; kT = 1e-2,
dt = 0.5 t0: +6 %).  Units: sigma, k0, t0."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from mlc.sim.integrator import (FLUCT_PAIR_RATIO, FLUCT_R_WINDOW, SimOptions, Simulation, _cheb_factor,
                                fluct_pair_bias)
from mlc.sim.testscenes import bond_length_var_closed, bonded_pairs

RESULTS = Path(__file__).resolve().parent.parent / "benchmarks" / "results" / "sim_fluct_bias.json"


def test_table_is_the_benchmark():
    rows = [r for r in json.loads(RESULTS.read_text())["rows"] if r["fluct"]]
    assert len(rows) == sum(len(v) for v in FLUCT_PAIR_RATIO.values())
    for r in rows:
        table = dict(FLUCT_PAIR_RATIO[r["kT"]])
        assert table[r["dt_t0"]] == pytest.approx(r["ratio"], abs=6e-4), (r["kT"], r["dt_t0"])


def test_reported_in_variance_bias():
    from mlc.gates.library import gate_scene
    sim = Simulation(gate_scene("NAND"), {"a": 1, "b": 1}, SimOptions(kT=1e-3, dt=5.0, fluct=True))
    vb = sim.variance_bias()
    ref = dict(FLUCT_PAIR_RATIO[1e-3])
    assert vb["scheme"] == "stiff-fluct" and vb["pair_ratio_measured"] == pytest.approx(ref[5.0], abs=6e-4)
    assert vb["pair_ratio_kT"] == 1e-3 and vb["noise_turn_rad2"] == pytest.approx(20.0)
    # 2 kT h/gamma = 10 sigma^2 > 0.5: base factor 3, then the window on the stiffest mode
    q = math.sqrt(vb["h_rho"] * 1.2 / 2.0)
    assert math.ceil(3.0 * q) <= vb["stages"] <= math.ceil(1.5 * math.ceil(3.0 * q))
    assert vb["stage_factor"] >= 3.0 and math.ceil(vb["stage_factor"] * q) == vb["stages"]
    assert vb["R_stiffest"] == pytest.approx(_cheb_factor(vb["h_rho"], vb["stages"]))
    small = Simulation(gate_scene("NAND"), {"a": 1, "b": 1}, SimOptions(kT=1e-3, dt=0.05, fluct=True)).variance_bias()
    q = math.sqrt(small["h_rho"] * 1.2 / 2.0)     # 0.1 sigma^2 of noise a step: base factor 1
    assert math.ceil(q) <= small["stages"] <= math.ceil(1.5 * math.ceil(q))
    # interpolation in log dt between measured points, nearest measured kT, clamped dt
    a, b = ref[2.0], ref[5.0]
    mid = fluct_pair_bias(2e-3, math.sqrt(2.0 * 5.0))["pair_ratio_measured"]
    assert min(a, b) - 1e-3 <= mid <= max(a, b) + 1e-3
    assert fluct_pair_bias(1e-3, 1e4)["pair_ratio_measured"] == pytest.approx(ref[100.0], abs=6e-4)
    assert "extrapolation" in fluct_pair_bias(1e-3, 1e4)["pair_note"]
    assert fluct_pair_bias(0.0, 1.0) == {}
    plain = Simulation(gate_scene("NAND"), {"a": 1, "b": 1}, SimOptions(kT=1e-3, dt=5.0)).variance_bias()
    assert "pair_ratio_measured" not in plain


def test_cheb_factor_is_chebyshev():
    # R_s(-hr) = T_s(1 - hr/s^2), inside and outside [-1, 1], against numpy's Chebyshev series
    for s in (2, 5, 16, 17, 40):
        for hr in (0.3, 7.0, 400.0, 1.9 * s * s, 2.3 * s * s):
            x = 1.0 - hr / s ** 2
            assert _cheb_factor(hr, s) == pytest.approx(np.polynomial.chebyshev.chebval(x, [0] * s + [1]), rel=1e-9)


def test_stage_rule_avoids_the_extremum():
    # the former +40 % point: kT = 1e-3, dt = 0.2 t0 took s = 16 stages, the pair's mode at
    # R = T_16(1 - 400/256) = -0.991; the rule moves it into the window, and the kernel takes it
    kw = dict(kT=1e-3, dt=0.2, fluct=True, wca_eps=0.0)
    sim = Simulation(bonded_pairs(4), None, SimOptions(**kw))
    m, s, R = sim.fluct_stages_target()
    assert _cheb_factor(400.0, 16) < -0.99 and s == 17 and FLUCT_R_WINDOW[0] <= R <= FLUCT_R_WINDOW[1]
    assert sim.run(0.6, quiet=True).stages == s
    # a fixed factor is taken as given (no window)
    assert Simulation(bonded_pairs(4), None, SimOptions(fluct_stages=1.0, **kw)).run(0.6, quiet=True).stages == 16
    # every table point of the benchmark gets a stiffest-mode factor in the window or the nearest
    # to it within 1.5 times the base stages
    lo, hi = FLUCT_R_WINDOW
    for kT in FLUCT_PAIR_RATIO:
        for dt, _ in FLUCT_PAIR_RATIO[kT]:
            _, s, R = Simulation(bonded_pairs(2), None, SimOptions(kT=kT, dt=dt, fluct=True)).fluct_stages_target()
            hr = 2.0 * dt * 1000.0                  # the pair's mode: rate 2 k/gamma
            s0 = math.ceil((3.0 if 2.0 * kT * dt * 1000.0 > 0.5 else 1.0) * math.sqrt(1.2 * hr / 2.0))
            ks = range(s0, math.ceil(1.5 * s0) + 1)     # distance of each candidate's R from the window
            out = [max(lo - _cheb_factor(hr, k), _cheb_factor(hr, k) - hi, 0.0) for k in ks]
            print(f"kT={kT:g} dt={dt:g}: s0={s0} s={s} R={R:+.3f}")
            assert R == pytest.approx(_cheb_factor(hr, s))
            assert s == (ks[out.index(0.0)] if 0.0 in out else ks[out.index(min(out))])


def test_stage_factor_option_checked():
    from mlc.errors import MlcError
    with pytest.raises(MlcError, match="stage factor"):
        Simulation(bonded_pairs(2), None, SimOptions(kT=1e-3, fluct=True, fluct_stages=0.5))


@pytest.mark.parametrize("kT, dt", [(1e-3, 0.2), (1e-3, 5.0), (1e-2, 0.2), (1e-2, 0.01), (1e-2, 0.5), (1e-2, 20.0)])
def test_goal_within_5_percent_another_seed(kT, dt):
    # 200 independent pairs, 50 steps of burn-in, 200 measured: standard error ~0.01, so the goal
    # (|ratio - 1| < 0.05) is resolved at 3 standard errors
    exact = bond_length_var_closed(kT, 1.0)
    sim = Simulation(bonded_pairs(200, 1.0, 0.0), None, SimOptions(kT=kT, dt=dt, seed=12, fluct=True, wca_eps=0.0))
    sim.run(50 * dt)
    res = sim.run(200 * dt, frames=201)
    d = res.frame_pos[:-1, 1::2] - res.frame_pos[:-1, 0::2]
    v = np.linalg.norm(d, axis=2).var(axis=0, ddof=1) / exact
    m, e = float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v)))
    ref = dict(FLUCT_PAIR_RATIO[kT])[dt]
    print(f"\n--fluct kT={kT:g} dt={dt:g} t0 (stage factor {sim.fluct_stage_factor():g}), seed 12: bond variance "
          f"/ exact = {m:.4f} +- {e:.4f}; benchmark (seed 11) {ref}; goal |x - 1| < 0.05")
    assert 3 * e <= 0.05, "too few samples to resolve the goal"
    assert abs(m - 1.0) < 0.05
    assert abs(m - ref) < 4 * math.hypot(e, 0.012)      # agrees with the benchmark's table
