"""Disc-cutter geometry: 2D cross-section profiles, revolution into watertight
triangle meshes, inward offsets and binary STL output.

Units: SI everywhere. All lengths are metres, volumes cubic metres, angles are
given in degrees (parameter names end in ``_deg``). STL files carry no units;
the coordinates written by :func:`write_stl` are metres, matching LAMMPS/LIGGGHTS
``units si``.

Profiles
--------
A cutter is a solid of revolution about its own axis. Its cross-section is a
closed polygon in the ``(rho, a)`` half-plane, stored as an ``(n, 2)`` float
array of ``[rho, a]`` rows:

* ``rho`` >= 0 is the radial distance from the disc axis,
* ``a`` is the axial coordinate.

The polygon is closed implicitly (last vertex -> first vertex). The profile
builders in this module return it counter-clockwise (``rho`` to the right,
``a`` up), starting at the axis point of one face and ending at the axis
point of the other face, so the closing edge lies on the axis. Edges that lie
on the axis produce no surface when revolved.

Frame conventions (shared by all builders)
------------------------------------------
* The disc centre is at the origin: the axial origin ``a = 0`` is the plane of
  the cutting edge, i.e. of the outermost rim point (for the symmetric V and
  CCS discs this is the mid-plane; for the asymmetric and cone discs the flat
  face sits at ``a = -tip_radius``).
* :func:`revolve` puts the disc axis along global +y by default: the disc
  rolls about y when it translates along x, and the cut depth is along -z.
  The lowest rim point ``(0, 0, -D/2)`` is always a mesh vertex.

Public API
----------
Profiles: :func:`v_disc`, :func:`ccs_disc`, :func:`asymmetric_disc`,
:func:`cone_disc`; parameter dataclasses :class:`VDiscParams`,
:class:`CCSDiscParams`, :class:`AsymmetricDiscParams`,
:class:`ConeDiscParams`. Meshing: :func:`offset_profile`, :func:`revolve`,
:func:`segments_for_radius`, :func:`tilt`, :func:`build_cutter`. Output and
reporting: :func:`write_stl`, :func:`cutter_summary`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import trimesh

__all__ = [
    "AXES",
    "CUTTER_KINDS",
    "AsymmetricDiscParams",
    "CCSDiscParams",
    "ConeDiscParams",
    "VDiscParams",
    "asymmetric_disc",
    "build_cutter",
    "ccs_disc",
    "cone_disc",
    "cutter_summary",
    "offset_profile",
    "profile_width",
    "revolve",
    "segments_for_radius",
    "tilt",
    "v_disc",
    "wear_flat",
    "write_stl",
]

#: Largest accepted disc diameter [m]; a larger value almost always means the
#: caller passed millimetres.
MAX_DIAMETER_M = 5.0

#: Default chord tolerance at the rim for the azimuthal resolution [m].
DEFAULT_CHORD_TOL_M = 2.0e-5

#: Largest angular step used to discretise tip arcs in the profile [deg].
ARC_STEP_DEG = 3.0

AXES = ("x", "y", "z")

# (e1, e2, e3) with e1 x e2 = e3 (right-handed): position =
# rho*(cos t*e1 + sin t*e2) + a*e3. e3 is the disc axis.
_AXIS_FRAMES: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {
    "z": (np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0])),
    "y": (np.array([0, 0, 1.0]), np.array([1.0, 0, 0]), np.array([0, 1.0, 0])),
    "x": (np.array([0, 1.0, 0]), np.array([0, 0, 1.0]), np.array([1.0, 0, 0])),
}

_AXIS_META_KEY = "deckgen_axis"


# ---------------------------------------------------------------------------
# validation helpers
# ---------------------------------------------------------------------------


def _finite(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}={value!r} is not a number; pass a float") from None
    if not math.isfinite(v):
        raise ValueError(f"{name}={value!r} must be finite")
    return v


def _positive(name: str, value: float) -> float:
    v = _finite(name, value)
    if v <= 0.0:
        raise ValueError(f"{name}={v!r} must be > 0 (lengths are in metres)")
    return v


def _non_negative(name: str, value: float) -> float:
    v = _finite(name, value)
    if v < 0.0:
        raise ValueError(f"{name}={v!r} must be >= 0 (use 0 for a sharp edge)")
    return v


def _diameter(name: str, value: float) -> float:
    v = _positive(name, value)
    if v > MAX_DIAMETER_M:
        raise ValueError(
            f"{name}={v!r} m is larger than {MAX_DIAMETER_M} m; deckgen lengths "
            f"are in metres (did you pass millimetres? use {v / 1000.0!r})"
        )
    return v


def _angle_open(name: str, value: float, lo: float, hi: float) -> float:
    v = _finite(name, value)
    if not (lo < v < hi):
        raise ValueError(f"{name}={v!r} deg must lie in the open interval ({lo:g}, {hi:g}) deg")
    return v


def _check_axis(axis: str) -> str:
    if axis not in _AXIS_FRAMES:
        raise ValueError(f"axis={axis!r} must be one of {AXES}")
    return axis


# ---------------------------------------------------------------------------
# profile helpers
# ---------------------------------------------------------------------------


def _arc(center: tuple[float, float], radius: float, ang0_deg: float, ang1_deg: float) -> list:
    """Points on a circular arc in the (rho, a) plane, from ang0 to ang1 (deg,
    measured from +rho towards +a). Angle 0 (the outermost point) is always a
    vertex when it lies inside the range. A zero radius returns the centre."""
    cr, ca = center
    if radius == 0.0:
        return [(cr, ca)]
    breaks = [ang0_deg, ang1_deg]
    if min(ang0_deg, ang1_deg) < 0.0 < max(ang0_deg, ang1_deg):
        breaks = [ang0_deg, 0.0, ang1_deg]
    angles: list[float] = []
    for s, e in zip(breaks[:-1], breaks[1:]):
        n = max(1, math.ceil(abs(e - s) / ARC_STEP_DEG))
        seg = np.linspace(s, e, n + 1)
        if angles:
            seg = seg[1:]
        angles.extend(seg.tolist())
    out = []
    for ang in angles:
        t = math.radians(ang)
        out.append((cr + radius * math.cos(t), ca + radius * math.sin(t)))
    return out


def _clean(profile: Any) -> np.ndarray:
    """Return a float (n, 2) copy with consecutive duplicates (incl. wrap-around)
    removed and near-axis rho snapped to 0. Raises ValueError on bad input."""
    p = np.array(profile, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 3:
        raise ValueError(f"profile must be an (n, 2) array with n >= 3, got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("profile contains non-finite values")
    scale = float(np.max(np.abs(p))) or 1.0
    tol = 1e-12 * scale
    if np.any(p[:, 0] < -1e-9 * scale):
        raise ValueError("profile has rho < 0: every vertex must satisfy rho >= 0")
    p[p[:, 0] < tol, 0] = 0.0
    keep = [0]
    for i in range(1, len(p)):
        if np.linalg.norm(p[i] - p[keep[-1]]) > tol:
            keep.append(i)
    p = p[keep]
    while len(p) > 1 and np.linalg.norm(p[-1] - p[0]) <= tol:
        p = p[:-1]
    if len(p) < 3:
        raise ValueError("profile has fewer than 3 distinct vertices")
    return p


def _signed_area(p: np.ndarray) -> float:
    r, a = p[:, 0], p[:, 1]
    return 0.5 * float(np.sum(r * np.roll(a, -1) - np.roll(r, -1) * a))


def _ccw(p: np.ndarray) -> np.ndarray:
    area = _signed_area(p)
    if area == 0.0:
        raise ValueError("profile encloses zero area")
    return p if area > 0 else p[::-1].copy()


def _bevel_profile(R: float, gamma_deg: float, r: float, width: float) -> np.ndarray:
    """Flat face at a = -r, bevel at gamma to it, tip arc of radius r whose
    outermost point is (R, 0), hub face at a = -r + width. No validation."""
    g = math.radians(gamma_deg)
    a_f = -r
    R0 = R - r + (r / math.tan(g / 2.0) if r > 0 else 0.0)  # virtual sharp apex
    rho_h = R0 - width / math.tan(g)
    pts = [(0.0, a_f)]
    pts += _arc((R - r, 0.0), r, -90.0, 90.0 - gamma_deg)
    pts += [(rho_h, a_f + width), (0.0, a_f + width)]
    return np.array(pts, dtype=float)


# ---------------------------------------------------------------------------
# profiles and parameter dataclasses
# ---------------------------------------------------------------------------


def v_disc(diameter: float, edge_angle_deg: float, tip_radius: float, hub_width: float) -> np.ndarray:
    """Profile of a symmetric V disc.

    Two straight flanks, each inclined at ``edge_angle_deg / 2`` to the disc's
    mid-plane (``a = 0``), meet at the rim; the apex is rounded by a circular
    arc of ``tip_radius`` tangent to both flanks, whose outermost point lies
    exactly at ``rho = diameter / 2``. The flanks run inward until the disc is
    ``hub_width`` wide, then flat hub faces (perpendicular to the axis) run
    down to the axis.

    Parameters
    ----------
    diameter : float
        Rim diameter [m] (outermost point, after rounding the tip).
    edge_angle_deg : float
        Included edge angle between the two flanks [deg], in (0, 180).
    tip_radius : float
        Tip arc radius [m]; 0 gives a sharp edge.
    hub_width : float
        Total axial width of the disc body [m] (the mesh's axial extent).

    Returns
    -------
    numpy.ndarray
        ``(n, 2)`` CCW profile ``[rho, a]`` [m], see module docstring.
    """
    D = _diameter("diameter", diameter)
    ang = _angle_open("edge_angle_deg", edge_angle_deg, 0.0, 180.0)
    r = _non_negative("tip_radius", tip_radius)
    w = _positive("hub_width", hub_width)
    R = D / 2.0
    if r >= R:
        raise ValueError(f"tip_radius={r!r} m must be < diameter/2 = {R!r} m; reduce tip_radius")
    beta = math.radians(ang / 2.0)
    w_tip = 2.0 * r * math.cos(beta)  # disc width where the tip arc meets the flanks
    if w <= w_tip:
        raise ValueError(
            f"tip_radius={r!r} m is too large for hub_width={w!r} m: the tip arc is "
            f"{w_tip:.6g} m wide where it meets the flanks (2*tip_radius*cos(edge_angle/2)); "
            f"reduce tip_radius below {w / (2.0 * math.cos(beta)):.6g} m or increase hub_width"
        )
    R0 = R - r + r / math.sin(beta)
    rho_h = R0 - (w / 2.0) / math.tan(beta)
    if rho_h <= 0.0:
        raise ValueError(
            f"hub_width={w!r} m is too large for diameter={D!r} m and edge_angle_deg={ang!r}: "
            f"the flanks reach the axis before the disc is that wide; use "
            f"hub_width < {2.0 * R0 * math.tan(beta):.6g} m or a larger edge angle"
        )
    pts = [(0.0, -w / 2.0), (rho_h, -w / 2.0)]
    pts += _arc((R - r, 0.0), r, -(90.0 - ang / 2.0), 90.0 - ang / 2.0)
    pts += [(rho_h, w / 2.0), (0.0, w / 2.0)]
    return np.array(pts, dtype=float)


def ccs_disc(
    diameter: float,
    tip_width: float,
    tip_radius: float,
    flank_angle_deg: float,
    hub_width: float,
) -> np.ndarray:
    """Profile of a constant cross-section (CCS) disc, e.g. a 17-inch
    (0.4318 m) TBM disc with a 12-20 mm tip.

    A flat tip land (a cylinder ``rho = diameter/2``) is joined to two flanks
    by corner arcs of ``tip_radius`` tangent to the land and to the flank.
    Each flank is inclined at ``flank_angle_deg`` to the disc's radial
    (mid-)plane, so the disc widens inward; the flanks run inward until the
    disc is ``hub_width`` wide, then flat hub faces run down to the axis.

    **Tip width definition**: ``tip_width`` is the nominal (drawing) width at
    the rim, measured between the virtual sharp corners, i.e. between the
    points where the extended flank lines cross the rim cylinder
    ``rho = diameter/2``. It is the flat land plus both rounded corners. The
    flat land itself is ``tip_width - 2*tip_radius*tan(45 deg -
    flank_angle/2)``; with ``flank_angle -> 0`` and a full-radius tip,
    ``tip_width = 2*tip_radius``.

    Parameters
    ----------
    diameter : float
        Rim diameter [m] (the flat land's radius times two).
    tip_width : float
        Nominal tip width [m] (see above).
    tip_radius : float
        Corner radius [m] between land and flanks; 0 gives sharp corners.
    flank_angle_deg : float
        Flank inclination to the radial plane [deg], in (0, 90).
    hub_width : float
        Total axial width of the disc body [m].

    Returns
    -------
    numpy.ndarray
        ``(n, 2)`` CCW profile ``[rho, a]`` [m].
    """
    D = _diameter("diameter", diameter)
    W = _positive("tip_width", tip_width)
    r = _non_negative("tip_radius", tip_radius)
    phi_deg = _angle_open("flank_angle_deg", flank_angle_deg, 0.0, 90.0)
    w = _positive("hub_width", hub_width)
    R = D / 2.0
    phi = math.radians(phi_deg)
    t = r * math.tan(math.radians(45.0 - phi_deg / 2.0))  # corner tangent length
    land = W - 2.0 * t
    if land < -1e-12 * W:
        raise ValueError(
            f"tip_radius={r!r} m is too large for tip_width={W!r} m: the two corner arcs "
            f"use {2.0 * t:.6g} m of the tip width (2*tip_radius*tan(45-flank_angle/2)); "
            f"use tip_radius <= {W / (2.0 * math.tan(math.radians(45.0 - phi_deg / 2.0))):.6g} m "
            f"or a wider tip"
        )
    land = max(land, 0.0)
    if r >= R:
        raise ValueError(f"tip_radius={r!r} m must be < diameter/2 = {R!r} m")
    w_tan = land + 2.0 * r * math.cos(phi)  # width where the corner arcs meet the flanks
    if w <= w_tan:
        raise ValueError(
            f"hub_width={w!r} m must exceed the disc width where the flanks start, "
            f"{w_tan:.6g} m (tip land plus corner arcs); increase hub_width"
        )
    rho_h = R - (w / 2.0 - W / 2.0) / math.tan(phi)
    if rho_h <= 0.0:
        raise ValueError(
            f"hub_width={w!r} m is too large for diameter={D!r} m and flank_angle_deg={phi_deg!r}: "
            f"the flanks reach the axis first; use hub_width < "
            f"{W + 2.0 * R * math.tan(phi):.6g} m or a larger flank angle"
        )
    pts = [(0.0, -w / 2.0), (rho_h, -w / 2.0)]
    pts += _arc((R - r, -land / 2.0), r, -(90.0 - phi_deg), 0.0)
    pts += _arc((R - r, land / 2.0), r, 0.0, 90.0 - phi_deg)
    pts += [(rho_h, w / 2.0), (0.0, w / 2.0)]
    return np.array(pts, dtype=float)


def asymmetric_disc(
    diameter: float,
    blade_angle_deg: float,
    tip_radius: float,
    hub_width: float,
    flat_side: int = -1,
) -> np.ndarray:
    """Profile of an asymmetric (single-bevel) disc, e.g. seed 000's disc
    (D = 0.150 or 0.160 m, blade angle 40 deg, tip radius 0.001 m).

    One face is flat (perpendicular to the axis; the face toward the free
    edge). The other face is a bevel (cone) at ``blade_angle_deg`` to the flat
    face. They meet at the rim in a tip arc of ``tip_radius`` tangent to both;
    the arc's outermost point is at ``rho = diameter/2``, ``a = 0``, so the
    flat face lies at ``a = -tip_radius * flat_side_sign``. The bevel runs
    inward until the disc is ``hub_width`` wide, then a flat hub face runs
    down to the axis.

    Parameters
    ----------
    diameter : float
        Rim diameter [m].
    blade_angle_deg : float
        Angle between bevel and flat face [deg], in (0, 90).
    tip_radius : float
        Tip arc radius [m]; 0 gives a sharp edge.
    hub_width : float
        Total axial width of the disc body [m], flat face to hub face.
    flat_side : int
        -1 (default): the flat face is at the minimum axial coordinate
        (faces -a, i.e. -y with the default axis); +1: at the maximum.

    Returns
    -------
    numpy.ndarray
        ``(n, 2)`` CCW profile ``[rho, a]`` [m].
    """
    D = _diameter("diameter", diameter)
    g = _angle_open("blade_angle_deg", blade_angle_deg, 0.0, 90.0)
    r = _non_negative("tip_radius", tip_radius)
    w = _positive("hub_width", hub_width)
    if flat_side not in (-1, 1):
        raise ValueError(f"flat_side={flat_side!r} must be -1 (flat face at min a) or +1 (at max a)")
    R = D / 2.0
    if r >= R:
        raise ValueError(f"tip_radius={r!r} m must be < diameter/2 = {R!r} m")
    gr = math.radians(g)
    w_tip = r * (1.0 + math.cos(gr))
    if w <= w_tip:
        raise ValueError(
            f"tip_radius={r!r} m is too large for hub_width={w!r} m: the tip arc is "
            f"{w_tip:.6g} m wide (tip_radius*(1+cos(blade_angle))); reduce tip_radius "
            f"below {w / (1.0 + math.cos(gr)):.6g} m or increase hub_width"
        )
    R0 = R - r + (r / math.tan(gr / 2.0) if r > 0 else 0.0)
    if R0 - w / math.tan(gr) <= 0.0:
        raise ValueError(
            f"hub_width={w!r} m is too large for diameter={D!r} m and blade_angle_deg={g!r}: "
            f"the bevel reaches the axis first; use hub_width < {R0 * math.tan(gr):.6g} m"
        )
    p = _bevel_profile(R, g, r, w)
    if flat_side == 1:
        p = p[::-1].copy()
        p[:, 1] *= -1.0
    return p


def cone_disc(
    small_diameter: float,
    large_diameter: float,
    rake_angle_deg: float = 30.0,
    tip_radius: float = 0.0,
) -> np.ndarray:
    """Profile of seed 003's oscillating-disc cutter: a truncated cone
    ("a cone with two diameters of 1 and 2 cm").

    Parametrisation (chosen here, see also :class:`ConeDiscParams`):

    * the large flat face (diameter ``large_diameter``) is the clearance
      face; its rim is the cutting edge;
    * the conical side is the rake face. ``rake_angle_deg`` is the rake angle
      at zero clearance, i.e. the angle between the cone generatrix and the
      disc axis, so the wedge angle at the edge is ``90 - rake_angle_deg``
      (60 deg for the seed's 30 deg rake);
    * the small flat face has diameter ``small_diameter``; the thickness
      follows: ``(large_diameter - small_diameter)/2 * tan(90 - rake)`` for a
      sharp edge (8.66 mm for 10/20 mm and 30 deg);
    * the clearance angle is NOT part of the solid: it is a mounting tilt
      (the same cutter tilted by the clearance angle has rake = rake - clearance,
      so 0 deg clearance <-> 30 deg rake). :func:`build_cutter` applies it.

    The edge is sharp by default; ``tip_radius`` > 0 rounds it with an arc
    tangent to both faces whose outermost point is at ``large_diameter/2``.
    The large face lies at ``a = -tip_radius`` (``a = 0`` when sharp), the
    cone body extends to +a.

    Parameters
    ----------
    small_diameter, large_diameter : float
        Face diameters [m], ``0 < small < large``.
    rake_angle_deg : float
        Rake angle at zero clearance [deg], in (0, 90).
    tip_radius : float
        Edge rounding radius [m], default 0 (sharp).

    Returns
    -------
    numpy.ndarray
        ``(n, 2)`` CCW profile ``[rho, a]`` [m].
    """
    d = _diameter("small_diameter", small_diameter)
    D = _diameter("large_diameter", large_diameter)
    rake = _angle_open("rake_angle_deg", rake_angle_deg, 0.0, 90.0)
    r = _non_negative("tip_radius", tip_radius)
    if d >= D:
        raise ValueError(
            f"small_diameter={d!r} m must be < large_diameter={D!r} m (the large face carries the edge)"
        )
    R = D / 2.0
    wedge = 90.0 - rake
    g = math.radians(wedge)
    c_rho = R - r
    rho_tan = c_rho + r * math.sin(g)  # where the edge arc meets the cone
    if rho_tan <= d / 2.0:
        raise ValueError(
            f"tip_radius={r!r} m is too large: the edge arc reaches radius {rho_tan:.6g} m, "
            f"inside small_diameter/2 = {d / 2.0!r} m; reduce tip_radius"
        )
    R0 = R - r + (r / math.tan(g / 2.0) if r > 0 else 0.0)
    thickness = (R0 - d / 2.0) * math.tan(g)
    return _bevel_profile(R, wedge, r, thickness)


@dataclass(frozen=True)
class VDiscParams:
    """Parameters of :func:`v_disc` (lengths in m, angles in deg)."""

    kind: ClassVar[str] = "v_disc"
    diameter: float
    edge_angle_deg: float
    tip_radius: float
    hub_width: float

    def profile(self) -> np.ndarray:
        return v_disc(self.diameter, self.edge_angle_deg, self.tip_radius, self.hub_width)


@dataclass(frozen=True)
class CCSDiscParams:
    """Parameters of :func:`ccs_disc` (lengths in m, angles in deg)."""

    kind: ClassVar[str] = "ccs_disc"
    diameter: float
    tip_width: float
    tip_radius: float
    flank_angle_deg: float
    hub_width: float

    def profile(self) -> np.ndarray:
        return ccs_disc(self.diameter, self.tip_width, self.tip_radius, self.flank_angle_deg, self.hub_width)


@dataclass(frozen=True)
class AsymmetricDiscParams:
    """Parameters of :func:`asymmetric_disc` (lengths in m, angles in deg)."""

    kind: ClassVar[str] = "asymmetric_disc"
    diameter: float
    blade_angle_deg: float
    tip_radius: float
    hub_width: float
    flat_side: int = -1

    def profile(self) -> np.ndarray:
        return asymmetric_disc(self.diameter, self.blade_angle_deg, self.tip_radius, self.hub_width, self.flat_side)


@dataclass(frozen=True)
class ConeDiscParams:
    """Parameters of :func:`cone_disc` plus the mounting clearance angle.

    ``clearance_angle_deg`` (>= 0, < 90) is applied by :func:`build_cutter`
    as a rigid tilt about the global x axis (the travel direction), only for
    the default disc axis y: the flat (large, -y facing) clearance face is
    rotated so that, above the lowest rim point (0, 0, -D/2), it recedes
    toward +y at the clearance angle, i.e. its outward normal becomes
    ``(0, -cos c, sin c)``. Effective rake = ``rake_angle_deg - clearance``.
    """

    kind: ClassVar[str] = "cone_disc"
    small_diameter: float
    large_diameter: float
    clearance_angle_deg: float = 0.0
    rake_angle_deg: float = 30.0
    tip_radius: float = 0.0

    def profile(self) -> np.ndarray:
        return cone_disc(self.small_diameter, self.large_diameter, self.rake_angle_deg, self.tip_radius)


_PARAMS: dict[str, type] = {
    "v_disc": VDiscParams,
    "ccs_disc": CCSDiscParams,
    "asymmetric_disc": AsymmetricDiscParams,
    "cone_disc": ConeDiscParams,
}

CUTTER_KINDS = tuple(_PARAMS)


# ---------------------------------------------------------------------------
# slices and wear
# ---------------------------------------------------------------------------


def profile_width(profile: Any, rho: Any) -> np.ndarray:
    """Axial width [m] of a convex profile's slice at radius ``rho`` [m] (array-like; 0 outside).

    The slice of a convex polygon by the line ``rho = const`` is one segment; its length is the
    disc's width at that radius (e.g. the tip land width at the rim, the groove width at a depth).
    """
    return _slice_width(_ccw(_clean(profile)), rho)


def _slice_width(p: np.ndarray, rho: Any) -> np.ndarray:
    """:func:`profile_width` of an already cleaned profile."""
    q = np.roll(p, -1, axis=0)
    r = np.atleast_1d(np.asarray(rho, dtype=float))
    r0, r1, a0, a1 = p[:, 0][None, :], q[:, 0][None, :], p[:, 1][None, :], q[:, 1][None, :]
    lo, hi = np.minimum(r0, r1), np.maximum(r0, r1)
    hit = (r[:, None] >= lo) & (r[:, None] <= hi) & (hi > lo)
    t = np.where(hit, (r[:, None] - r0) / np.where(r1 != r0, r1 - r0, 1.0), 0.0)
    a = a0 + t * (a1 - a0)
    amax = np.where(hit, a, -np.inf).max(axis=1)
    amin = np.where(hit, a, np.inf).min(axis=1)
    return np.where(np.isfinite(amax) & np.isfinite(amin), np.maximum(amax - amin, 0.0), 0.0)


def wear_flat(profile: Any, width: float) -> np.ndarray:
    """The profile worn down to a flat land of axial ``width`` [m] at the rim.

    The rim is cut off by the cylinder ``rho = rho_w`` where the (convex) profile is ``width``
    wide, as abrasive wear flattens a disc's edge (seed 003 sec. 1: "a wear flat ... the tool will
    attack the rock with a flat area"). Returns the profile unchanged for ``width = 0`` and the
    profile's own tip land when it is already at least that wide.
    """
    from scipy.optimize import brentq

    w = _non_negative("width", width)
    p = _ccw(_clean(profile))
    if w == 0.0:
        return p
    R = float(p[:, 0].max())
    if float(_slice_width(p, R * (1.0 - 1e-12))[0]) >= w:
        return p
    hub = float(p[:, 1].max() - p[:, 1].min())
    if w >= hub:
        raise ValueError(f"wear flat width={w!r} m is not less than the disc width {hub:.6g} m; use a narrower flat")
    lo = float(p[p[:, 0] > 0, 0].min()) if (p[:, 0] > 0).any() else 0.0
    rho_w = brentq(lambda x: float(_slice_width(p, x)[0]) - w, lo, R * (1.0 - 1e-12), xtol=1e-12)
    out: list[tuple[float, float]] = []
    for i in range(len(p)):  # clip to rho <= rho_w (Sutherland-Hodgman, one half-plane)
        a, b = p[i], p[(i + 1) % len(p)]
        ina, inb = a[0] <= rho_w, b[0] <= rho_w
        if ina:
            out.append((float(a[0]), float(a[1])))
        if ina != inb:
            t = (rho_w - a[0]) / (b[0] - a[0])
            out.append((rho_w, float(a[1] + t * (b[1] - a[1]))))
    return _ccw(_clean(np.array(out)))


# ---------------------------------------------------------------------------
# offset
# ---------------------------------------------------------------------------


class _Spike(Exception):
    """Two consecutive (active) edges are antiparallel."""


def _miter(n_in: np.ndarray, s_in: float, n_out: np.ndarray, s_out: float) -> np.ndarray:
    """Displacement per unit offset of the vertex between two edges with unit
    inward normals n_in, n_out and offset rates s_in, s_out (0 or 1)."""
    det = n_in[0] * n_out[1] - n_in[1] * n_out[0]
    if abs(det) < 1e-12:
        if float(np.dot(n_in, n_out)) < 0.0:
            raise _Spike
        return n_in * max(s_in, s_out)
    # solve [n_in; n_out] m = [s_in; s_out]
    return np.array([(s_in * n_out[1] - s_out * n_in[1]) / det, (n_in[0] * s_out - n_out[0] * s_in) / det])


def offset_profile(profile: Any, delta: float) -> np.ndarray:
    """Offset a closed profile inward by ``delta`` [m].

    Each surface edge is moved ``delta`` along its inward normal and each
    vertex is moved to the intersection of its two offset edges (mitre
    join). Edges lying on the axis (``rho = 0`` at both ends) are not moved,
    so vertices on the axis slide along it and ``rho >= 0`` holds. Edges whose
    length shrinks to zero (e.g. a tip arc with radius < delta) are removed
    as the offset grows (event-driven, exact for convex profiles; all
    profiles built here are convex), so a sharp edge stays sharp and a tip arc
    of radius r becomes one of radius ``r - delta`` around the same centre.

    Why: LAMMPS represents an STL cutter as a shell of spheres of radius r_s
    on the surface, making the tool r_s fatter; a mesh offset inward by r_s
    gives an effective surface that matches the true one (with edges rounded
    to at least r_s).

    Parameters
    ----------
    profile : array_like
        ``(n, 2)`` closed profile ``[rho, a]`` [m], either orientation.
    delta : float
        Inward offset [m], >= 0.

    Returns
    -------
    numpy.ndarray
        ``(m, 2)`` CCW offset profile [m].
    """
    d = _non_negative("delta", delta)
    p = _ccw(_clean(profile))
    if d == 0.0:
        return p
    n = len(p)
    tangents = np.roll(p, -1, axis=0) - p
    lengths = np.linalg.norm(tangents, axis=1)
    t_hat = tangents / lengths[:, None]
    normals = np.stack([-t_hat[:, 1], t_hat[:, 0]], axis=1)  # left normal = inward for CCW
    on_axis = (p[:, 0] == 0.0) & (np.roll(p, -1, axis=0)[:, 0] == 0.0)
    rate = np.where(on_axis, 0.0, 1.0)

    edges = list(range(n))  # active edge ids; vertex k starts edge edges[k]
    verts = [p[i].copy() for i in range(n)]
    done = 0.0
    while True:
        m = len(edges)
        if m < 3:
            raise ValueError(f"delta={d!r} m is too large for this profile: it collapses; use a smaller delta")
        try:
            mit = [
                _miter(normals[edges[k - 1]], rate[edges[k - 1]], normals[edges[k]], rate[edges[k]])
                for k in range(m)
            ]
        except _Spike:
            raise ValueError(
                f"delta={d!r} m is too large for this profile (it collapses to a sliver), "
                f"or the profile has a zero-angle spike; use a smaller delta"
            ) from None
        # collapse parameter of each edge
        best_k, best_t = -1, d - done
        for k in range(m):
            e = edges[k]
            k1 = (k + 1) % m
            length = float(np.dot(verts[k1] - verts[k], t_hat[e]))
            slope = float(np.dot(mit[k1] - mit[k], t_hat[e]))
            if slope < 0.0:
                t_col = -length / slope
                if t_col < best_t:
                    best_k, best_t = k, max(t_col, 0.0)
        for k in range(m):
            verts[k] = verts[k] + best_t * mit[k]
        done += best_t
        if best_k < 0:
            break
        if on_axis[edges[best_k]]:
            raise ValueError(f"delta={d!r} m is too large: the hub collapses; use a smaller delta")
        # remove edge best_k: its two end vertices merge into one vertex that
        # joins edges[best_k - 1] and edges[best_k + 1] (and starts the latter)
        k1 = (best_k + 1) % m
        verts[k1] = 0.5 * (verts[best_k] + verts[k1])
        del edges[best_k]
        del verts[best_k]
    out = np.array(verts)
    out[:, 0] = np.maximum(out[:, 0], 0.0)
    return _ccw(_clean(out))


# ---------------------------------------------------------------------------
# revolve
# ---------------------------------------------------------------------------


def segments_for_radius(
    radius: float,
    chord_tol: float = DEFAULT_CHORD_TOL_M,
    n_min: int = 64,
    n_max: int = 720,
) -> int:
    """Number of azimuthal segments so that the chord (sagitta) error at
    ``radius`` [m] is below ``chord_tol`` [m], rounded up to a multiple of 4
    (so the +-x and +-z extremes of a y-axis disc are vertices) and clipped
    to ``[n_min, n_max]``."""
    R = _positive("radius", radius)
    tol = _positive("chord_tol", chord_tol)
    if tol >= R:
        n = n_min
    else:
        n = math.ceil(math.pi / math.acos(1.0 - tol / R))
    n = 4 * math.ceil(n / 4)
    return int(min(max(n, n_min), n_max))


def revolve(profile: Any, n_segments: int | None = None, axis: str = "y") -> trimesh.Trimesh:
    """Revolve a closed ``(rho, a)`` profile [m] into a watertight triangle mesh.

    Vertices with ``rho = 0`` become single vertices on the axis (no
    degenerate triangles); edges lying on the axis produce no faces. Faces
    are wound so normals point outward (positive volume) whatever the profile
    orientation.

    Parameters
    ----------
    profile : array_like
        ``(n, 2)`` closed profile ``[rho, a]`` [m] (simple polygon, rho >= 0).
    n_segments : int, optional
        Azimuthal segments (>= 3). Default: :func:`segments_for_radius` of the
        largest rho (chord error <= 0.02 mm, 64..720, multiple of 4).
    axis : {"x", "y", "z"}
        Global axis of the disc (default "y"). Azimuth 0 is along +z for
        axis y, +x for axis z and +y for axis x; frames are right-handed.

    Returns
    -------
    trimesh.Trimesh
        Mesh in metres; ``mesh.metadata["deckgen_axis"]`` holds the unit axis
        vector (used by :func:`cutter_summary`).
    """
    _check_axis(axis)
    p = _ccw(_clean(profile))
    rmax = float(p[:, 0].max())
    if rmax <= 0.0:
        raise ValueError("profile lies entirely on the axis")
    if n_segments is None:
        N = segments_for_radius(rmax)
    else:
        if int(n_segments) != n_segments or n_segments < 3:
            raise ValueError(f"n_segments={n_segments!r} must be an integer >= 3")
        N = int(n_segments)
    e1, e2, e3 = _AXIS_FRAMES[axis]
    theta = 2.0 * math.pi * np.arange(N) / N
    ring_dirs = np.cos(theta)[:, None] * e1 + np.sin(theta)[:, None] * e2  # (N, 3)
    # exact zeros at quarter turns keep the bounding box exact
    ring_dirs[np.abs(ring_dirs) < 1e-15] = 0.0

    verts: list[np.ndarray] = []
    index: list[np.ndarray] = []  # per profile vertex: (N,) vertex ids
    count = 0
    for rho, a in p:
        if rho == 0.0:
            verts.append((a * e3)[None, :])
            index.append(np.full(N, count))
            count += 1
        else:
            verts.append(rho * ring_dirs + a * e3)
            index.append(np.arange(count, count + N))
            count += N
    V = np.vstack(verts)
    jn = np.roll(np.arange(N), -1)
    faces = []
    n = len(p)
    for i in range(n):
        j = (i + 1) % n
        A, B = index[i], index[j]
        a_axis, b_axis = p[i, 0] == 0.0, p[j, 0] == 0.0
        if a_axis and b_axis:
            continue
        if not a_axis:
            faces.append(np.stack([A, A[jn], B], axis=1))
        if not b_axis:
            faces.append(np.stack([A[jn], B[jn], B], axis=1))
    F = np.vstack(faces)
    mesh = trimesh.Trimesh(vertices=V, faces=F, process=False)
    used = np.zeros(len(V), dtype=bool)
    used[F.ravel()] = True
    if not used.all():
        mesh.remove_unreferenced_vertices()
    if not mesh.volume > 0.0:  # pragma: no cover - guarded by _ccw
        raise RuntimeError("revolved mesh has non-positive volume; profile orientation bug")
    mesh.metadata[_AXIS_META_KEY] = e3.copy()
    mesh.metadata["deckgen_n_segments"] = N
    return mesh


def tilt(mesh: trimesh.Trimesh, angle_deg: float, about: str = "x") -> trimesh.Trimesh:
    """Return a copy of ``mesh`` rotated by ``angle_deg`` [deg] about the
    global axis ``about`` through the origin (right-hand rule). The stored
    disc axis in ``metadata["deckgen_axis"]`` is rotated too."""
    _check_axis(about)
    ang = _finite("angle_deg", angle_deg)
    out = mesh.copy()
    Rm = trimesh.transformations.rotation_matrix(math.radians(ang), _AXIS_FRAMES[about][2])
    out.apply_transform(Rm)
    if _AXIS_META_KEY in mesh.metadata:
        out.metadata[_AXIS_META_KEY] = Rm[:3, :3] @ np.asarray(mesh.metadata[_AXIS_META_KEY], dtype=float)
    return out


# ---------------------------------------------------------------------------
# dispatch, output, summary
# ---------------------------------------------------------------------------


def _coerce_params(kind: str, params: Any) -> Any:
    if kind not in _PARAMS:
        raise ValueError(f"kind={kind!r} is not a known cutter; use one of {CUTTER_KINDS}")
    cls = _PARAMS[kind]
    if isinstance(params, cls):
        return params
    if isinstance(params, Mapping):
        names = {f.name for f in fields(cls)}
        unknown = sorted(set(params) - names)
        if unknown:
            raise ValueError(f"params for kind={kind!r} has unknown keys {unknown}; allowed: {sorted(names)}")
        try:
            return cls(**params)
        except TypeError as exc:
            raise ValueError(f"params for kind={kind!r}: {exc}") from None
    raise ValueError(
        f"params={params!r} must be a {cls.__name__} or a mapping of its fields for kind={kind!r}"
    )


def build_cutter(
    kind: str,
    params: Any,
    *,
    n_segments: int | None = None,
    axis: str = "y",
    offset: float = 0.0,
    wear: float = 0.0,
    tilt_deg: float = 0.0,
) -> trimesh.Trimesh:
    """Build the cutter mesh [m] for ``kind`` in :data:`CUTTER_KINDS`.

    Parameters
    ----------
    kind : str
        "v_disc", "ccs_disc", "asymmetric_disc" or "cone_disc".
    params : dataclass or mapping
        The matching ``*Params`` dataclass or a dict of its fields
        (lengths in m, angles in deg).
    n_segments : int, optional
        Azimuthal segments, see :func:`revolve`.
    axis : {"x", "y", "z"}
        Disc axis (default "y").
    offset : float
        Inward surface offset [m] (e.g. the LAMMPS shell-sphere radius r_s),
        see :func:`offset_profile`. Default 0.

    wear : float
        Width [m] of a worn flat land at the rim, see :func:`wear_flat` (applied before the offset).
    tilt_deg : float
        Tilt [deg] of the disc axis about the global x axis, rim toward +y for positive values
        (after any clearance tilt; requires ``axis="y"``).

    For "cone_disc" a non-zero ``clearance_angle_deg`` tilts the revolved
    cutter, see :class:`ConeDiscParams` (requires ``axis="y"``).
    """
    prm = _coerce_params(kind, params)
    _check_axis(axis)
    prof = prm.profile()
    if wear:
        prof = wear_flat(prof, wear)
    if offset:
        prof = offset_profile(prof, offset)
    mesh = revolve(prof, n_segments=n_segments, axis=axis)
    if kind == "cone_disc":
        c = _finite("clearance_angle_deg", prm.clearance_angle_deg)
        if not (0.0 <= c < 90.0):
            raise ValueError(f"clearance_angle_deg={c!r} must lie in [0, 90) deg")
        if c != 0.0:
            if axis != "y":
                raise ValueError(
                    f"clearance_angle_deg={c!r} is only defined for axis='y' (got axis={axis!r}); "
                    f"use axis='y' and rotate the mesh afterwards"
                )
            mesh = tilt(mesh, -c, about="x")
    if tilt_deg:
        if axis != "y":
            raise ValueError(f"tilt_deg={tilt_deg!r} is only defined for axis='y' (got axis={axis!r})")
        mesh = tilt(mesh, _finite("tilt_deg", tilt_deg), about="x")
    mesh.metadata["deckgen_kind"] = kind
    return mesh


_STL_HEADER = b"deckgen binary STL; units: m"


def write_stl(mesh: trimesh.Trimesh, path: str | Path) -> Path:
    """Write ``mesh`` as a binary STL (coordinates in metres, float32).

    The 80-byte header starts with ``deckgen binary STL`` (never ``solid``,
    so readers that sniff ASCII STL by that keyword treat it as binary).
    Parent directories are created. Returns the path as a ``Path``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = mesh.export(file_type="stl")  # trimesh writes binary STL
    if not isinstance(data, (bytes, bytearray)) or len(data) < 84:
        raise RuntimeError("trimesh did not produce a binary STL")
    header = _STL_HEADER.ljust(80, b" ")
    path.write_bytes(header + bytes(data[80:]))
    return path


def cutter_summary(mesh: trimesh.Trimesh, axis: str | None = None) -> dict:
    """Report numbers for a cutter mesh.

    The disc axis is ``mesh.metadata["deckgen_axis"]`` (set by
    :func:`revolve`, rotated by :func:`tilt`) unless ``axis`` is given; the
    axis line passes through the origin.

    Returns
    -------
    dict
        ``diameter_m`` (twice the largest vertex distance from the axis),
        ``width_m`` (extent along the axis), ``volume_m3``, ``watertight``,
        ``winding_consistent`` (bools), ``n_triangles``, ``n_vertices``.
    """
    if axis is not None:
        u = _AXIS_FRAMES[_check_axis(axis)][2]
    elif _AXIS_META_KEY in mesh.metadata:
        u = np.asarray(mesh.metadata[_AXIS_META_KEY], dtype=float)
        u = u / np.linalg.norm(u)
    else:
        u = _AXIS_FRAMES["y"][2]
    V = np.asarray(mesh.vertices, dtype=float)
    along = V @ u
    radial = np.linalg.norm(V - along[:, None] * u, axis=1)
    return {
        "diameter_m": float(2.0 * radial.max()),
        "width_m": float(along.max() - along.min()),
        "volume_m3": float(mesh.volume),
        "watertight": bool(mesh.is_watertight),
        "winding_consistent": bool(mesh.is_winding_consistent),
        "n_triangles": int(len(mesh.faces)),
        "n_vertices": int(len(mesh.vertices)),
    }
