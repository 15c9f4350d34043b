"""Scenes other than the library gates: odd joints are reported, not silently printed."""
import numpy as np
import pytest

from mlc.errors import MlcError
from mlc.mesh import examples as ex
from mlc.mesh.build import build_assembly
from mlc.mesh.profiles import load_profile
from mlc.scene.model import Bond


def test_plain_bond_is_noted_not_printed():
    sc = ex.hinge_pair()
    sc.bonds.append(Bond("spring", "A.tip", "B.tip", kind="bond", joint="spring", rest=1.0))
    asm = build_assembly(sc.check(), load_profile("mjp"), None)
    assert len(asm.parts) == 2
    assert any("spring" in n and "not printed" in n for n in asm.notes)


def test_hinge_needs_two_bonds():
    sc = ex.hinge_pair()
    sc.bonds = sc.bonds[:1]
    with pytest.raises(MlcError, match="two"):
        build_assembly(sc, load_profile("mjp"), None)


def test_hinge_with_bonds_at_one_point():
    sc = ex.hinge_pair()
    sc.bonds[1].a, sc.bonds[1].b = sc.bonds[0].a, sc.bonds[0].b
    with pytest.raises(MlcError, match="no axis"):
        build_assembly(sc, load_profile("mjp"), None)


def test_body_without_joints_is_a_part():
    sc = ex.hinge_pair()
    sc.bonds = []
    sc.muscles = []
    sc.inputs = []
    asm = build_assembly(sc.check(), load_profile("sla"), None)
    assert len(asm.parts) == 2 and not asm.axes
    assert all(float(p.solid.volume()) > 0 for p in asm.parts)


def test_nand_universal_joint_layout():
    from mlc.gates.library import gate_scene
    asm = build_assembly(gate_scene("NAND"), load_profile("mjp"), None, resolve=False)
    (uj,) = asm.ujoints
    assert uj.part == "ujoint_d" and uj.bodies == ("core_cd", "out_hi")
    assert np.allclose(uj.axes[0], [0, 0, 1]) and np.allclose(uj.axes[1], [1, 0, 0])
