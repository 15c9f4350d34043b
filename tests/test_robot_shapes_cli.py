"""``mlc robot shapes`` options checked before any work (docs/robot.md): ``--dt`` sets the
Brownian-dynamics step of ``--dynamic`` and is refused alone or when not a finite time > 0,
with one message naming the option and exit 2, and nothing written."""
import pytest

from mlc.cli import main


@pytest.mark.parametrize("argv, words", [
    (["--dt", "0.2"], "--dt needs --dynamic"),
    (["--dynamic", "--dt", "0"], "--dt must be a finite time > 0"),
    (["--dynamic", "--dt", "nan"], "--dt must be a finite time > 0"),
    (["--dynamic", "--dt", "-1"], "--dt must be a finite time > 0"),
])
def test_dt_is_checked_before_the_scene_is_read(argv, words, tmp_path, capsys):
    scene = tmp_path / "robot.yaml"
    scene.write_text("not: a robot\n")          # never read: the option is refused first
    rc = main(["robot", "shapes", str(scene), "-o", str(tmp_path / "s.png"), *argv])
    err = capsys.readouterr().err
    assert rc == 2 and words in err and err.count("\n") == 1, err
    assert not (tmp_path / "s.png").exists()


def test_dynamic_shapes_use_the_seed_and_step_asked_for(tmp_path, tiny_robot_yaml, capsys):
    """``--seed`` picks the run's seed and ``--dt`` its step: the report records both, and two
    seeds give different final poses (thermal noise), each still folded right."""
    import json

    (tmp_path / "tiny.robot.yaml").write_text(tiny_robot_yaml)
    assert main(["compile", "-e", "u1_up = a; u2_dn = a", "--robot", str(tmp_path / "tiny.robot.yaml"),
                 "-o", str(tmp_path / "out")]) == 0
    reps = {}
    for seed in (0, 5):
        js = tmp_path / f"rep{seed}.json"
        rc = main(["robot", "shapes", str(tmp_path / "out" / "robot.yaml"), "--dynamic", "--dt", "0.2",
                   "--seed", str(seed), "-o", str(tmp_path / f"s{seed}.png"), "--json", str(js)])
        assert rc == 0
        reps[seed] = json.loads(js.read_text())
    capsys.readouterr()
    for seed, rep in reps.items():
        assert rep["params"]["dt"] == 0.2 and rep["params"]["first_seed"] == seed
        assert all(r["per_seed"][0]["seed"] == seed for r in rep["rows"])
    turns = [[r["per_seed"][0]["turns_read"] for r in reps[s]["rows"]] for s in (0, 5)]
    assert turns[0] != turns[1]
