"""The skeleton's relaxation test (mlc.robot.verify.angles_relaxed, docs/robot.md 3.2):
joint angles that only fluctuate thermally pass, whatever their noise level; a fold still
creeping (a drift larger than the noise allows) does not.  Synthetic Ornstein-Uhlenbeck
angles with a known variance kT/kappa and correlation time tau, seeded."""
import numpy as np
import pytest

from mlc.robot.verify import angles_relaxed


def ou(n, dt, tau, sd, rng, dofs=5):
    """n samples every dt t0 of dofs independent OU processes (stationary sd, correlation time tau)."""
    a = np.exp(-dt / tau)
    x = np.empty((n, dofs))
    x[0] = rng.normal(0, sd, dofs)
    for i in range(1, n):
        x[i] = a * x[i - 1] + rng.normal(0, sd * np.sqrt(1 - a * a), dofs)
    return x


@pytest.mark.parametrize("sd_deg", [0.5, 5.0, 15.0])
def test_thermal_noise_alone_is_relaxed(sd_deg):
    # plateau of 600 t0 sampled every 5 t0 (the benchmark's tau/20 windows), tau = 100 t0:
    # over 40 seeds at most a few false alarms (z = 3 per DOF, 5 DOFs)
    fails = 0
    for seed in range(40):
        rng = np.random.default_rng(seed)
        ok, d = angles_relaxed(90.0 + ou(120, 5.0, 20.0, sd_deg, rng), block=200.0, tau=100.0)
        fails += not ok
        assert np.allclose(d["noise_deg"], sd_deg, rtol=0.5)
    assert fails <= 4


def test_a_creeping_fold_is_not_relaxed():
    rng = np.random.default_rng(1)
    t = np.arange(120) * 5.0
    creep = (10.0 / 100.0) * t[:, None] * np.array([1, 0, 0, 0, 0])   # 10 degrees per 100 t0 on one DOF
    ok, d = angles_relaxed(ou(120, 5.0, 20.0, 5.0, rng) + creep, block=200.0, tau=100.0)
    assert not ok and d["drift_deg"][0] > d["tol_deg"][0]
    assert all(dr <= tol for dr, tol in zip(d["drift_deg"][1:], d["tol_deg"][1:]))


def test_too_few_samples_are_not_relaxed():
    assert angles_relaxed(np.zeros((5, 2)), block=1.0, tau=1.0)[0] is False
