"""A small robot end to end through the CLI (docs/robot.md): one input folds a two-unit
skeleton into a hook.  mlc compile --robot writes one scene that the existing scene tools
load; mlc verify reads the shape from the body poses and fails when the expected pose is
altered; mlc robot draws the shapes and writes a fold as GIF and GSD."""
import json
from pathlib import Path

import numpy as np
import pytest

from mlc.cli import main
from mlc.scene.io import dump_scene, load_scene

@pytest.fixture(scope="module")
def robot(tmp_path_factory, tiny_robot_yaml):
    d = tmp_path_factory.mktemp("tiny")
    (d / "tiny.robot.yaml").write_text(tiny_robot_yaml)
    rc = main(["compile", "-e", "u1_up = a; u2_dn = a", "--robot", str(d / "tiny.robot.yaml"), "-o", str(d / "out")])
    assert rc == 0
    return d


def test_one_scene_with_circuit_skeleton_and_couplings(robot):
    sc = load_scene(robot / "out" / "robot.yaml")
    names = [b.name for b in sc.bodies]
    assert sc.meta["element"] == "robot"
    assert {"skel_u0", "skel_j1", "skel_u1", "skel_j2", "skel_u2"} <= set(names)
    assert any(n.startswith("rc_u1_up_") for n in names) and any(n.startswith("rc_u2_dn_") for n in names)
    # the skeleton hangs on the chains only: every coupling ends in two universal joints on lever sites
    ends = [b for b in sc.bonds if b.name.startswith("rc_") and "_end_" in b.name]
    assert len(ends) == 4 and all(b.kind == "universal" and ".lever_" in b.b for b in ends)
    assert [p.name for p in sc.probes if p.name.startswith("dof_")] == ["dof_u1_up", "dof_u2_dn"]


def test_static_verify_reads_the_shapes(robot, capsys):
    rc = main(["verify", str(robot / "out" / "robot.yaml"), "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 0 and rep["ok"]
    rows = {r["state"]: r for r in rep["rows"]}
    assert rows["1"]["shape_read"] == "hook" and rows["1"]["turns_expected"] == [90, -90]
    assert np.allclose(rows["1"]["turns_read"], [90, -90], atol=0.01)
    assert rows["0"]["cells_read"] == [[1, 0], [2, 0]] and rows["1"]["cells_read"] == [[0, 1], [1, 1]]
    assert rows["1"]["max_dof_error_deg"] < 0.01


def test_static_verify_with_jobs_gives_the_same_report(robot, capsys):
    """--jobs 2: the rows in forked processes (mlc.verify.circuit.map_rows), the same report."""
    import multiprocessing
    if "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork here: rows run one at a time whatever --jobs says")
    reps = []
    for jobs in ("1", "2"):
        assert main(["verify", str(robot / "out" / "robot.yaml"), "--jobs", jobs, "--json"]) == 0
        rep = json.loads(capsys.readouterr().out)
        rep.pop("seconds")
        for row in rep["rows"]:
            row.pop("seconds")
        reps.append(rep)
    assert len(reps[0]["rows"]) == 2 and reps[1] == reps[0]


def test_altered_expected_pose_is_a_wrong_shape(robot, capsys):
    sc = load_scene(robot / "out" / "robot.yaml")
    sc.meta["robot"]["poses"]["1"]["turns"] = [90, 90]
    sc.meta["robot"]["poses"]["1"]["shape"] = "U"
    bad = robot / "altered.yaml"
    bad.write_text(dump_scene(sc))
    rc = main(["verify", str(bad)])
    out = capsys.readouterr().out
    assert rc == 1
    assert "WRONG: row 1: the skeleton folded into ?ud (turns [90, -90], cells [[0, 1], [1, 1]]), expected U" in out


def test_dynamic_verify_folds(robot, capsys):
    # Brownian dynamics at kT = 1e-5 from rest until relaxed (tau ~ 100 t0 here): the shape
    # from the final poses; the DOF angles fluctuate thermally by a few degrees (docs/robot.md)
    rc = main(["verify", str(robot / "out" / "robot.yaml"), "--dynamic", "--seeds", "1", "--rows", "1", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 0, rep["rows"]
    r1 = rep["rows"][0]
    assert r1["state"] == "1" and r1["relaxed"] and r1["shape_read"] == "hook"
    assert r1["max_dof_mean_error_rad"] < 0.2 and r1["max_dof_error_rad"] < 0.3
    # at the robot defaults (docs/robot.md 3.4): the step and drift bound the report says it ran
    from mlc.robot.verify import ROBOT_DISP_ACC, ROBOT_DT, ROBOT_SCHEME
    assert rep["params"]["dt"] == ROBOT_DT and rep["params"]["disp_acc"] == ROBOT_DISP_ACC
    assert rep["params"]["scheme"] == ROBOT_SCHEME == "implicit"


def test_dynamic_verify_folds_with_the_stiff_scheme_too(robot, capsys):
    # the robot's default integrator is the linearly implicit scheme (ROBOT_SCHEME, above);
    # SK-ROCK at the same step and drift bound folds it the same way
    rc = main(["verify", str(robot / "out" / "robot.yaml"), "--dynamic", "--seeds", "1", "--rows", "1", "--json",
               "--scheme", "stiff"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 0, rep["rows"]
    r1 = rep["rows"][0]
    assert r1["state"] == "1" and r1["relaxed"] and r1["shape_read"] == "hook"
    assert r1["max_dof_mean_error_rad"] < 0.2 and r1["max_dof_error_rad"] < 0.3
    from mlc.robot.verify import ROBOT_DISP_ACC, ROBOT_DT
    assert rep["params"]["scheme"] == "stiff"
    assert rep["params"]["dt"] == ROBOT_DT and rep["params"]["disp_acc"] == ROBOT_DISP_ACC


def test_the_implicit_scheme_takes_short_steps_while_a_fold_is_fast(robot, monkeypatch):
    """run_fold steps the implicit scheme at ROBOT_FOLD_DT over a fold's first ROBOT_FOLD_TIME
    t0 and at the run's dt after (and leaves that dt set); the stiff scheme at its dt throughout.
    It pays: at kT = 0 the tiny robot's fold at 20 t0, against the stiff scheme's (which the
    Euler reference confirms, benchmarks/robot_euler_reference.py), lags by tens of degrees at
    ROBOT_DT throughout (26 deg, session 49, docs/robot.md 3.4) and by less than half of that
    with the short steps."""
    import mlc.robot.verify as V
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation
    sc = load_scene(robot / "out" / "robot.yaml")

    def fold(scheme, t_end, kT=0.0):
        # stretch_joint 0.25 as benchmarks/robot_euler_reference.py: at kT = 0 a joint's bound is c_0 alone
        sim = Simulation(sc, {"a": Drive.constant(1)}, SimOptions(scheme=scheme, kT=kT, seed=0, dt=V.ROBOT_DT,
                                                                   disp_acc=V.ROBOT_DISP_ACC, stretch_joint=0.25))
        steps, run = [], sim.run

        def spy(time, **kw):
            steps.append((round(sim.t / sim.t_unit, 6), sim.dt))
            return run(time, **kw)
        sim.run = spy
        V.run_fold(sim, sc, "1", kT, 100.0, t_end)          # tau 100 t0: windows of 5 t0, no relaxation before 300
        assert sim.dt == V.ROBOT_DT
        return np.array(V.dof_angles(sc, sim.pos, sim.quat)), steps

    ref, steps = fold("stiff", 20.0)
    assert [d for _, d in steps] == [V.ROBOT_DT] * 4
    fine, steps = fold("implicit", 20.0)
    assert V.ROBOT_FOLD_TIME >= 20.0 and [d for _, d in steps] == [V.ROBOT_FOLD_DT] * 4
    monkeypatch.setattr(V, "ROBOT_FOLD_TIME", 0.0)
    coarse, steps = fold("implicit", 20.0)
    assert [d for _, d in steps] == [V.ROBOT_DT] * 4
    lag_fine, lag_coarse = np.max(np.abs(fine - ref)), np.max(np.abs(coarse - ref))
    assert lag_coarse > 10.0 and lag_fine < 0.5 * lag_coarse, (lag_fine, lag_coarse)
    # the switch: short steps in the windows that start before ROBOT_FOLD_TIME, dt from there on
    monkeypatch.setattr(V, "ROBOT_FOLD_TIME", 5.0)
    _, steps = fold("implicit", 15.0, kT=1e-5)
    assert steps == [(0.0, V.ROBOT_FOLD_DT), (5.0, V.ROBOT_DT), (10.0, V.ROBOT_DT)]


def test_pictures_and_trajectory(robot, capsys):
    out = robot / "out"
    assert main(["robot", "shapes", str(out / "robot.yaml"), "-o", str(out / "shapes.png")]) == 0
    assert (out / "shapes.png").read_bytes()[:4] == b"\x89PNG"
    rc = main(["robot", "fold", str(out / "robot.yaml"), "--row", "1", "--time", "3", "--frames", "4",
               "--gif", str(out / "fold.gif"), "--gsd", str(out / "fold.gsd")])
    assert rc == 0, capsys.readouterr()
    assert (out / "fold.gif").read_bytes()[:3] == b"GIF"
    import gsd.hoomd
    with gsd.hoomd.open(str(out / "fold.gsd"), "r") as f:
        assert len(f) == 4 and f[0].particles.N == len(load_scene(out / "robot.yaml").bodies)
        assert f[0].particles.type_shapes[0]["type"] == "Mesh"


def test_existing_scene_tools_load_the_robot(robot, capsys):
    out = robot / "out"
    assert main(["simulate", str(out / "robot.yaml"), "--time", "0.2", "--set", "a=1", "--quiet"]) == 0
    capsys.readouterr()


def _joint_energy(sc, dm, t_deg, state, coupling=True):
    """Energy (k0 sigma^2) of the bonds between a DOF's two bodies (and its coupling pair
    as one spring at the output's length) with the second body turned rigidly by t_deg
    about the hinge, from the scene's sites alone (flat-bottom law of the kernel)."""
    import math
    b1, b2 = dm["bodies"]
    O = sc.site_world(f"{b1}.h_{dm['name']}_0")
    sgn = 1.0 if dm["side"] == "up" else -1.0
    a = sgn * math.radians(t_deg)
    R = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1.0]])
    springs = [(b.a, b.b, b.k, b.rest, b.tolerance) for b in sc.bonds
               if {b.a.split(".")[0], b.b.split(".")[0]} == {b1, b2}]
    if coupling and dm["coupling"] == "lever":
        g = sc.meta["robot"]["dof_geometry"]
        springs.append((f"{b1}.lever_{dm['name']}", f"{b2}.lever_{dm['name']}", 1.0,
                        (g["actuated"] if state else g["rest"]) / g["gain"], 0.0))
    U = 0.0
    for sa, sb, k, rest, tol in springs:
        pa, pb = sc.site_world(sa), sc.site_world(sb)
        pa = O + R @ (pa - O) if sa.startswith(b2 + ".") else pa
        pb = O + R @ (pb - O) if sb.startswith(b2 + ".") else pb
        U += 0.5 * k * max(0.0, abs(float(np.linalg.norm(pb - pa)) - rest) - tol) ** 2
    return U


def test_joint_stops_close_the_mirror_branches(robot):
    # docs/robot.md 2.3: without stops the lever triangle's actuated pair length recurs at a
    # 180-degree turn (barrier k0/2 (p + q - L1)^2 = 0.0035); the two stop bonds leave the
    # joint free over [-15, 105] degrees and put >= 0.5 k0 sigma^2 at 180 and at -90
    sc = load_scene(robot / "out" / "robot.yaml")
    dm = next(d for d in sc.meta["robot"]["dofs"] if d["name"] == "u1_up")
    assert dm["coupling"] == "lever"
    stops = [b for b in sc.bonds if b.name.startswith("skel_stop_") and b.name.endswith("_u1_up")]
    assert len(stops) == 2 and all(b.tolerance > 0 for b in stops)
    free = [_joint_energy(sc, dm, t, 0, coupling=False) for t in (-14, 0, 45, 90, 104)]
    assert max(free) < 1e-20                      # hinge and stops alone: free in the band
    assert _joint_energy(sc, dm, 90, 1) < 1e-20 and _joint_energy(sc, dm, 0, 0) < 1e-20
    assert _joint_energy(sc, dm, 180, 1) > 0.5 and _joint_energy(sc, dm, -90, 0) > 0.5
    scan = [_joint_energy(sc, dm, t, 1) for t in np.arange(90, 181, 2.0)]
    assert scan[-1] == max(scan)                   # climbs all the way from the target to 180
    # the same bodies without the stops: the mirror minimum at 180 degrees is back
    sc.bonds = [b for b in sc.bonds if not b.name.startswith("skel_stop_")]
    assert _joint_energy(sc, dm, 180, 1) < 1e-12


@pytest.mark.parametrize("opts, words", [
    (["--tau", "0"], "--tau must be a finite time > 0"),
    (["--tau", "-5"], "--tau must be a finite time > 0"),
    (["--tau", "nan"], "--tau must be a finite time > 0"),
    (["--dt", "inf"], "--dt must be a finite time > 0"),
    (["--dt", "0"], "--dt must be a finite time > 0"),
])
def test_verify_tau_dt_are_validated(robot, capsys, opts, words):
    rc = main(["verify", str(robot / "out" / "robot.yaml"), "--dynamic", *opts])
    err = capsys.readouterr().err
    assert rc == 2 and words in err and "Traceback" not in err


def test_verify_tau_dt_need_dynamic(robot, capsys):
    rc = main(["verify", str(robot / "out" / "robot.yaml"), "--tau", "100"])
    err = capsys.readouterr().err
    assert rc == 2 and "--tau needs --dynamic" in err
    rc = main(["verify", str(robot / "out" / "circuit.yaml"), "--dt", "0.1"])
    err = capsys.readouterr().err
    assert rc == 2 and "--dt needs --dynamic" in err and "Traceback" not in err


def test_verify_tau_dt_reach_the_robot_run(robot, capsys):
    # given tau and dt are used as given (no relaxation-time computation): the report says so
    rc = main(["verify", str(robot / "out" / "robot.yaml"), "--dynamic", "--seeds", "1", "--rows", "0",
               "--tau", "2", "--dt", "0.1", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 0 and rep["params"]["tau"] == 2.0 and rep["params"]["dt"] == 0.1
    assert rep["rows"][0]["shape_read"] == "I"


def test_dynamic_verify_bar_moves_within_a_fold(robot, monkeypatch):
    """One row and one seed: the bar and its ETA still move during the fold (the time run over
    3 tau), not only when the run ends."""
    import io

    import mlc.io.progress as P
    from mlc.robot.verify import verify_robot_dynamic
    seen = []

    class Spy(P.Progress):
        def __init__(self, label, total=None, expect=None, show=None, delay=2.0, stream=None):
            super().__init__(label, total, expect, True, 0.0, io.StringIO())

        def update(self, done):
            super().update(done)
            seen.append((done, self.line()))

    monkeypatch.setattr(P, "Progress", Spy)
    verify_robot_dynamic(load_scene(robot / "out" / "robot.yaml"), rows=["1"], seeds=1, max_time=20.0)
    mids = [(d, t) for d, t in seen if 0 < d < 1]
    assert len(mids) >= 3 and [d for d, _ in mids] == sorted(d for d, _ in mids)
    assert all("0/1" in t for _, t in mids) and any("ETA     ? s" not in t for _, t in mids)
    assert seen[-1][0] == 1


def test_the_tetris_robot_with_a_muscle_per_lever_folds_every_shape(tmp_path, capsys):
    """The paper's robot with a muscle on every input lever (docs/robot.md 3.4, sessions 46
    and 47): under a quarter of the default build's bodies, u3_up (= y) driven by a muscle of
    y across its own tips instead of a chain, and the static verifier reads I, L, S and O."""
    root = Path(__file__).resolve().parents[1] / "examples"
    out = tmp_path / "r"
    assert main(["compile", str(root / "tetris.tt"), "--robot", str(root / "tetris.robot.yaml"),
                 "--muscle-per-lever", "-o", str(out)]) == 0
    sc = load_scene(out / "robot.yaml")
    assert sc.meta["circuit"]["connector"]["muscle_per_lever"] is True
    assert sc.meta["circuit"]["connector"]["input_outputs"] == {"u3_up": "y"}
    assert len(sc.bodies) < 600 and not any(b.name.startswith(("w_y_", "w_b_")) and "_stub" not in b.name
                                            for b in sc.bodies)
    dofs = {d["name"]: d for d in sc.meta["robot"]["dofs"]}
    assert dofs["u3_up"]["coupling"] == "muscle" and "chain" not in dofs["u3_up"]
    assert not any(b.name.startswith("rc_u3_up") for b in sc.bodies)
    dm = next(m for m in sc.muscles if m.name == "muscle_y_u3_up")
    assert (dm.input, dm.a, dm.b) == ("y", "skel_u2.muscle_u3_up", "skel_j3.muscle_u3_up")
    # the lever arms' gain d0/L0: the muscle's sites are L0/d0 times the tips' distance, in both states
    by = {b.name: b for b in sc.bodies}
    probe = next(p for p in sc.probes if p.name == "dof_u3_up")
    gap = np.linalg.norm(by["skel_u2"].world("muscle_u3_up") - by["skel_j3"].world("muscle_u3_up"))
    tips = np.linalg.norm(by["skel_u2"].world("tip_u3_up") - by["skel_j3"].world("tip_u3_up"))
    assert tips == pytest.approx(probe.rest) and gap == pytest.approx(dm.rest)
    assert dm.actuated / dm.rest == pytest.approx(probe.actuated / probe.rest)
    src = next(m for m in sc.muscles if m.name == "muscle_y")          # the same material as y's source
    assert (dm.rest, dm.actuated, dm.k) == (src.rest, src.actuated, src.k)
    # three gate levers and y's source (it still carries the circuit's output u3_up) and the DOF
    assert sum(m.input == "y" for m in sc.muscles) == 5 and sum(m.input == "b" for m in sc.muscles) == 3
    capsys.readouterr()
    assert main(["verify", str(out / "robot.yaml"), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    rows = {r["state"]: r for r in rep["rows"]}
    assert {s: r["shape_read"] for s, r in rows.items()} == {"00": "I", "01": "L", "10": "S", "11": "O"}
    assert all(r["max_dof_error_deg"] < 0.01 for r in rows.values())


def test_a_muscle_coupling_needs_an_output_that_is_a_circuit_input(tmp_path, capsys):
    """``coupling: muscle`` on a gate's output, or without --muscle-per-lever, is one clear
    message naming the robot file's line (mlc.robot.build), and no robot is written."""
    root = Path(__file__).resolve().parents[1] / "examples"
    text = (root / "tetris.robot.yaml").read_text()
    for line, flags in (("  - {unit: 2, side: up, output: u2_up}", ["--muscle-per-lever"]),
                        ("  - {unit: 3, side: up, output: u3_up}", [])):
        assert line + "\n" in text
        bad = tmp_path / f"bad{len(flags)}.robot.yaml"
        bad.write_text(text.replace(line + "\n", line[:-1] + ", coupling: muscle}\n"))
        out = tmp_path / f"o{len(flags)}"
        capsys.readouterr()
        assert main(["compile", str(root / "tetris.tt"), "--robot", str(bad), "-o", str(out), *flags]) == 2
        err = capsys.readouterr().err
        lineno = bad.read_text().splitlines().index(line[:-1] + ", coupling: muscle}") + 1
        assert f"{bad}:{lineno}" in err and "cannot carry a muscle" in err and "Traceback" not in err
        assert not (out / "robot.yaml").exists()


def test_a_computed_tau_is_the_dense_spectrum_up_to_the_robot_limit(robot, monkeypatch):
    """verify_robot_dynamic(tau="compute") runs with the scene's slowest relaxation time at
    rest, from the dense spectrum up to DENSE_ROBOT coordinates: the sparse Lanczos did not
    converge on the 524-body per-lever Tetris robot (session 47, docs/robot.md 3)."""
    import mlc.verify.dynamic as D
    from mlc.robot.verify import verify_robot_dynamic
    sc = load_scene(robot / "out" / "robot.yaml")
    asked = []
    real = D.relaxation_time

    def spy(scene, *a, **kw):
        asked.append(kw.get("dense_max"))
        return real(scene, *a, **kw)

    monkeypatch.setattr(D, "relaxation_time", spy)
    rep = verify_robot_dynamic(sc, rows=["0"], seeds=1, max_time=1.0, tau="compute")
    assert asked == [D.DENSE_ROBOT] and 6 * len(sc.bodies) < D.DENSE_ROBOT
    assert rep.params["tau"] == pytest.approx(real(sc), rel=1e-9) and rep.params["tau"] > 0


def test_the_readme_robot_folds_row_10_statically_and_is_clear_as_built(tmp_path):
    """The README's Tetris robot (``mlc compile examples/tetris.tt --robot ...``) folds S in row
    10 at its static equilibrium, every output and DOF probe right, and no two slabs
    interpenetrate as built.  Session 53's print lean (``mlc.circuit.build.PRINT_LEANS``) changed
    the robot's circuit (1675 bodies) and with it its couplings: every start of the coupling to
    ``u4_dn`` met another body, the builder kept the least overlapping one (through gate g2 and
    against ``rc_u4_up``: -0.229 sigma as built), and row 10 stopped 12.6 degrees short of its
    turn (``u4_dn`` read 1.449 sigma); a robot's circuit takes no print lean
    (``mlc.robot.build.CIRCUIT_PRINT_LEANS``, docs/robot.md 6)."""
    from mlc.robot.verify import verify_robot_static
    root = Path(__file__).resolve().parents[1]
    assert main(["compile", str(root / "examples" / "tetris.tt"), "--robot", str(root / "examples" / "tetris.robot.yaml"),
                 "-o", str(tmp_path / "robot")]) == 0
    scene = load_scene(tmp_path / "robot" / "robot.yaml")
    rep = verify_robot_static(scene, rows=["10"])
    assert rep.params["as_built"]["clearance"] > -1e-3, rep.params["as_built"]
    (row,) = rep.rows
    assert row["shape_ok"] and row["ok"], row
    assert all(e["ok"] for e in rep.entries), [e for e in rep.entries if not e["ok"]]
    assert "branch_lean" not in load_scene(tmp_path / "robot" / "circuit.yaml").meta["connector"]


def test_dynamic_verify_reports_the_slabs_clearance_at_the_end(robot):
    """Each seed's final pose gets the slab test: the report's value is the test of the pose
    the run ended in (kept with keep_poses), not of the scene as built."""
    from mlc.robot.verify import verify_robot_dynamic
    from mlc.verify.overlap import clearance

    sc = load_scene(robot / "out" / "robot.yaml")
    rep = verify_robot_dynamic(sc, rows=["1"], seeds=1, max_time=20.0, keep_poses=True)
    row = rep.rows[0]
    pos, quat = rep.poses[("1", 0)]
    end = clearance(sc, pos, quat).min_clearance
    assert row["end"]["clearance"] == pytest.approx(end if abs(end) > 1e-12 else 0.0, abs=1e-12)
    assert row["per_seed"][0]["clearance_end"] == row["end"]["clearance"] and row["end"]["seed"] == 0
    assert abs(end - clearance(sc).min_clearance) > 1e-6          # it moved: not the built pose's


def _overlap(*_a, **_k):
    return {"clearance": -0.05, "clearance_pair": ["ua", "ub"], "overlaps": [["ua", "ub", 0.05]], "n_overlaps": 1,
            "clearance_ok": False}


def test_require_clearance_fails_a_robot_row_whose_slabs_meet(robot, monkeypatch, capsys):
    """--require-clearance: a row whose slabs interpenetrate fails (static: the row's pose;
    dynamic: a seed's final pose); without it the same report warns and passes."""
    import mlc.robot.verify as rv

    monkeypatch.setattr(rv, "_clearance_row", _overlap)
    path = str(robot / "out" / "robot.yaml")
    assert main(["verify", path, "--rows", "1"]) == 0
    assert "WARNING: row 1: slabs ua and ub interpenetrate by 0.0500 sigma" in capsys.readouterr().out
    assert main(["verify", path, "--rows", "1", "--require-clearance"]) == 1
    out = capsys.readouterr().out
    assert "WRONG: row 1: slabs ua and ub interpenetrate" in out and "FAILED: rows 1" in out
    sc = load_scene(path)
    rep = rv.verify_robot_dynamic(sc, rows=["1"], seeds=1, max_time=20.0, require_clearance=True)
    assert not rep.ok and rep.rows[0]["shape_ok"]
    text = rv.format_robot_report(rep)
    assert "WRONG: row 1: slabs ua and ub end 0.0500 sigma inside each other (1 pairs, seed 0)" in text
    rep = rv.verify_robot_dynamic(sc, rows=["1"], seeds=1, max_time=20.0)
    assert rep.ok and "WARNING: row 1: slabs ua and ub end" in rv.format_robot_report(rep)
