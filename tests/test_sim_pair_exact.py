"""The exact reference of the bond-fluctuation benchmarks (bonded pair, k = 1 k0, rest 1 sigma):
closed form against quadrature, and against Euler far below its limit extrapolated to dt -> 0
(benchmarks/sim_pair_exact.py, committed JSON).  Units: sigma, k0, k0 sigma^2."""
import json
import math
from pathlib import Path

import pytest

from mlc.sim.testscenes import bond_length_var, bond_length_var_closed

RESULTS = Path(__file__).resolve().parent.parent / "benchmarks" / "results" / "sim_pair_exact.json"


@pytest.mark.parametrize("kT, L, k", [(kT, 1.0, 1.0) for kT in (1e-5, 1e-4, 1e-3, 1e-2, 1.5e-2)]
                         + [(kT, 0.5, 2.0) for kT in (1e-5, 1e-3, 7e-3)])
def test_closed_form_matches_quadrature(kT, L, k):
    # the closed form extends the weight to r < 0: exact to double precision while sqrt(kT/k) < L/8
    assert math.sqrt(kT / k) < L / 8
    assert bond_length_var_closed(kT, L, k) == pytest.approx(bond_length_var(kT, L, k), rel=1e-8)


def test_not_kT_over_k_at_large_kT():
    # 1 - 2 kT/(k L^2) to first order: 2 % below kT/k at kT = 1e-2
    assert bond_length_var_closed(1e-2) / 1e-2 == pytest.approx(0.98059, abs=1e-5)
    assert bond_length_var_closed(1e-5) / 1e-5 == pytest.approx(1 - 2e-5, abs=1e-8)


def test_euler_far_below_its_limit_agrees():
    rows = json.loads(RESULTS.read_text())["rows"]
    assert {r["kT"] for r in rows} == {1e-2, 1e-3}
    for r in rows:
        print(f"\nkT={r['kT']:g}: Euler extrapolated to dt -> 0: {r['euler_extrapolated_over_kT']:.4f} "
              f"+- {r['euler_extrapolated_se']:.4f} kT/k; closed form {r['closed_form_over_kT']:.5f}")
        assert abs(r["euler_extrapolated_over_kT"] - r["closed_form_over_kT"]) < 3 * r["euler_extrapolated_se"]
        assert r["euler_extrapolated_se"] < 0.006
        # each Euler dt on its linear theory, 1/(1 - h lambda/2), within sampling error
        assert r["euler_dt1e-5_over_kT"] / r["closed_form_over_kT"] == pytest.approx(1 / 0.99, abs=0.008)
