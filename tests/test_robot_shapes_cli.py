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
