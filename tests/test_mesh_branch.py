"""Branch junctions (issue 13): where a connector branches (fan-out), the pages of the branch
all hang on one point of the source half unit.  Their universal joints share ONE joint part: a
compound junction on the source's hinge with one second pin carrying every page's yoke
knuckle.  Before, only the first page's joint was compound and the others overlapped it (up to
5.3 mm^3 between the two joint parts of this scene) and the source's slabs."""
import itertools

import numpy as np
import pytest

from mlc.mesh.pipeline import export_assembly
from mlc.mesh.profiles import load_profile
from mlc.scene.model import Scene


@pytest.fixture(scope="module")
def branch():
    # the smallest circuit with a branch: input a feeds two gates (two pages on src_a); the
    # source half unit and the first half unit of each page, without muscles (rest pose)
    from mlc import pipeline
    sc = pipeline.build(pipeline.compile_spec(pipeline.load(None, "x = a & b; y = a & c"))).circuit.scene
    keep = {b.name for b in sc.bodies
            if b.name.startswith(("src_a_", "w_a_p0_", "w_a_p1_")) and b.name.count("_") <= 3}
    assert len(keep) == 12
    sub = Scene(name="branch", bodies=[b for b in sc.bodies if b.name in keep],
                bonds=[x for x in sc.bonds if x.a.split(".")[0] in keep and x.b.split(".")[0] in keep],
                muscles=[], probes=[], units=sc.units, source=sc.source)
    sub.inputs, sub.outputs = [], []
    return export_assembly(sub, load_profile("mjp"))


def test_pages_share_one_joint_part(branch):
    asm, _ = branch
    assert len(asm.ujoints) == 4
    parts = {u.part for u in asm.ujoints}
    assert len(parts) == 2                      # one joint part per joint point (hinges B and D of src_a)
    for part in parts:
        members = [u for u in asm.ujoints if u.part == part]
        assert sum(u.primary for u in members) == 1
        src = {u.bodies[0] for u in members}
        assert len(src) == 1 and src.pop().startswith("src_a_")
        # one second pin: every page's knuckle on the same line, on disjoint intervals
        v = members[0].axes[1]
        assert all(abs(abs(float(np.dot(u.axes[1], v))) - 1) < 1e-9 for u in members)
        ivs = sorted(iv for u in members for iv in u.layouts[1].own)
        assert all(a[1] < b[0] for a, b in zip(ivs, ivs[1:]))
        assert {u.bodies[1] for u in members} <= set(asm.part(part).partners)


def test_branch_prints(branch):
    _, rep = branch
    by = {c.name: c for c in rep.checks}
    for name in ("watertight", "part_count", "min_gap", "retention", "features"):
        assert by[name].ok, (name, by[name].detail, by[name].failures[:5])


def test_no_overlap_as_printed(branch):
    # independent of the report: manifold3d, every pair of parts
    asm, _ = branch
    c = asm.profile.clearance
    for a, b in itertools.combinations(asm.parts, 2):
        assert (a.solid ^ b.solid).volume() < 1e-9, (a.name, b.name)
        if a.kind == "joint" or b.kind == "joint":
            assert a.solid.min_gap(b.solid, 2 * c) >= c - 1e-6, (a.name, b.name)
