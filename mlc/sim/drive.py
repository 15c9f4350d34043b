"""Drives: the time course of each named input (muscle rest length follows it).

A drive gives u(t): 0 = the muscles of the input at ``rest``, 1 = ``actuated``,
fractions interpolate the rest length linearly.  Times are in t0 = gamma/(1e-3 k0).

* ``Drive.constant(v)``                       u = v
* ``Drive.step(at, before=0, after=1)``       a switch at time ``at``
* ``Drive.square(period, duty=0.5, start=0, low=0, high=1)``
                                              high for the first ``duty`` of each period from ``start``
* ``Drive.table(times, values)``              piecewise linear, constant outside

Text form (``--set``/``--drive`` on the command line): ``0``, ``1``, ``0.3``,
``step:T[:BEFORE:AFTER]``, ``square:PERIOD[:DUTY[:START]]``, ``table:T0=V0,T1=V1,...``.
Its values must lie in [0, 1] (:data:`LOW`, :data:`HIGH`): past them a muscle would be driven
beyond its rest or actuated length, which no mechanism is designed for.  The constructors
accept any finite value (tests push a gate past its actuated length on purpose).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mlc.errors import MlcError

KINDS = {"constant": 0, "step": 1, "square": 2, "table": 3}
LOW, HIGH = 0.0, 1.0          # the values a drive given as text may take: muscles at rest .. actuated


def _finite(kind: str, *nums: float) -> tuple:
    """``nums`` as floats, or an error if one is nan or infinite (a drive must say when and what)."""
    nums = tuple(float(x) for x in nums)
    if not all(np.isfinite(nums)):
        raise MlcError(f"{kind} drive: every time and value must be a finite number, got "
                       f"{':'.join(f'{x:g}' for x in nums)}", "drive", "give times in t0 and values such as 0 or 1")
    return nums


@dataclass(frozen=True)
class Drive:
    kind: str
    params: tuple = ()
    times: tuple = field(default=())
    values: tuple = field(default=())

    # -- constructors -------------------------------------------------------
    @staticmethod
    def constant(v: float) -> "Drive":
        return Drive("constant", _finite("constant", float(v)))

    @staticmethod
    def step(at: float, before: float = 0.0, after: float = 1.0) -> "Drive":
        return Drive("step", _finite("step", float(at), float(before), float(after)))

    @staticmethod
    def square(period: float, duty: float = 0.5, start: float = 0.0, low: float = 0.0, high: float = 1.0) -> "Drive":
        _finite("square", period, duty, start, low, high)
        if not period > 0:
            raise MlcError(f"square drive: period must be > 0, got {period}", "drive", "give a positive period in t0")
        if not 0.0 <= duty <= 1.0:
            raise MlcError(f"square drive: duty must be in [0, 1], got {duty}", "drive")
        return Drive("square", (float(period), float(duty), float(start), float(low), float(high)))

    @staticmethod
    def table(times, values) -> "Drive":
        t = [float(x) for x in times]
        v = [float(x) for x in values]
        if not t or len(t) != len(v):
            raise MlcError("table drive: need as many values as times (at least one)", "drive")
        if any(b <= a for a, b in zip(t, t[1:])):
            raise MlcError(f"table drive: times must increase strictly, got {t}", "drive")
        if not np.all(np.isfinite(t + v)):
            raise MlcError("table drive: times and values must be finite", "drive",
                           "give times in t0 and values such as 0 or 1")
        return Drive("table", (), tuple(t), tuple(v))

    @staticmethod
    def parse(text: str, where: str = "--set") -> "Drive":
        """The drive of a text form (module docstring); one :class:`MlcError` naming ``where`` if it
        cannot be read or takes a value outside [0, 1]."""
        s = text.strip()
        try:
            d = Drive._parse(s)
        except MlcError as e:          # a constructor's complaint, about this option
            raise MlcError(e.message, where, e.fix) from None
        except (ValueError, TypeError):
            raise MlcError(f"cannot read drive {text!r}", where,
                           "use 0, 1, step:T[:BEFORE:AFTER], square:PERIOD[:DUTY[:START]] "
                           "or table:T0=V0,T1=V1,... (times in t0)") from None
        out = [v for v in d.levels() if not LOW <= v <= HIGH]
        if out:
            raise MlcError(f"drive value {out[0]:g} is outside {LOW:g}..{HIGH:g}", where,
                           "0 holds the input's muscles at rest, 1 actuated, a fraction in between")
        return d

    @staticmethod
    def _parse(s: str) -> "Drive":
        if ":" not in s:
            return Drive.constant(float(s))
        kind, rest = s.split(":", 1)
        if kind == "step":
            p = [float(x) for x in rest.split(":")]
            if len(p) not in (1, 3):
                raise ValueError
            return Drive.step(*p)
        if kind == "square":
            p = [float(x) for x in rest.split(":")]
            if not 1 <= len(p) <= 5:
                raise ValueError
            return Drive.square(*p)
        if kind == "table":
            pairs = [x.split("=") for x in rest.split(",") if x]
            return Drive.table([float(a) for a, _ in pairs], [float(b) for _, b in pairs])
        raise ValueError

    def levels(self) -> tuple:
        """Every value the drive takes at a switch or table point (times left out)."""
        if self.kind == "constant":
            return self.params[:1]
        if self.kind == "step":
            return self.params[1:3]
        if self.kind == "square":
            return self.params[3:5]
        return self.values

    # -- evaluation (Python side, for tests and plots) ------------------------
    def value(self, t: float) -> float:
        p = self.params
        if self.kind == "constant":
            return p[0]
        if self.kind == "step":
            return p[1] if t < p[0] else p[2]
        if self.kind == "square":
            if t < p[2]:
                return p[3]
            return p[4] if ((t - p[2]) % p[0]) / p[0] < p[1] else p[3]
        return float(np.interp(t, self.times, self.values))

    def final(self) -> float:
        """The value the drive settles to (the last value it takes)."""
        if self.kind == "constant":
            return self.params[0]
        if self.kind == "step":
            return self.params[2]
        if self.kind == "table":
            return self.values[-1]
        return float("nan")


def pack_drives(drives: list[Drive], t_unit: float):
    """Arrays for the kernels; times converted from t0 to internal units (``t_unit`` per t0)."""
    n = len(drives)
    kind = np.zeros(n, dtype=np.int64)
    par = np.zeros((n, 5), dtype=np.float64)
    tt, tv = [], []
    for k, d in enumerate(drives):
        kind[k] = KINDS[d.kind]
        if d.kind == "constant":
            par[k, 0] = d.params[0]
        elif d.kind == "step":
            par[k, :3] = [d.params[0] * t_unit, d.params[1], d.params[2]]
        elif d.kind == "square":
            par[k, :] = [d.params[0] * t_unit, d.params[1], d.params[2] * t_unit, d.params[3], d.params[4]]
        else:
            par[k, 0] = len(tt)
            par[k, 1] = len(d.times)
            tt.extend(x * t_unit for x in d.times)
            tv.extend(d.values)
    if not tt:
        tt, tv = [0.0], [0.0]
    return kind, par, np.array(tt, dtype=np.float64), np.array(tv, dtype=np.float64)
