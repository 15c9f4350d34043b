"""Scenes of many mechanisms: split, copies built once, checks between mechanisms."""
import numpy as np

from mlc.mesh import examples as ex
from mlc.mesh.pipeline import export_assembly, split_mechanisms
from mlc.mesh.profiles import load_profile


def test_split_and_dedupe():
    sc = ex.grid(ex.hinge_pair(), 2, 2, (3.0, 3.0))
    mechs = split_mechanisms(sc)
    assert len(mechs) == 4 and all(len(m.bodies) == 2 for m in mechs)
    asm, rep = export_assembly(sc, load_profile("mjp"))
    assert rep.ok, rep.text()
    assert len(asm.parts) == 8
    assert [p.name for p in asm.parts[:2]] == ["A_0", "B_0"]
    # copies are translated, not rebuilt: equal volumes, shifted boxes
    v = [round(float(p.solid.volume()), 6) for p in asm.parts]
    assert v[0::2] == [v[0]] * 4
    b0 = np.asarray(asm.parts[0].solid.bounding_box())
    b2 = np.asarray(asm.parts[2].solid.bounding_box())
    assert np.allclose(b2 - b0, [0, 15, 0, 0, 15, 0])      # second copy: +3 sigma in y at 5 mm/sigma
    assert "states" in {c.name for c in rep.checks} and rep.check("states").ok


def test_mechanisms_too_close_fail():
    sc = ex.grid(ex.hinge_pair(), 2, 1, (0.3, 0.0))      # the second copy overlaps the first
    asm, rep = export_assembly(sc, load_profile("mjp"))
    assert not rep.ok
    assert not rep.check("min_gap").ok or not rep.check("states").ok


def test_single_mechanism_path_and_no_states():
    sc = ex.hinge_pair()
    asm, rep = export_assembly(sc, load_profile("mjp"), solve=False)
    assert not rep.check("states").ok                     # nothing posed: the states check fails
    asm, rep = export_assembly(sc, load_profile("mjp"))
    assert rep.ok and rep.check("states").detail.startswith("2 logic states")


def test_state_poses_side_by_side_are_the_poses_one_after_the_other(monkeypatch):
    """state_poses runs a large scene's minimisations on threads (_in_threads): the same keys in
    the same order and the same poses to the bit as one after the other, for the coarse paths
    and for the dense paths and switches (a NAND forced onto threads; a thread that shared a
    pose array with another, or a result out of its place, would show here)."""
    import mlc.mesh.pipeline as pl
    from mlc.gates.library import gate_scene
    scene = gate_scene("NAND", "expand")
    runs = {}
    for floor in (10 ** 9, 1):
        monkeypatch.setattr(pl, "THREADS_MIN_BODIES", floor)
        runs[floor] = (pl.state_poses(scene, path_steps=2)[0], pl.state_poses(scene, path_steps=1, max_move=0.05)[0])
    for one, two in zip(runs[10 ** 9], runs[1]):
        assert list(one) == list(two) and len(one) > 4
        for key in one:
            assert np.array_equal(one[key][0], two[key][0]) and np.array_equal(one[key][1], two[key][1]), key
