"""mlc.verify.dynamic: the multi-probe Brownian-dynamics check and its relaxation time.

The relaxation time is checked against closed forms (springs between point bodies) and
against the integrator itself (the decay rate of a deterministic run); the check is
run on a two-input gate (all rows, several seeds) and shown to catch a wrong truth table
and to need the time-scale condition (a plateau test alone reads a long chain wrong)."""
import numpy as np
import pytest

from mlc.errors import MlcError
from mlc.gates.connector import chain_scene
from mlc.gates.library import gate_scene
from mlc.scene.model import Body, Box, Muscle, Probe, Scene
from mlc.sim.drive import Drive
from mlc.sim.integrator import SimOptions, Simulation
from mlc.verify.dynamic import check_scene_dynamic_multi, probe_thermal_sd, relaxation_time, signal_time


def _points(n: int, k: float, gamma: float = 1.0) -> Scene:
    """``n`` point-like bodies along x, 1 sigma apart, neighbours joined by muscles of
    stiffness ``k`` and rest 1 (sites at the body centres: no torques)."""
    bodies = [Body(f"b{i}", np.array([float(i), 0, 0]), np.array([1.0, 0, 0, 0]),
                   [Box(np.array([0.1, 0.1, 0.1]))], {"c": np.zeros(3)}) for i in range(n)]
    muscles = [Muscle(f"m{i}", "a", f"b{i}.c", f"b{i + 1}.c", 1.0, 1.2, k) for i in range(n - 1)]
    probes = [Probe("out", "out", "b0.c", f"b{n - 1}.c", n - 1.0, 1.2 * (n - 1))]
    return Scene("points", bodies, [], muscles, probes, ["a"], ["out"], {"0": "0", "1": "1"},
                 units={"sigma": 1.0, "k0": 1.0, "gamma": gamma}).check()


@pytest.mark.parametrize("n,k,gamma,rate", [
    (2, 0.5, 1.0, 1.0),          # relative coordinate: 2k/gamma
    (2, 1.0, 2.0, 1.0),          # 2k/gamma again, but t0 is twice as long
    (3, 1.0, 1.0, 1.0),          # k [[1,-1,0],[-1,2,-1],[0,-1,1]]/gamma: eigenvalues 0, k, 3k
    (4, 1.0, 1.0, 2 - 2 ** 0.5),  # free chain of 4: 2k(1 - cos(pi/4))
])
def test_relaxation_time_closed_forms(n, k, gamma, rate):
    """tau = 1/lambda_min (rate in 1/(gamma/k0) time units), expressed in t0 =
    gamma/(1e-3 k0); the transverse and rotational modes of point bodies have no
    restoring force and are left out."""
    tau = relaxation_time(_points(n, k, gamma))
    assert tau == pytest.approx(1.0 / rate / (gamma / 1e-3), rel=1e-9)


def test_sparse_and_dense_spectra_agree():
    sc = chain_scene(3, "contract")
    dense = relaxation_time(sc)
    sparse = relaxation_time(sc, dense_max=0)
    assert sparse == pytest.approx(dense, rel=1e-6)


def test_a_lanczos_that_does_not_converge_is_one_clear_error(monkeypatch):
    """The shift-invert Lanczos of the sparse spectrum gave up on the 524-body Tetris robot
    (session 47: more zero modes than eigenvalues asked for); that is an MlcError naming
    --tau, not scipy's traceback.  Here the iteration is made to fail on a small chain."""
    import scipy.sparse.linalg as sla

    real = sla.eigsh

    def eigsh(A, *a, **kw):
        if kw.get("which") == "LM":          # the shift-invert call, not the largest-rate estimate
            raise sla.ArpackNoConvergence("ARPACK error -1: No convergence", np.zeros(0), np.zeros((0, 0)))
        return real(A, *a, **kw)

    monkeypatch.setattr(sla, "eigsh", eigsh)
    with pytest.raises(MlcError) as e:
        relaxation_time(chain_scene(3, "contract"), dense_max=0)
    assert e.value.where == "--tau" and "did not converge" in str(e.value)


def test_relaxation_time_is_the_decay_time_of_the_dynamics():
    """Independent check by the integrator: at kT = 0 a 5-unit chain switched to 1 approaches
    its far-end length exponentially, at the rate the linearised spectrum predicts."""
    sc = chain_scene(5, "expand")
    tau = relaxation_time(sc)
    sim = Simulation(sc, {"a": Drive.constant(1)}, SimOptions(scheme="stiff", kT=0.0, dt=0.01))
    res = sim.run(8 * tau, record_interval=0.05, quiet=True)
    t, dev = res.times, np.abs(1.5 - res.probes["out"])
    late = (t > 3 * tau) & (t < 7 * tau)
    fitted = -1.0 / np.polyfit(t[late], np.log(dev[late]), 1)[0]
    assert fitted == pytest.approx(tau, rel=0.05)
    assert dev[-1] < 1e-3


@pytest.mark.parametrize("rot_noise", [True, False])
def test_probe_thermal_spread_against_the_integrator(rot_noise):
    """The harmonic estimate kT g^T H^+ g of a probe's thermal spread is the Boltzmann one:
    the Euler-Maruyama reference with rotational noise (full equipartition) measures it
    within sampling error over 400 relaxation times; the default model (translational noise
    only, as in the paper) fluctuates less, so the estimate is an upper bound there."""
    from mlc.gates.connector import half_unit_scene

    sc = half_unit_scene("expand")
    pred = probe_thermal_sd(sc, 1e-5)["out"]
    tau = relaxation_time(sc)
    sim = Simulation(sc, {}, SimOptions(scheme="euler", kT=1e-5, seed=1, rot_noise=rot_noise))
    x = sim.run(400 * tau, record_interval=tau / 4, quiet=True).probes["out"][40:]
    if rot_noise:
        assert x.std() == pytest.approx(pred, rel=0.15)
    else:
        assert 0.3 * pred < x.std() < 0.9 * pred


def test_a_zero_mode_probe_has_no_finite_spread():
    sc = chain_scene(1, "expand")
    sc.muscles = []                     # nothing holds the signal: the probe reads a zero mode
    assert probe_thermal_sd(sc, 1e-5)["out"] == float("inf")
    assert probe_thermal_sd(chain_scene(1, "expand"), 1e-5)["out"] < 0.05


def test_a_probe_on_one_body_has_no_spread():
    sc = _points(2, 1.0)
    sc.bodies[0].sites["e"] = np.array([0.05, 0.0, 0.0])
    sc.probes[0].b = "b0.e"
    assert probe_thermal_sd(sc.check(), 1e-5)["out"] == 0.0


def test_two_input_gate_every_row_and_seed():
    sc = gate_scene("NAND", "expand")
    seen = []
    rows = check_scene_dynamic_multi(sc, kT=1e-5, seeds=[3, 4], progress=lambda d, n: seen.append((d, n)))
    assert [r["state"] for r in rows] == ["00", "01", "10", "11"]
    assert seen[-1] == (8, 8) and len(seen) == 8
    for r in rows:
        assert r["ok"] and r["relaxed"], r
        assert r["bit"] == r["expected"] == int(sc.truth_table[r["state"]])
        assert r["margin"] > 0.2 and len(r["per_seed"]) == 2 and r["seeds"] == [3, 4]


def test_a_wrong_truth_table_is_caught_on_its_row_and_output():
    sc = gate_scene("NAND", "contract")
    sc.truth_table = dict(sc.truth_table, **{"11": "1"})
    rows = check_scene_dynamic_multi(sc, kT=1e-5, seeds=1, rows=["00", "11"], progress=False)
    bad = [(r["state"], r["output"]) for r in rows if not r["ok"]]
    assert bad == [("11", "out")]
    assert rows[-1]["margin"] < -0.2


@pytest.mark.parametrize("as_circuit", [False, True])
def test_a_cache_reuses_each_rows_preparation_and_changes_nothing(monkeypatch, as_circuit):
    """A campaign's cache: the second call on a row does not solve its equilibrium or its
    signal times again and gives exactly the numbers of a call without the cache; another
    kT is prepared afresh.  ``as_circuit`` treats the gate as a circuit (DENSE_MAX lowered),
    whose preparation is the signal times rather than the spectrum."""
    import mlc.verify.dynamic as dyn
    import mlc.verify.static as st
    if as_circuit:
        monkeypatch.setattr(dyn, "DENSE_MAX", 6)
    sc = gate_scene("NAND", "expand")
    plain = check_scene_dynamic_multi(sc, 1e-5, [1], rows=["01"], progress=False)
    cache = {}
    first = check_scene_dynamic_multi(sc, 1e-5, [1], rows=["01"], progress=False, cache=cache)
    calls = []
    real_eq, real_sig = st.equilibrium, dyn.signal_time
    monkeypatch.setattr(st, "equilibrium", lambda *a, **k: calls.append("eq") or real_eq(*a, **k))
    monkeypatch.setattr(dyn, "signal_time", lambda *a, **k: calls.append("sig") or real_sig(*a, **k))
    again = check_scene_dynamic_multi(sc, 1e-5, [1], rows=["01"], progress=False, cache=cache)
    assert calls == []
    assert plain == first == again
    assert plain[0]["ok"] and (plain[0]["tau"] > 0)
    check_scene_dynamic_multi(sc, 2e-5, [1], rows=["01"], progress=False, cache=cache, max_time=1.0)
    assert "eq" in calls


def test_a_plateau_alone_is_fooled_by_a_long_chain():
    """Why the time-scale condition exists: without it the far end of a 10-unit chain, still
    at its old length when the first windows agree, is declared relaxed and read wrong;
    with it (the default) the same run reads the right bit."""
    sc = chain_scene(10, "expand")
    tau = relaxation_time(sc)
    early = check_scene_dynamic_multi(sc, 1e-5, [0], rows=["1"], tau_factor=0.0, window=0.05, tau=tau)[0]
    assert early["relaxed"] and not early["ok"] and early["relax_time"] < tau
    good = check_scene_dynamic_multi(sc, 1e-5, [0], rows=["1"], tau=tau)[0]
    assert good["ok"] and good["relax_time"] >= 3 * tau


def test_bad_arguments_are_one_clear_error():
    sc = gate_scene("AND", "expand")
    with pytest.raises(MlcError, match="row '1' is not an input state"):
        check_scene_dynamic_multi(sc, rows=["1"])
    with pytest.raises(MlcError, match="seeds"):
        check_scene_dynamic_multi(sc, seeds=0)
    with pytest.raises(MlcError, match="kT"):
        check_scene_dynamic_multi(sc, kT=-1.0)
    sc.truth_table = None
    with pytest.raises(MlcError, match="no truth table"):
        check_scene_dynamic_multi(sc)


def test_signal_time_of_one_mode_is_its_relaxation_time():
    """Two bodies and one muscle: one restoring mode, so the mean step time of the probe is
    that mode's relaxation time, 1/(2k/gamma)."""
    sc = _points(2, 0.5, 1.0)
    assert signal_time(sc, "0", "1") == pytest.approx(relaxation_time(sc), rel=1e-6)
    assert signal_time(sc, "1", "1") == 0.0                  # no switch, no signal


def test_signal_time_of_a_chain_is_pi2_over_8_of_tau():
    """Theory: a line diffusing from a step at one end answers at the other with
    1 - sum_n (4/pi) (-1)^n/(2n+1) exp(-(2n+1)^2 t/tau), whose integral is tau (4/pi) (pi^3/32)
    = (pi^2/8) tau.  A 10-unit connector chain is such a line."""
    sc = chain_scene(10, "contract")
    assert signal_time(sc, "0", "1") / relaxation_time(sc) == pytest.approx(np.pi ** 2 / 8, rel=0.01)


def test_signal_time_against_the_integrator():
    """Independent check by the integrator: at kT = 0 the far end of a 5-unit chain whose
    muscle switches by 1 % of its stroke (the linear regime) has a remaining response
    1 - a(t)/a(inf) whose integral is the predicted mean time."""
    sc = chain_scene(5, "contract")
    for m in sc.muscles:
        m.actuated = m.rest + 0.01 * (m.actuated - m.rest)
    T = signal_time(sc, "0", "1")
    sim = Simulation(sc, {"a": Drive.constant(1)}, SimOptions(scheme="stiff", kT=0.0, dt=0.01))
    res = sim.run(12 * T, record_interval=0.01, quiet=True)
    a = res.probes["out"]
    rem = (a[-1] - a) / (a[-1] - a[0])
    measured = float(np.sum(0.5 * (rem[1:] + rem[:-1]) * np.diff(res.times)))
    assert measured == pytest.approx(T, rel=0.03)


def test_a_large_scene_uses_the_signal_time(monkeypatch):
    """Above DENSE_MAX degrees of freedom (a circuit) the time floor comes from signal_time,
    not from the eigensolver, and a given tau is used as given."""
    import mlc.verify.dynamic as dyn

    sc = chain_scene(3, "expand")
    monkeypatch.setattr(dyn, "DENSE_MAX", 6)

    def boom(*a, **k):
        raise AssertionError("relaxation_time called")
    monkeypatch.setattr(dyn, "relaxation_time", boom)
    rest, row = dyn.check_scene_dynamic_multi(sc, 1e-5, [0], progress=False)
    assert row["ok"] and row["tau"] == pytest.approx(signal_time(sc, "0", "1"), rel=0.2)
    assert row["relax_time"] >= 3 * signal_time(sc, "0", "1")
    # the rest row has no switch: it is held to the slowest row's time, and relaxes
    assert rest["state"] == "0" and rest["ok"] and rest["tau"] == pytest.approx(signal_time(sc, "0", "1"))
    only_rest = dyn.check_scene_dynamic_multi(sc, 1e-5, [0], rows=["0"], progress=False)[0]
    assert only_rest["ok"] and only_rest["tau"] == rest["tau"]
    given = dyn.check_scene_dynamic_multi(sc, 1e-5, [0], rows=["1"], progress=False, tau=0.5, dt=0.02)[0]
    assert given["ok"] and given["tau"] == 0.5
    # the step: a circuit's default (DT_LARGE), or the one given; a small scene keeps DT
    assert row["dt"] == rest["dt"] == dyn.DT_LARGE["stiff"] != dyn.DT["stiff"] and given["dt"] == 0.02
    monkeypatch.setattr(dyn, "DENSE_MAX", 1800)
    small = dyn.check_scene_dynamic_multi(sc, 1e-5, [0], rows=["1"], progress=False, tau=0.5)[0]
    assert small["dt"] == dyn.DT["stiff"]


def test_circuit_verify_takes_tau_and_dt():
    from mlc.verify.circuit import verify_dynamic

    rep = verify_dynamic(chain_scene(2, "expand"), ["1"], seeds=1, tau=0.3, dt=0.02, progress=False)
    assert rep.ok and rep.params["tau"] == 0.3 and rep.params["dt"] == 0.02
    assert all(e["tau"] == 0.3 for e in rep.entries)


def test_the_bar_moves_within_one_long_run(monkeypatch):
    """One row and one seed is one item: the bar must still move (and give an ETA) while
    that run goes on, by the time run over the time it usually takes (issue 9: a progress
    bar with ETA on every run longer than a few seconds)."""
    import io

    import mlc.io.progress as P
    s = io.StringIO()
    lines = []

    class Spy(P.Progress):
        def __init__(self, label, total=None, expect=None, show=None, delay=2.0, stream=None):
            super().__init__(label, total, expect, show, 0.0, s)

        def update(self, done):
            super().update(done)
            lines.append((done, self.line()))

    monkeypatch.setattr(P, "Progress", Spy)
    sc = gate_scene("NAND", "expand")
    rows = check_scene_dynamic_multi(sc, kT=1e-5, seeds=1, rows=["11"], progress=True)
    assert rows[0]["ok"]
    fractions = [d for d, _ in lines if 0 < d < 1]
    assert len(fractions) >= 2 and fractions == sorted(fractions) and max(fractions) <= 0.95
    assert lines[-1][0] == 1 and "1/1" in lines[-1][1]
    mids = [t for d, t in lines if 0 < d < 1]
    assert all("0/1" in t for t in mids)                                # whole items counted
    assert mids[-1].split("[")[1].count("#") == int(24 * fractions[-1])  # the bar moved
    assert any("ETA     ? s" not in t for t in mids)                    # a finite ETA mid-run


def test_fractional_progress_shows_whole_items():
    import io

    from mlc.io.progress import Progress
    s = io.StringIO()
    bar = Progress("rows", total=2, show=True, delay=0.0, stream=s)
    bar.update(1.5)
    line = bar.line()
    assert "1/2" in line and line.count("#") == 18 and "ETA" in line


def test_euler_on_a_stiff_scene_warns_before_the_run(monkeypatch, capsys):
    """A run of more than SLOW_STEPS Euler steps (a circuit with 100 k0 joints: ~1e8 a row)
    says so before it starts, with the fix; silent callers (progress=False) get no line."""
    import mlc.verify.dynamic as D
    sc = gate_scene("NAND", "expand")
    monkeypatch.setattr(D, "SLOW_STEPS", 10.0)        # this gate's row takes more than 10 steps
    check_scene_dynamic_multi(sc, kT=1e-5, seeds=1, rows=["00"], scheme="euler", progress=False)
    assert capsys.readouterr().err == ""
    check_scene_dynamic_multi(sc, kT=1e-5, seeds=1, rows=["00", "11"], scheme="euler", progress=None)
    err = capsys.readouterr().err
    assert err.count("mlc: warning: --scheme euler") == 1 and "use --scheme stiff" in err
    monkeypatch.setattr(D, "SLOW_STEPS", 1e8)
    check_scene_dynamic_multi(sc, kT=1e-5, seeds=1, rows=["00"], scheme="euler", progress=None)
    assert "warning" not in capsys.readouterr().err
