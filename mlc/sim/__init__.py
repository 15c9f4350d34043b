"""sim: the Brownian-dynamics engine (``integrator``: state and run loop, ``kernels``: the
compiled force and step kernels, ``drive``: muscle drives, ``output``: trajectories).  This
module itself stays light (no numba), so commands can check their options before loading it."""
from __future__ import annotations

import math

from mlc.errors import MlcError

MAX_KT = 10.0                # k0 sigma^2: a bond's thermal stretch sqrt(kT/k) is then 3 sigma, past any mechanism
                             # (gates melt from about 1e-2, with a warning); far beyond, the noise overflows


def check_kT(kT, option: str = "--kT") -> float:
    """``kT`` (k0 sigma^2) as a float, or one :class:`MlcError` naming ``option``: it must be a
    finite number from 0 to :data:`MAX_KT`."""
    try:
        v = float(kT)
    except (TypeError, ValueError):
        v = float("nan")
    if not (math.isfinite(v) and 0 <= v <= MAX_KT):
        raise MlcError(f"kT must be finite and from 0 to {MAX_KT:g} (k0 sigma^2), got {kT}", option,
                       "the paper's temperature is 1e-5; gates stop computing from about 1e-2")
    return v
