"""The bundled Brownian-dynamics integrator: physics, schemes, determinism, outputs, CLI."""
import json

import numpy as np
import pytest

from mlc.cli import main
from mlc.errors import MlcError
from mlc.scene.io import write_scene
from mlc.scene.model import Body, Box, Scene
from mlc.sim import kernels as K
from mlc.sim.drive import Drive, pack_drives
from mlc.sim.integrator import SimOptions, Simulation, simulate
from mlc.sim.testscenes import chain_scene, lever_scene, tongs_scene


def free_bodies(n, spacing=1.0):
    bodies = [Body(f"f{i}", np.array([spacing * (i % 20), spacing * (i // 20), 0.0]), np.array([1.0, 0, 0, 0]),
                   [Box(np.array([0.5, 0.5, 0.01]))], {"c": np.zeros(3)}) for i in range(n)]
    return Scene("free", bodies).check()


# -- forces ---------------------------------------------------------------------------------

def _energy(sim):
    """Total bond + muscle + WCA energy (numpy, for the finite-difference check)."""
    sim._eval()
    ws = sim.ws
    d = ws[sim.sp_j] - ws[sim.sp_i]
    dist = np.linalg.norm(d, axis=1)
    rest = sim.sp_rest0 + np.where(sim.sp_inp >= 0, sim.uval[np.maximum(sim.sp_inp, 0)], 0) * (sim.sp_rest1 - sim.sp_rest0)
    e = np.maximum(0, np.abs(dist - rest) - sim.sp_tol)
    return 0.5 * np.sum(sim.sp_k * e**2)


def test_forces_and_torques_are_minus_energy_gradient():
    sc = tongs_scene(2)
    sim = Simulation(sc, {"a": 1}, SimOptions(kT=0, wca_eps=0))
    rng = np.random.default_rng(0)
    sim.pos += 0.05 * rng.standard_normal(sim.pos.shape)
    sim._eval()
    F, T = sim.F.copy(), sim.T.copy()
    h = 1e-6
    for b in range(sim.N):
        for c in range(3):
            p0 = sim.pos.copy()
            sim.pos[b, c] += h
            ep = _energy(sim)
            sim.pos[:] = p0
            sim.pos[b, c] -= h
            em = _energy(sim)
            sim.pos[:] = p0
            assert F[b, c] == pytest.approx(-(ep - em) / (2 * h), abs=1e-6)
            q0 = sim.quat.copy()
            w = np.zeros(3)
            w[c] = h
            sim.quat[b] = K.quat_exp_mul(*w, *q0[b])
            ep = _energy(sim)
            sim.quat[b] = K.quat_exp_mul(*(-w), *q0[b])
            em = _energy(sim)
            sim.quat[:] = q0
            assert T[b, c] == pytest.approx(-(ep - em) / (2 * h), abs=1e-6)


def test_wca_force_and_exclusion():
    sc = free_bodies(2)
    sim = Simulation(sc, None, SimOptions(kT=0))
    sim.pos[1] = [0.15, 0, 0]          # inside rc = 0.2: repulsive, along the line of centres
    sim._eval()
    r = 0.15
    s = 0.2
    f = 24e-4 * (2 * (s / r) ** 12 - (s / r) ** 6) / r
    assert sim.F[1, 0] == pytest.approx(f) and sim.F[0, 0] == pytest.approx(-f)
    assert sim.mon[2] == pytest.approx(0.15)
    sim.pos[1] = [0.25, 0, 0]          # beyond the cutoff
    sim._eval()
    assert np.all(sim.F == 0)


def test_flat_bottom_tolerance_and_finite_rest():
    sc = chain_scene(2, universal=True, tol=0.1)
    sim = Simulation(sc, None, SimOptions(kT=0, wca_eps=0))
    sim.pos[1, 0] += 0.05               # within the tolerance: no force
    sim._eval()
    assert np.all(sim.F == 0)
    sim.pos[1, 0] += 0.1                # 0.15 apart: force k (0.15 - 0.1) pulling back
    sim._eval()
    assert sim.F[1, 0] == pytest.approx(-0.05) and sim.F[0, 0] == pytest.approx(0.05)


# -- drives -----------------------------------------------------------------------------------

def test_drives_match_in_kernel_and_python():
    drives = [Drive.constant(0.3), Drive.step(1.0, 0, 1), Drive.square(2.0, 0.25, 0.5),
              Drive.table([0, 1, 3], [0, 1, 0.5]), Drive.parse("square:1:0.5"), Drive.parse("table:0=0,2=1")]
    kind, par, tt, tv = pack_drives(drives, 1000.0)
    out = np.zeros(len(drives))
    for t in np.linspace(-0.5, 5, 57):
        K.drive_values(t * 1000.0, kind, par, tt, tv, out)
        assert out == pytest.approx([d.value(t) for d in drives])


@pytest.mark.parametrize("bad", ["step", "square:0", "table:1=0,0=1", "nope:1", "x"])
def test_bad_drive_text(bad):
    with pytest.raises(MlcError):
        Drive.parse(bad)


def test_muscle_follows_step_drive():
    sc = lever_scene(2.0)
    sim = Simulation(sc, {"a": Drive.step(0.5)}, SimOptions(kT=0, scheme="stiff", dt=0.005))
    res = sim.run(1.0, record_interval=0.05)
    span = res.probes["span"]
    t = res.times
    assert np.all(np.abs(span[t < 0.45] - sc.probes[0].rest) < 1e-6)
    assert abs(span[-1] - sc.probes[0].actuated) < 2e-3


# -- schemes -----------------------------------------------------------------------------------

def test_schemes_agree_at_kT0_and_stiff_converges():
    sc = tongs_scene(3)
    ref = simulate(sc, 0.5, {"a": 1}, SimOptions(kT=0, scheme="euler", dt=2e-5), record_interval=0.01)
    errs = []
    for dt in (0.004, 0.001):
        r = simulate(sc, 0.5, {"a": 1}, SimOptions(kT=0, scheme="stiff", dt=dt), record_interval=0.01)
        errs.append(np.max(np.abs(np.interp(ref.times, r.times, r.probes["span"]) - ref.probes["span"])))
    assert errs[1] < 0.5 * errs[0]
    assert errs[1] < 5e-3
    assert abs(r.probes["span"][-1] - ref.probes["span"][-1]) < 1e-4


@pytest.mark.parametrize("scheme", ["euler", "stiff"])
def test_free_diffusion_coefficient(scheme):
    # D = kT/gamma per coordinate: <dx^2> = 2 kT t / gamma
    kT, T = 1e-3, 0.2
    sim = Simulation(free_bodies(400, spacing=2.0), None,
                     SimOptions(kT=kT, scheme=scheme, dt=0.002 if scheme == "stiff" else 1e-3, seed=3))
    p0 = sim.pos.copy()
    sim.run(T)
    msd = np.mean((sim.pos - p0) ** 2)
    assert msd / (2 * kT * T * 1000) == pytest.approx(1.0, abs=0.1)
    assert np.allclose(sim.quat, [1, 0, 0, 0])          # no torque, no rotational noise


def test_rotational_noise_option():
    sim = Simulation(free_bodies(200, 2.0), None, SimOptions(kT=1e-3, scheme="euler", dt=1e-3, rot_noise=True))
    sim.run(0.05)
    ang = 2 * np.arccos(np.clip(np.abs(sim.quat[:, 0]), 0, 1))
    # <theta^2> = 6 kT t / gamma_r for small angles
    assert np.mean(ang**2) / (6e-3 * 50) == pytest.approx(1.0, abs=0.15)
    assert np.allclose(np.linalg.norm(sim.quat, axis=1), 1.0)


def test_same_seed_same_trajectory_and_chunking_invariance():
    sc = chain_scene(6)
    a = Simulation(sc, None, SimOptions(kT=1e-4, seed=7, scheme="euler", dt=1e-4))
    a.run(0.1)
    b = Simulation(sc, None, SimOptions(kT=1e-4, seed=7, scheme="euler", dt=1e-4))
    b.run(0.05)
    b.run(0.05)
    assert np.array_equal(a.pos, b.pos) and np.array_equal(a.quat, b.quat)
    c = Simulation(sc, None, SimOptions(kT=1e-4, seed=8, scheme="euler", dt=1e-4))
    c.run(0.1)
    assert not np.allclose(a.pos, c.pos)
    s1 = simulate(sc, 0.2, None, SimOptions(kT=1e-4, seed=7, dt=0.01))
    s2 = simulate(sc, 0.2, None, SimOptions(kT=1e-4, seed=7, dt=0.01))
    assert np.array_equal(s1.pos, s2.pos)
    # the stiff scheme too, chunked differently (the spectral estimate and the last substep
    # persist between calls; the noise is keyed by the global step)
    s3 = Simulation(sc, None, SimOptions(kT=1e-4, seed=7, dt=0.01))
    for _ in range(4):
        s3.run(0.05)
    s4 = Simulation(sc, None, SimOptions(kT=1e-4, seed=7, dt=0.01))
    s4.advance(3)
    s4.advance(17)
    assert np.array_equal(s3.pos, s4.pos) and np.array_equal(s3.quat, s4.quat)


def test_record_times_do_not_depend_on_chunking(monkeypatch):
    # run() sizes its compiled chunks by wall time; the record times must be the exact
    # multiples of the step, whatever the chunks (they used to be a per-chunk running sum,
    # which differed in the last bits between a busy and an idle machine)
    sc = chain_scene(4)

    def times(fake_clock):
        if fake_clock:  # every chunk seems to take 1 s: chunks shrink to a step or two
            ticks = iter(range(10**6))
            monkeypatch.setattr("mlc.sim.integrator._time.perf_counter", lambda: float(next(ticks)))
        sim = Simulation(sc, None, SimOptions(kT=1e-4, seed=3, scheme="euler", dt=3e-5))
        res = sim.run(0.0123, record_interval=3e-4, quiet=True)
        monkeypatch.undo()
        return res.times, res.pos

    (ta, pa), (tb, pb) = times(False), times(True)
    assert np.array_equal(pa, pb)
    assert len(ta) == len(tb) and np.array_equal(ta, tb)
    assert np.max(np.abs(ta - np.arange(len(ta)) * 3e-4)) < 1e-15 and ta[-1] == 0.0123


def test_orientations_stay_unit():
    res = simulate(tongs_scene(4), 0.5, {"a": 1}, SimOptions(kT=1e-5, dt=0.01, seed=2))
    assert np.allclose(np.linalg.norm(res.quat, axis=1), 1.0, atol=1e-12)


def test_rng_is_standard_normal():
    z = np.array([K.gauss2(np.uint64(5), np.uint64(i), np.uint64(j)) for i in range(200) for j in range(50)]).ravel()
    assert abs(z.mean()) < 0.03 and abs(z.std() - 1) < 0.03
    assert abs(np.mean(z**4) - 3) < 0.15


# -- outputs and CLI ----------------------------------------------------------------------------

def test_cli_simulate_outputs(tmp_path, capsys):
    import gsd.hoomd
    from mlc.gates.library import gate_scene

    scene_path = tmp_path / "nand.yaml"
    write_scene(gate_scene("NAND"), scene_path)
    out, probes = tmp_path / "t.gsd", tmp_path / "p.csv"
    rc = main(["simulate", str(scene_path), "--time", "1", "--set", "a=1", "--set", "b=1", "--seed", "3",
               "--out", str(out), "--probes", str(probes), "--json", "--frames", "10"])
    assert rc == 0
    js = json.loads(capsys.readouterr().out)
    assert set(js) >= {"probes", "steps", "wall", "scheme", "dt"}
    assert abs(js["probes"]["out"] - 1.0) < 0.05            # NAND(1,1) = 0: rest length
    with gsd.hoomd.open(str(out)) as f:
        assert 5 <= len(f) <= 10                      # at most --frames, evenly spaced, the last is final
        assert f[-1].log["mlc/time_t0"][0] == pytest.approx(1.0)
        fr = f[0]
        assert fr.particles.N == 8 and fr.particles.type_shapes[0]["type"] == "Mesh"
        assert len(fr.particles.type_shapes) == len(fr.particles.types)
        assert np.allclose(np.linalg.norm(f[-1].particles.orientation, axis=1), 1, atol=1e-6)
    lines = probes.read_text().splitlines()
    assert lines[0] == "time_t0,out" and len(lines) > 10
    z = np.load(tmp_path / "p.npz")
    assert z["time"][-1] == pytest.approx(1.0) and z["out"][-1] == pytest.approx(js["probes"]["out"])


def test_cli_errors_are_one_line(tmp_path, capsys):
    from mlc.gates.library import gate_scene

    p = tmp_path / "g.yaml"
    write_scene(gate_scene("AND"), p)
    assert main(["simulate", str(p), "--time", "1", "--set", "z=1"]) == 2
    assert "no input named 'z'" in capsys.readouterr().err
    assert main(["simulate", str(p), "--time", "1", "--set", "a=bogus"]) == 2
    assert main(["simulate", str(p), "--time", "-1"]) == 2
    err = capsys.readouterr().err
    assert "--time" in err and "Traceback" not in err
    bad = tmp_path / "bad.yaml"
    bad.write_text(p.read_text().replace("orientation: [1.0, 0.0, 0.0, 0.0]", "orientation: [1.0, 1.0, 0.0, 0.0]", 1))
    assert main(["simulate", str(bad), "--time", "1"]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:" in err and "unit quaternion" in err


def test_progress_bar_only_on_tty(capsys):
    simulate(chain_scene(3), 0.01, None, SimOptions(scheme="euler", dt=1e-4))
    assert capsys.readouterr().err == ""


def test_parallel_kernels_match_serial():
    sc = chain_scene(40)
    a = simulate(sc, 0.02, None, SimOptions(kT=1e-4, seed=1, scheme="euler", dt=1e-4, threads=1))
    b = simulate(sc, 0.02, None, SimOptions(kT=1e-4, seed=1, scheme="euler", dt=1e-4, threads=2,
                                            parallel_min_bodies=0))
    assert np.allclose(a.pos, b.pos, atol=1e-12, rtol=0)
    sc = tongs_scene(3)
    a = simulate(sc, 0.1, {"a": 1}, SimOptions(kT=1e-5, seed=1, dt=0.01))
    b = simulate(sc, 0.1, {"a": 1}, SimOptions(kT=1e-5, seed=1, dt=0.01, threads=2, parallel_min_bodies=0))
    assert np.array_equal(a.pos, b.pos)


def test_progress_bar_draws_eta_for_long_runs(capsys):
    from mlc.sim.integrator import _Progress

    bar = _Progress(100, True)
    bar.update(10)                      # a short run so far: nothing drawn yet
    assert capsys.readouterr().err == ""
    bar.t0 -= 10.0                      # pretend 10 s have passed
    bar.update(50)
    bar.close()
    err = capsys.readouterr().err
    assert "ETA" in err and "50.0%" in err and err.endswith("\n")


def test_gsd_mesh_faces_point_outward():
    from mlc.gates.library import gate_scene
    from mlc.sim.output import body_mesh

    for body in gate_scene("NAND").bodies:          # bent levers: two boxes per body
        v, faces = body_mesh(body)
        for k in range(0, len(faces), 12):
            box = v[faces[k][0] // 8 * 8: faces[k][0] // 8 * 8 + 8]
            centre = box.mean(axis=0)
            for a, b, c in faces[k:k + 12]:
                n = np.cross(v[b] - v[a], v[c] - v[a])
                assert np.dot(n, (v[a] + v[b] + v[c]) / 3 - centre) > 0


def test_neighbour_list_overflow_grows_and_redoes_the_work():
    bodies = [Body(f"f{i}", np.array([0.15 * i, 0.01 * i * i, 0.0]), np.array([1.0, 0, 0, 0]),
                   [Box(np.array([0.5, 0.5, 0.01]))], {}) for i in range(6)]
    sc = Scene("row", bodies).check()
    ref = Simulation(sc, None, SimOptions(kT=0))
    ref._eval()
    small = Simulation(sc, None, SimOptions(kT=0))
    small.nl = np.zeros(1, np.int64)           # far too small: the evaluation stops, grows it, redoes
    small._eval()
    assert np.allclose(small.F, ref.F) and small.nl.shape[0] >= 2 * 8 and small.nlstate[0] == 1
    assert small.nlstate[2] == 0
    # moving a body past half the skin rebuilds the list
    builds = ref.nlstate[1]
    ref.pos[0, 0] -= 0.06
    ref._eval()
    assert ref.nlstate[1] == builds + 1
    # in a run, an overflow redoes the chunk with a larger list: the same trajectory bit for bit
    bodies = [Body(f"f{i}", np.array([0.25 * i, 0.0, 0.0]), np.array([1.0, 0, 0, 0]),
                   [Box(np.array([0.5, 0.5, 0.01]))], {}) for i in range(6)]
    sc = Scene("row", bodies).check()          # neighbours within the list radius 0.3
    for scheme in ("euler", "stiff"):
        dt = 1e-5 if scheme == "euler" else 0.01
        a = Simulation(sc, None, SimOptions(kT=1e-3, seed=2, scheme=scheme, dt=dt))
        b = Simulation(sc, None, SimOptions(kT=1e-3, seed=2, scheme=scheme, dt=dt))
        b.nl = np.zeros(1, np.int64)
        ra, rb = a.run(0.02, record_interval=0.005), b.run(0.02, record_interval=0.005)
        assert b.nl.shape[0] > 1 and np.array_equal(a.pos, b.pos) and np.array_equal(a.quat, b.quat)
        assert np.allclose(ra.times, rb.times, rtol=0, atol=1e-12)


def test_one_neighbour_search_in_the_kernels():
    import inspect

    src = inspect.getsource(K)
    # the cell-block walk (2x2x2 block of cells around a body) exists once: in the list build
    assert src.count("for ix in range(") == 1


# -- run length, refusals, interrupts (issue 14 item 5) -----------------------------------------

def test_last_step_ends_exactly_at_time(tmp_path, capsys):
    from mlc.gates.library import gate_scene

    p = tmp_path / "g.yaml"
    write_scene(gate_scene("AND"), p)
    assert main(["simulate", str(p), "--time", "0.01", "--dt", "0.003", "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["time"] == pytest.approx(0.01, abs=1e-15) and js["steps"] == 4
    res = Simulation(gate_scene("AND"), None, SimOptions(dt=0.3)).run(1.0)
    assert res.time == 1.0 and res.steps == 4 and res.times[-1] == 1.0


@pytest.mark.parametrize("args, words", [
    (["--time", "0.01", "--dt", "1"], "no larger than --time"),
    (["--time", "1", "--dt", "1e6"], "no larger than --time"),
    (["--time", "1", "--dt", "1e-12"], "steps"),
    (["--time", "1", "--record", "-1"], "--record"),
    (["--time", "1", "--record", "nan"], "--record"),
    (["--time", "1", "--threads", "-3"], "--threads"),
    (["--time", "1", "--fluct", "--scheme", "euler"], "--fluct"),
])
def test_cli_refuses_bad_run_lengths(tmp_path, capsys, args, words):
    from mlc.gates.library import gate_scene

    p = tmp_path / "g.yaml"
    write_scene(gate_scene("AND"), p)
    out = tmp_path / "t.gsd"
    assert main(["simulate", str(p), "--out", str(out)] + args) == 2
    err = capsys.readouterr().err
    assert words in err and "Traceback" not in err and not out.exists()


def test_ctrl_c_stops_within_a_second_with_complete_files(tmp_path, capsys):
    import os
    import signal
    import threading
    import time

    import gsd.hoomd

    p = tmp_path / "c.yaml"
    write_scene(chain_scene(30), p)
    out, probes = tmp_path / "t.gsd", tmp_path / "p.csv"
    main(["simulate", str(p), "--time", "0.001", "--scheme", "euler", "--quiet"])      # compile outside the clock
    capsys.readouterr()
    sent = []
    timer = threading.Timer(1.0, lambda: (sent.append(time.perf_counter()), os.kill(os.getpid(), signal.SIGINT)))
    timer.start()
    rc = main(["simulate", str(p), "--time", "1e5", "--dt", "1e-4", "--scheme", "euler", "--out", str(out),
               "--frames", "50", "--probes", str(probes), "--quiet"])
    back = time.perf_counter() - sent[0]
    timer.cancel()
    err = capsys.readouterr().err
    print(f"\nCtrl-C: run returned {back:.2f} s after the signal")
    assert rc == 130 and "interrupted at t =" in err
    assert back < 3.0                           # stops between chunks of ~0.25 s (not after 1e9 steps)
    with gsd.hoomd.open(str(out)) as f:
        assert len(f) >= 1 and np.all(np.isfinite(f[-1].particles.position))
    assert np.load(tmp_path / "p.npz")["time"][-1] > 0


def test_fluct_mode_reported_in_json(tmp_path, capsys):
    from mlc.gates.library import gate_scene

    p = tmp_path / "g.yaml"
    write_scene(gate_scene("NAND"), p)
    assert main(["simulate", str(p), "--time", "0.2", "--fluct", "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["fluct"] and js["variance_bias"]["ratio_min"] == 1.0 and js["warnings"] == []
    assert main(["simulate", str(p), "--time", "0.2", "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["variance_bias"]["ratio_min"] < 0.5           # plain SK-ROCK at dt = 0.05 t0: biased modes
    assert main(["simulate", str(p), "--time", "0.5", "--kT", "1", "--json"]) == 0
    cap = capsys.readouterr()
    js = json.loads(cap.out)
    assert js["warnings"] and "not bits" in cap.err
