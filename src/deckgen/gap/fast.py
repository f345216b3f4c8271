"""The fast backend: a reduced, physics-based disc-cutting force model with the spec's switches.

It answers the same question as a DEM run of a cutting case (mean steady normal, rolling and side
force on the disc, ``force_{normal,rolling,side}_N_mean_steady``) in microseconds, so the
discrepancy loop can screen candidates and the hidden-effect battery can run in CI. It is a
model of its own (not a surrogate fitted to deckgen's DEM), validated against small DEM runs in
``docs/discrepancy.md``.

Core: the CSM model of Rostami (1997; Rostami & Ozdemir 1993, cited in seed 001 sec. 1 and seed 002
sec. 1) for a disc of radius R cutting at penetration p with contact width T::

    phi = acos((R - p) / R)                                contact angle
    P0  = C * cbrt(S * sc^2 * st / (phi * sqrt(R * T)))    crushed-zone pressure, C = 2.12
    Ft  = T * R * phi * P0 / (1 + psi)                     total force, psi = 0.1 (sharp disc)
    Fn  = Ft cos(phi / 2),  Fr = Ft sin(phi / 2)           resultant at phi/2 from the vertical

with sc, st the rock's UCS and BTS (``material.targets``). T is the width of the disc's (worn)
profile half-way down the cut (from :mod:`deckgen.geometry`, so V, CCS, asymmetric and cone discs
all work). The spec switches act on this model as follows (each is a catalogued effect,
:mod:`deckgen.gap.catalogue`):

``kinematics.neighbour_spacing_mm`` S
    CSM's S is the spacing to the neighbouring groove. An isolated groove relieves itself at
    S_iso = K_ISO * p (seed 001 sec. 6: neighbours at 100 mm no longer interact for p <= 7.6 mm,
    K_ISO = 13); S_eff = (S^-4 + S_iso^-4)^(-1/4) (none: S_eff = S_iso).
``kinematics.spin``
    ``none``: the rim slides on the rock and friction mu (``contact.cutter_friction``) adds
    mu * Ft to the rolling force (the friction moment of seed 003 sec. 5.5, where removing it
    lowered the force by 29 %); ``rolling``: no sliding term.
``cutter.wear_flat_mm`` w
    the profile is worn to a land of width w (:func:`deckgen.geometry.wear_flat`): T grows and R
    shrinks; the land's share w/T of Ft bears on the groove floor with its resultant at phi/4
    (a flat punch loads the floor near the bottom), so Fn rises more than Fr.
``kinematics.mode: rotary`` at ``kinematics.rotary_radius_mm`` r
    the contact arc l = R phi lies on a circle: the disc is skewed to its own path by
    beta = l / (2 r) on average; Fs = -K_SIDE * beta * Fn (toward the outside of the path) and
    Fr += K_SCRUB * |Fs|. K_SIDE = 2.37 and K_SCRUB = 0.49 are the least-squares coefficients of
    Fs/Fn and Fr/Fn on beta over seed 002's 58 LS-DYNA rotary runs (Table 2; R^2 = 0.91 for Fs/Fn).
``specimen.confining_stress_MPa`` s3
    Mohr-Coulomb strengthening of the crushed zone, sc' = sc + q s3 with q = (1 + sin 30 deg) /
    (1 - sin 30 deg) = 3, and st' = st + s3 (the chip's tensile crack must first cancel s3).
``cutter.tilt_deg`` tau
    the resultant in the disc plane turns with the disc: Fs += -Fn sin(tau), Fn *= cos(tau).
``kinematics.speed_m_s`` v
    momentum flux of the rock pushed ahead: Fr += rho v^2 T p (small at cutting speeds).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np
import pandas as pd

from deckgen.spec import MM, MPA

RESPONSES = ("force_normal_N_mean_steady", "force_rolling_N_mean_steady", "force_side_N_mean_steady")

CSM_C = 2.12          # Rostami (1997)
CSM_PSI = 0.1         # pressure-distribution exponent, sharp disc (Rostami 1997: -0.2 ... 0.2)
K_ISO = 13.0          # isolated groove relieves itself at S_iso = K_ISO p (seed 001 sec. 6)
K_SIDE = 2.37         # seed 002 Table 2: Fs/Fn = K_SIDE * l/(2r), least squares through 0
K_SCRUB = 0.49        # seed 002 Table 2: dFr/Fn = 1.17 * l/(2r) = K_SCRUB * Fs/Fn
MC_Q = 3.0            # Mohr-Coulomb passive factor at a 30 deg friction angle
# Fallback strengths when the case has no material.targets: ratios of the uncalibrated virtual
# tests in ENGINE_NOTES (bond tensile strength 30 MPa -> UCS 47 MPa, BTS 6.5 MPa).
UCS_PER_BOND_TENSILE = 47.0 / 30.0
BTS_PER_BOND_TENSILE = 6.5 / 30.0

#: Spec fields the fast model reads (flattened paths).
INPUTS = (
    "cutter.kind", "cutter.diameter_mm", "cutter.small_diameter_mm", "cutter.edge_angle_deg",
    "cutter.blade_angle_deg", "cutter.flank_angle_deg", "cutter.clearance_angle_deg", "cutter.rake_angle_deg",
    "cutter.tip_width_mm", "cutter.tip_radius_mm", "cutter.hub_width_mm", "cutter.wear_flat_mm", "cutter.tilt_deg",
    "kinematics.mode", "kinematics.speed_m_s", "kinematics.penetration_mm", "kinematics.rotary_radius_mm",
    "kinematics.spin", "kinematics.neighbour_spacing_mm", "specimen.confining_stress_MPa",
    "material.density_kg_m3", "material.targets.ucs_MPa", "material.targets.bts_MPa",
    "bonds.tensile_strength_MPa", "contact.cutter_friction",
)


class FastModelError(ValueError):
    """A case the reduced model does not cover (e.g. oscillation or indentation)."""


@lru_cache(maxsize=4096)
def _profile(kind: str, geom: tuple[float, ...], wear_m: float) -> np.ndarray:
    from dataclasses import fields

    from deckgen.geometry import _PARAMS, wear_flat

    cls = _PARAMS[kind]
    names = [f.name for f in fields(cls) if f.name not in ("flat_side", "clearance_angle_deg")]
    prm = cls(**dict(zip(names, geom)))
    return wear_flat(prm.profile(), wear_m)


def _geom(row: Any) -> tuple[str, tuple[float, ...]]:
    kind = row["cutter.kind"]
    g = lambda k: float(row[f"cutter.{k}"])  # noqa: E731
    if kind == "v_disc":
        return kind, (g("diameter_mm") * MM, g("edge_angle_deg"), g("tip_radius_mm") * MM, g("hub_width_mm") * MM)
    if kind == "ccs_disc":
        return kind, (g("diameter_mm") * MM, g("tip_width_mm") * MM, g("tip_radius_mm") * MM, g("flank_angle_deg"),
                      g("hub_width_mm") * MM)
    if kind == "asymmetric_disc":
        return kind, (g("diameter_mm") * MM, g("blade_angle_deg"), g("tip_radius_mm") * MM, g("hub_width_mm") * MM)
    return kind, (g("small_diameter_mm") * MM, g("diameter_mm") * MM, g("rake_angle_deg"), g("tip_radius_mm") * MM)


def contact_geometry(row: Any) -> tuple[float, float, float]:
    """(R, T, w) [m] of a case row: worn rim radius, contact width half-way down the cut, land width."""
    kind, geom = _geom(row)
    return _contact(kind, geom, float(row["cutter.wear_flat_mm"]) * MM, float(row["kinematics.penetration_mm"]) * MM)


@lru_cache(maxsize=65536)
def _contact(kind: str, geom: tuple[float, ...], w: float, p: float) -> tuple[float, float, float]:
    from deckgen.geometry import _slice_width as profile_width

    try:
        prof = _profile(kind, geom, w)
    except ValueError as exc:
        raise FastModelError(f"cutter: {exc}") from None
    R = float(prof[:, 0].max())
    if p >= R:
        raise FastModelError(f"kinematics.penetration_mm {p / MM:g} is not less than the (worn) cutter radius {R / MM:.4g} mm")
    T = float(profile_width(prof, R - 0.5 * p)[0])
    land = float(profile_width(prof, R * (1 - 1e-9))[0])
    return R, max(T, 1e-6), land


def _strengths(row: Any) -> tuple[float, float]:
    ucs, bts = row["material.targets.ucs_MPa"], row["material.targets.bts_MPa"]
    sb = float(row["bonds.tensile_strength_MPa"])
    ucs = float(ucs) if ucs is not None and np.isfinite(ucs) else UCS_PER_BOND_TENSILE * sb
    bts = float(bts) if bts is not None and np.isfinite(bts) else BTS_PER_BOND_TENSILE * sb
    return ucs * MPA, bts * MPA


def predict_row(row: Any) -> dict[str, float]:
    """Mean steady forces [N] for one flattened case row (a mapping of spec paths to values)."""
    mode = row["kinematics.mode"]
    if mode not in ("linear", "rotary"):
        raise FastModelError(f"kinematics.mode {mode}: the fast backend models linear and rotary cutting only "
                             f"(fix: use --backend dem)")
    R, T, land = contact_geometry(row)
    p = float(row["kinematics.penetration_mm"]) * MM
    sc, st = _strengths(row)
    s3 = float(row["specimen.confining_stress_MPa"]) * MPA
    sc, st = sc + MC_Q * s3, st + s3
    phi = math.acos((R - p) / R)
    s_iso = K_ISO * p
    S = row["kinematics.neighbour_spacing_mm"]
    if S is None or not np.isfinite(S):
        s_eff = s_iso
    else:
        S = float(S) * MM
        s_eff = (S**-4 + s_iso**-4) ** -0.25
    P0 = CSM_C * (s_eff * sc**2 * st / (phi * math.sqrt(R * T))) ** (1.0 / 3.0)
    Ft = T * R * phi * P0 / (1.0 + CSM_PSI)
    f_land = min(land / T, 1.0)
    Fn = Ft * ((1 - f_land) * math.cos(phi / 2) + f_land * math.cos(phi / 4))
    Fr = Ft * ((1 - f_land) * math.sin(phi / 2) + f_land * math.sin(phi / 4))
    if row["kinematics.spin"] == "none":
        Fr += float(row["contact.cutter_friction"]) * Ft
    v = float(row["kinematics.speed_m_s"])
    Fr += float(row["material.density_kg_m3"]) * v * v * T * p
    Fs = 0.0
    if mode == "rotary":
        beta = R * phi / (2.0 * float(row["kinematics.rotary_radius_mm"]) * MM)
        Fs = -K_SIDE * beta * Fn
        Fr += K_SCRUB * abs(Fs)
    tau = math.radians(float(row["cutter.tilt_deg"]))
    if tau:
        Fs += -Fn * math.sin(tau)
        Fn *= math.cos(tau)
    return {"force_normal_N_mean_steady": Fn, "force_rolling_N_mean_steady": Fr, "force_side_N_mean_steady": Fs}


def predict(table: pd.DataFrame) -> pd.DataFrame:
    """Responses for every row of a flattened case table (columns = spec paths, see :data:`INPUTS`)."""
    missing = [c for c in INPUTS if c not in table.columns]
    if missing:
        raise FastModelError(f"case table lacks {missing}")
    cols = {c: table[c].tolist() for c in INPUTS}
    rows = [dict(zip(INPUTS, vals)) for vals in zip(*cols.values())]
    return pd.DataFrame([predict_row(r) for r in rows], index=table.index, columns=list(RESPONSES))
