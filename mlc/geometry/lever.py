r"""Scissor levers (paper Eq. 2, Fig. 2B), derived from first principles.

A lever is two rigid bodies joined by one hinge, the pivot ``P``.  Body 1 carries the
upper input end ``A1`` at distance ``l1`` from ``P`` and one output end ``B1`` at
distance ``l2``; body 2 is its mirror image about the lever's axis.  In the rest
state the input ends are ``A1,2 = (-l1 cos t1, +-l1 sin t1)`` and the output ends
``(l2 cos t2, +-l2 sin t2)`` relative to ``P``, so that

    input length  = 2 l1 sin(t1),      output length = 2 l2 sin(t2),
    horizontal length l = l1 cos t1 + l2 cos t2 .

Rotating body 1 by ``dt`` (body 2 by ``-dt``) turns the input half-angle into
``t1 + dt``.  If body 1 carries the *upper* output end (``B1`` on the same side
as ``A1``: the *open* hinge, a bent "V" body) the output half-angle becomes
``t2 - dt``: the lever inverts expansion and contraction.  If body 1 carries the
*lower* output end (the *crossed* hinge, an "X"), it becomes ``t2 + dt``: the
lever keeps the direction.  The five equations are therefore

    l1 sin t1        = l_in / 2
    l2 sin t2        = l_out / 2
    l1 sin(t1 + dt)  = (l_in + dl_in) / 2
    l2 sin(t2 +- dt) = (l_out + dl_out) / 2       (+ crossed, - open)
    l1 cos t1 + l2 cos t2 = l

The paper prints the first two lines with ``l_in`` and ``l_out`` instead of their
halves; with its own next two lines that would make the lever's signal a factor 2
off.  The half-length form above is the one the kinematics (and the simulated
gates) obey.

Solution: for a trial ``t1``, lines 1, 3 and 5 give ``l1``, ``dt``, ``l2``, ``t2``
in closed form, and line 4 is a residual in ``t1`` alone, bracketed on a scan of
(0, pi/2).  The physical branch keeps every half-angle, at rest and actuated, in
(0, pi/2): the lever never passes through its flat or folded singularities, so
its transfer is monotonic between the two states.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mlc.errors import MlcError

LEVER_TYPES = ("open", "crossed")


@dataclass(frozen=True)
class LeverSolution:
    """A solved scissor lever (lengths in sigma, angles in radians)."""

    type: str
    lin: float
    lout: float
    dlin: float
    dlout: float
    l: float
    theta1: float
    theta2: float
    l1: float
    l2: float
    dtheta: float

    @property
    def sign(self) -> int:
        return 1 if self.type == "crossed" else -1

    def residuals(self) -> np.ndarray:
        t1, t2, l1, l2, dt = self.theta1, self.theta2, self.l1, self.l2, self.dtheta
        return np.array([
            l1 * np.sin(t1) - self.lin / 2,
            l2 * np.sin(t2) - self.lout / 2,
            l1 * np.sin(t1 + dt) - (self.lin + self.dlin) / 2,
            l2 * np.sin(t2 + self.sign * dt) - (self.lout + self.dlout) / 2,
            l1 * np.cos(t1) + l2 * np.cos(t2) - self.l,
        ])

    def output_length(self, input_length: float) -> float:
        """Kinematic transfer: output length for a given input length (sigma)."""
        s = input_length / (2 * self.l1)
        if not 0 < s < 1:
            raise MlcError(f"input length {input_length} is outside the lever's reach 0..{2*self.l1:.4f}")
        dt = np.arcsin(s) - self.theta1
        return 2 * self.l2 * np.sin(self.theta2 + self.sign * dt)

    def to_dict(self) -> dict:
        return {"type": self.type, "lin": self.lin, "lout": self.lout, "dlin": self.dlin,
                "dlout": self.dlout, "l": self.l, "theta1": float(self.theta1),
                "theta2": float(self.theta2), "l1": float(self.l1), "l2": float(self.l2),
                "dtheta": float(self.dtheta)}


def lever_type_for(dlin: float, dlout: float) -> str:
    """The lever type that maps an input change ``dlin`` to an output change ``dlout``."""
    return "crossed" if dlin * dlout > 0 else "open"


T_MIN = 1e-4          # rad: the smallest half-angle the lever scan considers


def solve_lever(lin: float, lout: float, dlin: float, dlout: float, l: float,
                type: str | None = None) -> LeverSolution:
    """Solve Eq. 2 (half-length form) for a lever of the given type.

    ``type`` defaults to the one the signs of ``dlin``/``dlout`` require; asking for
    the other type is infeasible and reported as such.
    """
    for name, v in (("--lin", lin), ("--lout", lout), ("--l", l)):
        if not np.isfinite(v) or v <= 0:
            raise MlcError(f"must be a positive length in sigma, got {v}", name)
    for name, v, rest in (("--dlin", dlin, lin), ("--dlout", dlout, lout)):
        if not np.isfinite(v) or v == 0:
            raise MlcError(f"the signal must be non-zero, got {v}", name)
        if rest + v <= 0:
            raise MlcError(f"the actuated length {rest}+({v}) is not positive", name)
    from scipy.optimize import brentq  # lazy: keeps `import mlc...` fast

    need = lever_type_for(dlin, dlout)
    type = type or need
    if type not in LEVER_TYPES:
        raise MlcError(f"unknown lever type {type!r}", "--type", "use open or crossed")
    if type != need:
        what = "inverts" if type == "open" else "keeps"
        article = "an" if type == "open" else "a"
        raise MlcError(f"{article} {type}-hinge lever {what} the signal direction, but dlin={dlin} and "
                       f"dlout={dlout} ask for the opposite", "--type", f"use --type {need}")
    sign = 1 if type == "crossed" else -1
    lin1, lout1 = lin + dlin, lout + dlout

    def parts(t1):
        l1 = lin / (2 * np.sin(t1))
        r = (lin1 / lin) * np.sin(t1)
        if not 0 < r < 1:
            return None
        dt = np.arcsin(r) - t1
        R = l - l1 * np.cos(t1)
        if R <= 0:
            return None
        return l1, np.hypot(lout / 2, R), np.arctan2(lout / 2, R), dt

    def g(t1):
        p = parts(t1)
        if p is None:
            return np.nan
        l1, l2, t2, dt = p
        return l2 * np.sin(t2 + sign * dt) - lout1 / 2

    # log-spaced near 0 (long levers have small angles), linear beyond
    ts = np.unique(np.concatenate([np.geomspace(T_MIN, 0.05, 400), np.linspace(0.05, np.pi / 2 - T_MIN, 2000)]))
    vs = np.array([g(t) for t in ts])
    sols = []
    for i in range(len(ts) - 1):
        if np.isfinite(vs[i]) and np.isfinite(vs[i + 1]) and np.sign(vs[i]) * np.sign(vs[i + 1]) < 0:
            t1 = brentq(g, ts[i], ts[i + 1], xtol=1e-15, maxiter=200)
            l1, l2, t2, dt = parts(t1)
            angles = (t1, t2, t1 + dt, t2 + sign * dt)
            if all(0 < a < np.pi / 2 for a in angles):
                margin = min(min(a, np.pi / 2 - a) for a in angles)
                sols.append((margin, LeverSolution(type, lin, lout, dlin, dlout, l, t1, t2, l1, l2, dt)))
    if not sols:
        # the scan covers half-angles from T_MIN: a lever so long that its angles (~ length / l)
        # fall below that is not solved, and a longer one would not help
        l_max = min(lin, lin1, lout, lout1) / (2.0 * np.tan(T_MIN))
        fix = (f"--l is too long for these lengths (its angles would fall below {T_MIN:g} rad): use --l of at "
               f"most {l_max:.4g} sigma" if l > l_max else "a longer lever (larger --l) or smaller signals make it "
               "feasible")
        raise MlcError(
            f"no {type}-hinge lever maps {lin}->{lin1} onto {lout}->{lout1} with horizontal length l={l}",
            "--l", fix)
    return max(sols, key=lambda ms: ms[0])[1]
