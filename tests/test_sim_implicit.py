"""The linearly implicit scheme (mlc/sim/implicit.py): checked against Euler (a second
integrator), the static equilibrium solver (a second implementation of the mechanics) and
linear theory (the stationary variance of a harmonic bond)."""
import numpy as np
import pytest

from mlc.sim.integrator import SimOptions, Simulation, simulate
from mlc.sim.testscenes import bond_length_var, bonded_pairs, chain_scene, tongs_scene


def test_agrees_with_euler_and_converges_first_order():
    sc = tongs_scene(3)
    ref = simulate(sc, 0.5, {"a": 1}, SimOptions(kT=0, scheme="euler", dt=2e-5), record_interval=0.01)
    errs = []
    for dt in (0.004, 0.001):
        # a drift bound that never splits these steps: the error is the step's own
        r = simulate(sc, 0.5, {"a": 1}, SimOptions(kT=0, scheme="implicit", dt=dt, disp_acc=1.0),
                     record_interval=0.01)
        errs.append(np.max(np.abs(np.interp(ref.times, r.times, r.probes["span"]) - ref.probes["span"])))
    # first order: 4 times the steps, about a quarter of the error
    assert errs[1] < 0.35 * errs[0]
    assert errs[1] < 5e-3
    assert abs(r.probes["span"][-1] - ref.probes["span"][-1]) < 1e-4


def test_steps_far_past_the_euler_limit_reach_the_static_equilibrium():
    from mlc.verify.static import equilibrium

    sc = tongs_scene(4, k=100.0)
    sim = Simulation(sc, {"a": 1}, SimOptions(kT=0, scheme="implicit", dt=0.2))
    assert sim.dt > 1e4 * sim.euler_limit()
    res = sim.run(20.0)
    eq = equilibrium(sc, "1")
    assert res.probes["span"][-1] == pytest.approx(eq.probes["span"], abs=1e-6)
    # one evaluation per step and per check of the step's end, and few steps split
    assert res.force_evals < 4 * res.steps
    sim._eval()
    assert sim.mon[0] < 1e-3


@pytest.mark.parametrize("rot_noise", [True, False])
def test_stationary_bond_variance_at_a_step_past_euler_stability(rot_noise):
    # a pair joined by a centre bond (k = 1, rest 1): its length's relaxation rate is 2k/gamma,
    # so h lambda = 2 k h/gamma = 8 at dt = 0.004 t0 (Euler is unstable above 2).  With
    # rotational noise the scheme's noise 2 kT (D/h + H+/2) makes the stationary variance
    # exact; without it the variance is kT/k / (1 + h lambda/2) (mlc/sim/implicit.py).
    # kT small: a step's transverse noise lengthens the bond by ~2 kT h/(gamma L) (second order),
    # which at kT = 1e-4 adds 10 % to the smaller variance of the uncorrected case
    kT, dt = 1e-6, 0.004
    sc = bonded_pairs(400, rest=1.0, k=1.0)
    sim = Simulation(sc, None, SimOptions(kT=kT, scheme="implicit", dt=dt, seed=11, rot_noise=rot_noise,
                                          disp_acc=1.0))
    hl = 2.0 * dt * sim.t_unit
    sim.run(20 * dt)
    lens = []
    for _ in range(150):
        sim.run(dt)
        lens.append(np.linalg.norm(sim.pos[1::2] - sim.pos[0::2], axis=1))     # bodies a0, b0, a1, b1, ...
    v = float(np.var(np.concatenate(lens)))
    exact = bond_length_var(kT)
    want = exact if rot_noise else exact / (1.0 + hl / 2)
    assert v / want == pytest.approx(1.0, abs=0.04)
    # and the two cases differ by far more than that (the test tells them apart)
    assert abs(1.0 / (1.0 + hl / 2) - 1.0) > 0.5


def test_same_seed_same_numbers_however_the_run_is_cut():
    sc = chain_scene(6)
    a = Simulation(sc, None, SimOptions(kT=1e-4, seed=7, scheme="implicit", dt=0.01))
    a.run(0.2)
    b = Simulation(sc, None, SimOptions(kT=1e-4, seed=7, scheme="implicit", dt=0.01))
    for _ in range(4):
        b.run(0.05)
    assert np.array_equal(a.pos, b.pos) and np.array_equal(a.quat, b.quat)
    c = Simulation(sc, None, SimOptions(kT=1e-4, seed=8, scheme="implicit", dt=0.01))
    c.run(0.2)
    assert not np.allclose(a.pos, c.pos)


def test_variance_bias_report():
    sc = bonded_pairs(4)
    for rot, lo in ((True, 1.0), (False, None)):
        sim = Simulation(sc, None, SimOptions(kT=1e-4, scheme="implicit", dt=0.004, rot_noise=rot))
        vb = sim.variance_bias()
        assert vb["scheme"] == "implicit" and vb["ratio_max"] == 1.0
        if lo is not None:
            assert vb["ratio_min"] == lo
        else:
            assert vb["ratio_min"] == pytest.approx(1.0 / (1.0 + 0.5 * vb["h_rho"]))
