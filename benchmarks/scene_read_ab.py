"""The fast scene reader (``mlc.io.yamlfast.parse``) and the compiled schema check
(``mlc.io.schema._compiled``) at an earlier commit against the current ones, on the same
texts, in one run.

For each scene (the examples compiled as ``mlc compile`` does, ``nand_mesh(7, depth)`` at -O0,
or scene files given with ``--files``): its text, read ``--repeats`` times by each reader in
turn (base, current, base, ...), CPU time of each read (``process_time``, after a garbage
collection).  The base reader is the file ``mlc/io/yamlfast.py`` as it was at ``--base``
(``git show``), loaded as a module of its own beside the current package, so both build the
same ``LocDict``/``LocList`` of today's ``mlc.io.yamlsrc``; the same for ``mlc/io/schema.py``,
whose compiled predicate of the scene schema is then timed on the current reader's data
(``--repeats`` times each, in turn).

Checks, per scene:
* ``same_as_base``: both readers give the same data (types, key order) and the same source
  location for every mapping, sequence and item (``yamlsrc.same_data``, ``yamlsrc.locations``);
* ``same_as_libyaml``: the current reader's data and locations equal those of PyYAML on
  libyaml's parser (``yamlsrc._CLoader``): a reader that shares no code with this one;
* ``schema_both_accept``: both compiled predicates accept the scene (their agreement on
  refused data is tests/test_schemas.py's).

    python benchmarks/scene_read_ab.py --base 8d0a7ce [--examples tetris.tt full_adder.tt mux4.blif]
        [--meshes 2] [--files S/robot.yaml ...] [--repeats 5]

Writes benchmarks/results/scene_read_ab.json and .png.  Ratios are base CPU over current CPU
(medians of the repeats) measured in one run on this shared machine: compare the ratios.
"""
from __future__ import annotations

import argparse
import gc
import importlib.util
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

from gitstate import commit
from mlc.io import schema, yamlfast, yamlsrc
from mlc.io.atomic import atomic_path
from mlc.scene import io
from static_polish import example_scene, mesh_scene

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"


def base_module(rev: str, name: str):
    """``mlc/io/<name>.py`` at git revision ``rev``, as a module of its own."""
    src = subprocess.run(["git", "-C", str(ROOT), "show", f"{rev}:mlc/io/{name}.py"], capture_output=True,
                         text=True, check=True).stdout
    d = tempfile.mkdtemp(prefix=f"{name}_base_")
    path = Path(d) / f"{name}_base.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location(f"{name}_base", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _cpu(f) -> float:
    gc.collect()
    t = time.process_time()
    f()
    return time.process_time() - t


def libyaml(text: str, name: str):
    loader = yamlsrc._CLoader(text, name)
    try:
        return loader.get_single_data()
    finally:
        loader.dispose()


def measure(name: str, text: str, base, base_schema, repeats: int) -> dict:
    fn = f"<{name}>"
    a, b = base.parse(text, fn), yamlfast.parse(text, fn)
    if a is None or b is None:
        raise SystemExit(f"{name}: a reader refused the text (base: {a is None}, current: {b is None})")
    same_base = yamlsrc.same_data(a, b) and yamlsrc.locations(a) == yamlsrc.locations(b)
    c = libyaml(text, fn)
    same_lib = yamlsrc.same_data(c, b) and yamlsrc.locations(c) == yamlsrc.locations(b)
    n_bodies = len(b.get("bodies") or [])
    sch = schema.load_schema("scene")
    ok_base, ok_new = base_schema._compiled(sch), schema._compiled(sch)
    both = bool(ok_base(b)) and bool(ok_new(b))
    v_base, v_new = [], []
    for _ in range(repeats):
        v_base.append(_cpu(lambda d=b: ok_base(d)))
        v_new.append(_cpu(lambda d=b: ok_new(d)))
    del a, b, c
    t_base, t_new = [], []
    for _ in range(repeats):
        t_base.append(_cpu(lambda: base.parse(text, fn)))
        t_new.append(_cpu(lambda: yamlfast.parse(text, fn)))
    mb, nb = statistics.median(t_base), statistics.median(t_new)
    vb, vn = statistics.median(v_base), statistics.median(v_new)
    return {"scene": name, "bodies": n_bodies, "mb": len(text.encode()) / 2 ** 20, "base_s": t_base, "new_s": t_new,
            "base_median_s": mb, "new_median_s": nb, "ratio": mb / nb,
            "new_mb_per_s": len(text.encode()) / 2 ** 20 / nb,
            "same_as_base": same_base, "same_as_libyaml": same_lib,
            "schema_base_s": v_base, "schema_new_s": v_new, "schema_base_median_s": vb, "schema_new_median_s": vn,
            "schema_ratio": vb / vn, "schema_both_accept": both}


def plot(res: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pts = res["scenes"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
    x = range(len(pts))
    for ax, (b, n, r, what) in zip(axes, (("base_median_s", "new_median_s", "ratio", "read (mlc.io.yamlfast.parse)"),
                                          ("schema_base_median_s", "schema_new_median_s", "schema_ratio",
                                           "schema check (compiled)"))):
        ax.bar([i - 0.2 for i in x], [p[b] / p["mb"] for p in pts], 0.4, label=f"base {res['base']}")
        ax.bar([i + 0.2 for i in x], [p[n] / p["mb"] for p in pts], 0.4, label=f"current {res['commit']}")
        for i, p in zip(x, pts):
            ax.text(i, p[b] / p["mb"], f"{p[r]:.2f}x", ha="center", va="bottom", fontsize=8)
        ax.set_xticks(list(x), [f"{p['scene']}\n{p['bodies']} bodies" for p in pts], fontsize=7)
        ax.set_ylabel("CPU per MB of scene (s)")
        ax.set_title(f"{what}: median of the repeats, one run", fontsize=9)
        ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", required=True, help="git revision of the reader to compare with")
    ap.add_argument("--examples", nargs="*", default=["tetris.tt", "full_adder.tt", "mux4.blif"])
    ap.add_argument("--meshes", type=int, nargs="*", default=[2])
    ap.add_argument("--files", type=Path, nargs="*", default=[])
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    if not yamlsrc.yaml.__with_libyaml__:
        raise SystemExit("PyYAML is built without libyaml here: no outside reader to compare with")
    base, base_schema = base_module(args.base, "yamlfast"), base_module(args.base, "schema")
    scenes = [(ex, lambda ex=ex: example_scene(ROOT / "examples" / ex)) for ex in args.examples]
    scenes += [(f"nand_mesh(7, {d})", lambda d=d: mesh_scene(d)) for d in args.meshes]
    points = []
    for name, make in scenes:
        points.append(measure(name, io.dump_scene(make()), base, base_schema, args.repeats))
        print(json.dumps(points[-1]), flush=True)
    for f in args.files:
        points.append(measure(f.name, f.read_text(), base, base_schema, args.repeats))
        print(json.dumps(points[-1]), flush=True)
    tb, tn = sum(p["base_median_s"] for p in points), sum(p["new_median_s"] for p in points)
    vb, vn = sum(p["schema_base_median_s"] for p in points), sum(p["schema_new_median_s"] for p in points)
    res = {"benchmark": "scene_read_ab", "commit": commit(), "base": args.base,
           "machine": {"platform": platform.platform(), "python": sys.version.split()[0], "cpus": os.cpu_count(),
                       "load": os.getloadavg()[0]},
           "repeats": args.repeats, "scenes": points,
           "summary": {"ratio_of_totals": tb / tn, "base_total_s": tb, "new_total_s": tn,
                       "schema_ratio_of_totals": vb / vn, "schema_base_total_s": vb, "schema_new_total_s": vn,
                       "all_schema_accept": all(p["schema_both_accept"] for p in points),
                       "all_same_as_base": all(p["same_as_base"] for p in points),
                       "all_same_as_libyaml": all(p["same_as_libyaml"] for p in points)}}
    OUT.mkdir(exist_ok=True)
    with atomic_path(OUT / "scene_read_ab.json") as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1))
    plot(res, OUT / "scene_read_ab.png")
    print(json.dumps(res["summary"], indent=1))


if __name__ == "__main__":
    main()
