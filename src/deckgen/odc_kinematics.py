"""The oscillating disc cutter's path as geometry: swept floor, removal rate and engaged contact (seed 003).

The disc (radius R, cutting edge a circle in its own plane x-z) moves forward at V while its centre circles the
eccentric shaft (radius e, angular speed w), as the decks do (``templates/lammps/cutting.lmp.j2``)::

    x_c = V t + e (cos w t - 1),   z_c = z_0 + s e sin w t      (s = +1 forward shaft sense, -1 backward)

with z_0 the centre's height above the rock surface: R - p at ``penetration_at: start`` and R - p + lift * e with
``orbit_lift_ratio`` lift (1 = ``orbit_bottom``, p the deepest cut of the orbit). In units of e the path depends on
nu = V / (e w) alone, and on e/R and p/R.

The rock is taken to fail exactly where the disc's circle passes and nowhere else, as seed 003 sec. 5.6.1 does for its
removal rates ("calculated from kinematics and assumes rock only fails at the positions at which the disc passes"):

- the **swept floor** is the deepest point any position of the circle reached in each column x. The circle's top is
  above the surface whenever p + (1 - lift) e < R, so the removed region in a column is the whole depth above the
  floor, and the removed area per unit travel is the mean floor depth (:func:`removal_ratio`: oscillating over
  straight, as seed 003 Table 5.2);
- the **engaged arc** at time t is the part of the circle below the surface that lies in rock no earlier position
  removed (its columns lie deeper than the floor swept so far). Its length, over the straight cut's R acos(1 - p/R),
  is a contact measure of the kind seed 003 sec. 5.4.3 names as the cause of the force drop ("the contact area during
  an oscillation cycle becomes smaller if backward motion occurs"); the fraction of the time it is non-zero is the
  geometric contact fraction (:func:`sweep`).

Chips, crushing ahead of the disc and the rate of loading are outside this model; docs/families.md (section "The ODC
path as geometry") sets it beside the bonded-particle runs. Written here because no library computes a swept
envelope of a moving circle; numpy does the per-column maxima.
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass

import numpy as np

#: seed 003 Table 5.2 (``../shared/data/grashof_removal_rate.csv``): eccentricity ratio e/R, rotation rev/s, forward
#: speed m/s, removal rate ratio (oscillating / straight). Disc radius 10 mm, depth 4 mm.
SEED003_TABLE52 = ((0.4, 22.5, 0.5, 1.1889), (0.4, 45.0, 0.5, 1.371), (0.4, 67.5, 0.5, 1.397), (0.2, 67.5, 0.5, 1.184))
SEED003_R_M = 0.010
SEED003_DEPTH_M = 0.004


@dataclass(frozen=True)
class Orbit:
    """One ODC path (SI). ``nu`` = V/(e w); ``lift`` raises the orbit's centre by lift * e (0 start, 1 orbit bottom)."""

    radius_m: float
    depth_m: float
    ecc_m: float
    nu: float
    lift: float = 0.0
    sense: float = 1.0

    def __post_init__(self):
        if not (0 < self.depth_m < self.radius_m):
            raise ValueError(f"Orbit: depth {self.depth_m} m must lie in (0, R = {self.radius_m} m)")
        if self.ecc_m < 0 or (self.ecc_m > 0 and self.nu <= 0):
            raise ValueError(f"Orbit: eccentricity {self.ecc_m} m needs nu > 0 (got {self.nu})")
        if not 0.0 <= self.lift <= 1.0:
            raise ValueError(f"Orbit: lift {self.lift} must lie in [0, 1] (fraction of e)")
        if self.depth_m + (1.0 - self.lift) * self.ecc_m >= self.radius_m:
            raise ValueError("Orbit: the deepest cut p + (1 - lift) e reaches the disc centre; the swept-floor model "
                             "needs it below R")

    @classmethod
    def from_rates(cls, radius_m: float, depth_m: float, ecc_m: float, speed_m_s: float, frequency_hz: float,
                   lift: float = 0.0, sense: float = 1.0) -> "Orbit":
        nu = speed_m_s / (ecc_m * 2 * math.pi * frequency_hz) if ecc_m > 0 else math.inf
        return cls(radius_m, depth_m, ecc_m, nu, lift, sense)

    @property
    def travel_per_cycle_m(self) -> float:
        return 2 * math.pi * self.ecc_m * self.nu if self.ecc_m > 0 else math.inf

    def centre(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Centre (x, z) at shaft angles ``theta`` = w t; z is the height above the rock surface. A straight cut
        (e = 0) takes theta as travel / R."""
        R, p, e = self.radius_m, self.depth_m, self.ecc_m
        if e == 0:
            return R * theta, np.full_like(theta, R - p)
        x = e * self.nu * theta + e * (np.cos(theta) - 1.0)
        z = R - p + self.lift * e + self.sense * e * np.sin(theta)
        return x, z


@dataclass(frozen=True)
class Sweep:
    """What :func:`sweep` measured over the steady cycles."""

    floor_mean_m: float  # mean swept floor depth over whole steady cycles = removed area per unit travel
    arc_mean_m: float  # mean engaged arc length
    contact_fraction: float  # fraction of the time with an engaged arc above the threshold
    arc_straight_m: float  # R acos(1 - p/R): the straight cut's engaged arc
    depth_m: float  # the straight cut's depth p

    @property
    def arc_ratio(self) -> float:
        """Mean engaged arc over the straight cut's."""
        return self.arc_mean_m / self.arc_straight_m

    @property
    def removal_ratio(self) -> float:
        """Removed area per unit travel over the straight cut's (seed 003 Table 5.2's rock removal rate)."""
        return self.floor_mean_m / self.depth_m


def straight_arc(radius_m: float, depth_m: float) -> float:
    return radius_m * math.acos(1.0 - depth_m / radius_m)


def sweep(orbit: Orbit, turns: int = 3, per_cycle: int = 2000, dx_m: float | None = None,
          contact_threshold: float = 0.01) -> Sweep:
    """Swept floor and engaged arc averaged over ``turns`` whole shaft turns, taken after the disc has moved 2R + 2e
    from its start (before that it cuts into a flat surface). ``dx_m``: column width (default R/2000);
    ``contact_threshold``: the engaged arc, as a fraction of the straight cut's, above which the disc counts as in
    contact. A straight cut (e = 0) averages over 2R of travel after the same lead-in."""
    R, e = orbit.radius_m, orbit.ecc_m
    dx = dx_m or R / 2000
    if e == 0:
        theta = np.linspace(0.0, 6.0, 3 * per_cycle + 1)  # theta = travel / R
        t0, t1 = 2.0, 4.0
    else:
        lam = orbit.travel_per_cycle_m
        n0 = math.ceil((2 * R + 2 * e) / lam)  # whole turns before the steady ones
        n = n0 + turns + math.ceil((R + 2 * e) / lam)  # the disc must also pass beyond the last steady columns
        theta = np.linspace(0.0, 2 * math.pi * n, n * per_cycle + 1)
        t0, t1 = 2 * math.pi * n0, 2 * math.pi * (n0 + turns)
    xc, zc = orbit.centre(theta)
    x = np.arange(xc.min() - R - dx, xc.max() + R + 2 * dx, dx)
    floor = np.zeros_like(x)
    arc = np.zeros(theta.size)
    for k in range(theta.size):
        i0, i1 = np.searchsorted(x, xc[k] - R), np.searchsorted(x, xc[k] + R)
        u = x[i0:i1] - xc[k]
        half = np.sqrt(np.maximum(R * R - u * u, 0.0))
        depth = half - zc[k]  # depth of the circle's lowest point in each column (negative: above the surface)
        cut = depth > floor[i0:i1] + 1e-12 * R
        if cut.any():  # arc length element ds = R / sqrt(R^2 - u^2) dx, capped at the circle's sides
            arc[k] = float(np.minimum(R / np.maximum(half[cut], 1e-9 * R), 50.0).sum() * dx)
        np.maximum(floor[i0:i1], depth, out=floor[i0:i1])
    a0 = straight_arc(R, orbit.depth_m)
    steady = (theta >= t0) & (theta < t1)
    # the floor over the columns of the steady turns: one travel per turn, starting where the centre was at t0
    x_lo = float(orbit.centre(np.array([t0]))[0][0])
    x_hi = float(orbit.centre(np.array([t1]))[0][0])
    cols = (x >= x_lo) & (x < x_hi)
    return Sweep(float(floor[cols].mean()), float(arc[steady].mean()),
                 float((arc[steady] > contact_threshold * a0).mean()), a0, orbit.depth_m)


def removal_ratio(orbit: Orbit, **kw) -> float:
    """Removed area per unit travel, oscillating over straight (seed 003 Table 5.2's rock removal rate)."""
    return sweep(orbit, **kw).removal_ratio


def fit_lift(ecc_ratio: float, rev_s: float, speed_m_s: float, target: float, radius_m: float = SEED003_R_M,
             depth_m: float = SEED003_DEPTH_M, **kw) -> float:
    """The lift (fraction of e) at which :func:`removal_ratio` equals ``target``."""
    from scipy.optimize import brentq

    e = ecc_ratio * radius_m

    def gap(lift: float) -> float:
        return removal_ratio(Orbit.from_rates(radius_m, depth_m, e, speed_m_s, rev_s, lift), **kw) - target

    lo, hi = gap(0.0), gap(1.0)
    if lo * hi > 0:
        raise ValueError(f"fit_lift: removal ratio {target} is outside [{hi + target:.3f}, {lo + target:.3f}] "
                         f"for lifts 0..1 (e/R {ecc_ratio}, {rev_s} rev/s)")
    return float(brentq(gap, 0.0, 1.0, xtol=1e-3))


def table52(**kw) -> list[dict]:
    """Seed 003 Table 5.2 beside the model at the start and orbit-bottom readings, and the lift that fits each row."""
    rows = []
    for er, f, V, tab in SEED003_TABLE52:
        o = lambda lift: Orbit.from_rates(SEED003_R_M, SEED003_DEPTH_M, er * SEED003_R_M, V, f, lift)  # noqa: E731
        rows.append({"eccentricity_ratio_1": er, "rotation_rev_s": f, "forward_speed_m_s": V, "nu_1": o(0).nu,
                     "removal_ratio_seed_1": tab, "removal_ratio_start_1": removal_ratio(o(0.0), **kw),
                     "removal_ratio_bottom_1": removal_ratio(o(1.0), **kw),
                     "lift_fit_1": fit_lift(er, f, V, tab, **kw)})
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m deckgen.odc_kinematics", description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("table52", help="seed 003 Table 5.2 against the swept-floor model, and the lift that fits it")
    one = sub.add_parser("orbit", help="removal ratio, engaged arc and contact fraction of one path")
    one.add_argument("--radius-mm", type=float, default=10.0)
    one.add_argument("--depth-mm", type=float, default=4.0)
    one.add_argument("--ecc-mm", type=float, required=True)
    one.add_argument("--speed-m-s", type=float, required=True)
    one.add_argument("--frequency-hz", type=float, required=True)
    one.add_argument("--lift", type=float, default=0.0, help="orbit lift as a fraction of e (0 start, 1 bottom)")
    one.add_argument("--sense", choices=["forward", "backward"], default="forward")
    a = ap.parse_args(argv)
    if a.cmd == "table52":
        import pandas as pd

        print(pd.DataFrame(table52()).to_string(index=False, float_format=lambda v: f"{v:.3f}"))
        return 0
    try:
        o = Orbit.from_rates(a.radius_mm * 1e-3, a.depth_mm * 1e-3, a.ecc_mm * 1e-3, a.speed_m_s, a.frequency_hz,
                             a.lift, 1.0 if a.sense == "forward" else -1.0)
        s = sweep(o)
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(f"nu {o.nu:.3f}  removal ratio {s.removal_ratio:.3f}  engaged arc / straight {s.arc_ratio:.3f}  "
          f"contact fraction {s.contact_fraction:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
