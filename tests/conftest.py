"""Test configuration.

* Import mlc first so that its BLAS thread default applies (see mlc/__init__.py).
* Under CI (``CI=true``) hypothesis runs derandomized: the same examples every run,
  so a CI result is reproducible.  Locally it explores new examples each run.
"""
import os

import pytest
from hypothesis import settings

import mlc  # noqa: F401

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


TINY_ROBOT = """mlc_robot: 1
name: tiny
inputs: [a]
skeleton: {units: 2}
dofs:
  - {unit: 1, side: up, output: u1_up}
  - {unit: 2, side: dn, output: u2_dn}
poses:
  - {row: "0", shape: I, turns: [0, 0]}
  - {row: "1", shape: hook, turns: [90, -90]}
"""


@pytest.fixture(scope="session")
def tiny_robot_yaml() -> str:
    """A robot file for a two-unit skeleton that one input folds into a hook (outputs
    u1_up, u2_dn): the small robot of tests/test_robot_build.py and test_robot_chain_stops.py."""
    return TINY_ROBOT
