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
                  support and most bed contact), "axes_flat" (hinge axes flat on the bed) or "as_is"

A profile is a built-in name or a YAML/JSON file validated against
``mlc/schemas/profile.schema.json``; command-line overrides replace single values.
"""
from __future__ import annotations

import json
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


PIN_KINDS = ("pin", "cone")
ORIENTS = ("as_is", "axes_flat", "auto")

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
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        raise MlcError(f"cannot read profile: {e.strerror}", str(path)) from None
    if path.suffix.lower() == ".json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise MlcError(f"profile is not valid JSON: {e.msg}", f"{path}:{e.lineno}") from None
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
