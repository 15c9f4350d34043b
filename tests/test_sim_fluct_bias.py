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

from mlc.sim.integrator import (FLUCT_NOISE_HI, FLUCT_PAIR_RATIO, FLUCT_R_WINDOW, SimOptions, Simulation, _cheb_factor,
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
    # 2 kT h/gamma = 10 sigma^2 > FLUCT_NOISE_HI: base factor 3, then the window on the stiffest mode
    q = math.sqrt(vb["h_rho"] * 1.2 / 2.0)
    assert math.ceil(3.0 * q) <= vb["stages"] <= math.ceil(1.5 * math.ceil(3.0 * q))
    assert vb["stage_factor"] >= 3.0 and math.ceil(vb["stage_factor"] * q) == vb["stages"]
    assert vb["R_stiffest"] == pytest.approx(_cheb_factor(vb["h_rho"], vb["stages"]))
    small = Simulation(gate_scene("NAND"), {"a": 1, "b": 1}, SimOptions(kT=1e-5, dt=0.02, fluct=True)).variance_bias()
    q = math.sqrt(small["h_rho"] * 1.2 / 2.0)     # 4e-4 sigma^2 of noise a step: base factor 1
    assert math.ceil(q) <= small["stages"] <= math.ceil(1.5 * math.ceil(q))
    mid = Simulation(gate_scene("NAND"), {"a": 1, "b": 1}, SimOptions(kT=1e-3, dt=0.05, fluct=True)).variance_bias()
    q = math.sqrt(mid["h_rho"] * 1.2 / 2.0)       # 0.1 sigma^2 a step: base factor 3 (1 before session 17)
    assert math.ceil(3.0 * q) <= mid["stages"] <= math.ceil(1.5 * math.ceil(3.0 * q))
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
    # R = T_16(1 - 400/256) = -0.991; the rule moves it into the window, and the kernel takes it.
    # Since session 17 that point has base factor 3 (its noise, 0.4 sigma^2 a step, is above
    # FLUCT_NOISE_HI); at kT = 1e-6 (4e-4 sigma^2) the base factor is 1, the former case
    kw = dict(kT=1e-6, dt=0.2, fluct=True, wca_eps=0.0)
    sim = Simulation(bonded_pairs(4), None, SimOptions(**kw))
    m, s, R = sim.fluct_stages_target()
    assert _cheb_factor(400.0, 16) < -0.99 and s == 17 and FLUCT_R_WINDOW[0] <= R <= FLUCT_R_WINDOW[1]
    # full-size steps only (fluct_levels 1), so the last substep is a full step
    kw1 = dict(kw, fluct_levels=1)
    assert Simulation(bonded_pairs(4), None, SimOptions(**kw1)).run(0.6, quiet=True).stages == s
    # a fixed factor is taken as given (no window)
    assert Simulation(bonded_pairs(4), None, SimOptions(fluct_stages=1.0, **kw1)).run(0.6, quiet=True).stages == 16
    # every table point of the benchmark gets a stiffest-mode factor in the window or the nearest
    # to it within 1.5 times the base stages
    lo, hi = FLUCT_R_WINDOW
    for kT in FLUCT_PAIR_RATIO:
        for dt, _ in FLUCT_PAIR_RATIO[kT]:
            _, s, R = Simulation(bonded_pairs(2), None, SimOptions(kT=kT, dt=dt, fluct=True)).fluct_stages_target()
            hr = 2.0 * dt * 1000.0                  # the pair's mode: rate 2 k/gamma
            s0 = math.ceil((3.0 if 2.0 * kT * dt * 1000.0 > FLUCT_NOISE_HI else 1.0) * math.sqrt(1.2 * hr / 2.0))
            ks = range(s0, math.ceil(1.5 * s0) + 1)     # distance of each candidate's R from the window
            out = [max(lo - _cheb_factor(hr, k), _cheb_factor(hr, k) - hi, 0.0) for k in ks]
            print(f"kT={kT:g} dt={dt:g}: s0={s0} s={s} R={R:+.3f}")
            assert R == pytest.approx(_cheb_factor(hr, s))
            assert s == (ks[out.index(0.0)] if 0.0 in out else ks[out.index(min(out))])


def test_stage_factor_option_checked():
    from mlc.errors import MlcError
    with pytest.raises(MlcError, match="stage factor"):
        Simulation(bonded_pairs(2), None, SimOptions(kT=1e-3, fluct=True, fluct_stages=0.5))
    for bad in (0, 9, 2.5):
        with pytest.raises(MlcError, match="substep levels"):
            Simulation(bonded_pairs(2), None, SimOptions(kT=1e-3, fluct=True, fluct_levels=bad))


#: groups of bonded pairs whose stiffnesses spread over a factor 33 (benchmarks/sim_fluct_modes.py)
SPREAD_KS = np.geomspace(1.0, 0.03, 12)


def _spread_ratios(kT, dt, levels, per=100, seed=12, noise_hi=None, monkeypatch=None):
    """Bond-length variance / exact (quadrature) per stiffness group: (means, standard errors).
    Each pair's records are taken about the group's pooled mean (over all its pairs and records):
    a pair's own mean would bias the variance low where records stay correlated over many steps
    (|R| near 1); with the pooled mean the pairs' ratios are independent, so their spread is an
    honest standard error (benchmarks/sim_fluct_modes.py, ratio_pool)."""
    from mlc.sim.testscenes import bond_length_var
    if noise_hi is not None:                      # a former rule's noise threshold
        monkeypatch.setattr("mlc.sim.integrator.FLUCT_NOISE_HI", noise_hi)
    kk = np.repeat(SPREAD_KS, per)
    sim = Simulation(bonded_pairs(len(kk), k=kk), None,
                     SimOptions(kT=kT, dt=dt, seed=seed, fluct=True, wca_eps=0.0, fluct_levels=levels))
    sim.run(50 * dt, quiet=True)                  # from the bonds at rest
    res = sim.run(200 * dt, frames=201, quiet=True)
    L = np.linalg.norm(res.frame_pos[:-1, 1::2] - res.frame_pos[:-1, 0::2], axis=2)
    m, e = [], []
    for j, k in enumerate(SPREAD_KS):
        Lj = L[:, j * per:(j + 1) * per]
        v = ((Lj - Lj.mean()) ** 2).mean(axis=0) / bond_length_var(kT, 1.0, float(k))
        m.append(float(v.mean()))
        e.append(float(v.std(ddof=1) / math.sqrt(per)))
    return np.array(m), np.array(e)


@pytest.mark.parametrize("kT, dt, former, per", [
    (1e-5, 0.2, "s13", 300), (1e-5, 0.5, "s13", 100), (1e-4, 5.0, "s13", 100),
    (1e-3, 0.2, None, 300), (1e-3, 0.05, "s16", 300), (1e-2, 0.01, "s16", 100)])
def test_many_stiff_modes(kT, dt, former, per, monkeypatch):
    # 12 groups of 100 pairs, k = 1 ... 0.03 k0: the pairs' modes fill h lambda over a factor 33
    # below the stiffest, which the stage rule places.  Goal 5 % at every point.  The former rules
    # fail it: s13, every step at full size (fluct_levels 1, session 13): the modes near an
    # interior Chebyshev extremum stay frozen at their start (kT = 1e-5, 1e-4: 0.39 to 0.64 of
    # exact); s16, random substep levels but base factor 1 up to 0.5 sigma^2 of noise a step
    # (sessions 15-16): up to +8 % at kT = 1e-3, dt = 0.05-0.2 t0 and +21 % at kT = 1e-2,
    # dt = 0.01 t0 (benchmarks/sim_fluct_modes.py, docs/simulation.md).  300 pairs a group at
    # dt = 0.2 t0 (kT = 1e-5: 100 pairs read one group 1.061 +- 0.022, 300 read 0.993-1.019) and
    # at kT = 1e-3: the per-pair ratios are heavy-tailed there (100 pairs, seed 12, read one group
    # 1.058 +- 0.014 at dt = 0.2 t0 where 400 pairs, seed 21, read 0.987-1.014); the former rule's
    # +8 % at dt = 0.2 t0 is not 3 standard errors past the goal (1.082 +- 0.011), so that point
    # checks the goal only
    goal = 0.05
    new, new_e = _spread_ratios(kT, dt, 4, per=per)
    hl = 2.0 * SPREAD_KS * dt * 1000.0
    old, old_e = (None, None) if former is None else _spread_ratios(
        kT, dt, 1 if former == "s13" else 4, per=per, noise_hi=0.5, monkeypatch=monkeypatch)
    for j in range(len(SPREAD_KS)):
        was = "" if old is None else f", {old[j]:.3f} +- {old_e[j]:.3f} (former rule {former})"
        print(f"\nkT={kT:g} dt={dt:g} k={SPREAD_KS[j]:.4f} (h lambda {hl[j]:.1f}): bond variance / exact "
              f"{new[j]:.3f} +- {new_e[j]:.3f} (now){was}", end="")
    assert 3 * float(np.median(new_e)) <= goal, "too few samples to resolve the goal"
    assert np.all(np.abs(new - 1.0) < goal), new
    if old is not None:
        # the test fails on the former rule: some mode off by more than the goal and 3 standard errors
        assert np.any(np.abs(old - 1.0) > goal + 3 * old_e), old


def test_random_levels_only_above_four_stages():
    # a full step of more than FLUCT_LEVELS_MIN_STAGES stages draws from fluct_levels levels; at 4
    # stages (dt = 0.01 t0 on k0 pairs) the random levels gave the pair 1.150 of exact at kT = 1e-2,
    # full-size steps 1.007 (benchmarks/sim_fluct_bias.py), so full-size steps are kept there.
    # Since session 17 kT = 1e-2, dt = 0.01 t0 takes base factor 3 (11 stages, so random levels);
    # kT = 1e-5 (2e-4 sigma^2 of noise a step) keeps 4 stages
    from mlc.sim.integrator import FLUCT_LEVELS_MIN_STAGES
    for kT, dt, want in ((1e-2, 0.01, 4), (1e-5, 0.01, 1), (1e-5, 0.05, 4), (1e-2, 0.05, 4), (0.0, 0.2, 1)):
        sim = Simulation(bonded_pairs(2), None, SimOptions(kT=kT, dt=dt, fluct=True))
        s = sim.fluct_stages_target()[1]
        assert sim.fluct_level_span() == want and (want == 1) == (s <= FLUCT_LEVELS_MIN_STAGES or kT == 0)
        if kT > 0:
            assert sim.variance_bias()["substep_levels"] == want
    assert Simulation(bonded_pairs(2), None, SimOptions(kT=1e-3, dt=0.2, fluct=True, fluct_levels=1)).fluct_level_span() == 1
    # what the kernel is given: at 4 stages a run is bit for bit the one with fluct_levels 1
    kw = dict(kT=1e-5, dt=0.01, seed=3, fluct=True, wca_eps=0.0)
    a = Simulation(bonded_pairs(4), None, SimOptions(**kw))
    a.run(0.5, quiet=True)
    b = Simulation(bonded_pairs(4), None, SimOptions(fluct_levels=1, **kw))
    b.run(0.5, quiet=True)
    assert np.array_equal(a.pos, b.pos)


def test_random_levels_do_not_depend_on_chunking():
    kw = dict(kT=1e-3, dt=0.2, seed=5, fluct=True, wca_eps=0.0)
    sc = bonded_pairs(6, k=[1.0, 0.5, 0.3, 0.2, 0.1, 0.05])
    a = Simulation(sc, None, SimOptions(**kw))
    a.run(4.0, quiet=True)
    b = Simulation(sc, None, SimOptions(**kw))
    b.advance(3)
    b.advance(17)
    assert np.array_equal(a.pos, b.pos) and np.array_equal(a.quat, b.quat)
    # the levels do change the trajectory (random least levels taken), and cost more evaluations
    c = Simulation(sc, None, SimOptions(fluct_levels=1, **kw))
    c.run(4.0, quiet=True)
    assert not np.array_equal(a.pos, c.pos) and a.stages_out[0] > c.stages_out[0]


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
