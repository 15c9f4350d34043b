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


def _arm_pairs(n: int, arm: float, k: float = 1.0, rest: float = 1.0, spacing: float = 4.0):
    """n pairs of bodies, each joined by one bond (rest ``rest``) between sites ``arm`` sigma off
    their centres, across the bond: the bond's mode is part rotational (translational share
    f = 1/(1 + arm^2) at gamma_r = gamma); arm 0 is bonded_pairs's centre bond."""
    import math

    from mlc.scene.model import Body, Bond, Box, Scene
    bodies, bonds = [], []
    side = int(math.ceil(math.sqrt(n)))
    for i in range(n):
        c = spacing * np.array([i % side, i // side, 0.0])
        for tag, dx in (("a", -0.5 * rest), ("b", 0.5 * rest)):
            bodies.append(Body(f"{tag}{i}", c + [dx, -arm, 0], np.array([1.0, 0, 0, 0]),
                               [Box(np.array([0.3, 0.3, 0.01]))], {"c": np.array([0.0, arm, 0.0])}))
        bonds.append(Bond(f"u{i}", f"a{i}.c", f"b{i}.c", k, rest, 0.0, "universal", f"u{i}"))
    return Scene("arm_pairs", bodies, bonds).check()


def _bond_var(sc, arm, scheme, dt, every, rot_noise=False, n=150):
    from mlc.geometry.rotation import quat_to_matrix
    sim = Simulation(sc, None, SimOptions(kT=1e-6, scheme=scheme, dt=dt, seed=11, rot_noise=rot_noise, disp_acc=1.0))
    sim.run(20 * every)
    site, lens = np.array([0.0, arm, 0.0]), []
    for _ in range(n):
        sim.run(every)
        w = sim.pos + np.einsum("bij,j->bi", np.array([quat_to_matrix(q) for q in sim.quat]), site)
        lens.append(np.linalg.norm(w[1::2] - w[0::2], axis=1))     # bodies a0, b0, a1, b1, ...
    return float(np.var(np.concatenate(lens))), sim


@pytest.mark.parametrize("rot_noise", [True, False])
def test_stationary_bond_variance_at_a_step_past_euler_stability(rot_noise):
    # a pair joined by a centre bond (k = 1, rest 1): its length's relaxation rate is 2k/gamma,
    # so h lambda = 2 k h/gamma = 8 at dt = 0.004 t0 (Euler is unstable above 2).  The scheme's
    # correction noise makes the stationary variance exact with rotational noise (covariance
    # 2 kT (D/h + H+/2)) and without it (the row's translational share, here 1); without the
    # correction it would be kT/k / (1 + h lambda/2) = 0.2 of exact (mlc/sim/implicit.py).
    # kT small: a step's transverse noise lengthens the bond by ~2 kT h/(gamma L) (second order)
    kT, dt = 1e-6, 0.004
    sc = bonded_pairs(400, rest=1.0, k=1.0)
    v, sim = _bond_var(sc, 0.0, "implicit", dt, dt, rot_noise)
    hl = 2.0 * dt * sim.t_unit
    assert v / bond_length_var(kT) == pytest.approx(1.0, abs=0.04)
    # and the uncorrected variance is far from it (the test tells a missing correction)
    assert abs(1.0 / (1.0 + hl / 2) - 1.0) > 0.5


def test_bond_at_arms_without_rotational_noise_has_the_continuous_variance():
    """Without rotational noise (the paper's model) a bond between sites 0.5 sigma off the
    centres relaxes through translations and rotations but is shaken through translations only:
    the continuous dynamics gives its length the variance f kT/k, f = 1/(1 + 0.5^2) = 0.8 (its
    translational share of mobility), not Boltzmann's kT/k.  Euler at h lambda = 0.1 (a second
    integrator; its own bias 1/(1 - h lambda/2) = 1.053 divided out) and the implicit scheme at
    h lambda = 10 both give it; the implicit scheme without its correction would give
    1/(1 + h lambda/2) = 0.17 of it, and with the full (rotational-noise) correction kT/k."""
    arm, kT, dt = 0.5, 1e-6, 0.004
    f = 1.0 / (1.0 + arm ** 2)
    sc = _arm_pairs(400, arm)
    v, sim = _bond_var(sc, arm, "implicit", dt, dt)
    hl = 2.0 * (1.0 + arm ** 2) * dt * sim.t_unit
    assert hl == pytest.approx(10.0)
    assert v / (f * kT) == pytest.approx(1.0, abs=0.05)
    ve, sime = _bond_var(sc, arm, "euler", dt / 100, dt)
    hle = 2.0 * (1.0 + arm ** 2) * sime.dt * sime.t_unit
    assert ve * (1.0 - hle / 2) / (f * kT) == pytest.approx(1.0, abs=0.05)
    assert v / (ve * (1.0 - hle / 2)) == pytest.approx(1.0, abs=0.07)
    # the alternatives are far off: no correction (0.17) and Boltzmann's kT/k (1/f = 1.25)
    assert 1.0 / (1.0 + hl / 2) < 0.2 and 1.0 / f > 1.2


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
    for rot in (True, False):
        sim = Simulation(sc, None, SimOptions(kT=1e-4, scheme="implicit", dt=0.004, rot_noise=rot))
        vb = sim.variance_bias()
        assert vb["scheme"] == "implicit" and vb["ratio_max"] == 1.0 and vb["ratio_min"] == 1.0
        assert ("translational share" in vb["note"]) == (not rot)
