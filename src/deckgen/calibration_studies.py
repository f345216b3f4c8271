"""Studies around the calibration (issue #3), each a real DEM measurement with its own table.

``python -m deckgen.calibration_studies <study> ...``:

- ``ratio``: how the bond shear/tensile strength ratio, contact friction, rolling friction, the
  bond radius multiplier and clumps move UCS, BTS, E and UCS/BTS (one UCS + one BTS test per variant;
  ``--set high-strain``: at sigma_c/E_b 3e-3, ``--card``: base case and speeds of a material card).
- ``quasistatic``: a material card's calibrated point at its platen speeds and at half of them; the
  change of the peak stresses says whether the loading is quasi-static (issue #3 asks < 3 %).
- ``seeds``: a calibrated card re-run on new packing seeds: mean, standard deviation and coefficient
  of variation of UCS, BTS and E.
- ``table``: the per-rock results table (markdown) from the calibrated cards and the seed studies.
- ``resolution``: calibrated cards of one rock at several grain sizes side by side (markdown): how the
  calibrated micro-parameters move with the particle size (issue #3, item 6).

Every study writes ``<out>/<study>.csv`` (one row per virtual test pair) and ``<out>/<study>.md``; the
engine runs live under ``<out>/work/`` and are answered from disk when repeated (like the calibration).
"""

from __future__ import annotations

import argparse
import json
import math
import shlex
import sys
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from deckgen.calibrate import (
    BTS_MAX_BROKEN_AT_PEAK,
    COARSE_PACKING,
    DEFAULT_BTS,
    DEFAULT_UCS,
    GPA,
    MPA,
    CardError,
    DemEvaluator,
    MicroParams,
    broken_at_peak,
    load_card,
    quasi_static_specimens,
)
from deckgen.spec import SpecError, deep_merge

#: Variants of the ratio study, relative to the base point (E_b 40 GPa, sigma_c 30 MPa).
RATIO_VARIANTS: list[tuple[str, dict[str, float]]] = [
    ("tau/sigma=1", {"shear_strength_MPa": 30.0}),
    ("tau/sigma=2 (base)", {}),
    ("tau/sigma=1, interaction range gap 0.4 r", {"shear_strength_MPa": 30.0, "gap_tolerance": 0.4}),
    ("tau/sigma=1, interaction range gap 0.8 r", {"shear_strength_MPa": 30.0, "gap_tolerance": 0.8}),
    ("tau/sigma=0.5", {"shear_strength_MPa": 15.0}),
    ("tau/sigma=1, friction 1.0", {"shear_strength_MPa": 30.0, "friction": 1.0}),
    ("tau/sigma=1, radius multiplier 0.6", {"shear_strength_MPa": 30.0, "radius_multiplier": 0.6}),
    ("tau/sigma=1, interaction range gap 0.6 r", {"shear_strength_MPa": 30.0, "gap_tolerance": 0.6}),
]

#: High bond failure strain (issue #3: sandstone and concrete need sigma_c/E_b of 3e-3 to 6e-3, where
#: the interaction range and the contact modulus left UCS/BTS at 5-7.7). Base point: E_b 20 GPa,
#: sigma_c = tau_c = 60 MPa (sigma_c/E_b = 3e-3), g 0.4, E_c/E_b 4; each variant changes one mechanism.
HIGH_STRAIN_BASE = MicroParams(youngs_modulus_GPa=20.0, tensile_strength_MPa=60.0, shear_strength_MPa=60.0,
                               gap_tolerance=0.4, contact_modulus_ratio=4.0)
HIGH_STRAIN_VARIANTS: list[tuple[str, dict[str, Any]]] = [
    ("base (sigma_c/E_b 3e-3, g 0.4, E_c/E_b 4, tau/sigma 1)", {}),
    ("tau/sigma=0.5", {"shear_strength_MPa": 30.0}),
    ("tau/sigma=0.25", {"shear_strength_MPa": 15.0}),
    ("rolling friction 0.3", {"rolling_friction": 0.3}),
    ("friction 1.0", {"friction": 1.0}),
    ("clumps of 2", {"clump_size": 2}),
    ("clumps of 4", {"clump_size": 4}),
    ("clumps of 8", {"clump_size": 8}),
    ("clumps of 4, intra-clump stiffness x10", {"clump_size": 4, "clump_stiffness_factor": 10.0}),
    ("interaction range g 0.05", {"gap_tolerance": 0.05}),
    ("clumps of 4, g 0.05", {"clump_size": 4, "gap_tolerance": 0.05}),
    ("tau/sigma=0.5, sigma_c/E_b 6e-3", {"tensile_strength_MPa": 120.0, "shear_strength_MPa": 60.0}),
    ("tau/sigma=0.25, sigma_c/E_b 6e-3", {"tensile_strength_MPa": 120.0, "shear_strength_MPa": 30.0}),
    ("clumps of 16", {"clump_size": 16}),
    ("clumps of 8, tau/sigma=0.5", {"clump_size": 8, "shear_strength_MPa": 30.0}),
    ("clumps of 8, tau/sigma=0.25", {"clump_size": 8, "shear_strength_MPa": 15.0}),
    # tau_c = 60 MPa (tau_c/E_b 3e-3 as the base), sigma_c raised: how much does sigma_c matter at fixed tau_c?
    ("tau/sigma=0.25 at tau_c/E_b 3e-3 (sigma_c 240)", {"tensile_strength_MPa": 240.0}),
    ("tau/sigma=0.1 at tau_c/E_b 3e-3 (sigma_c 600)", {"tensile_strength_MPa": 600.0}),
    # the two that raise M = (UCS/BTS)(UCS/E) most, together
    ("clumps of 16, sigma_c 600 (tau/sigma=0.1)", {"clump_size": 16, "tensile_strength_MPa": 600.0}),
    # closed cohesionless contacts (Schoepfer et al. 2009 "crack density"): tension loses the missing bonds,
    # compression keeps them as frictional contacts
    ("unbonded 0.25", {"unbonded_fraction": 0.25}),
    ("unbonded 0.5", {"unbonded_fraction": 0.5}),
    ("unbonded 0.75", {"unbonded_fraction": 0.75}),
    # bending and twisting strengths set apart from sigma_c and tau_c
    ("bending strength x10", {"bending_strength_factor": 10.0}),
    ("bending strength x0.3", {"bending_strength_factor": 0.3}),
    ("twisting strength x10", {"twisting_strength_factor": 10.0}),
    ("unbonded 0.5, clumps of 16", {"unbonded_fraction": 0.5, "clump_size": 16}),
    # the torque factors that raised UCS/BTS (bending x0.3) and M (twisting x10), together and with clumps
    ("bending x0.3 and twisting x10", {"bending_strength_factor": 0.3, "twisting_strength_factor": 10.0}),
    ("twisting x10, clumps of 16", {"twisting_strength_factor": 10.0, "clump_size": 16}),
    ("bending x0.1 and twisting x100", {"bending_strength_factor": 0.1, "twisting_strength_factor": 100.0}),
    ("bending x0.3 and twisting x10, clumps of 16", {"bending_strength_factor": 0.3, "twisting_strength_factor": 10.0,
                                                      "clump_size": 16}),
    ("bending x0.3 and twisting x10, tau/sigma=0.5", {"bending_strength_factor": 0.3, "twisting_strength_factor": 10.0,
                                                       "shear_strength_MPa": 30.0}),
    ("twisting x100, clumps of 16", {"twisting_strength_factor": 100.0, "clump_size": 16}),
    # with clumps of 16 and twisting x100 (M 11.9): which knob trades UCS/E for UCS/BTS?
    ("t100c16 + sigma_c 240 (tau/sigma 0.25)", {"twisting_strength_factor": 100.0, "clump_size": 16,
                                                "tensile_strength_MPa": 240.0}),
    ("t100c16 + g 0.2", {"twisting_strength_factor": 100.0, "clump_size": 16, "gap_tolerance": 0.2}),
    ("t100c16 + E_c/E_b 1", {"twisting_strength_factor": 100.0, "clump_size": 16, "contact_modulus_ratio": 1.0}),
    ("twisting x10 + clumps of 16 + tau/sigma=0.5", {"twisting_strength_factor": 10.0, "clump_size": 16,
                                                    "shear_strength_MPa": 30.0}),
    # with clumps a lower tau/sigma lowered UCS/BTS (5.1 at 0.5, 4.5 at 0.25): the other way, lower sigma_c at
    # tau_c 60 MPa; and both strengths halved (the failure strain axis, at constant tau/sigma)
    ("t100c16 + sigma_c 30 (tau/sigma 2)", {"twisting_strength_factor": 100.0, "clump_size": 16,
                                            "tensile_strength_MPa": 30.0}),
    ("t100c16 + sigma_c 15 (tau/sigma 4)", {"twisting_strength_factor": 100.0, "clump_size": 16,
                                            "tensile_strength_MPa": 15.0}),
    ("t100c16 + sigma_c = tau_c = 30 (sigma_c/E_b 1.5e-3)", {"twisting_strength_factor": 100.0, "clump_size": 16,
                                                             "tensile_strength_MPa": 30.0, "shear_strength_MPa": 30.0}),
    # twisting x10 and x100 with clumps of 16 did not fail in compression within 4 % strain: the twisting
    # factor between 1 (clumps of 16: fails at 1.0 %) and 10
    ("c16 + twisting x1.5", {"twisting_strength_factor": 1.5, "clump_size": 16}),
    ("c16 + twisting x2", {"twisting_strength_factor": 2.0, "clump_size": 16}),
    ("c16 + twisting x2.5", {"twisting_strength_factor": 2.5, "clump_size": 16}),
    ("c16 + twisting x3", {"twisting_strength_factor": 3.0, "clump_size": 16}),
    ("c16 + twisting x5", {"twisting_strength_factor": 5.0, "clump_size": 16}),
    # at twisting x2 (the strongest that fails): tau/sigma 2 (sigma_c 30 at tau_c 60), and both strengths doubled
    ("c16t2 + sigma_c 30 (tau/sigma 2)", {"twisting_strength_factor": 2.0, "clump_size": 16, "tensile_strength_MPa": 30.0}),
    ("c16t2 + sigma_c = tau_c = 120 (sigma_c/E_b 6e-3)", {"twisting_strength_factor": 2.0, "clump_size": 16,
                                                           "tensile_strength_MPa": 120.0, "shear_strength_MPa": 120.0}),
    # E from the contacts instead of the bonds (E_c/E_b 4 -> 10) at the failing twisting x2 point: lower UCS/E?
    ("c16t2 + E_c/E_b 10", {"twisting_strength_factor": 2.0, "clump_size": 16, "contact_modulus_ratio": 10.0}),
    # weakest-link flaws: Weibull-distributed bond strengths (mean 1; CoV 0.23 / 0.36 / 0.52): does tension, which
    # runs one crack through the weakest bonds, lose more than compression, which needs many bonds to break?
    ("Weibull m 5", {"strength_weibull_modulus": 5.0}),
    ("Weibull m 3", {"strength_weibull_modulus": 3.0}),
    ("Weibull m 2", {"strength_weibull_modulus": 2.0}),
    ("c16t2 + Weibull m 3", {"twisting_strength_factor": 2.0, "clump_size": 16, "strength_weibull_modulus": 3.0}),
    # the 2 % radius shrink before bonding opens a gap of 2 % of the radii at every contact: an unbonded pair then
    # carries no compression until the specimen has strained that far. Without it, unbonded pairs are closed
    # contacts from the start (the cohesionless cracks of Schoepfer et al. 2009, or the slit elements of a
    # flat-joint model): they carry compression at once and no tension
    ("shrink 0.005", {"shrink_before_bonding": 0.005}),
    ("no shrink", {"shrink_before_bonding": 0.0}),
    ("no shrink, unbonded 0.25", {"unbonded_fraction": 0.25, "shrink_before_bonding": 0.0}),
    ("no shrink, unbonded 0.5", {"unbonded_fraction": 0.5, "shrink_before_bonding": 0.0}),
    # a cylinder of 776 grains holds only about 48 clumps of 16: does the twisting factor act as smoothly on
    # smaller clumps (about 97 of 8, 194 of 4 per cylinder)?
    ("c8 + twisting x2", {"twisting_strength_factor": 2.0, "clump_size": 8}),
    ("c8 + twisting x3", {"twisting_strength_factor": 3.0, "clump_size": 8}),
    ("c4 + twisting x3", {"twisting_strength_factor": 3.0, "clump_size": 4}),
    ("c4 + twisting x5", {"twisting_strength_factor": 5.0, "clump_size": 4}),
]
#: The split base of the flat-joint set (beta 0, sigma_c 30, c 120 MPa: the highest UCS/BTS whose discs split)
_SPLIT_BASE: dict[str, Any] = {"flat_joint": 1, "moment_contribution": 0.0, "tensile_strength_MPa": 30.0,
                               "shear_strength_MPa": 120.0}
#: The flat joint (bonds.model flat_joint, deckgen's plugin bond: tension and Mohr-Coulomb shear checked apart,
#: a broken bond stays a frictional face that resists rocking) at the high-strain base point; the first row is
#: the bpm/rotational base itself, measured beside it.
FLAT_JOINT_VARIANTS: list[tuple[str, dict[str, Any]]] = [
    ("bpm/rotational base (sigma_c/E_b 3e-3, g 0.4, E_c/E_b 4, tau/sigma 1)", {}),
    ("flat joint, mu 0.5", {"flat_joint": 1}),
    ("flat joint, mu 1.0", {"flat_joint": 1, "joint_friction": 1.0}),
    ("flat joint, mu 0.5, c/sigma 2", {"flat_joint": 1, "shear_strength_MPa": 120.0}),
    ("flat joint, mu 0.5, c/sigma 0.5", {"flat_joint": 1, "shear_strength_MPa": 30.0}),
    ("flat joint, mu 0.5, g 0.05", {"flat_joint": 1, "gap_tolerance": 0.05}),
    ("flat joint, mu 0.5, E_c/E_b 1", {"flat_joint": 1, "contact_modulus_ratio": 1.0}),
    # UCS failed by tension breaks (bending included) at c/sigma 1 and 2: the tensile strength lowered at c 60 MPa
    ("flat joint, mu 0.5, sigma_c 30 (c/sigma 2)", {"flat_joint": 1, "tensile_strength_MPa": 30.0}),
    ("flat joint, mu 0.5, sigma_c 15 (c/sigma 4)", {"flat_joint": 1, "tensile_strength_MPa": 15.0}),
    ("flat joint, mu 1.0, sigma_c 15 (c/sigma 4)", {"flat_joint": 1, "joint_friction": 1.0, "tensile_strength_MPa": 15.0}),
    # slit faces (Potyondy 2012): pairs left unbonded are faces broken from the start: compression, friction and
    # rocking resistance, no tension
    ("flat joint, mu 0.5, slits 0.25", {"flat_joint": 1, "unbonded_fraction": 0.25}),
    ("flat joint, mu 0.5, slits 0.5", {"flat_joint": 1, "unbonded_fraction": 0.5}),
    ("flat joint, mu 0.5, slits 0.75", {"flat_joint": 1, "unbonded_fraction": 0.75}),
    # UCS scaled with sigma_c (tension breaks, bending included): PFC's moment-contribution factor beta
    ("flat joint, mu 0.5, beta 0.5", {"flat_joint": 1, "moment_contribution": 0.5}),
    ("flat joint, mu 0.5, beta 0", {"flat_joint": 1, "moment_contribution": 0.0}),
    # the face radius: rocking limit |F_n| R_b, bending stiffness ~ R_b^4
    ("flat joint, mu 0.5, bond radius x2", {"flat_joint": 1, "radius_multiplier": 2.0}),
    # the best M so far (c/sigma 2) pushed: a higher cohesion, and with more friction
    ("flat joint, mu 0.5, c/sigma 4", {"flat_joint": 1, "shear_strength_MPa": 240.0}),
    ("flat joint, mu 1.0, c/sigma 2", {"flat_joint": 1, "joint_friction": 1.0, "shear_strength_MPa": 120.0}),
    # beta 0 gave the highest M (7.9 %): with the other knobs that raised M
    ("flat joint, beta 0, c/sigma 2", {"flat_joint": 1, "moment_contribution": 0.0, "shear_strength_MPa": 120.0}),
    ("flat joint, beta 0, mu 1.0", {"flat_joint": 1, "moment_contribution": 0.0, "joint_friction": 1.0}),
    ("flat joint, beta 0, slits 0.5", {"flat_joint": 1, "moment_contribution": 0.0, "unbonded_fraction": 0.5}),
    # beta 0 (M 7.9 %), mu 1 with c/sigma 2 (8.6 %) and the bond radius x2 (8.2 %) together
    ("flat joint, beta 0, mu 1.0, c/sigma 2", {"flat_joint": 1, "moment_contribution": 0.0, "joint_friction": 1.0,
                                               "shear_strength_MPa": 120.0}),
    # beta 0, c/sigma 2 gave M 12.8 % at UCS/BTS 5.8: does a lower sigma_c (c 120 MPa kept) trade UCS/E for UCS/BTS?
    ("flat joint, beta 0, sigma_c 30, c 120 (c/sigma 4)", {"flat_joint": 1, "moment_contribution": 0.0,
                                                           "tensile_strength_MPa": 30.0, "shear_strength_MPa": 120.0}),
    ("flat joint, beta 0, sigma_c 15, c 120 (c/sigma 8)", {"flat_joint": 1, "moment_contribution": 0.0,
                                                           "tensile_strength_MPa": 15.0, "shear_strength_MPa": 120.0}),
    # c/sigma 8 gave UCS/BTS 8.3 at M 15 %: the tensile strength lowered further at c 120 MPa
    ("flat joint, beta 0, sigma_c 7.5, c 120 (c/sigma 16)", {"flat_joint": 1, "moment_contribution": 0.0,
                                                             "tensile_strength_MPa": 7.5, "shear_strength_MPa": 120.0}),
    ("flat joint, beta 0, sigma_c 3.75, c 120 (c/sigma 32)", {"flat_joint": 1, "moment_contribution": 0.0,
                                                              "tensile_strength_MPa": 3.75, "shear_strength_MPa": 120.0}),
    # bpm/rotational's UCS/BTS rose as the failure strain fell: beta 0, c/sigma 2 at half and a quarter of the strengths
    ("flat joint, beta 0, sigma_c 30, c 60 (c/sigma 2)", {"flat_joint": 1, "moment_contribution": 0.0,
                                                          "tensile_strength_MPa": 30.0}),
    ("flat joint, beta 0, sigma_c 15, c 30 (c/sigma 2)", {"flat_joint": 1, "moment_contribution": 0.0,
                                                          "tensile_strength_MPa": 15.0, "shear_strength_MPa": 30.0}),
    # the interaction range (Scholtes & Donze 2013) with the flat joint's faces
    ("flat joint, beta 0, c/sigma 2, g 0.2", {"flat_joint": 1, "moment_contribution": 0.0, "shear_strength_MPa": 120.0,
                                              "gap_tolerance": 0.2}),
    ("flat joint, beta 0, c/sigma 2, g 0.6", {"flat_joint": 1, "moment_contribution": 0.0, "shear_strength_MPa": 120.0,
                                              "gap_tolerance": 0.6}),
    # faces of several elements (bonds.face_sectors, one ring): a partly broken face keeps resisting bending
    # (3 and 4 sectors gave UCS/BTS 5.1 and 4.9 at 5-8 min a row; their combinations were not run)
    ("flat joint with 3 sectors", {"flat_joint": 1, "face_sectors": 3}),
    ("flat joint with 4 sectors", {"flat_joint": 1, "face_sectors": 4}),
    # gapped faces (bonds.face_gap_tolerance; Potyondy's installation gap): near neighbours that are not bonded
    # meet as flat faces once they touch, instead of round Hertz grains
    ("flat joint gapped to 0.4, g 0.05", {"flat_joint": 1, "gap_tolerance": 0.05, "face_gap_tolerance": 0.4}),
    ("flat joint gapped to 0.8", {"flat_joint": 1, "face_gap_tolerance": 0.8}),
    ("flat joint gapped to 0.4, g 0.05, beta 0", {"flat_joint": 1, "gap_tolerance": 0.05, "face_gap_tolerance": 0.4,
                                                  "moment_contribution": 0.0}),
    # split or crushed (docs/calibration.md): c/sigma above 4 at c 120 MPa crushed the discs (25-56 % of the bonds
    # broken at the peak); what raises UCS/BTS above 8.3 (c/sigma 4) while the discs still split?
    ("split: beta 0, sigma_c 30, c 120, mu 1.0", {**_SPLIT_BASE, "joint_friction": 1.0}),
    ("split: beta 0, sigma_c 20, c 120 (c/sigma 6)", {**_SPLIT_BASE, "tensile_strength_MPa": 20.0}),
    ("split: beta 0, sigma_c 30, c 240 (c/sigma 8)", {**_SPLIT_BASE, "shear_strength_MPa": 240.0}),
    ("split: beta 0, sigma_c 30, c 120, slits 0.25", {**_SPLIT_BASE, "unbonded_fraction": 0.25}),
    # a stiffer shear spring (k_n/k_s 1) lowers the grains' lateral tension under compression (Poisson's ratio);
    # a stiffer Hertz contact and a longer interaction range add load paths in compression
    ("split: beta 0, sigma_c 30, c 120, k_n/k_s 1", {**_SPLIT_BASE, "stiffness_ratio": 1.0}),
    ("split: beta 0, sigma_c 30, c 120, E_c/E_b 8", {**_SPLIT_BASE, "contact_modulus_ratio": 8.0}),
    ("split: beta 0, sigma_c 30, c 120, g 0.6", {**_SPLIT_BASE, "gap_tolerance": 0.6}),
]
#: Variant sets of the ratio study: (base point, variants, output name).
RATIO_SETS: dict[str, tuple[MicroParams, list[tuple[str, dict[str, Any]]], str]] = {
    "default": (MicroParams(youngs_modulus_GPa=40.0, tensile_strength_MPa=30.0, shear_strength_MPa=60.0),
                RATIO_VARIANTS, "ratio"),
    "high-strain": (HIGH_STRAIN_BASE, HIGH_STRAIN_VARIANTS, "ratio_high_strain"),
    "flat-joint": (HIGH_STRAIN_BASE, FLAT_JOINT_VARIANTS, "ratio_flat_joint"),
}


def intra_clump_broken(run_dir: Path, parsed_dir: Path) -> dict[str, int]:
    """Broken bonds of a run split into intra-clump and other bonds.

    Intra-clump bonds are those whose type is in ``spec.json`` derived.clumps.intra_clump_bond_types
    (bond types are read from the Bonds section of ``specimen.data``); the broken bonds are the
    parsed ``broken`` table (atom-id pairs).
    """
    from deckgen.datafile import iter_section

    spec = json.loads((run_dir / "spec.json").read_text())
    intra_types = set(spec["derived"].get("clumps", {}).get("intra_clump_bond_types", []))
    btype: dict[tuple[int, int], int] = {}
    for _, parts in iter_section(run_dir / "specimen.data", "Bonds"):
        a, b = int(parts[2]), int(parts[3])
        btype[(min(a, b), max(a, b))] = int(parts[1])
    broken = pd.read_parquet(parsed_dir / "broken.parquet", columns=["id1", "id2"])
    types = [btype.get((min(a, b), max(a, b)), 0) for a, b in zip(broken["id1"], broken["id2"])]
    n_intra = sum(t in intra_types for t in types)
    return {"bonds": len(btype), "intra_bonds": sum(t in intra_types for t in btype.values()),
            "broken": len(types), "broken_intra": int(n_intra), "broken_other": int(len(types) - n_intra)}


def smoothed_peak(parsed_dir: Path, window_s: float) -> float:
    """Peak of the platen stress after a centred moving mean over ``window_s`` [s].

    The raw series of a coarse specimen is noisy (the jaw loads of the BTS discs swing by up to +-30 %
    between samples), so the raw peak is partly the noise's; the mean over a few P-wave transits is
    closer to the load the specimen carries.
    """
    ts = pd.read_parquet(parsed_dir / "timeseries.parquet", columns=["time_s", "stress_Pa"])
    if len(ts) < 2:
        return math.nan
    step = float(np.median(np.diff(ts["time_s"].to_numpy())))
    n = max(1, int(round(window_s / step))) if step > 0 else 1
    return float(ts["stress_Pa"].rolling(n, center=True, min_periods=1).mean().max())


def _smoothed(ev: DemEvaluator, p: MicroParams, E_Pa: float) -> dict[str, float]:
    """Smoothed peaks (:func:`smoothed_peak`, window = SMOOTH_TRANSITS P-wave transits of the loaded length
    at the measured E) of the UCS and BTS tests of a point, each the mean over its replicate packings."""
    out: dict[str, float] = {}
    for test in ("ucs", "bts"):
        case = ev.case(p, test)
        sp = case.specimen
        length = (sp.height_mm if test == "ucs" else sp.diameter_mm) * 1e-3  # type: ignore[union-attr]
        window = SMOOTH_TRANSITS * length / math.sqrt(E_Pa / case.material.density_kg_m3)
        vals = [smoothed_peak(ev.used_folder(p, test, i) / "parsed", window) for i in range(ev.replicates[test])]
        out[f"{test}_smoothed_Pa"] = float(np.mean(vals))
        if len(vals) > 1:
            out[f"{test}_smoothed_cv_1"] = float(np.std(vals, ddof=1) / np.mean(vals))
    out["ucs_to_bts_smoothed_1"] = out["ucs_smoothed_Pa"] / out["bts_smoothed_Pa"]
    return out


#: Moving-mean window of the smoothed peaks, in P-wave transits of the loaded specimen length.
SMOOTH_TRANSITS = 3.0


def _summaries(ev: DemEvaluator, p: MicroParams) -> tuple[dict[str, Any], dict[str, Any]]:
    return (json.loads((ev.used_folder(p, "ucs") / "parsed" / "summary.json").read_text()),
            json.loads((ev.used_folder(p, "bts") / "parsed" / "summary.json").read_text()))


def _row(label: str, ev: DemEvaluator, p: MicroParams) -> dict[str, Any]:
    r = ev.evaluate(p)
    row: dict[str, Any] = {"variant": label, **asdict(p), "ok": r["ok"], "error": r["error"],
                           "ucs_Pa": r["ucs_Pa"], "bts_Pa": r["bts_Pa"], "E_Pa": r["E_Pa"],
                           "ucs_to_bts_1": r["ucs_Pa"] / r["bts_Pa"] if r["ok"] else math.nan,
                           "wall_s": r.get("wall_s", math.nan)}
    if r["ok"]:
        u, b = _summaries(ev, p)
        row.update({
            "poisson_ratio_1": u.get("poisson_ratio_1", math.nan),
            "ucs_strain_at_peak_1": u.get("strain_at_peak_1"), "bts_strain_at_peak_1": b.get("strain_at_peak_1"),
            "ucs_max_strain_1": u.get("max_strain_1"), "bts_max_strain_1": b.get("max_strain_1"),
            "ucs_broken_tension": u.get("bonds_broken_tension"), "ucs_broken_shear": u.get("bonds_broken_shear"),
            "bts_broken_tension": b.get("bonds_broken_tension"), "bts_broken_shear": b.get("bonds_broken_shear"),
            "ucs_grains": u.get("n_grains"), "bts_grains": b.get("n_grains"),
            "ucs_steps": u.get("steps"), "bts_steps": b.get("steps"),
            "ucs_bonds_initial": u.get("n_bonds_initial"), "bts_bonds_initial": b.get("n_bonds_initial"),
            "ucs_bonds_broken": u.get("bonds_broken"), "bts_bonds_broken": b.get("bonds_broken"),
        })
        row.update(_smoothed(ev, p, r["E_Pa"]))
        # split or crushed (docs/calibration.md, "Split or crushed"): the discs' bonds broken at their peaks
        # (evaluate() has them from the discs' summaries already)
        row["bts_broken_at_peak_1"] = r["bts_broken_at_peak_1"]
        row["ucs_broken_at_peak_1"] = broken_at_peak(u)
        if "bts_cv_1" in r:
            row["bts_cv_1"] = r["bts_cv_1"]
        # the Brazilian stress when the disc has split (docs/calibration.md, "BTS at the split")
        row.update({"bts_split_Pa": r["bts_split_Pa"], "ucs_to_bts_split_1": r["ucs_Pa"] / r["bts_split_Pa"],
                    "bts_broken_at_split_1": r["bts_broken_at_split_1"], "bts_split_cv_1": r.get("bts_split_cv_1", math.nan)})
        if p.clump_size > 1:  # did the intra-clump bonds hold?
            for test in ("ucs", "bts"):
                used = ev.used_folder(p, test)
                c = intra_clump_broken(used / "run", used / "parsed")
                row.update({f"{test}_intra_clump_bonds": c["intra_bonds"], f"{test}_broken_intra_clump": c["broken_intra"]})
                spec = json.loads((used / "run" / "spec.json").read_text())
                row[f"{test}_clump_sizes"] = json.dumps(spec["derived"]["clumps"]["size_distribution"])
    return row


def _write(rows: list[dict[str, Any]], out: Path, name: str, title: str, cols: list[str]) -> pd.DataFrame:
    out.mkdir(parents=True, exist_ok=True)
    df = pd.DataFrame(rows)
    df.to_csv(out / f"{name}.csv", index=False)
    show = df[[c for c in cols if c in df]].copy()
    for c in show:
        if c.endswith("_Pa"):
            show[c.replace("_Pa", "_MPa")] = show.pop(c) / MPA
        if c == "E_Pa":
            show["E_GPa"] = show.pop("E_MPa") / 1e3
    (out / f"{name}.md").write_text(f"# {title}\n\n" + show.to_markdown(index=False, floatfmt=".4g") + "\n")
    return df


def ratio_study(out: Path, *, base: dict[str, Any] | None = None, ucs: dict[str, Any] | None = None,
                bts: dict[str, Any] | None = None, cache: Path | None = None,
                command: list[str] | None = None, parallel: bool = False, variant_set: str = "default",
                only: list[str] | None = None, bts_packings: int = 1) -> pd.DataFrame:
    """One UCS + BTS pair per variant of a set in :data:`RATIO_SETS` (calibration specimens, coarse grains;
    default base and specimens: density 2650, 0.1 m/s). ``only``: run the variants whose label starts
    with one of these strings (the table holds those)."""
    if variant_set not in RATIO_SETS:
        raise ValueError(f"ratio: unknown variant set {variant_set!r} (fix: one of {', '.join(RATIO_SETS)})")
    p0, variants, name = RATIO_SETS[variant_set]
    base = base or {"material": {"density_kg_m3": 2650}, "packing": dict(COARSE_PACKING)}
    ucs = ucs or {**DEFAULT_UCS, "platen_speed_m_s": 0.1}
    bts = bts or {**DEFAULT_BTS, "platen_speed_m_s": 0.1}
    ev = DemEvaluator(base, ucs, bts, out / "work", cache=cache, command=command, name="ratio", parallel=parallel,
                      bts_packings=bts_packings)
    if only:
        variants = [(lab, ch) for lab, ch in variants if any(lab.startswith(o) for o in only)]
        if not variants:
            raise ValueError(f"ratio: --only {only} matches no variant of {variant_set!r}")
    rows = []
    for label, change in variants:
        rows.append(_row(label, ev, replace(p0, **change)))
        r = rows[-1]
        print(f"{name}: {label}: UCS {r['ucs_Pa'] / MPA:.4g} MPa, BTS {r['bts_Pa'] / MPA:.4g} MPa, "
              f"E {r['E_Pa'] / GPA:.4g} GPa, UCS/BTS {r['ucs_to_bts_1']:.3g}, smoothed "
              f"{r.get('ucs_to_bts_smoothed_1', math.nan):.3g} ({r['wall_s']:.0f} s)", flush=True)
    return _write(rows, out, name, f"UCS/BTS mechanisms, set {variant_set} (deckgen.calibration_studies ratio)",
                  ["variant", "ucs_Pa", "bts_Pa", "E_Pa", "ucs_to_bts_1", "ucs_smoothed_Pa", "bts_smoothed_Pa",
                   "ucs_to_bts_smoothed_1", "bts_cv_1", "poisson_ratio_1", "bts_broken_at_peak_1",
                   "bts_split_Pa", "ucs_to_bts_split_1", "bts_split_cv_1", "bts_broken_at_split_1",
                   "ucs_bonds_broken", "bts_bonds_broken", "ucs_broken_intra_clump", "bts_broken_intra_clump",
                   "bts_broken_tension", "bts_broken_shear", "ucs_broken_tension", "ucs_broken_shear"])


def _card_setup(card_path: Path) -> tuple[Any, MicroParams, dict[str, Any], dict[str, Any], dict[str, Any]]:
    card = load_card(card_path)
    if card.calibrated is None:
        raise CardError(f"{card_path}: calibrated: missing (fix: run python -m deckgen.calibrate on it first)")
    p = MicroParams.from_overrides(card.calibrated.bonds, card.calibrated.contact)
    ucs, bts = quasi_static_specimens(card)
    return card, p, card.case_overrides(), ucs, bts


def quasistatic_study(card_path: Path, out: Path, *, cache: Path | None = None,
                      command: list[str] | None = None, parallel: bool = False,
                      ucs_packings: int | None = None, bts_packings: int | None = None) -> pd.DataFrame:
    """The calibrated point at the card's platen speeds and at half of them (same replicate packings
    as the calibration's evaluations, so the full-speed row reproduces the card's achieved values).
    ``ucs_packings``/``bts_packings`` (default: the card's) average more specimens, the calibration's first: the
    change at half speed is a paired difference whose noise falls with the number of specimens."""
    card, p, base, ucs, bts = _card_setup(card_path)
    n_ucs = ucs_packings or card.calibration.ucs_packings
    n_bts = bts_packings or card.calibration.bts_packings
    rows = []
    for factor in (1.0, 0.5):
        u = {**ucs, "platen_speed_m_s": ucs["platen_speed_m_s"] * factor}
        b = {**bts, "platen_speed_m_s": bts["platen_speed_m_s"] * factor}
        # the calibration's own evaluation (its replicate packings), at full and half speed
        ev = DemEvaluator(base, u, b, out / "work" / f"speed_{factor:g}", cache=cache, command=command, name=card.rock,
                          parallel=parallel, ucs_packings=n_ucs, bts_packings=n_bts,
                          bts_reading=card.calibration.bts_reading)
        row = _row(f"speed x{factor:g}", ev, p)
        row.update({"rock": card.rock, "speed_factor": factor, "ucs_speed_m_s": u["platen_speed_m_s"],
                    "bts_speed_m_s": b["platen_speed_m_s"], "ucs_packings": n_ucs, "bts_packings": n_bts})
        rows.append(row)
        if factor == 1.0 and row["ok"]:  # failure patterns of the calibrated point (issue #3: a snapshot per test)
            failure_snapshots(ev, p, out / f"plots_{card.rock}")
    df = pd.DataFrame(rows)
    for k in ("ucs_Pa", "bts_Pa", "E_Pa"):
        df[f"{k.removesuffix('_Pa')}_change_at_half_speed_1"] = df[k] / df[k].iloc[0] - 1.0
    return _write(df.to_dict("records"), out, f"quasistatic_{card.rock}",
                  f"Quasi-static check, {card.rock} (deckgen.calibration_studies quasistatic)",
                  ["variant", "ucs_packings", "bts_packings", "ucs_speed_m_s", "bts_speed_m_s", "ucs_Pa", "bts_Pa", "E_Pa",
                   "ucs_change_at_half_speed_1", "bts_change_at_half_speed_1", "E_change_at_half_speed_1"])


def failure_snapshots(ev: DemEvaluator, p: MicroParams, out: Path) -> list[Path]:
    """Plots of a point's first UCS cylinder and first Brazilian disc (deckgen.plots.plot_run: stress-strain, broken
    bonds, the damage-coloured failure pattern and, for the disc, where its bonds broke by the split) into ``out``."""
    from deckgen.plots import plot_run

    files: list[Path] = []
    for test in ("ucs", "bts"):
        files += plot_run(ev.used_folder(p, test) / "parsed", out)
    return files


def seeds_study(card_path: Path, out: Path, seeds: list[int], *, cache: Path | None = None,
                command: list[str] | None = None, parallel: bool = False) -> pd.DataFrame:
    """The calibrated point on new packing seeds: one UCS and one BTS test per seed, so the scatter is
    that of single specimens (the calibration itself averages ``bts_packings`` discs)."""
    card, p, base, ucs, bts = _card_setup(card_path)
    rows = []
    for seed in seeds:
        b = deep_merge(base, {"packing": {"seed": int(seed)}})
        ev = DemEvaluator(b, ucs, bts, out / "work" / f"seed_{seed}", cache=cache, command=command, name=card.rock,
                          parallel=parallel, bts_reading=card.calibration.bts_reading)
        row = _row(f"seed {seed}", ev, p)
        row.update({"rock": card.rock, "packing_seed": seed})
        rows.append(row)
        print(f"seeds {card.rock}: seed {seed}: UCS {row['ucs_Pa'] / MPA:.4g} MPa, BTS {row['bts_Pa'] / MPA:.4g} MPa, "
              f"E {row['E_Pa'] / GPA:.4g} GPa", flush=True)
    return _write(rows, out, f"seeds_{card.rock}", f"Packing-seed scatter, {card.rock} (deckgen.calibration_studies seeds)",
                  ["variant", "ucs_Pa", "bts_Pa", "E_Pa", "poisson_ratio_1", "ucs_grains", "bts_grains"])


def scatter(df: pd.DataFrame) -> dict[str, float]:
    """Mean, standard deviation (ddof 1) and coefficient of variation of UCS, BTS and E over the ok rows."""
    ok = df[df["ok"].astype(bool)]
    out: dict[str, float] = {"n": float(len(ok))}
    for k in ("ucs_Pa", "bts_Pa", "E_Pa"):
        v = ok[k].to_numpy(dtype=float)
        m, s = float(np.mean(v)) if len(v) else math.nan, float(np.std(v, ddof=1)) if len(v) > 1 else math.nan
        out.update({f"{k}_mean": m, f"{k}_std": s, f"{k}_cv": s / m if m else math.nan})
    return out


def _bond_law(bonds: dict[str, Any]) -> str:
    """Short name of a calibrated bonds block's law, e.g. 'flat joint, β 0' or 'bpm/rotational'."""
    if bonds.get("model") != "flat_joint":
        return "bpm/rotational"
    extra = [f"β {bonds['moment_contribution']:g}"] if "moment_contribution" in bonds else []
    if bonds.get("joint_friction", 0.5) != 0.5:
        extra.append(f"μ {bonds['joint_friction']:g}")
    if "bond_friction" in bonds:  # the intact bond's own friction (the broken face keeps joint_friction)
        extra.append(f"intact μ {bonds['bond_friction']:g}")
    return ", ".join(["flat joint", *extra])


def _split_cell(broken: float | None, limit: float | None, reading: str = "peak") -> str:
    """Table cell of the calibrated point's Brazilian discs: where the BTS is read (peak or split) and the fraction
    of bonds broken there, split or crushed against the card's limit (the default when the card has none)."""
    if broken is None:
        return f"{reading}: not recorded"
    limit = limit if limit is not None else BTS_MAX_BROKEN_AT_PEAK
    return f"{reading}: {broken:.0%} ({'split' if broken <= limit else 'crushed'}, limit {limit:.0%})"


def results_table(cards: list[Path], studies: Path) -> str:
    """Markdown table: per rock the achieved values, errors, evaluations, wall time and seed scatter."""
    head = ("| rock | grain radii mm | UCS MPa (err) | BTS MPa (err) | E GPa (err) | ν | UCS/BTS | evaluations "
            "| wall min (2 cores) | bond law | E_b GPa | σ_c MPa | τ_c/σ_c | g | E_c/E_b "
            "| new seeds: UCS, BTS, E mean ± sd (CV) | new-seed mean vs target | half speed: ΔUCS, ΔBTS "
            "| BTS read at: bonds broken there |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    lines = []
    for path in cards:
        try:
            card = load_card(path)
        except CardError as exc:
            lines.append(f"| {path} | {exc} |")
            continue
        p = card.provenance
        if p is None or card.calibrated is None:
            lines.append(f"| {card.rock} | not calibrated | | | | | | | | | | | | | | | | | |")
            continue
        a, b = p.achieved, card.calibrated.bonds
        nu = "–"
        sfile = studies / f"seeds_{card.rock}.csv"
        seeds = seed_err = "–"
        if sfile.is_file():
            sd = pd.read_csv(sfile)
            s = scatter(sd)
            seeds = (f"{s['ucs_Pa_mean'] / MPA:.3g} ± {s['ucs_Pa_std'] / MPA:.2g} ({s['ucs_Pa_cv']:.1%}), "
                     f"{s['bts_Pa_mean'] / MPA:.3g} ± {s['bts_Pa_std'] / MPA:.2g} ({s['bts_Pa_cv']:.1%}), "
                     f"{s['E_Pa_mean'] / GPA:.3g} ± {s['E_Pa_std'] / GPA:.2g} ({s['E_Pa_cv']:.1%}); n = {s['n']:.0f}")
            tg = card.targets.as_pa()
            seed_err = (f"{s['ucs_Pa_mean'] / tg['ucs'] - 1:+.1%}, {s['bts_Pa_mean'] / tg['bts'] - 1:+.1%}, "
                        f"{s['E_Pa_mean'] / tg['E'] - 1:+.1%}")
            if "poisson_ratio_1" in sd:
                nu = f"{sd['poisson_ratio_1'].mean():.2f}"
        qfile = studies / f"quasistatic_{card.rock}.csv"
        qs = "–"
        if qfile.is_file():
            q = pd.read_csv(qfile)
            if len(q) == 2:
                qs = f"{q['ucs_change_at_half_speed_1'].iloc[1]:+.1%}, {q['bts_change_at_half_speed_1'].iloc[1]:+.1%}"
        radii = (f"{p.radius_min_mm:g}-{p.radius_max_mm:g}" if p.radius_min_mm is not None and p.radius_max_mm is not None
                 else "–")
        lines.append(
            f"| {card.rock} | {radii} | {a.ucs_MPa:.4g} ({a.ucs_error:+.1%}) | {a.bts_MPa:.4g} ({a.bts_error:+.1%}) | "
            f"{a.youngs_modulus_GPa:.4g} ({a.youngs_modulus_error:+.1%}) | {nu} | {a.ucs_MPa / a.bts_MPa:.3g} | "
            f"{p.evaluations}{'' if p.converged else ' (not converged)'} | {p.wall_s / 60:.1f} | "
            f"{_bond_law(b)} | {b['youngs_modulus_GPa']:.4g} | {b['tensile_strength_MPa']:.4g} | "
            f"{b['shear_strength_MPa'] / b['tensile_strength_MPa']:.3g} | {b.get('gap_tolerance', 0.05):.3g} | "
            f"{card.calibrated.contact.get('youngs_modulus_GPa', b['youngs_modulus_GPa']) / b['youngs_modulus_GPa']:.3g} | "
            f"{seeds} | {seed_err} | {qs} | {_split_cell(a.bts_broken_at_peak, p.bts_max_broken_at_peak, p.bts_reading)} |")
    return head + "\n".join(lines) + "\n"


def _grain_radii_mm(card: Any) -> tuple[float, float]:
    """(r_min, r_max) of the packing a calibrated card was calibrated on (its provenance), mm."""
    pv = card.provenance
    if pv is None or pv.radius_min_mm is None or pv.radius_max_mm is None:
        raise CardError(f"{card.rock}: provenance.radius_min_mm/radius_max_mm: missing (fix: re-run "
                        f"python -m deckgen.calibrate on the card, which records them)")
    return float(pv.radius_min_mm), float(pv.radius_max_mm)


def resolution_table(cards: list[Path]) -> str:
    """Markdown table: calibrated cards of the same rock at different grain sizes, coarsest first per rock, with
    each micro-parameter also as a ratio to the coarsest card's (issue #3, item 6: how the micro-parameters move
    with the particle size). D/d is the specimen diameter over the mean grain diameter r_min + r_max."""
    head = ("| rock | grain radii mm | UCS D/d | BTS D/d | bond law | evaluations | UCS (err) | BTS (err) | E (err) "
            "| E_b GPa (× coarse) | σ_c MPa (× coarse) | τ_c MPa (× coarse) | τ_c/σ_c | g |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    groups: dict[str, list[Any]] = {}
    for path in cards:
        card = load_card(path)
        if card.calibrated is None or card.provenance is None:
            raise CardError(f"{path}: calibrated: missing (fix: give calibrated cards; run python -m deckgen.calibrate)")
        groups.setdefault(card.rock, []).append(card)
    lines = []
    for rock, group in groups.items():
        group.sort(key=lambda c: sum(_grain_radii_mm(c)), reverse=True)
        ref = group[0].calibrated.bonds
        for card in group:
            b, a, pv = card.calibrated.bonds, card.provenance.achieved, card.provenance
            r_min, r_max = _grain_radii_mm(card)
            d = r_min + r_max  # the mean grain diameter of uniform radii
            u, t = quasi_static_specimens(card)

            def cell(key: str) -> str:
                return f"{b[key]:.4g} (×{b[key] / ref[key]:.3f})"

            lines.append(
                f"| {rock} | {r_min:g}-{r_max:g} | {u['diameter_mm'] / d:.1f} | "
                f"{t['diameter_mm'] / d:.1f} | {_bond_law(b)}, BTS at {pv.bts_reading} | "
                f"{pv.evaluations}{'' if pv.converged else ' (not converged)'} | "
                f"{a.ucs_MPa:.4g} ({a.ucs_error:+.1%}) | {a.bts_MPa:.4g} ({a.bts_error:+.1%}) | "
                f"{a.youngs_modulus_GPa:.4g} ({a.youngs_modulus_error:+.1%}) | {cell('youngs_modulus_GPa')} | "
                f"{cell('tensile_strength_MPa')} | {cell('shear_strength_MPa')} | "
                f"{b['shear_strength_MPa'] / b['tensile_strength_MPa']:.3g} | {b.get('gap_tolerance', 0.05):.3g} |")
    return head + "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    from deckgen.runner import engine_command, stop_engines_on_sigterm

    stop_engines_on_sigterm()
    ap = argparse.ArgumentParser(prog="python -m deckgen.calibration_studies", description=__doc__.split("\n\n")[0])
    ap.add_argument("study", choices=["ratio", "quasistatic", "seeds", "table", "resolution"])
    ap.add_argument("cards", nargs="*", help="calibrated material cards (quasistatic, seeds, table, resolution)")
    ap.add_argument("--out", default="results/calibration/studies", help="output folder")
    ap.add_argument("--cache", default=None, help="packing cache")
    ap.add_argument("--seeds", default="101,202,303,404,505", help="seeds study: comma-separated packing seeds")
    ap.add_argument("--ranks", type=int, default=None, help="MPI ranks per engine run")
    ap.add_argument("--engine-cmd", default=None, help="engine command line")
    ap.add_argument("--jobs", type=int, choices=[1, 2], default=1,
                    help="2: run the UCS and BTS tests of a point at the same time (1 rank each unless --ranks)")
    ap.add_argument("--write", default=None, help="table, resolution: also write the markdown here")
    ap.add_argument("--set", dest="variant_set", default="default", choices=sorted(RATIO_SETS),
                    help="ratio: variant set (high-strain: sigma_c/E_b 3e-3, g 0.4, E_c/E_b 4)")
    ap.add_argument("--card", default=None, help="ratio: take the base case and the quasi-static specimens from "
                    "this material card (one packing per test) instead of density 2650 at 0.1 m/s")
    ap.add_argument("--only", action="append", default=None,
                    help="ratio: run the variants whose label starts with this prefix; repeat it for several (labels "
                         "hold commas, so a prefix is taken whole)")
    ap.add_argument("--bts-packings", type=int, default=None,
                    help="ratio: BTS discs (packing seeds) per variant, averaged (default 1); quasistatic: per speed "
                         "(default: the card's)")
    ap.add_argument("--ucs-packings", type=int, default=None, help="quasistatic: UCS cylinders per speed (default: the card's)")
    ap.add_argument("--ucs-stop", type=float, default=None, help="ratio: UCS stop_fraction_of_peak (default: the specimen's)")
    ap.add_argument("--bts-stop", type=float, default=None, help="ratio: BTS stop_fraction_of_peak (default: the specimen's)")
    a = ap.parse_args(argv)
    ranks = a.ranks or (1 if a.jobs == 2 else None)
    command = shlex.split(a.engine_cmd) if a.engine_cmd else (engine_command(ranks) if ranks else None)
    par = a.jobs == 2
    out, cache = Path(a.out), (Path(a.cache) if a.cache else None)
    try:
        if a.study == "ratio":
            base = ucs = bts = None
            if a.card:
                card = load_card(a.card)
                # the card's targets, base and specimens, not its calibrated point (the variants set the bonds)
                base = card.model_copy(update={"calibrated": None}).case_overrides()
                ucs, bts = quasi_static_specimens(card)
            only = [o for o in a.only if o.strip()] if a.only else None  # an empty prefix would match all
            ucs = ucs or {**DEFAULT_UCS, "platen_speed_m_s": 0.1}
            bts = bts or {**DEFAULT_BTS, "platen_speed_m_s": 0.1}
            if a.ucs_stop is not None:
                ucs = {**ucs, "stop_fraction_of_peak": a.ucs_stop}
            if a.bts_stop is not None:
                bts = {**bts, "stop_fraction_of_peak": a.bts_stop}
            print(ratio_study(out, base=base, ucs=ucs, bts=bts, cache=cache, command=command, parallel=par,
                              variant_set=a.variant_set, only=only, bts_packings=a.bts_packings or 1).to_string())
        elif a.study in ("table", "resolution"):
            if a.study == "resolution" and not a.cards:
                ap.error("resolution: give the calibrated cards of a rock at its grain sizes")
            paths = [Path(c) for c in a.cards]
            text = results_table(paths, out) if a.study == "table" else resolution_table(paths)
            print(text)
            if a.write:
                Path(a.write).write_text(text)
        else:
            if not a.cards:
                ap.error(f"{a.study}: give at least one calibrated card")
            for c in a.cards:
                if a.study == "quasistatic":
                    print(quasistatic_study(Path(c), out, cache=cache, command=command, parallel=par,
                                            ucs_packings=a.ucs_packings, bts_packings=a.bts_packings).to_string())
                else:
                    seeds = [int(s) for s in a.seeds.split(",") if s.strip()]
                    df = seeds_study(Path(c), out, seeds, cache=cache, command=command, parallel=par)
                    print(json.dumps(scatter(df), indent=1))
    except (CardError, SpecError, ValueError) as exc:
        print(str(exc), file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
