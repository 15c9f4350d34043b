"""Other assembly branches of the library gates (issue 12, item 6): indicators, the fold
barrier, quenching, and the local rigidity of the design equilibria."""
import numpy as np
import pytest

from mlc.gates.library import GATE_NAMES, gate_scene
from mlc.geometry.rotation import quat_to_matrix
from mlc.verify.branches import DESIGN_SIGN, INDICATORS, fold_barrier, folded, indicators, quench, singular_values
from mlc.verify.static import equilibrium


def _R(quat):
    return np.array([quat_to_matrix(q) for q in quat])


@pytest.mark.parametrize("signal", ["expand", "contract"])
def test_design_equilibria_are_on_the_design_branch(signal):
    for name in GATE_NAMES:
        s = gate_scene(name, signal)
        for state in s.states():
            eq = equilibrium(s, state)
            ind = indicators(s, eq.pos, _R(eq.quat))
            assert not folded(ind), (name, signal, state, ind)
            # every indicator is well away from its fold (sigma or sigma^2)
            assert min(abs(ind[k]) for k in INDICATORS) > 0.3, (name, state, ind)


def test_fold_barrier_and_the_other_branch_of_nand_contract():
    """NAND contracting, inputs 11: folding input lever a's output side towards its other
    branch costs a barrier, and beyond it lies a second zero-energy equilibrium that still
    reads 0 but near 0.854 sigma (margin ~0.10 instead of 0.25): the issue's finding,
    reproduced through a different route (constrained continuation, then a quench)."""
    s = gate_scene("NAND", "contract")
    eq = equilibrium(s, "11")
    fb = fold_barrier(s, "11", "a.out", eq.pos, eq.quat, steps=6)
    energies = [e for _, e in fb.profile]
    print("a.out profile (indicator sigma, energy k0 sigma^2):", [(round(a, 3), round(e, 5)) for a, e in fb.profile])
    assert energies[0] < 1e-20 and fb.peak > 0.01
    peak_at = int(np.argmax(energies))
    assert 0 < peak_at < len(energies) - 1 and min(energies[peak_at:]) < fb.peak / 10
    q = quench(s, "11", fb.pos, fb.quat)
    print("quenched:", q)
    assert not q["design"] and q["stretch"] < 1e-6
    assert abs(q["probe"] - 0.854) < 0.01 and s.probes[0].bit(q["probe"]) == 0
    assert s.probes[0].margin(q["probe"], 0) < 0.15


def test_quench_of_a_perturbed_design_pose_returns_to_it():
    s = gate_scene("AND", "contract")
    eq = equilibrium(s, "01")
    rng = np.random.default_rng(3)
    q = quench(s, "01", eq.pos + rng.normal(0, 0.01, eq.pos.shape), eq.quat, eq)
    assert q["design"] and abs(q["probe"] - 1.0) < 1e-6


def test_smallest_singular_value_in_every_state():
    """Locally rigid: with one body fixed, the joint and muscle Jacobian has full column
    rank at every design equilibrium; smallest singular value 0.074 to 0.104 over the
    library (NIMPLY expanding, 11, is the softest; AND expanding, 00, the stiffest)."""
    vals = {}
    for name, signal in (("NIMPLY", "expand"), ("AND", "expand")):
        s = gate_scene(name, signal)
        for state in s.states():
            eq = equilibrium(s, state)
            vals[(name, state)] = singular_values(s, state, eq.pos, eq.quat).min()
    print({k: round(v, 4) for k, v in vals.items()})
    assert vals[("NIMPLY", "11")] == pytest.approx(0.0739, abs=1e-3)
    assert vals[("AND", "00")] == pytest.approx(0.1044, abs=1e-3)
    assert all(0.07 < v < 0.11 for v in vals.values())


def test_design_signs_cover_every_indicator():
    assert set(DESIGN_SIGN) == set(INDICATORS)


def test_check_gate_branches_option_errors(capsys):
    from mlc.cli import main
    assert main(["check-gate", "NAND", "--branches", "--dynamic"]) == 2
    assert "--branches" in capsys.readouterr().err
    assert main(["check-gate", "NAND", "--branches", "--kT", "0"]) == 2
    assert "kT > 0" in capsys.readouterr().err
