"""Catalogue of candidate physical effects for the discrepancy loop.

Every effect is a switch of the case spec that changes the model itself (deck, geometry or
kinematics), never a factor on the output: :meth:`Effect.apply` returns the case table with the
switch's spec fields set, and the backend (DEM decks or the reduced model) simulates that.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd


@dataclass(frozen=True)
class Magnitude:
    """The effect's size: a spec field fitted on a subset of cases when MEASURED.csv does not give it."""

    field: str
    unit: str
    lo: float
    hi: float
    scale: str = "lin"        # grid spacing: lin or log
    off: float | None = 0.0   # value that means "effect off" (None: off is a different switch)

    def grid(self, n: int) -> np.ndarray:
        if self.scale == "log":
            return np.geomspace(self.lo, self.hi, n)
        return np.linspace(self.lo, self.hi, n)


@dataclass(frozen=True)
class Effect:
    id: str
    name: str
    explanation: str
    responses: tuple[str, ...]
    factors: tuple[str, ...]
    signature: str
    switch: dict[str, Any] = field(default_factory=dict)
    magnitude: Magnitude | None = None
    evidence: str = ""

    @property
    def fields(self) -> list[str]:
        return list(self.switch) + ([self.magnitude.field] if self.magnitude else [])

    def is_on(self, row: dict[str, Any]) -> bool:
        """True when the base case already has this effect switched on."""
        if any(row.get(k) != v for k, v in self.switch.items()):
            return False
        if self.magnitude is not None and not self.switch:
            v = row.get(self.magnitude.field)
            return v is not None and v != self.magnitude.off
        return True

    def given(self, factors: list[str]) -> bool:
        """True when MEASURED.csv gives the magnitude per case (then nothing is fitted)."""
        return self.magnitude is not None and self.magnitude.field in factors

    def apply(self, cases: pd.DataFrame, value: float | None, factors: list[str]) -> pd.DataFrame:
        out = cases.copy()
        for k, v in self.switch.items():
            out[k] = v
        if self.magnitude is not None and not self.given(factors):
            out[self.magnitude.field] = float(value) if value is not None else math.nan
        return out

    def card(self) -> dict[str, Any]:
        d = {"id": self.id, "name": self.name, "explanation": self.explanation, "responses": list(self.responses),
             "factors": list(self.factors), "signature": self.signature, "switch": dict(self.switch),
             "evidence": self.evidence}
        if self.magnitude:
            m = self.magnitude
            d["magnitude"] = {"field": m.field, "unit": m.unit, "range": [m.lo, m.hi], "scale": m.scale}
        else:
            d["magnitude"] = None
        return d


N, R, S = "force_normal_N_mean_steady", "force_rolling_N_mean_steady", "force_side_N_mean_steady"

CATALOGUE: tuple[Effect, ...] = (
    Effect(
        id="free_rolling",
        name="Free rolling of the disc instead of a fixed (sliding) disc",
        explanation=(
            "A disc held fixed on its axle slides over the rock at the cutting speed, so the contact carries "
            "sliding friction; its moment about the axle is the friction moment T = mu Ft R. A disc on free "
            "bearings rolls on the groove floor and that moment vanishes. Seed 003 (sec. 5.5) found that "
            "removing the slip moment of its fixed disc changed the cutting force by 29 %."),
        responses=(R,),
        factors=("kinematics.penetration_mm", "contact.cutter_friction"),
        signature=("rolling force over-predicted by about mu times the total contact force in every case, normal "
                   "and side force unchanged: a constant offset of the rolling-to-normal force ratio (the lab-scale "
                   "CSM picture). In deckgen's DEM, at cut depths of one or two grains, the sliding friction also "
                   "pulls the disc into the rock, so a rolling disc carries a normal force 2-6 times higher "
                   "(docs/discrepancy.md, DEM end to end)"),
        switch={"kinematics.spin": "rolling"},
        evidence="seed 003 sec. 5.5 (29 % force change from the friction moment)",
    ),
    Effect(
        id="wear_flat",
        name="Wear flat (blunt rim) of width w",
        explanation=(
            "Abrasive wear flattens the rim into a land of width w (seed 003 sec. 1; recommended for its DEM in "
            "sec. 6). The land bears on the groove floor like a flat punch: the contact width and area grow, the "
            "crushed zone widens, and the extra load acts near the bottom of the contact arc, so the normal "
            "force rises much more than the rolling force. Seed 002 (sec. 5) notes that wear increases contact "
            "area and alters the force distribution."),
        responses=(N, R),
        factors=("kinematics.penetration_mm", "cutter.diameter_mm"),
        signature=("normal force under-predicted, relatively most at shallow penetration (the land is a larger "
                   "share of the contact width there); rolling-to-normal ratio over-predicted"),
        magnitude=Magnitude("cutter.wear_flat_mm", "mm", 0.0, 2.5, "lin", 0.0),
        evidence="seed 003 secs. 1, 6 (wear flat increases normal forces); seed 002 sec. 5",
    ),
    Effect(
        id="rotary_path",
        name="Rotary path at installation radius r instead of a straight cut",
        explanation=(
            "On a cutterhead the disc runs on a circle of radius r, while its plane is tangent to that circle at "
            "the centre only: over the contact arc l = R phi the disc is skewed to its own path by about l/(2r), "
            "scrubs the groove wall and pushes it sideways. Seed 002's 58 LS-DYNA rotary runs show side force "
            "and rolling force rising as r falls, which a linear-cutting model cannot produce."),
        responses=(S, R),
        factors=("kinematics.rotary_radius_mm", "kinematics.penetration_mm", "cutter.diameter_mm"),
        signature=("side force missing (model ~0) with magnitude growing like sqrt(penetration)/r; rolling force "
                   "under-predicted by about half the side force; normal force almost unchanged"),
        switch={"kinematics.mode": "rotary"},
        magnitude=Magnitude("kinematics.rotary_radius_mm", "mm", 15.0, 5000.0, "log", None),
        evidence="seed 002 Table 2 (Fs/Fn vs r), Table 4 (RCM measurements)",
    ),
    Effect(
        id="relieved_cutting",
        name="Neighbouring grooves at spacing S (relieved cutting)",
        explanation=(
            "A disc between existing grooves of its neighbours at spacing S needs only to break the ridge "
            "between them; an isolated groove has to break rock on both sides until the chip reaches the free "
            "surface. Seed 001 (sec. 6, Tables 3-4) shows normal and rolling forces rising with S until the "
            "cuts stop interacting (S/p of about 13 or more). In the deck the neighbouring grooves are cut out "
            "of the block before the cut."),
        responses=(N, R),
        factors=("kinematics.penetration_mm", "kinematics.neighbour_spacing_mm"),
        signature=("normal and rolling forces over-predicted by the same factor, more at deep cuts (where S/p is "
                   "small): the relative residual falls with penetration"),
        magnitude=Magnitude("kinematics.neighbour_spacing_mm", "mm", 1.0, 300.0, "log", None),
        evidence="seed 001 sec. 6 and eqs. 8-9 (forces rise with spacing); Gertsch et al. 2007 via seed 001 Table 3",
    ),
    Effect(
        id="confinement",
        name="Confining stress on the cutting block",
        explanation=(
            "In situ or in a loaded test rig the rock beside the groove is under a lateral stress s3. It raises "
            "the strength of the crushed zone (Mohr-Coulomb: by about 3 s3 at a 30 degree friction angle) and "
            "the side crack that makes the chip must first overcome s3. Seeds 002 (secs. 1, 5) and 001 name "
            "in-situ stress as the next missing factor of unconfined cutting models."),
        responses=(N, R, S),
        factors=("specimen.confining_stress_MPa",),
        signature=("all forces under-predicted by one common factor, independent of penetration and geometry; "
                   "indistinguishable from a strength calibration error unless the confinement varies"),
        magnitude=Magnitude("specimen.confining_stress_MPa", "MPa", 0.0, 60.0, "lin", 0.0),
        evidence="seed 002 secs. 1 and 5 (in-situ stress left out); Mohr-Coulomb",
    ),
    Effect(
        id="tilt",
        name="Tilt of the disc axis (camber / clearance misalignment)",
        explanation=(
            "A disc whose axis is tilted about the cut direction leans into one groove wall: the contact "
            "pressure is no longer symmetric about the disc plane and the resultant turns with the disc, giving "
            "a side force of about Fn tan(tau) of one sign in every case. Mounting play, a bent saddle or a "
            "deliberate clearance angle (seed 003's cone disc) do this."),
        responses=(S,),
        factors=("cutter.tilt_deg",),
        signature=("side force missing, proportional to the normal force (constant side-to-normal ratio, "
                   "independent of penetration and radius); rolling force unchanged"),
        magnitude=Magnitude("cutter.tilt_deg", "deg", -20.0, 20.0, "lin", 0.0),
        evidence="seed 003 (clearance angle sweeps of the cone disc)",
    ),
)

BY_ID = {e.id: e for e in CATALOGUE}


def catalogue_cards() -> list[dict[str, Any]]:
    return [e.card() for e in CATALOGUE]
