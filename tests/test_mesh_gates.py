"""The library gates as printable meshes: golden part counts, and the paper's NAND passes
the printability report for every printer profile."""
import pytest

from mlc.gates.library import GATE_NAMES, gate_scene
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import check_assembly
from mlc.mesh.examples import gate_poses
from mlc.mesh.export import part_meshes, read_3mf, read_parts, stl_bytes, threemf_bytes
from mlc.mesh.profiles import load_profile

# 8 slabs + the universal joint at d; 7 hinge axes (the one at c joins three slabs)
GOLDEN = {"parts": 9, "bodies": 8, "joint_parts": 1, "hinge_axes": 7, "three_body_axes": 1}


@pytest.mark.parametrize("name", GATE_NAMES)
def test_golden_part_counts(name):
    asm = build_assembly(gate_scene(name, "expand"), load_profile("mjp"), None, resolve=False)
    assert len(asm.parts) == GOLDEN["parts"]
    assert sum(p.kind == "body" for p in asm.parts) == GOLDEN["bodies"]
    assert sum(p.kind == "joint" for p in asm.parts) == GOLDEN["joint_parts"]
    assert len(asm.axes) == GOLDEN["hinge_axes"]
    assert sum(len(ax.bodies) == 3 for ax in asm.axes) == GOLDEN["three_body_axes"]
    assert all(len(p.solid.decompose()) == 1 for p in asm.parts)


@pytest.mark.parametrize("profile", ["mjp", "sla", "fdm"])
def test_nand_passes_for_every_profile(profile, tmp_path):
    scene = gate_scene("NAND", "expand")
    asm = build_assembly(scene, load_profile(profile), gate_poses("NAND", "expand"))
    rep = check_assembly(asm, walls=False)     # the measured walls: tests/test_mesh_print.py
    # the mechanism checks pass; how it sits on the bed is reported (issue 13: the gates do not
    # meet the bed-contact and support goals yet, see docs/printing.md)
    for name in ("watertight", "part_count", "min_gap", "states", "retention", "features"):
        assert rep.check(name).ok, rep.text()
    assert not rep.check("bed_contact").ok and rep.check("bed_contact").value < 0.2
    assert rep.check("supports").value > 0
    assert rep.check("states").detail.startswith("4 logic states")
    assert rep.check("part_count").value == 9
    # the round trip through STL and 3MF keeps every part
    meshes = part_meshes(asm)
    (tmp_path / "n.stl").write_bytes(stl_bytes(meshes))
    (tmp_path / "n.3mf").write_bytes(threemf_bytes(meshes))
    pieces = read_parts(tmp_path / "n.stl")
    # with the dense path poses (issue 13) a trim can leave a zero-area two-triangle sliver that the
    # STL's welded vertices split off; known, reported; the 9 solid parts must all be there
    assert sum(len(m.faces) >= 4 for _, m in pieces) == 9
    assert all(len(m.faces) >= 4 or m.area < 1e-9 for _, m in pieces)
    back = read_3mf(tmp_path / "n.3mf")
    assert [n for n, _ in back] == [p.name for p in asm.parts]
    assert all(m.is_watertight and m.volume > 0 for _, m in back)


def test_axes_flat_lays_hinge_axes_flat():
    asm = build_assembly(gate_scene("NAND"), load_profile("fdm", {"orient": "axes_flat"}), None, resolve=False)
    R = asm.orient[:3, :3]
    dirs = [ax.direction for ax in asm.axes] + [a for uj in asm.ujoints for a in uj.axes]
    assert max(abs((R @ d)[2]) for d in dirs) < 1e-6      # every hinge axis parallel to the bed
