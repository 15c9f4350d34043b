"""Static verification of every library gate, both conventions, all four input states."""
import numpy as np
import pytest

from mlc.gates.library import GATE_NAMES, gate_scene
from mlc.verify.static import _Problem, equilibrium, verify_scene


@pytest.mark.parametrize("signal", ["expand", "contract"])
@pytest.mark.parametrize("name", GATE_NAMES)
def test_every_gate_statically(name, signal):
    rows = verify_scene(gate_scene(name, signal))
    assert len(rows) == 4
    for r in rows:
        assert r["ok"], r
        assert r["error"] < 0.05 and r["joint_stretch"] < 1e-3
        assert r["bit"] == r["expected"] and r["margin"] > 0.2


def test_mechanism_is_rigid_in_each_state():
    """No floppy mode: with one body pinned, the constraint Jacobian has full column rank."""
    s = gate_scene("NAND", "expand")
    A = s.arrays()
    prob = _Problem(s, A.pos, A.quat)
    J = prob.jacobian(np.zeros(6 * len(prob.free)), A.muscle_lengths([0, 0])).toarray()
    assert np.linalg.svd(J, compute_uv=False).min() > 1e-2


def test_converges_from_perturbed_poses():
    s = gate_scene("OR", "expand")
    A = s.arrays()
    rng = np.random.default_rng(7)
    pos = A.pos + rng.normal(0, 0.03, A.pos.shape)
    q = A.quat + rng.normal(0, 0.02, A.quat.shape)
    q /= np.linalg.norm(q, axis=1)[:, None]
    e = equilibrium(s.with_poses(pos, q), "01", steps=1)
    assert e.probes["out"] == pytest.approx(1.5, abs=1e-8)


def test_a_wrong_gate_is_caught():
    """Verification can fail: a NAND scene claiming the AND truth table is reported wrong."""
    s = gate_scene("NAND", "expand")
    s.truth_table = {"00": "0", "01": "0", "10": "0", "11": "1"}
    rows = verify_scene(s)
    assert not any(r["ok"] for r in rows)


def test_muscle_too_weak_shows_stretch():
    """A muscle that cannot reach its length leaves residual strain and the check notices."""
    s = gate_scene("AND", "expand")
    s.muscles[0].actuated = 2.5         # beyond what the lever can reach
    e = equilibrium(s, "10")
    assert e.max_muscle_strain > 1e-3 or e.max_joint_stretch > 1e-3


def test_stiff_joints_converge_by_stiffness_homotopy(monkeypatch):
    """A circuit compiled with 1000x stiffer connector joints: every row reaches the ideal
    output length with no residual energy; the same equilibrium (to 1e-9 sigma) as a plain
    Levenberg-Marquardt run at the full stiffness, which needs more iterations (the
    stiffness continuation, mlc.verify.static module doc)."""
    import mlc.verify.static as S
    from mlc.circuit.build import CircuitOptions
    from mlc.pipeline import build, compile_spec, load

    sc = build(compile_spec(load(None, "y = (a & b) | c")), options=CircuitOptions(joint_k=1000.0)).circuit.scene
    A = sc.arrays()
    assert A.bond_k.max() == pytest.approx(1000.0) and A.muscle_k.max() == pytest.approx(1.0)
    states = sc.states()
    homotopy = {s: equilibrium(sc, s) for s in states}
    monkeypatch.setattr(S, "STIFF_CAP", float("inf"))
    direct = {s: equilibrium(sc, s) for s in states}
    for s in states:
        want = 1.5 if sc.truth_table[s] == "1" else 1.0
        assert homotopy[s].probes["y"] == pytest.approx(want, abs=1e-9), s
        assert homotopy[s].energy < 1e-20 and homotopy[s].max_joint_stretch < 1e-9
        assert homotopy[s].probes["y"] == pytest.approx(direct[s].probes["y"], abs=1e-9)
    assert sum(e.iterations for e in homotopy.values()) < sum(e.iterations for e in direct.values())


def test_spd_lu_solves_the_normal_equations_with_less_fill_than_colamd():
    """SuperLU's symmetric mode (``spd_lu``, which the dynamic check's harmonic analyses take)
    solves the damped normal equations of a small compiled circuit (condition ~1e10: its
    chains' floppy bends are held only by REG) with a backward error |Mx - b| / (|M| |x|) near
    the rounding unit, as small as COLAMD's (the order the static minimiser keeps), and keeps
    less fill; a singular matrix raises."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import splu

    from mlc.pipeline import build, compile_spec, load
    from mlc.verify.static import REG, spd_lu

    s = build(compile_spec(load(None, "y = (a & b) | c"))).circuit.scene
    A = s.arrays()
    prob = _Problem(s, A.pos, A.quat, pin_first=False)
    J = prob.jacobian(np.zeros(6 * len(prob.free)), A.muscle_lengths([1, 1, 1])).tocsc()
    M = prob.normal_matrix(J, REG)
    b = np.random.default_rng(3).standard_normal(M.shape[0])
    lu, colamd = spd_lu(M), splu(M, permc_spec="COLAMD")
    norm_m = sp.linalg.norm(M, 1)

    def backward(f):
        x = f.solve(b)
        return np.linalg.norm(M @ x - b, 1) / (norm_m * np.linalg.norm(x, 1))

    assert backward(lu) < 1e-14 and backward(lu) < 10 * backward(colamd) + 1e-16
    assert lu.L.nnz + lu.U.nnz < colamd.L.nnz + colamd.U.nnz
    with pytest.raises(RuntimeError):
        spd_lu(sp.csc_matrix(np.diag([1.0, 0.0, 2.0])))


def test_a_row_reports_its_progress_and_the_report_is_unchanged():
    """A large circuit's row takes minutes: equilibrium() reports after each minimisation
    (the continuation steps, then the polish), and verify_static passes that on as a
    fractional row, so the bar moves within a row; whole rows are reported as they finish.
    Reporting changes nothing: the same poses and the same report as without a callback."""
    from mlc.verify.circuit import ROW_SHARES, verify_static
    from mlc.verify.static import CONTINUATION_STEPS

    s = gate_scene("NAND", "expand")
    fs = []
    eq = equilibrium(s, "11", progress=fs.append)
    assert fs == [k / (CONTINUATION_STEPS + 1) for k in range(1, CONTINUATION_STEPS + 2)]
    assert np.array_equal(eq.pos, equilibrium(s, "11").pos)

    calls = []
    rep = verify_static(s, rows=["01", "11"], progress=lambda d, t: calls.append((d, t)))
    assert all(t == 2 for _, t in calls)
    done = [d for d, _ in calls]
    assert done == sorted(done) and len(set(done)) == len(done)          # always forward
    assert done.count(1) == 1 and done[-1] == 2                          # whole rows as they finish
    within = [d for d in done if 0 < d < 1]
    assert len(within) == CONTINUATION_STEPS + 2                         # the minimisations, the spread
    assert within[-1] == ROW_SHARES[1] and within[-2] == ROW_SHARES[0]
    plain = verify_static(s, rows=["01", "11"])
    assert [(e["measured"], e["ok"]) for e in rep.entries] == [(e["measured"], e["ok"]) for e in plain.entries]


def test_the_polish_is_left_out_only_where_the_minimisation_converged(monkeypatch):
    """verify_static polishes a row's equilibrium only when the pose before the polish has a
    joint stretched (or a muscle strained) by more than POLISH_ABOVE: the polish is a third
    of a circuit row's factorisations (benchmarks/results/static_polish.json).  Where the
    minimisation converged, the pose left unpolished is exactly the one the polish starts
    from, and within 1e-8 sigma of the polished one, with fewer factorisations; where the
    threshold is passed (here: forced to 0), the pose is exactly the polished one."""
    from mlc.pipeline import build, compile_spec, load
    from mlc.verify import static

    sc = build(compile_spec(load("examples/tetris.tt"))).circuit.scene
    lus = {}

    def counting(key):
        def lu_of(M):
            lus[key] = lus.get(key, 0) + 1
            return static.colamd_lu(M)
        return lu_of
    row = "11"
    a = equilibrium(sc, row, lu_of=counting("polish"))
    b = equilibrium(sc, row, lu_of=counting("none"), polish=False)
    c = equilibrium(sc, row, lu_of=counting("auto"), polish=None)
    assert lus["none"] == lus["auto"] < lus["polish"]
    assert np.array_equal(b.pos, c.pos) and b.max_joint_stretch < static.POLISH_ABOVE
    assert np.abs(a.pos - b.pos).max() < 1e-8
    assert max(abs(a.probes[n] - b.probes[n]) for n in a.probes) < 1e-8
    assert not np.array_equal(a.pos, b.pos)                              # the polish did run in a
    monkeypatch.setattr(static, "POLISH_ABOVE", 0.0)
    assert np.array_equal(equilibrium(sc, row, polish=None).pos, a.pos)


def test_a_minimisation_cut_short_is_reported_as_not_converged(monkeypatch):
    """Equilibrium.converged is False when the minimisation stopped short (here: one
    iteration a step), True when it reached equilibrium; verify_static passes it on, and
    the report's words on such a row are in the next test."""
    from mlc.verify import static
    from mlc.verify.circuit import verify_static

    s = gate_scene("NAND", "expand")
    assert equilibrium(s, "11").converged
    monkeypatch.setattr(static, "GN_MAX_ITER", 1)
    eq = equilibrium(s, "11", polish=False)
    assert not eq.converged and eq.max_joint_stretch > static.POLISH_ABOVE
    rep = verify_static(s, rows=["11"], kT=None, polish=False)
    assert rep.rows[0]["converged"] is False and rep.rows[0]["iterations"] == static.CONTINUATION_STEPS
    assert rep.rows[0]["joint_stretch"] == eq.max_joint_stretch


def test_the_report_tells_a_right_bit_off_its_length_from_a_wrong_bit():
    """A read with the right bit but too far from its length is not called a wrong bit, and a
    probe on a zero-stiffness mode (infinite harmonic spread) gets its own warning instead of
    a --joint-k suggestion of infinity."""
    from mlc.verify.circuit import Report, format_report

    rep = Report("c", "static", params={"tol_length": 0.05, "tol_stretch": 1e-3, "kT": 1e-5, "joint_k": 1.0})
    rep.entries = [
        {"state": "11", "output": "y0", "expected": 0, "measured": 1.1058, "bit": 0, "margin": 0.1442,
         "error": 0.1058, "ok": False, "thermal_sd": float("inf")},
        {"state": "11", "output": "y1", "expected": 1, "measured": 1.1, "bit": 0, "margin": -0.15,
         "error": 0.4, "ok": False, "thermal_sd": 0.01}]
    rep.rows = [{"state": "11", "joint_stretch": 7.7e-4, "converged": False, "iterations": 98, "clearance": 0.02,
                 "ok": False}]
    text = format_report(rep)
    assert "output y0: bit 0 as expected, but read 1.1058 sigma, 0.1058 sigma from its length" in text
    assert "output y1: expected 1, read 1.1000 sigma (bit 0)" in text
    assert "row 11, output y0 (and 0 more entries, in 1 rows) sits on a mode of zero stiffness" in text
    assert "ended with energy left in the bonds (joint stretch 7.70e-04 sigma after 98 iterations)" in text
    assert "stopped short of equilibrium, or the mechanism is jammed" in text and "--dynamic --rows 11" in text
    assert "inf" not in text.replace("infinite", "")


def test_a_stall_stops_a_minimisation_at_once_only_where_its_bonds_are_closed(monkeypatch):
    """One iteration that gains little (a stall) ends a minimisation whose joints and muscles
    are within STALL_CLOSED; with bonds still off it takes STALL_RUN stalls in a row (a deep
    circuit's cost falls in a sawtooth, docs/circuits.md).  Here every iteration counts as
    stalled (STALL_GAIN > 1)."""
    from mlc.verify import static
    s = gate_scene("NAND", "expand")
    A = s.arrays()
    L = A.muscle_lengths(static._state_bits(s, "11"))
    monkeypatch.setattr(static, "STALL_GAIN", 2.0)
    monkeypatch.setattr(static, "STALL_RUN", 5)
    prob = static._Problem(s, A.pos, A.quat, pin_first=False)           # at rest, the muscles at '11'
    it = static._minimise(prob, L)                                      # stops at the first closed stall
    assert 1 < it < 5 and max(static._strains(prob, L)) <= static.STALL_CLOSED
    monkeypatch.setattr(static, "STALL_CLOSED", 0.0)                    # bonds never closed: STALL_RUN stalls
    for run in (2, 5):
        monkeypatch.setattr(static, "STALL_RUN", run)
        prob = static._Problem(s, A.pos, A.quat, pin_first=False)
        assert static._minimise(prob, L) == run
    monkeypatch.undo()
    eq = equilibrium(s, "11")                                          # at equilibrium: one stall ends it
    prob = static._Problem(s, eq.pos, eq.quat, pin_first=False)
    assert max(static._strains(prob, L)) <= static.STALL_CLOSED
    before = prob.pos.copy()
    assert static._minimise(prob, L) == 1 and np.abs(prob.pos - before).max() < 1e-9
