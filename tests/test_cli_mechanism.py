"""Every issue-2 CLI command, run through mlc.cli.main."""
import json


from mlc.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_core_json(capsys):
    code, out, _ = run(capsys, "core", "--din", "0.5", "--h", "2", "--json")
    d = json.loads(out)
    assert code == 0 and abs(d["dout"] - 0.56) < 0.005 and {"x", "phi", "dout"} <= set(d)


def test_core_out_of_range_is_one_line(capsys):
    code, out, err = run(capsys, "core", "--din", "5", "--h", "2")
    assert code == 2 and err.count("\n") == 1 and "accessible range" in err and "Traceback" not in err


def test_core_plot(tmp_path, capsys):
    png, data = tmp_path / "fig1b.png", tmp_path / "fig1b.json"
    code, _, _ = run(capsys, "core", "--plot", str(png), "--data", str(data))
    assert code == 0 and png.read_bytes()[:4] == b"\x89PNG"
    d = json.loads(data.read_text())
    assert d["boundary"] and len(d["curves"]) >= 4


def test_lever_json(capsys):
    code, out, _ = run(capsys, "lever", "--lin", "1", "--lout", "1", "--dlin", "-0.5", "--dlout", "0.5",
                       "--l", "1.5", "--type", "open", "--json")
    d = json.loads(out)
    assert code == 0 and {"theta1", "theta2", "l1", "l2", "dtheta"} <= set(d) and d["residual"] < 1e-10


def test_lever_wrong_type(capsys):
    code, _, err = run(capsys, "lever", "--lin", "1", "--lout", "1", "--dlin", "-0.5", "--dlout", "0.5",
                       "--l", "1.5", "--type", "crossed")
    assert code == 2 and "--type open" in err


def test_check_gate_nand_json(capsys):
    code, out, _ = run(capsys, "check-gate", "NAND", "--signal", "expand", "--json")
    d = json.loads(out)
    assert code == 0 and d["ok"] and len(d["rows"]) == 4
    assert {"expected", "measured", "margin", "joint_stretch"} <= set(d["rows"][0])


def test_check_gate_all(capsys):
    code, out, _ = run(capsys, "check-gate", "all")
    assert code == 0 and "64 of 64 gate states correct" in out


def test_gate_writes_scene_and_draw(tmp_path, capsys):
    y = tmp_path / "nand.yaml"
    assert run(capsys, "gate", "NAND", "--signal", "expand", "-o", str(y))[0] == 0
    png = tmp_path / "nand.png"
    assert run(capsys, "draw", str(y), "-o", str(png))[0] == 0
    assert png.read_bytes()[:4] == b"\x89PNG"
    png2 = tmp_path / "g.png"
    assert run(capsys, "draw", "NOR", "--signal", "contract", "-o", str(png2))[0] == 0


def test_unknown_gate_and_missing_dir(tmp_path, capsys):
    code, _, err = run(capsys, "check-gate", "XOR")
    assert code == 2 and "choose one of" in err
    code, _, err = run(capsys, "gate", "AND", "-o", str(tmp_path / "no" / "x.yaml"))
    assert code == 2 and "does not exist" in err


def test_gate_picture_geometry_names_every_part():
    """The first panel of `mlc draw` names every slab and joint: each label sits at a distinct
    place (the two halves of a scissor lever share a centre, so labels are moved off it) and
    every joint is drawn where its bonded sites are."""
    import numpy as np

    from mlc.draw import _scene_geometry
    from mlc.gates.library import gate_scene
    from mlc.verify.static import solve_states
    scene = gate_scene("NAND", "expand")
    eq = solve_states(scene)["00"]
    faces, labels, site, joints = _scene_geometry(scene, eq.pos, eq.quat)
    assert set(labels) == {b.name for b in scene.bodies}
    pts = np.array(list(labels.values()))
    gaps = np.linalg.norm(pts[:, None] - pts[None], axis=-1) + np.eye(len(pts)) * 1e9
    assert gaps.min() > 0.1                           # sigma: no two slab names on one spot
    assert set(joints) == {b.joint or b.name for b in scene.bonds}
    for b in scene.bonds:                             # a hinge's two sites coincide at equilibrium
        kind, x = joints[b.joint or b.name]
        assert kind == b.kind and np.linalg.norm(site[b.a] - x) < 0.3 and np.linalg.norm(site[b.b] - x) < 0.3
