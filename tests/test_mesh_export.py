"""Outputs: STL/3MF/per-part files round-trip with the same parts; writes are atomic; the CLI."""
import json
import subprocess
import sys

import pytest

from mlc.cli import main
from mlc.errors import MlcError
from mlc.mesh import examples as ex
from mlc.mesh.build import build_assembly
from mlc.mesh.export import part_meshes, read_3mf, read_parts, stl_bytes, threemf_bytes, write_outputs
from mlc.mesh.profiles import load_profile


@pytest.fixture(scope="module")
def asm():
    sc = ex.ujoint_pair()
    return build_assembly(sc, load_profile("mjp"), None)


def test_stl_round_trip_keeps_every_part(asm, tmp_path):
    meshes = part_meshes(asm)
    f = tmp_path / "a.stl"
    f.write_bytes(stl_bytes(meshes))
    back = read_parts(f)
    assert len(back) == len(asm.parts) == 3
    assert all(m.is_watertight for _, m in back)
    assert sorted(round(m.volume, 3) for _, m in back) == sorted(round(float(p.solid.volume()), 3) for p in asm.parts)


def test_3mf_round_trip_keeps_names_and_volumes(asm, tmp_path):
    f = tmp_path / "a.3mf"
    f.write_bytes(threemf_bytes(part_meshes(asm), "ujoint"))
    back = read_3mf(f)
    assert [n for n, _ in back] == [p.name for p in asm.parts]
    for (n, m), p in zip(back, asm.parts):
        assert m.is_watertight
        assert abs(m.volume - float(p.solid.volume())) < 1e-3


def test_print_frame_rests_on_the_bed(asm):
    lo = min(m.bounds[0][2] for _, m in part_meshes(asm))
    assert abs(lo) < 1e-6


def test_write_outputs_all_files(asm, tmp_path):
    out = write_outputs(asm, stl=tmp_path / "x.stl", threemf=tmp_path / "x.3mf", parts_dir=tmp_path / "parts")
    assert len(out) == 2 + len(asm.parts)
    assert sorted(p.name for p in (tmp_path / "parts").iterdir()) == sorted(f"{p.name}.stl" for p in asm.parts)


def test_failed_export_leaves_no_file(asm, tmp_path):
    (tmp_path / "blocker").write_text("a file where the parts directory should go")
    with pytest.raises(MlcError, match=r"--parts: .*blocker: exists and is not a directory"):
        write_outputs(asm, stl=tmp_path / "x.stl", threemf=tmp_path / "x.3mf", parts_dir=tmp_path / "blocker")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blocker"]


def test_render_mesh(asm, tmp_path):
    from mlc.mesh.render import render_mesh
    f = tmp_path / "a.3mf"
    f.write_bytes(threemf_bytes(part_meshes(asm)))
    render_mesh(f, tmp_path / "a.png")
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_scene_file(tmp_path, capsys):
    from mlc.scene.io import write_scene
    sc = ex.hinge_pair()
    write_scene(sc, tmp_path / "h.yaml")
    rc = main(["stl", str(tmp_path / "h.yaml"), "--profile", "sla", "-o", str(tmp_path / "h.stl"),
               "--3mf", str(tmp_path / "h.3mf"), "--json", "--report", str(tmp_path / "r.json")])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["ok"] and len(out["parts"]) == 2
    assert json.loads((tmp_path / "r.json").read_text())["checks"] == out["checks"]
    assert len(out["size_mm"]) == 3 and min(out["size_mm"]) > 0
    assert len(read_parts(tmp_path / "h.stl")) == 2 and len(read_3mf(tmp_path / "h.3mf")) == 2


def test_cli_failed_check_writes_nothing_unless_forced(tmp_path, capsys):
    from mlc.scene.io import write_scene
    write_scene(ex.hinge_pair(), tmp_path / "h.yaml")
    args = ["stl", str(tmp_path / "h.yaml"), "--clearance", "0", "--knuckle-gap", "0", "-o", str(tmp_path / "h.stl")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "printability checks failed" in err and "min_gap" in err
    assert not (tmp_path / "h.stl").exists()
    assert main(args + ["--force"]) == 0
    assert (tmp_path / "h.stl").exists()


def test_cli_unknown_target():
    assert main(["stl", "NOTAGATE", "-o", "x.stl"]) == 2


def test_cli_subprocess_help():
    r = subprocess.run([sys.executable, "-m", "mlc.cli", "stl", "--help"], capture_output=True, text=True)
    assert r.returncode == 0 and "--3mf" in r.stdout and "--clearance" in r.stdout


def test_export_scene_api(tmp_path):
    from mlc.errors import MlcError
    from mlc.mesh import export_scene
    sc = ex.hinge_pair()
    rep = export_scene(sc, "sla", stl=tmp_path / "a.stl", threemf=tmp_path / "a.3mf")
    assert rep.ok and len(rep.outputs) == 2
    with pytest.raises(MlcError) as e:
        export_scene(sc, "sla", overrides={"clearance": 0.0}, stl=tmp_path / "b.stl")
    assert not e.value.report.ok and not (tmp_path / "b.stl").exists()
