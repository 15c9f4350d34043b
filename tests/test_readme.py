"""The README's two set-up commands stay true: CI runs the README's test command."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_ci_runs_the_readme_test_command():
    readme = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```sh\n(.*?)\n```", readme, re.S)
    assert len(blocks) >= 2
    test_cmd = blocks[1].strip()
    assert test_cmd == "pip install '.[test]' && pytest -q"
    ci = (ROOT / ".ci" / "run").read_text()
    assert "pip install '.[test]'" in ci and "\npytest -q\n" in ci
    assert blocks[0].startswith("pip install . && mlc ")
