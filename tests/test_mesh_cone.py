"""``--pin cone`` on the library gates (issues 13/14): truncated cone knuckles that print, and
the refusal, before any final trim, where the knuckles cannot fit (sizes in mm)."""
import itertools

import manifold3d as mf
import numpy as np
import pytest
import trimesh

import mlc.mesh.build as B
from mlc.cli import main
from mlc.gates.library import gate_scene
from mlc.mesh.export import read_3mf
from mlc.mesh.profiles import load_profile


def _manifold(m: trimesh.Trimesh) -> mf.Manifold:
    mesh = mf.Mesh(vert_properties=np.asarray(m.vertices, np.float32), tri_verts=np.asarray(m.faces, np.uint32))
    mesh.merge()
    return mf.Manifold(mesh)


def test_cone_gate_prints_and_its_parts_are_apart(tmp_path, capsys):
    """NAND at sla with cones (182 s, 4.9 GB and a failed min_gap before): the report passes;
    the STL read back with trimesh has 9 closed pieces (the 3MF's 9 named parts, same volumes),
    every pair of them at least the clearance (0.3 mm) apart and disjoint, checked with
    manifold3d here, not by the report."""
    f3, fs = tmp_path / "n.3mf", tmp_path / "n.stl"
    assert main(["stl", "NAND", "--profile", "sla", "--pin", "cone", "-o", str(fs), "--3mf", str(f3)]) == 0
    out = capsys.readouterr().out
    assert "PASS" in out and "cone" in out
    assert fs.stat().st_size > 0
    named = dict(read_3mf(f3))
    assert sorted(named) == sorted(p.name for p in gate_scene("NAND", "expand").bodies) + ["ujoint_d"]
    # the STL, read with trimesh alone: its connected pieces are the parts
    stl = trimesh.load(str(fs), force="mesh")
    pieces = stl.split(only_watertight=False)
    # (float32 STL vertices leave one flat sliver of out_hi, no volume, as a piece of its own)
    assert sum(abs(m.volume) for m in pieces if abs(m.volume) < 1e-3) < 1e-3
    parts = {f"piece_{i}": m for i, m in enumerate(m for m in pieces if abs(m.volume) >= 1e-3)}
    assert len(parts) == 9
    assert all(m.is_watertight for m in parts.values())
    assert sorted(m.volume for m in parts.values()) == pytest.approx(sorted(m.volume for m in named.values()),
                                                                      rel=1e-4)
    solids = {k: _manifold(m) for k, m in parts.items()}
    assert all(s.status() == mf.Error.NoError and s.volume() > 1.0 for s in solids.values())
    c = load_profile("sla").clearance
    gaps = {(a, b): float(solids[a].min_gap(solids[b], 2 * c)) for a, b in itertools.combinations(sorted(solids), 2)}
    assert min(gaps.values()) >= c - 1e-4, min(gaps.items(), key=lambda x: x[1])
    assert all((solids[a] ^ solids[b]).volume() < 1e-9 for a, b in gaps)


def test_cone_knuckles_are_truncated():
    """sla: cone 1.7 mm across at its base (r = min_feature/2 + gap + clearance = 0.85 mm), cut
    where it is min_feature (0.5 mm) across, 0.6 mm high; knuckles 0.6 + 0.3 - 0.3 + 0.5 = 1.1 mm
    (the pointed cone needed 1.474 mm)."""
    asm = B.build_assembly(gate_scene("NAND", "expand"), load_profile("sla", {"pin": "cone"}), None, resolve=False)
    assert min(ax.knuckle for ax in asm.axes) == pytest.approx(1.1)     # longer where the slab is
    assert dict((k, v) for k, v, _ in asm.features)["cone pin diameter"] == pytest.approx(1.7)
    assert asm.cone_conflicts == []


def test_cone_refused_before_the_trims(tmp_path, capsys, monkeypatch):
    """NAND at mjp (sigma 5 mm): core_ab's knuckles on hinge_m reach a_lo's on hinge_a; one
    message naming them, the sizes and the fix, exit 2, nothing written, and no final trim run."""
    def no_trims(*a, **k):
        raise AssertionError("final trims started")
    monkeypatch.setattr(B, "_resolve", no_trims)
    f = tmp_path / "x.stl"
    assert main(["stl", "NAND", "--profile", "mjp", "--pin", "cone", "-o", str(f)]) == 2
    err = capsys.readouterr().err
    assert "pin: cone does not fit at sigma 5 mm" in err
    assert "core_ab's on hinge_m and a_lo's on hinge_a" in err
    assert "knuckle radius 1.533 mm" in err
    assert "--pin pin, or --sigma-mm >= 7" in err
    assert "Traceback" not in err and err.count("error") == 1
    assert not f.exists() and list(tmp_path.iterdir()) == []


def test_refusal_is_real():
    """The conflict the refusal names, rebuilt from the hinge layout alone: core_ab's end
    knuckle on hinge_m (x axis) and a_lo's knuckle on hinge_a (z axis, x = -2.69 mm) overlap
    at sigma 5 mm, and are more than the clearance apart at sigma 7 mm (the suggested fix)."""
    def knuckles(sigma):
        prof = load_profile("mjp", {"pin": "cone", "sigma_mm": sigma})
        B._CONE_PROBE[0] = True
        try:
            asm = B.build_assembly(gate_scene("NAND", "expand"), prof, None, resolve=False)
        finally:
            B._CONE_PROBE[0] = False
        ax = {a.name: a for a in asm.axes}

        def cyl(a, bn):
            out = mf.Manifold()
            for a0, a1 in a.intervals[bn]:
                c = mf.Manifold.cylinder(a1 - a0, a.R, a.R, 64).translate([0, 0, a0])
                if abs(a.direction[0]) > 0.5:          # x axis: turn z onto x
                    c = c.rotate([0, 90, 0])
                out += c.translate(a.origin.tolist())
            return out
        return cyl(ax["hinge_m"], "core_ab"), cyl(ax["hinge_a"], "a_lo"), prof.clearance, asm.cone_conflicts
    m, a, c, conf = knuckles(5.0)
    assert (m ^ a).volume() > 0.01 and ("core_ab", "a_lo", None) in conf
    m, a, c, conf = knuckles(7.0)
    assert m.min_gap(a, 1.0) > c and conf == []
