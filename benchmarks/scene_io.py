"""How fast scene files are written and read, with PyYAML's pure-Python emitter and parser
against libyaml's (what ``dump_scene`` and ``load_scene`` use when PyYAML has it).

A compiled circuit's scene grows with its bodies: 184 MB for the 200-gate mesh
(docs/circuits.md, "Scaling").  For each scene here:

* written: ``mlc.scene.io._emit`` with ``_PyDumper`` and with ``_CDumper`` (the same
  representers), and whether the two texts are identical; and by mlc's writer
  (``mlc.io.yamlemit``, session 33: what ``dump_scene`` writes with), whether its text is
  libyaml's;
* read: ``mlc.io.yamlsrc.load`` with its pure-Python ``_Loader`` and with ``_CLoader``
  (libyaml's scanner and parser under the same composer and constructors), whether the
  data and every recorded source location are identical, and the whole ``parse_scene``
  (read, schema, model) as ``load_scene`` does it;
* read by mlc's line reader (``mlc.io.yamlfast``, session 33: what ``yamlsrc.load`` reads
  the block YAML mlc writes with), and whether its data and every location equal libyaml's;
* the schema check: the checker walking the data (``mlc.io.schema._check``, which words an
  error) against the schema compiled into closures (``_compiled``, which only says yes or no,
  what ``validate`` runs first), and whether both accept the scene;
* the whole ``parse_scene`` (read, schema, model) as ``load_scene`` does it, now
  (``parse_scene_s``) and as before session 33 (``parse_scene_pyyaml_s``: libyaml's reader,
  the schema walked by the checker);
* the memory of a read: the peak resident size a fresh process adds while ``yamlsrc.load``
  reads the text, by the line reader (``read_line_*``) and by PyYAML's reader with each item
  constructed as it is composed (``read_stream_*``, :class:`mlc.io.yamlsrc._Limits`) and with
  the whole node tree composed first (``read_tree_*``, ``STREAM_DEPTH = 0``, PyYAML's own
  order), and the wall time of each.

Scenes: the examples compiled as ``mlc compile`` does (``--examples``), and
``nand_mesh(7, depth)`` at -O0 for each ``--meshes`` depth (static_polish.py's builds).
``--saved FILE ...``: scene files already written (the 200-gate mesh's, 184 MB, from
``circuit_scaling.py --save-scenes``), measured by the line reader, the compiled schema and
``load_scene`` only (``saved`` in the JSON; PyYAML's reader would take many minutes).

    python benchmarks/scene_io.py [--examples tetris.tt full_adder.tt mux4.blif] [--meshes 2]
    python benchmarks/scene_io.py --examples --meshes --saved S/mesh_29.yaml   (merged into the JSON)

Writes benchmarks/results/scene_io.json and .png.  Wall seconds in one run on this
(shared) machine: compare the ratios, not absolute numbers.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

from mlc.io import schema, yamlemit, yamlfast, yamlsrc
from mlc.io.atomic import atomic_path
from mlc.io.schema import load_schema
from mlc.scene import io
from static_polish import example_scene, mesh_scene

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"


def _timed(f):
    t0 = time.perf_counter()
    out = f()
    return out, time.perf_counter() - t0


_READ = """
import sys, time, json
from mlc.io import yamlsrc
mode = sys.argv[2]
if mode == "tree":
    yamlsrc.STREAM_DEPTH = 0
if mode != "line":                     # PyYAML's reader (libyaml's parser), as load falls back to
    from mlc.io import yamlfast
    yamlfast.parse = lambda text, filename: None
text = open(sys.argv[1], encoding="utf-8").read()

def status(key):
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith(key + ":"))
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")                       # the peak resident size (VmHWM) starts again from now
before = status("VmRSS")
t0 = time.perf_counter()
data = yamlsrc.load(text, "s.yaml", max_bytes=2 ** 31)
dt = time.perf_counter() - t0
print(json.dumps({"s": dt, "peak_mb": (status("VmHWM") - before) / 1024}))
"""


def read_memory(text: str) -> dict:
    """Peak resident MB that ``yamlsrc.load`` adds to a fresh process (Linux: the peak is
    reset through /proc/self/clear_refs before the read): by the line reader
    (``mlc.io.yamlfast``, what ``load`` reads a scene with), and by PyYAML's reader item by
    item (the default) and whole tree first (``STREAM_DEPTH = 0``)."""
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "s.yaml"
        path.write_text(text, encoding="utf-8")
        for key in ("line", "stream", "tree"):
            r = subprocess.run([sys.executable, "-c", _READ, str(path), key], check=True,
                               capture_output=True, text=True)
            m = json.loads(r.stdout.strip().splitlines()[-1])
            out[f"read_{key}_peak_mb"], out[f"read_{key}_s"] = m["peak_mb"], m["s"]
    out["read_peak_ratio"] = out["read_tree_peak_mb"] / out["read_stream_peak_mb"]
    out["read_line_peak_ratio"] = out["read_stream_peak_mb"] / out["read_line_peak_mb"]
    return out


def measure(name: str, scene) -> dict:
    data = io.scene_to_data(scene)
    py_text, py_w = _timed(lambda: io._emit(data, io._PyDumper))
    c_text, c_w = _timed(lambda: io._emit(data, io._CDumper))
    text = io.dump_scene(scene)
    fast_text, fast_w = _timed(lambda: yamlemit.dump(data))
    py_data, py_r = _timed(lambda: yamlsrc._Loader(text, name).get_single_data())
    c_data, c_r = _timed(lambda: yamlsrc._CLoader(text, name).get_single_data())
    same_data = py_data == c_data and yamlsrc.locations(py_data) == yamlsrc.locations(c_data)
    fast_data, fast_r = _timed(lambda: yamlfast.parse(text, name))
    same_fast = fast_data is not None and yamlsrc.same_data(fast_data, c_data) and \
        yamlsrc.locations(fast_data) == yamlsrc.locations(c_data)
    sch = load_schema("scene")
    checked, check_s = _timed(lambda: schema._check(c_data, sch, sch, [], c_data.loc))
    compiled, compiled_s = _timed(lambda: schema._compiled(sch)(c_data))
    py_data = c_data = fast_data = None
    parsed, parse_s = _timed(lambda: io.parse_scene(text, name))
    with _pyyaml_only():
        _, parse_old_s = _timed(lambda: io.parse_scene(text, name))
    return {"scene": name, "bodies": len(scene.bodies), "mb": len(text.encode()) / 2 ** 20,
            "write_python_s": py_w, "write_libyaml_s": c_w, "write_ratio": py_w / c_w,
            "same_text": py_text == c_text,
            "write_fast_s": fast_w, "write_fast_ratio": c_w / fast_w, "fast_same_text": fast_text == c_text,
            "read_python_s": py_r, "read_libyaml_s": c_r, "read_ratio": py_r / c_r,
            "same_data_and_locations": same_data,
            "read_fast_s": fast_r, "fast_ratio": c_r / fast_r, "fast_same_data_and_locations": same_fast,
            "validate_checker_s": check_s, "validate_compiled_s": compiled_s,
            "validate_ratio": check_s / compiled_s, "compiled_says_valid": compiled and checked is None,
            "parse_scene_s": parse_s, "parse_scene_pyyaml_s": parse_old_s, "parse_ratio": parse_old_s / parse_s,
            "round_trip": io.dump_scene(parsed) == text,
            **read_memory(text)}


def measure_saved(path: Path) -> dict:
    """A scene file as written: the line reader, the compiled schema, ``load_scene`` (in a
    fresh process, for the peak resident size) and ``dump_scene`` of what it read (the same
    text?), no PyYAML."""
    import hashlib
    text = path.read_text(encoding="utf-8")
    out = {"file": path.name, "mb": len(text.encode()) / 2 ** 20,
           "sha256_16": hashlib.sha256(text.encode()).hexdigest()[:16]}
    data, out["read_fast_s"] = _timed(lambda: yamlfast.parse(text, path.name))
    out["fast_read"] = data is not None
    sch = load_schema("scene")
    ok = schema._compiled(sch)
    out["compiled_says_valid"], out["validate_compiled_s"] = _timed(lambda: ok(data))
    data = None
    r = subprocess.run([sys.executable, "-c", _LOAD, str(path)], check=True, capture_output=True, text=True)
    out.update(json.loads(r.stdout.strip().splitlines()[-1]))
    return out


_LOAD = """
import sys, time, json
from mlc.scene.io import load_scene
t0 = time.perf_counter()
sc = load_scene(sys.argv[1])
dt = time.perf_counter() - t0
with open("/proc/self/status") as f:
    peak = next(int(line.split()[1]) for line in f if line.startswith("VmHWM:"))
from mlc.scene.io import dump_scene
text = open(sys.argv[1], encoding="utf-8").read()
t0 = time.perf_counter()
out = dump_scene(sc)
dw = time.perf_counter() - t0
print(json.dumps({"load_scene_s": dt, "bodies": len(sc.bodies), "load_scene_peak_mb": peak / 1024,
                  "dump_scene_s": dw, "dump_same_text": out == text}))
"""


@contextmanager
def _pyyaml_only():
    """``parse_scene`` as before session 33: PyYAML's reader, the schema walked by its checker."""
    parse, compiled = yamlfast.parse, schema._compiled
    yamlfast.parse = lambda text, filename: None
    schema._compiled = lambda s: (lambda data: False)
    try:
        yield
    finally:
        yamlfast.parse, schema._compiled = parse, compiled


def _panel(ax, pts: list, series, ylabel: str, title: str) -> None:
    """One log-log panel: each (key, label, marker) of ``series`` against the file size."""
    for key, label, m in series:
        ax.loglog([p["mb"] for p in pts], [p[key] for p in pts], m, label=label)
    ax.set_xlabel("scene file (MB)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)


def plot(res: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pts = sorted(res["scenes"], key=lambda p: p["mb"])
    fig, (ax, am) = plt.subplots(1, 2, figsize=(11, 4.2))
    _panel(ax, pts, (("write_python_s", "write, Python emitter", "o--"),
                     ("write_libyaml_s", "write, libyaml emitter", "o-"),
                     ("write_fast_s", "write, mlc's writer", "P-"),
                     ("read_python_s", "read, Python parser", "s--"),
                     ("read_libyaml_s", "read, libyaml parser", "s-"),
                     ("read_fast_s", "read, mlc's line reader", "D-"),
                     ("parse_scene_pyyaml_s", "parse_scene before (libyaml, schema checker, model)", "^:"),
                     ("parse_scene_s", "parse_scene (line reader, compiled schema, model)", "v-")),
           "wall seconds", "Scene files: PyYAML's paths and mlc's line reader")
    _panel(am, pts, (("read_tree_peak_mb", "PyYAML: whole node tree, then data", "s--"),
                     ("read_stream_peak_mb", "PyYAML: each item's data as it is read", "s-"),
                     ("read_line_peak_mb", "mlc's line reader", "D-")),
           "peak resident MB added by the read", "Memory of a read (libyaml parser)")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--examples", nargs="*", default=["tetris.tt", "full_adder.tt", "mux4.blif"])
    ap.add_argument("--meshes", type=int, nargs="*", default=[2])
    ap.add_argument("--saved", type=Path, nargs="*", default=[])
    args = ap.parse_args()
    if not yamlsrc.yaml.__with_libyaml__:
        raise SystemExit("PyYAML is built without libyaml here: nothing to compare")
    before = json.loads((OUT / "scene_io.json").read_text()) if (OUT / "scene_io.json").exists() else {}
    saved = [measure_saved(p) for p in args.saved] or before.get("saved", [])
    if args.saved:
        print(json.dumps(saved, indent=1))
    if not args.examples and not args.meshes:
        with atomic_path(OUT / "scene_io.json") as tmp:
            Path(tmp).write_text(json.dumps({**before, "saved": saved}, indent=1))
        return
    points = []
    for ex in args.examples:
        points.append(measure(ex, example_scene(ROOT / "examples" / ex)))
        print(json.dumps(points[-1]), flush=True)
    for d in args.meshes:
        points.append(measure(f"nand_mesh(7, {d})", mesh_scene(d)))
        print(json.dumps(points[-1]), flush=True)
    tot = {k: sum(p[k] for p in points) for k in ("mb", "write_python_s", "write_libyaml_s", "write_fast_s",
                                                  "read_python_s",
                                                  "read_libyaml_s", "read_fast_s", "parse_scene_s",
                                                  "parse_scene_pyyaml_s", "validate_checker_s",
                                                  "validate_compiled_s")}
    res = {"machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "load": os.getloadavg()[0]},
           "scenes": points, "saved": saved,
           "summary": {"write_ratio": tot["write_python_s"] / tot["write_libyaml_s"],
                       "read_ratio": tot["read_python_s"] / tot["read_libyaml_s"],
                       "libyaml_write_mb_per_s": tot["mb"] / tot["write_libyaml_s"],
                       "libyaml_read_mb_per_s": tot["mb"] / tot["read_libyaml_s"],
                       "fast_write_ratio": tot["write_libyaml_s"] / tot["write_fast_s"],
                       "fast_write_mb_per_s": tot["mb"] / tot["write_fast_s"],
                       "fast_read_ratio": tot["read_libyaml_s"] / tot["read_fast_s"],
                       "validate_ratio": tot["validate_checker_s"] / tot["validate_compiled_s"],
                       "parse_scene_ratio": tot["parse_scene_pyyaml_s"] / tot["parse_scene_s"],
                       "fast_read_mb_per_s": tot["mb"] / tot["read_fast_s"],
                       "parse_scene_mb_per_s": tot["mb"] / tot["parse_scene_s"],
                       "parse_scene_pyyaml_mb_per_s": tot["mb"] / tot["parse_scene_pyyaml_s"],
                       "read_peak_mb_per_file_mb": {k: [round(p[f"read_{k}_peak_mb"] / p["mb"], 1) for p in points]
                                                    for k in ("line", "stream", "tree")},
                       "all_same": all(p["same_text"] and p["fast_same_text"] and p["same_data_and_locations"]
                                       and p["round_trip"]
                                       and p["fast_same_data_and_locations"] and p["compiled_says_valid"]
                                       for p in points)}}
    OUT.mkdir(exist_ok=True)
    with atomic_path(OUT / "scene_io.json") as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1))
    plot(res, OUT / "scene_io.png")
    print(json.dumps(res["summary"], indent=1))


if __name__ == "__main__":
    main()
