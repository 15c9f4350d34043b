"""Printer profiles: every dimension of the printed mechanism that depends on the printer.

All lengths in millimetres.  The built-in defaults follow published design guidance for
each process (service-bureau design rules for minimum wall, minimum feature/hole size and
moving-part clearance) and, for ``mjp``, the paper's own print (ProJet 3500, sigma = 5 mm,
0.2 mm clearance between parts and between consecutive knuckles).

Fields
------
sigma_mm          the length of sigma (the muscle rest length) in mm: the scene's scale
clearance         radial clearance of every hinge and minimum gap between distinct parts
knuckle_gap       axial gap between consecutive knuckles of one hinge
slab_thickness    printed slab thickness (the paper's 0.01 sigma is far below any minimum wall)
min_wall          minimum wall: slabs, the wall around a pin hole, lug rings
min_feature       minimum feature: knuckle length, lug hole diameter
pin_diameter      hinge pin diameter (>= min_feature)
circular_segments polygon segments of every cylinder (never manifold3d's default)
pin               "pin" (a straight pin through the knuckles) or "cone" (45 degree cone pins)
orient            "auto" (the up direction, of the world axes and slab normals, with the least
                  support and most bed contact), "auto_config" (the same, and the configuration of
                  the mechanism its joints reach with the best bed: mlc.mesh.configs), "axes_flat"
                  (hinge axes flat on the bed) or "as_is"

A profile is a built-in name or a YAML/JSON file validated against
``mlc/schemas/profile.schema.json``; command-line overrides replace single values.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

from mlc.errors import MlcError


@dataclass(frozen=True)
class Profile:
    name: str
    sigma_mm: float
    clearance: float
    knuckle_gap: float
    slab_thickness: float
    min_wall: float
    min_feature: float
    pin_diameter: float
    circular_segments: int = 32
    pin: str = "pin"
    orient: str = "as_is"
    description: str = ""

    def to_dict(self) -> dict:
        return asdict(self)

    def check(self, where: str = "profile") -> "Profile":
        """Reject values no print can use (non-positive sizes, too few segments)."""
        for f in ("sigma_mm", "slab_thickness", "min_wall", "min_feature", "pin_diameter"):
            v = getattr(self, f)
            if not (isinstance(v, (int, float)) and v > 0 and v == v and v != float("inf")):
                raise MlcError(f"profile {self.name}: {f} must be a positive number, got {v!r}", where)
            if f != "sigma_mm" and v < MIN_SIZE_MM:
                raise MlcError(f"profile {self.name}: {f} {v:g} mm is below {MIN_SIZE_MM:g} mm", where,
                               "finer than any of the printers mlc targets resolve (MJP, SLA, FDM: 0.02 mm and up)")
        for f in ("clearance", "knuckle_gap"):
            v = getattr(self, f)
            if not (isinstance(v, (int, float)) and v >= 0 and v == v and v != float("inf")):
                raise MlcError(f"profile {self.name}: {f} must be a number >= 0, got {v!r}", where)
        if not isinstance(self.circular_segments, int) or self.circular_segments < 8:
            raise MlcError(f"profile {self.name}: circular_segments must be an integer >= 8, "
                           f"got {self.circular_segments!r}", where)
        if self.pin not in PIN_KINDS:
            raise MlcError(f"profile {self.name}: pin must be one of {', '.join(PIN_KINDS)}, got {self.pin!r}", where)
        if self.orient not in ORIENTS:
            raise MlcError(f"profile {self.name}: orient must be one of {', '.join(ORIENTS)}, got {self.orient!r}",
                           where)
        return self


#: smallest printed size accepted (mm)
MIN_SIZE_MM = 0.01
PIN_KINDS = ("pin", "cone")
ORIENTS = ("as_is", "axes_flat", "auto", "auto_config")

#: the paper printed 0.1 mm slabs at sigma = 5 mm (0.02 sigma); the simulations use 0.01 sigma.
PAPER_SLAB_MM = 0.1

PROFILES: dict[str, Profile] = {
    "mjp": Profile(
        "mjp", sigma_mm=5.0, clearance=0.2, knuckle_gap=0.2, slab_thickness=0.6, min_wall=0.6,
        min_feature=0.5, pin_diameter=0.6, circular_segments=32, pin="pin", orient="as_is",
        description="MultiJet (ProJet 3500, acrylic with wax support), the paper's print: sigma 5 mm, "
                    "0.2 mm clearance; PolyJet/MJP guidance: walls >= 0.6 mm, holes/features >= 0.5 mm"),
    "sla": Profile(
        "sla", sigma_mm=8.0, clearance=0.3, knuckle_gap=0.3, slab_thickness=0.8, min_wall=0.5,
        min_feature=0.5, pin_diameter=0.8, circular_segments=32, pin="pin", orient="as_is",
        description="resin SLA/MSLA: loose clearance ~0.3 mm, walls >= 0.5 mm (0.8 mm supported), "
                    "holes/features >= 0.5 mm; supports required"),
    "fdm": Profile(
        "fdm", sigma_mm=20.0, clearance=0.4, knuckle_gap=0.4, slab_thickness=1.2, min_wall=1.2,
        min_feature=2.0, pin_diameter=3.0, circular_segments=32, pin="pin", orient="auto",
        description="filament FDM, 0.4 mm nozzle: moving-part clearance ~0.4 mm, walls >= 1.2 mm, "
                    "holes/features >= 2 mm, pins >= 3 mm; oriented for the least support"),
}

FIELD_NAMES = tuple(f.name for f in fields(Profile))
OVERRIDABLE = ("sigma_mm", "clearance", "knuckle_gap", "slab_thickness", "min_wall", "min_feature",
               "pin_diameter", "circular_segments", "pin", "orient")


def load_profile(spec: str | None = None, overrides: dict | None = None, *, where: str = "--profile") -> Profile:
    """A built-in profile name or a profile file (YAML or JSON), then ``overrides``.

    A file may set ``base: mjp`` to start from a built-in profile and change some values.
    """
    spec = spec or "mjp"
    if spec in PROFILES:
        prof = PROFILES[spec]
    else:
        path = Path(spec)
        if not path.exists():
            raise MlcError(f"unknown printer profile {spec!r}", where,
                           f"use one of {', '.join(PROFILES)} or a profile file")
        prof = profile_from_file(path)
    if overrides:
        clean = {k: v for k, v in overrides.items() if v is not None}
        for k in clean:
            if k not in OVERRIDABLE:
                raise MlcError(f"profile has no overridable value {k!r}", where)
        if "circular_segments" in clean:
            clean["circular_segments"] = int(clean["circular_segments"])
        for k in ("sigma_mm", "clearance", "knuckle_gap", "slab_thickness", "min_wall", "min_feature",
                  "pin_diameter"):
            if k in clean:
                clean[k] = float(clean[k])
        prof = replace(prof, **clean)
    return prof.check(where)


def profile_from_file(path) -> Profile:
    from mlc.io import yamlsrc
    from mlc.io.schema import load_schema, validate

    path = Path(path)
    text = yamlsrc.read_text(path, "profile")
    if path.suffix.lower() == ".json":
        data = yamlsrc.load_json(text, str(path))
    else:
        data = yamlsrc.load(text, str(path))
    if not isinstance(data, dict):
        raise MlcError("a profile file must be a mapping", str(path))
    validate(data, load_schema("profile"), str(path))
    data = {str(k): _plain(v) for k, v in data.items()}
    base = PROFILES[data.pop("base", "mjp")]
    values = base.to_dict()
    values.update(data)
    values.setdefault("name", path.stem)
    if "name" not in data:
        values["name"] = path.stem
    return Profile(**values).check(str(path))


def _plain(v):
    if isinstance(v, bool):
        return v
    if isinstance(v, int):
        return int(v)
    if isinstance(v, float):
        return float(v)
    if isinstance(v, str):
        return str(v)
    return v


#: largest sigma accepted (mm): a gate is about 3.6 sigma across, so 1000 mm makes a 3.6 m gate
MAX_SIGMA_MM = 1000.0
#: most polygon segments per circle (a 3 mm pin at 256 segments is within 0.0001 mm of a circle)
MAX_SEGMENTS = 256
MAX_MECHANISM_BODIES = 3000  # larger mechanisms are refused (check_against_scene).  Measured (session 12,
                             # benchmarks/results/mesh_circuit.json, 2 shared cores at load 3-4): the Tetris
                             # circuit (1628-body mechanism) 11 min, 2.96 GB; the Tetris robot (a mechanism of
                             # about 2450 bodies) 22 min (8.4 of them static poses), 4.4 GB (docs/printing.md);
                             # session 52: the 2404-body robot 1:32:11 and 6.0 GB at load 4-7
                             # (robot_mesh_s52.json).  2500 until session 53: the Tetris robot with branch
                             # trees (one mechanism of 2669 bodies) was refused, and the README's job with it
#: memory an export may always plan to use (bytes); see :func:`memory_budget`
MEMORY_BUDGET = 2 * 2 ** 30


def memory_budget() -> float:
    """Bytes an export may plan to use: half the memory available now (Linux: MemAvailable in
    /proc/meminfo), and never less than :data:`MEMORY_BUDGET` (2 GiB)."""
    avail = 0.0
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    avail = float(line.split()[1]) * 1024
                    break
    except (OSError, ValueError, IndexError):
        pass
    return max(float(MEMORY_BUDGET), 0.5 * avail)


def _widths(scene) -> tuple[float, float]:
    """(narrowest slab width, extent of the scene), in sigma.  A slab is a plate: a box whose
    thickness is at most half its width (its middle edge length); bars of square section (the
    posts of compiled circuits' connectors, 0.08 x 0.08 sigma) are not slabs and carry no hinge
    knuckles of their own.  Without plates, every box counts."""
    import numpy as np
    widths, bars, lo, hi = [], [], [], []
    for b in scene.bodies:
        for x in b.boxes:
            w = sorted(float(v) for v in x.size)
            (widths if w[0] <= 0.5 * w[1] else bars).append(w[1])
            c = np.asarray(b.position, float) + np.asarray(x.center, float)
            r = 0.5 * float(np.linalg.norm(x.size))
            lo.append(c - r)
            hi.append(c + r)
    widths = widths or bars
    if not widths:
        return 0.0, 0.0
    ext = np.max(hi, axis=0) - np.min(lo, axis=0)
    return min(widths), ext


def _mechanisms(scene) -> tuple[list[list], int]:
    """(the bodies of each distinct mechanism, number of mechanisms).  Bodies joined by bonds or
    muscles form a mechanism; mechanisms equal up to a translation are built once (as
    mlc.mesh.pipeline does; here compared by their bodies' boxes and relative positions)."""
    import numpy as np
    idx = {b.name: i for i, b in enumerate(scene.bodies)}
    parent = list(range(len(scene.bodies)))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for it in list(scene.bonds) + list(scene.muscles):
        a, b = idx.get(it.a.split(".")[0]), idx.get(it.b.split(".")[0])
        if a is not None and b is not None:
            parent[find(a)] = find(b)
    groups: dict = {}
    for i in range(len(scene.bodies)):
        groups.setdefault(find(i), []).append(scene.bodies[i])
    distinct = {}
    for bodies in groups.values():
        p0 = np.asarray(bodies[0].position, float)
        key = tuple((tuple(np.round(np.asarray(b.position, float) - p0, 6)),
                     tuple(tuple(np.round(np.asarray(x.size, float), 6)) for x in b.boxes)) for b in bodies)
        distinct.setdefault(key, bodies)
    return list(distinct.values()), len(groups)


def _body_cells(b, prof: Profile) -> float:
    """Cells of the voxel wall check's grid (spacing min_wall / 8) over one body, uncapped."""
    import numpy as np
    lo = np.min([np.asarray(x.center, float) - 0.5 * np.asarray(x.size, float) for x in b.boxes], axis=0)
    hi = np.max([np.asarray(x.center, float) + 0.5 * np.asarray(x.size, float) for x in b.boxes], axis=0)
    size = np.maximum((hi - lo) * prof.sigma_mm, prof.slab_thickness)
    return float(np.prod(size / (prof.min_wall / 8) + 5))


_WALL_CELLS = 6e6       # mlc.mesh.walls.MAX_CELLS


#: bytes a body for the bed check (mlc.mesh.printability.bed_stats rasterises every triangle of
#: the print at once: the Tetris circuit went from 1.68 to 2.94 GB there, 2.82 M triangles, 1631
#: bodies, about 0.77 MB a body); fitted with a margin on the compiled circuits (session 14)
BED_BYTES_PER_BODY = 1.2e6

#: bytes a body for its meshes and the working copies of the build and checks; 0.8 MB until
#: session 44, when the Tetris circuit (1623 bodies) peaked at 4.13 GB against an estimate of 3.64
#: (session 14: 3.26 GB for 1631 bodies; the growth in between was not isolated)
MESH_BYTES_PER_BODY = 1.3e6

#: measured peak resident memory (bytes) of ``mlc stl`` at mjp: (case, bodies, peak); the test of
#: :func:`estimate_memory` checks the estimate stays above each (tests/test_mesh_profiles.py).
#: ``a & b``: session 14; ``(a & b) | c``: session 44 (``/usr/bin/time -v``, code 2dcd5be, chains
#: ending under the levers; beside the test suite and another job); the Tetris circuit: session 52
#: (its fan-outs as branch trees, 1651 bodies; ``/usr/bin/time -v`` of ``mlc stl`` run in-process
#: through ``mlc.cli.main`` with a JSON dump of the report, code of 9b52683, at load 4-7; session 44's
#: k-way build, 1623 bodies, peaked at 4.133e9; session 53: 1763 bodies (PRINT_LEANS), 4.423e9 by
#: ``/usr/bin/time -v`` of ``mlc stl ... --force`` through ``mlc.cli.main``, at load 5-7; session 52's
#: build, 1651 bodies, peaked at 4.242e9)
MEASURED_PEAKS = (("gate a & b", 8, 0.229e9), ("(a & b) | c", 136, 0.540e9), ("examples/tetris.tt", 1763, 4.423e9))


def estimate_memory(prof: Profile, scene) -> dict:
    """Rough peak memory (bytes) of an export of ``scene`` at ``prof``, from the sizes in mm.

    Counted: the sample points on the mid-planes of the slabs of each distinct mechanism
    (spacing as in mlc.mesh.build, about 100 bytes a point with the copies made while trimming),
    the voxel grid of the wall check (one part at a time, at most 6e6 cells, about 40 bytes a
    cell), the support-column grid of the bed check over the whole print (spacing
    ``max(0.05, min(min_wall, size/150))`` mm, about 300 bytes a column),
    :data:`MESH_BYTES_PER_BODY` of meshes and working copies per body, :data:`BED_BYTES_PER_BODY` for the bed check's raster of every triangle of the print at
    once, and a fixed 250 MB.  Measured peaks (NAND at sigma 20 mm: 0.50 GB, estimate 0.51; grids of
    9 and 36 NAND at mjp: 0.24 and 0.41 GB, estimates 0.41 and 0.87; a grid of 900 NAND is
    estimated at 15.3 GB and refused).  Compiled circuits at mjp, ``mlc stl`` (``/usr/bin/time -v``,
    session 14): ``a & b`` (8 bodies) 0.23 GB, estimate 0.30; ``(a & b) | c`` (144 bodies) 0.49 GB
    (0.39 before the states check loaded numba), estimate 0.57; the Tetris circuit (1631 bodies)
    3.26 GB (3.09 with the session-13 checks), its peak in the bed check (1.75 GB resident before
    it), estimate 3.66 (1.70 before the bed term).  Session 44 (the chains ending under the
    levers): ``(a & b) | c`` (136 bodies) 0.54 GB, the Tetris circuit (1623 bodies) 4.13 GB, which the
    estimate then missed (3.64) until :data:`MESH_BYTES_PER_BODY` went from 0.8 to 1.3 MB (now
    0.63 and 4.45).  :data:`MEASURED_PEAKS` lists them for the test."""
    import numpy as np
    s = prof.sigma_mm
    t = prof.slab_thickness
    c = prof.clearance
    h = float(np.clip(max(min(t, c) if c > 0 else t, 0.015 * s), 0.05, 0.5))
    reps, _ = _mechanisms(scene)
    n = 0.0
    cells = 0.0
    for bodies in reps:
        for b in bodies:
            cells = max(cells, min(_body_cells(b, prof), _WALL_CELLS))
            for x in b.boxes:
                w = sorted(float(v) * s for v in x.size)
                n += (w[1] / h + 2) * (w[2] / h + 2)
    _, ext = _widths(scene)
    size = np.sort(np.asarray(ext, float) * s)
    hb = max(0.05, min(prof.min_wall, float(size[-1]) / 150))
    cols = (size[-1] / hb + 2) * (size[-2] / hb + 2)
    total = 100.0 * n + 40.0 * cells + 300.0 * cols + (MESH_BYTES_PER_BODY + BED_BYTES_PER_BODY) * len(scene.bodies) + 250e6
    return {"bytes": total, "samples": n, "sample_step_mm": h, "columns": cols, "column_step_mm": hb}


def estimate_seconds(prof: Profile, scene) -> float:
    """A rough duration (s) of an export with its checks, for the progress line's ETA.

    For each distinct mechanism half a second per body (building, trimming, posing) plus the
    voxel wall check: three distance transforms per part on a grid of spacing ``min_wall / 8``
    (at most 6e6 cells), about 1.4e-7 s a cell; 0.15 s for each copy of a mechanism.  Measured on
    a loaded 2-core machine: NAND at mjp about 5 s (estimate 4.5), with every grid at its cap 22 s
    (24); grids of 9 and 36 NAND 12 and 16 s (estimates 5.7 and 9.8); with cone pins 105 s
    (:data:`CONE_SLOWDOWN`: 104)."""
    reps, count = _mechanisms(scene)
    t = 0.0
    for bodies in reps:
        for b in bodies:
            t += (0.5 * CONE_SLOWDOWN if prof.pin == "cone" else 0.5) + \
                3 * min(_body_cells(b, prof), _WALL_CELLS) * 1.4e-7
    return t + 0.15 * (count - len(reps))


#: cone pins make building and trimming much slower (NAND, mjp, no states: 105 s against 4 s)
CONE_SLOWDOWN = 25.0


def check_against_scene(prof: Profile, scene, where: str = "--profile", options: dict | None = None) -> None:
    """Check the profile's sizes against the scene's geometry before any mesh is built.

    ``options`` maps a field to the command-line option that set it (``{"clearance":
    "--clearance"}``): an error names that option, else ``where``.  Refused (:class:`MlcError`
    naming the value, and the smallest ``sigma_mm`` at which the rest of the profile fits):

    * ``sigma_mm`` above :data:`MAX_SIGMA_MM`, ``circular_segments`` above :data:`MAX_SEGMENTS`;
    * a minimum feature or pin wider than the narrowest slab (its width in mm is ``sigma_mm``
      times its width in sigma), or a slab thickness, wall, clearance or knuckle gap of more than
      half of it: the parts would not fit between each other (a 2 mm slab on the 2.5 mm slabs of
      NAND at sigma 5 mm ran for more than 30 s; 1.2 mm took 6 s);
    * a knuckle gap below the clearance (knuckles of different parts closer than the clearance);
    * hinges wider across (pin + 2 clearance + 2 walls) than the narrowest slab: the knuckles of
      neighbouring hinges would overlap, and the trimming that follows runs for minutes (NAND at
      sigma 4 mm: more than 30 s and 0.8 GB; at 5 mm, 2.2 mm hinges on 2.5 mm slabs: 4 s);
    * an estimated peak memory (:func:`estimate_memory`) above :func:`memory_budget`.
    """
    options = options or {}

    def opt(f):
        return options.get(f, where)

    s = prof.sigma_mm
    if s > MAX_SIGMA_MM:
        raise MlcError(f"sigma_mm {s:g} mm is larger than {MAX_SIGMA_MM:g} mm (a gate would be "
                       f"{3.6 * s / 1000:.3g} m across)", opt("sigma_mm"),
                       "printers build parts up to about 1 m; use a smaller sigma_mm")
    if prof.circular_segments > MAX_SEGMENTS:
        raise MlcError(f"circular_segments {prof.circular_segments} is more than {MAX_SEGMENTS}",
                       opt("circular_segments"),
                       f"{MAX_SEGMENTS} segments already keep a 10 mm circle within 0.001 mm; use 32 to {MAX_SEGMENTS}")
    w_sigma, _ = _widths(scene)
    if w_sigma <= 0:
        return
    W = w_sigma * s
    at = f"the narrowest slab of {scene.name} is {W:.3g} mm wide ({w_sigma:.3g} sigma at sigma_mm {s:g})"
    pin = max(prof.pin_diameter, prof.min_feature)
    hinge = pin + 2 * prof.clearance + 2 * prof.min_wall
    limits = [(f, part, getattr(prof, f), f"{f} {getattr(prof, f):g} mm is {what}")
              for f, part, what in (("min_feature", 1.0, "wider than the slabs"),
                                    ("pin_diameter", 1.0, "wider than the slabs"),
                                    ("slab_thickness", 0.5, "more than half the slab width"),
                                    ("min_wall", 0.5, "more than half the slab width"),
                                    ("clearance", 0.5, "more than half the slab width"),
                                    ("knuckle_gap", 0.5, "more than half the slab width"))]
    limits.append(("hinge", 1.0, hinge, f"hinges {hinge:.3g} mm across (pin {pin:g} + 2 x clearance "
                   f"{prof.clearance:g} + 2 x min_wall {prof.min_wall:g}) are wider than the slabs they join"))
    s_min = max(v / (part * w_sigma) for _f, part, v, _m in limits)
    for f, part, v, msg in limits:
        if v > part * W * (1 + 1e-9):
            if f == "hinge" or (f not in options and "sigma_mm" in options):
                fix = f"use sigma_mm >= {s_min:.3g}"
                if f == "hinge":
                    fix += ", or a smaller pin, clearance or min_wall"
                f = f if f in options else "sigma_mm"
            else:
                fix = f"use {f} <= {part * W:.3g} mm, or sigma_mm >= {s_min:.3g}"
            raise MlcError(f"{msg}: {at}", opt(f), fix)
    if prof.knuckle_gap < prof.clearance:
        f = "clearance" if "clearance" in options and "knuckle_gap" not in options else "knuckle_gap"
        raise MlcError(f"knuckle_gap {prof.knuckle_gap:g} mm is less than the clearance {prof.clearance:g} mm: "
                       f"consecutive knuckles belong to different parts, which must stay a clearance apart "
                       f"(every knuckle would be trimmed: a single hinge then takes 20 s instead of 2 s)", opt(f),
                       f"use knuckle_gap >= {prof.clearance:g} mm" if f == "knuckle_gap" else
                       f"use clearance <= {prof.knuckle_gap:g} mm, or raise knuckle_gap with it")
    reps, _ = _mechanisms(scene)
    largest = max((len(b) for b in reps), default=0)
    if largest > MAX_MECHANISM_BODIES:
        raise MlcError(f"one mechanism of this scene has {largest} bodies; mlc meshes mechanisms of at most "
                       f"{MAX_MECHANISM_BODIES} (measured on 2 shared cores: the Tetris circuit's 1628 bodies take "
                       f"11 min at 3.0 GB, the Tetris robot's 2404 bodies 1.5 h at 6.0 GB; "
                       f"docs/printing.md, 'Compiled circuits')",
                       "TARGET", "mesh the library gates on their own (mlc stl NAND), or a circuit of fewer gates")
    est = estimate_memory(prof, scene)
    budget = memory_budget()
    if est["bytes"] > budget:
        raise MlcError(f"this export would need about {est['bytes'] / 2 ** 30:.3g} GiB of memory "
                       f"({est['samples']:.3g} slab samples {est['sample_step_mm']:.2g} mm apart, "
                       f"{est['columns']:.3g} support columns {est['column_step_mm']:.2g} mm apart, "
                       f"{len(scene.bodies)} bodies); the limit is {budget / 2 ** 30:.3g} GiB (half the memory "
                       f"available, at least 2 GiB)", opt("sigma_mm"),
                       "use a smaller sigma_mm, or mesh the circuit in parts")
