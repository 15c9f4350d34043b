"""Stiff connector joints in a robot (``mlc compile``, default K = 100; ``--joint-k K``, docs/robot.md 2.5): the
coupling chains get the circuit's joint stiffness K k0 on every bond, like the circuit's own
chains; the skeleton's hinges, joint stops and locks and the circuit's muscles keep k0."""
import pytest

from mlc.cli import main
from mlc.scene.io import load_scene

K = 100.0


@pytest.fixture(scope="module")
def stiff(tmp_path_factory, tiny_robot_yaml):
    d = tmp_path_factory.mktemp("tinyk")
    (d / "tiny.robot.yaml").write_text(tiny_robot_yaml)
    rc = main(["compile", "-e", "u1_up = a; u2_dn = a", "--robot", str(d / "tiny.robot.yaml"),
               "-o", str(d / "out")])                      # the default joints: K = 100 k0
    assert rc == 0
    return load_scene(d / "out" / "robot.yaml")


def test_chain_bonds_carry_joint_k_skeleton_and_muscles_k0(stiff):
    assert stiff.meta["circuit"]["connector"]["joint_k"] == K
    assert stiff.meta["robot"]["k"] == {"chains": K, "skeleton": 1.0, "joint_k": K}
    chain = [b for b in stiff.bonds if b.name.startswith("rc_")]
    kinds = {b.kind for b in chain}
    assert {"hinge", "universal"} <= kinds            # half-unit hinges and the end joints on the lever sites
    assert sum("_end_" in b.name for b in chain) == 4
    assert all(b.k == K for b in chain), sorted({(b.name, b.k) for b in chain if b.k != K})[:5]
    skel = [b for b in stiff.bonds if b.name.startswith("skel_")]
    hinges = [b for b in skel if b.name.startswith("skel_h_")]
    stops = [b for b in skel if b.name.startswith("skel_stop_")]
    assert len(hinges) == 8 and all(b.k == 1.0 for b in hinges)      # 2 units x up/dn x 2 bonds
    assert stops and all(b.k == 4.0 for b in stops)                    # STOP_K k0
    assert all(b.k == 1.0 for b in skel if b.name.startswith("skel_lock_"))
    assert stiff.muscles and all(m.k == 1.0 for m in stiff.muscles)
    # the circuit part is stiffened by the circuit builder itself (mlc.circuit.build)
    assert any(b.k == K for b in stiff.bonds if not b.name.startswith(("rc_", "skel_")))


def test_paper_joints_build_is_k0(tmp_path, tiny_robot_yaml):
    (tmp_path / "tiny.robot.yaml").write_text(tiny_robot_yaml)
    assert main(["compile", "-e", "u1_up = a; u2_dn = a", "--robot", str(tmp_path / "tiny.robot.yaml"),
                 "--joint-k", "1", "-o", str(tmp_path / "out")]) == 0
    sc = load_scene(tmp_path / "out" / "robot.yaml")
    assert sc.meta["robot"]["k"]["joint_k"] == 1.0
    assert all(b.k == 1.0 for b in sc.bonds if b.name.startswith("rc_"))
