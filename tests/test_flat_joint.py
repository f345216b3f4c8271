"""bonds.model: flat_joint — deckgen's own LAMMPS bond style (src/deckgen/plugins/bond_flatjoint.cpp).

Two-grain engine checks of the law itself (tension strength, Mohr-Coulomb shear strength, the broken face's
friction and its lack of tension), the case validation, the deck, the calibration parameters and the parser
of the plugin's broken-bond file.
"""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from deckgen import plugins
from deckgen.calibrate import MicroParams
from deckgen.deck import FLAT_JOINT_BROKEN, render_case
from deckgen.parse import ParseError
from deckgen.results import _read_broken_joints, parse_run
from deckgen.runner import engine_available, engine_command, engine_env, limit_ranks, run_deck, set_ranks
from deckgen.spec import SpecError, load_case, resolved_dict

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "tests" / "data" / "cases"
FJ = {"bonds": {"model": "flat_joint"}}

have_compiler = shutil.which("g++") is not None or shutil.which("c++") is not None
needs_engine = pytest.mark.skipif(not (engine_available() and have_compiler),
                                  reason="no LAMMPS binary or no C++ compiler for the plugin (make setup)")

# two grains of radius 1 mm, density 2500, touching; the bond law's numbers
R, RHO = 1e-3, 2500.0
E_B, KAPPA, LAM, SIGMA_C, COH, MU = 1e9, 2.5, 1.0, 1e6, 2e6, 0.5
AREA = math.pi * (LAM * R) ** 2
K_N = E_B / (2 * R) * AREA  # N/m
DT, STEP = 1e-7, 1e-9  # s; platen-like motion of grain 2 per step [m]


def _deck_head(lib: Path, x2: tuple[float, float, float], coeffs: str) -> str:
    """Grain 1 at the origin, grain 2 at ``x2``, bonded with ``bond_coeff 1 <coeffs>``; groups g1, g2; dt DT."""
    return f"""plugin load {lib}
units si
atom_style bpm/sphere
special_bonds lj 0 1 1 coul 1 1 1
newton on off
comm_modify vel yes
region b block -0.01 0.01 -0.01 0.01 -0.01 0.01
create_box 1 b bond/types 1 extra/bond/per/atom 2 extra/special/per/atom 2
create_atoms 1 single 0.0 0.0 0.0
create_atoms 1 single {x2[0]:.12g} {x2[1]:.12g} {x2[2]:.12g}
set type 1 diameter {2 * R:.10g}
set type 1 density {RHO:.10g}
pair_style granular
pair_coeff * * hertz/material 1e9 0.5 0.25 tangential linear_nohistory 1.0 0.0
bond_style deckgen/flatjoint {FLAT_JOINT_BROKEN}
bond_coeff 1 {coeffs}
create_bonds single/bond 1 1 2
group g1 id 1
group g2 id 2
timestep {DT:.10g}
"""


def _two_grains(tmp: Path, moves: list[tuple[float, float, int]], beta: float = 1.0,
                spin_period_s: float = 0.0, sectors: int = 1, gap: float = 0.0, slit: int = 0,
                mu_b: float | None = None) -> np.ndarray:
    """Grain 1 held, grain 2 moved by ``(vx, vy, steps)`` legs (or, with ``spin_period_s``, turned about its own
    centre and the z axis for ``steps``); ``sectors`` > 1: a face of that many elements in one ring; ``gap``: grain
    2 starts that far from touching; ``slit``: the bond's slit code; ``mu_b``: the intact bond's own friction (the
    13th coefficient); returns rows step, fx2, fy2 every step."""
    elements = f" {slit} {sectors} 1" if sectors > 1 or mu_b is not None else (f" {slit}" if slit else "")
    if mu_b is not None:
        elements += f" {mu_b:.10g}"
    lib = plugins.install(tmp, "flatjoint")
    if spin_period_s:
        legs = "\n".join(f"fix m g2 move rotate {2 * R:.10g} 0 0 0 0 1 {spin_period_s:.10g}\nrun {n}\nunfix m"
                         for _, _, n in moves)
    else:
        legs = "\n".join(f"fix m g2 move linear {vx:.10g} {vy:.10g} 0\nrun {n}\nunfix m" for vx, vy, n in moves)
    coeffs = f"{E_B:.10g} {KAPPA:.10g} {LAM:.10g} {SIGMA_C:.10g} {COH:.10g} {MU:.10g} 0.0 {beta:.10g}{elements}"
    (tmp / "in.two").write_text(_deck_head(lib, (2 * R + gap, 0.0, 0.0), coeffs) + f"""variable fx2 equal fx[2]
variable fy2 equal fy[2]
thermo 100000
fix out all print 1 "$(step) ${{fx2}} ${{fy2}}" file forces.txt screen no
{legs}
""")
    proc = subprocess.run(engine_command(1) + ["-in", "in.two", "-log", "none"], cwd=tmp, env=engine_env(),
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return np.loadtxt(tmp / "forces.txt", comments="#")


def _breaks(tmp: Path) -> list[list[str]]:
    return [ln.split() for ln in (tmp / FLAT_JOINT_BROKEN).read_text().splitlines() if not ln.startswith("#")]


@needs_engine
def test_tension_breaks_at_sigma_c_and_the_broken_face_carries_compression_only(tmp_path):
    v = STEP / DT
    f = _two_grains(tmp_path, [(v, 0.0, 3000), (-v, 0.0, 5000)])
    pull, push = f[:3000], f[3000:]
    peak = -pull[:, 1].min()  # tension pulls grain 2 back (-x)
    assert peak == pytest.approx(SIGMA_C * AREA, rel=2e-3)  # 3.1416 N; one step moves the force by 5e-4 of it
    assert peak / K_N == pytest.approx(SIGMA_C * 2 * R / E_B, rel=2e-3)  # the failure strain sigma_c / E_b
    (brk,) = _breaks(tmp_path)
    assert brk[3] == "1" and 1990 <= int(brk[0]) <= 2010  # mode tension, at 2 um of stretch
    after = pull[int(brk[0]) + 1:]
    assert np.all(after[:, 1] == 0.0)  # an open face pulls nothing
    # pushed back to 2 um of compression: the broken face carries k_n * overlap, like the intact bond
    assert push[-1, 1] == pytest.approx(K_N * 2e-6, rel=5e-3)
    assert len(_breaks(tmp_path)) == 1


@needs_engine
@pytest.mark.parametrize("squeeze_um,mu_b", [(0.0, None), (1.0, None), (1.0, 0.0), (1.0, 1.5)])
def test_shear_strength_is_cohesion_plus_friction_times_compression(tmp_path, squeeze_um, mu_b):
    v = STEP / DT
    n_sq = int(round(squeeze_um * 1e-6 / STEP))
    f = _two_grains(tmp_path, ([(-v, 0.0, n_sq)] if n_sq else []) + [(0.0, v, 16000)], mu_b=mu_b)
    (brk,) = _breaks(tmp_path)
    assert brk[3] == "2"  # shear
    k = int(brk[0]) - 1  # the last step before the break
    step, fx, fy = f[k - 1, 0], f[k - 1, 1], f[k - 1, 2]
    # the bond's frame: grain 2 has slid (step - n_sq) * STEP along y at x = 2R - squeeze, so the normal is turned by
    # theta (7 mrad at 14 um of slip); resolving in it keeps the normal and shear forces apart
    theta = math.atan2((step - n_sq) * STEP, 2 * R - squeeze_um * 1e-6)
    f_normal = fx * math.cos(theta) + fy * math.sin(theta)  # compression pushes grain 2 away from grain 1
    f_shear = -fx * math.sin(theta) + fy * math.cos(theta)
    sigma_n = max(f_normal, 0.0) / AREA
    assert sigma_n * AREA == pytest.approx(K_N * squeeze_um * 1e-6, rel=6e-2, abs=1e-3)
    # 6.28 N alone, 7.07 N with 0.5 MPa of compression; the intact bond's own friction mu_b replaces mu here
    expected = (COH + (MU if mu_b is None else mu_b) * sigma_n) * AREA
    assert -f_shear == pytest.approx(expected, rel=5e-3)
    tail = f[k + 10:]
    if squeeze_um:  # after breaking, the closed face slides at mu (the broken face's, whatever mu_b) times its normal force
        assert np.allclose(np.abs(tail[:, 2]), MU * tail[:, 1], rtol=0.05)
    else:  # nothing presses the broken face: no shear either
        assert np.all(np.abs(tail[:, 2]) < 1e-9)


@needs_engine
@pytest.mark.parametrize("beta", [1.0, 0.0])
def test_bending_breaks_in_tension_unless_the_moment_contribution_is_zero(tmp_path, beta):
    omega = 10.0  # rad/s: 1e-6 rad per step
    _two_grains(tmp_path, [(0.0, 0.0, 12000)], beta=beta, spin_period_s=2 * math.pi / omega)
    (brk,) = _breaks(tmp_path)
    theta = (int(brk[0]) - 1) * DT * omega  # relative rotation at the break
    if beta:  # k_n I theta R_b / I = sigma_c  ->  theta = sigma_c r0 / (E_b R_b) = 2e-3 rad
        assert brk[3] == "1" and theta == pytest.approx(SIGMA_C * 2 * R / (E_B * LAM * R), rel=0.01)
    else:  # only the shear at the face (k_s A R theta) breaks it: theta = c r0 kappa / (E_b R) = 1e-2 rad
        assert brk[3] == "2" and theta == pytest.approx(COH * 2 * R * KAPPA / (E_B * R), rel=0.01)


@needs_engine
def test_a_face_of_elements_breaks_in_tension_at_sigma_c_all_at_once(tmp_path):
    v = STEP / DT
    f = _two_grains(tmp_path, [(v, 0.0, 3000)], sectors=4)
    assert -f[:, 1].min() == pytest.approx(SIGMA_C * AREA, rel=2e-3)  # uniform stretch: every element at sigma_c
    (brk,) = _breaks(tmp_path)
    assert brk[3] == "1" and 1990 <= int(brk[0]) <= 2010


@needs_engine
def test_a_bent_face_of_elements_breaks_element_by_element(tmp_path):
    """Four elements at the ring's radius of gyration R/sqrt(2), at 45, 135, 225, 315 degrees from the bending
    axis' normal: turning grain 2 about z opens the two elements on one side, which break in tension at
    theta = sigma_c r0 / (E_b R/2) = 4e-3 rad (twice the one-element face's 2e-3: its rim is at R); the face then
    presses on the other two (the normal force jumps from 0 to a push), and they break in shear at
    k_s R theta = c + mu k_n (R/2) theta, theta = c r0 / (E_b R (1/kappa - mu/2)) = 2.67e-2 rad."""
    omega = 10.0  # rad/s: 1e-6 rad per step
    f = _two_grains(tmp_path, [(0.0, 0.0, 30000)], spin_period_s=2 * math.pi / omega, sectors=4)
    theta = f[:, 0] * DT * omega
    push = f[:, 1] > 1e-3 * SIGMA_C * AREA  # compression pushes grain 2 to +x
    first = theta[np.argmax(push)]
    assert first == pytest.approx(SIGMA_C * 2 * R / (E_B * R / 2), rel=0.01)
    assert not push[theta < 0.99 * first].any()  # bending alone leaves no net normal force while all hold
    (brk,) = _breaks(tmp_path)  # one line: the joint, when its last element breaks
    theta_last = (int(brk[0]) - 1) * DT * omega
    assert brk[3] == "2" and theta_last == pytest.approx(COH * 2 * R / (E_B * R * (1 / KAPPA - MU / 2)), rel=0.01)


@needs_engine
def test_a_gapped_face_carries_nothing_until_the_grains_touch(tmp_path):
    v = STEP / DT
    gap = 1e-6  # 1 um apart: 1000 steps of approach before contact, then 2 um of overlap
    f = _two_grains(tmp_path, [(-v, 0.0, 3000), (v, 0.0, 4000)], gap=gap, slit=2)
    steps, fx = f[:, 0], f[:, 1]
    assert np.all(fx[steps <= 999] == 0.0)  # open: no force across the gap (no Hertz contact either)
    assert fx[2999] == pytest.approx(K_N * 2e-6, rel=5e-3)  # touching at r0 = r1 + r2: k_n A overlap
    assert np.all(fx[steps >= 4001 + 1000] == 0.0)  # pulled apart again: no tension
    assert not _breaks(tmp_path)  # a gapped face is never a break


@needs_engine
def test_a_face_of_elements_loads_the_grains_as_the_one_element_face_while_elastic(tmp_path):
    """Grains on a diagonal, grain 2 turned about its own centre and a skew axis (shear, bending and twist at
    once), strengths out of reach: the element face's force and torques equal the one-element face's (a first
    version applied its shear at a wrong arm off the x axis: a negative Poisson's ratio in the UCS tests)."""
    lib = plugins.install(tmp_path, "flatjoint")
    d = 2 * R / math.sqrt(3.0)
    rows = {}
    for sectors in (1, 4):
        elements = f" 0 {sectors} 1" if sectors > 1 else ""
        coeffs = f"{E_B:.10g} {KAPPA:.10g} {LAM:.10g} 1e12 1e12 {MU:.10g} 0.0 1.0{elements}"
        (tmp_path / "in.skew").write_text(_deck_head(lib, (d, d, d), coeffs) + f"""fix f1 g1 move linear 0 0 0
fix m g2 move rotate {d:.12g} {d:.12g} {d:.12g} 0.3 -0.5 0.8 0.01
dump d all custom 100 dump.txt id fx fy fz tqx tqy tqz
dump_modify d format float %.10e
run 100
""")
        proc = subprocess.run(engine_command(1) + ["-in", "in.skew", "-log", "none"], cwd=tmp_path, env=engine_env(),
                              capture_output=True, text=True, timeout=300)
        assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
        rows[sectors] = np.loadtxt((tmp_path / "dump.txt").read_text().splitlines()[-2:])[:, 1:]
    assert np.abs(rows[1][:, 3:]).max() > 1e-3  # N m: the torques are real
    assert rows[4] == pytest.approx(rows[1], rel=1e-5, abs=1e-9)


def test_flat_joint_validation_names_field_and_fix():
    case = load_case(CASES / "tiny_ucs.yaml", overrides=FJ)
    assert resolved_dict(case)["bonds"]["model"] == "flat_joint"
    assert "model" not in resolved_dict(load_case(CASES / "tiny_ucs.yaml"))["bonds"]
    with pytest.raises(SpecError, match="clump_size: not available with model: flat_joint"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint", "clump_size": 4}})
    with pytest.raises(SpecError, match="joint_friction: used only by model: flat_joint"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"joint_friction": 0.8}})
    with pytest.raises(SpecError, match="flat_joint is a LAMMPS plugin"):
        load_case(CASES / "tiny_ucs.yaml", overrides={**FJ, "engine": "liggghts"})
    with pytest.raises(SpecError, match="model"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint; shell rm -rf /"}})
    with pytest.raises(SpecError, match="face_gap_tolerance: 0.03 is not above gap_tolerance 0.05"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint", "gap_tolerance": 0.05,
                                                                "face_gap_tolerance": 0.03}})
    with pytest.raises(SpecError, match="bond_friction: used only by model: flat_joint"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"bond_friction": 0.1}})
    with pytest.raises(SpecError, match="bond_friction"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint", "bond_friction": -0.1}})
    with pytest.raises(SpecError, match="face_sectors: used only by model: flat_joint"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"face_sectors": 4}})
    with pytest.raises(SpecError, match="face_sectors: 2 halves"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint", "face_sectors": 2}})
    with pytest.raises(SpecError, match="face_rings: 2 rings need face_sectors"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint", "face_rings": 2}})
    with pytest.raises(SpecError, match="moment_contribution: used by the one-element face only"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint", "face_sectors": 4,
                                                                "moment_contribution": 0.0}})


def test_micro_params_keep_their_keys_and_map_the_flat_joint():
    p = MicroParams(youngs_modulus_GPa=20.0, tensile_strength_MPa=60.0, shear_strength_MPa=60.0)
    # the key of a bpm/rotational point is the one it had before the flat-joint fields existed
    assert p.key() == MicroParams(youngs_modulus_GPa=20.0, tensile_strength_MPa=60.0, shear_strength_MPa=60.0,
                                  joint_friction=0.5).key()
    q = MicroParams(youngs_modulus_GPa=20.0, tensile_strength_MPa=60.0, shear_strength_MPa=60.0, flat_joint=1)
    assert q.key() != p.key()
    assert "model" not in p.overrides()["bonds"]
    assert q.overrides()["bonds"]["model"] == "flat_joint" and q.overrides()["bonds"]["joint_friction"] == 0.5
    assert "face_sectors" not in q.overrides()["bonds"]
    e = MicroParams(youngs_modulus_GPa=20.0, tensile_strength_MPa=60.0, shear_strength_MPa=60.0, flat_joint=1,
                    face_sectors=4)
    assert e.key() != q.key() and e.overrides()["bonds"]["face_sectors"] == 4
    m = MicroParams(youngs_modulus_GPa=20.0, tensile_strength_MPa=60.0, shear_strength_MPa=60.0, flat_joint=1,
                    bond_friction=0.0)
    assert "bond_friction" not in q.overrides()["bonds"] and m.overrides()["bonds"]["bond_friction"] == 0.0
    assert m.key() != q.key() and MicroParams.from_overrides(**m.overrides()) == m
    from deckgen.calibration_studies import _bond_law

    assert _bond_law(m.overrides()["bonds"]) == "flat joint, intact μ 0" and _bond_law(q.overrides()["bonds"]) == "flat joint"


def test_flat_joint_start_table_returns_a_measured_point_for_its_own_macro_values():
    from deckgen.calibrate import MICRO_MACRO_FLAT_JOINT, CardTargets, ParameterSpace, analytic_start, prior_jacobian

    sp = ParameterSpace(["log_E_b", "log_sigma_c", "log_tau_ratio"], bounds={"log_tau_ratio": (0.0, 4.6)})
    sigma_c, c, E, ucs, bts, bts_split = MICRO_MACRO_FLAT_JOINT[3]  # c/sigma_c 16 at c 120 MPa: UCS/BTS 11.9 (28.1)
    for table, b in (("flat_joint", bts), ("flat_joint_split", bts_split)):
        t = CardTargets(density_kg_m3=2450, ucs_MPa=ucs, bts_MPa=b, youngs_modulus_GPa=E, poisson_ratio=0.2,
                        citation="table row")
        p = analytic_start(t, None, sp, table=table)
        assert (p.youngs_modulus_GPa, p.tensile_strength_MPa, p.shear_strength_MPa) == pytest.approx((20.0, sigma_c, c),
                                                                                                      rel=1e-6), table
        assert p.flat_joint == 1 and p.moment_contribution == 0.0 and p.gap_tolerance == 0.4
        J = prior_jacobian(sp, table)  # rows UCS, BTS, E; columns E_b, sigma_c, c/sigma_c
        assert J[2, 0] > 0.8 and J[1, 1] > 0.8 and J[0, 2] > J[1, 2] > 0, table  # c/sigma_c raises UCS more than BTS
    # read at the split, BTS falls faster with c/sigma_c: the split table needs a lower c/sigma_c for a given ratio
    assert prior_jacobian(sp, "flat_joint_split")[1, 2] < prior_jacobian(sp, "flat_joint")[1, 2]
    with pytest.raises(ValueError, match="unknown table 'split'"):
        analytic_start(t, None, sp, table="split")


def test_a_calibrated_card_keeps_the_bond_model_token_and_refuses_others():
    from deckgen.calibrate import CalibratedParams

    q = MicroParams(youngs_modulus_GPa=2.76, tensile_strength_MPa=1.12, shear_strength_MPa=13.15, flat_joint=1,
                    moment_contribution=0.0)
    c = CalibratedParams(bonds=q.overrides()["bonds"], contact=q.overrides()["contact"])
    assert c.bonds["model"] == "flat_joint" and c.bonds["moment_contribution"] == 0.0
    with pytest.raises(ValueError, match="model"):
        CalibratedParams(bonds={**q.overrides()["bonds"], "model": "flat_joint; shell rm -rf /"})


@pytest.mark.skipif(not have_compiler, reason="no C++ compiler for the plugin (apt-get install g++)")
def test_deck_loads_the_plugin_from_the_run_folder_with_si_coefficients(tmp_path):
    case = load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint", "joint_friction": 0.7}})
    render_case(case, tmp_path, progress=False)
    deck = (tmp_path / "in.deck").read_text()
    assert "plugin          load plugins/deckgen_flatjoint.so" in deck
    assert (tmp_path / "plugins" / "deckgen_flatjoint.so").is_file()
    line = next(ln for ln in deck.splitlines() if ln.startswith("bond_coeff"))
    b = case.bonds
    assert [float(v) for v in line.split()[2:]] == pytest.approx(
        [b.youngs_modulus_GPa * 1e9, b.stiffness_ratio, b.radius_multiplier, b.tensile_strength_MPa * 1e6,
         b.shear_strength_MPa * 1e6, 0.7, b.damping_ratio, 1.0])
    assert "bpm/rotational" not in deck and "broken.dump.gz" not in deck
    # bonds.bond_friction: the intact bond's own friction, the plugin's 13th argument after slit 0, 1 sector, 1 ring
    case = load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint", "joint_friction": 0.7,
                                                                   "bond_friction": 0.1}})
    render_case(case, tmp_path / "mu_b", progress=False)
    line = next(ln for ln in (tmp_path / "mu_b" / "in.deck").read_text().splitlines() if ln.startswith("bond_coeff"))
    assert [float(v) for v in line.split()[7:]] == pytest.approx([0.7, b.damping_ratio, 1.0, 0.0, 1.0, 1.0, 0.1])


def test_broken_joints_file_is_read_with_modes_and_fails_with_file_and_line(tmp_path):
    p = tmp_path / FLAT_JOINT_BROKEN
    p.write_text("# step id1 id2 mode x_m y_m z_m\n20 7 3 2 0.1 0.2 0.3\n10 1 2 1 0 0 0\n")
    d = _read_broken_joints(p)
    assert d["step"].tolist() == [10, 20] and d["id1"].tolist() == [1, 3] and d["id2"].tolist() == [2, 7]
    assert d["mode"].tolist() == ["tension", "shear"]
    p.write_text("# header\n10 1 2 1 0 0 0\n11 1 3 9 0 0 0\n")
    with pytest.raises(ParseError, match=rf"{FLAT_JOINT_BROKEN}:3: mode must be 1 or 2"):
        _read_broken_joints(p)
    p.write_text("10 1 2 1 0 0\n")
    with pytest.raises(ParseError, match=r":1: expected 7 fields"):
        _read_broken_joints(p)


@needs_engine
@pytest.mark.parametrize("slits,sectors,gapped", [(0.0, 1, 0.0), (0.5, 1, 0.0), (0.5, 4, 0.0), (0.0, 1, 0.4)])
def test_tiny_ucs_with_flat_joints_runs_and_reports_modes(tmp_path, slits, sectors, gapped):
    case = load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"model": "flat_joint", "unbonded_fraction": slits,
                                                                   "face_sectors": sectors,
                                                                   "face_gap_tolerance": gapped}})
    spec = render_case(case, tmp_path, progress=False)
    if gapped:  # pairs with gaps beyond the bonding gap: one more bond type, written with slit code 2
        assert spec["derived"]["gapped_faces"] > 0
        assert f"bond_coeff      {spec['derived']['n_bond_types'] + 1} " in (tmp_path / "in.deck").read_text()
    if sectors > 1:
        assert " 0 4 1\n" in (tmp_path / "in.deck").read_text() and " 1 4 1\n" in (tmp_path / "in.deck").read_text()
    if slits:  # the unbonded pairs are slit faces: bonds of one more type, broken from the start, never counted
        n_slit = spec["derived"]["unbonded"]["slit_faces"]
        assert n_slit == spec["derived"]["unbonded"]["unbonded_pairs"] > 0
        assert f"bond_coeff      {spec['derived']['n_bond_types'] + 1} " in (tmp_path / "in.deck").read_text()
    run_deck(tmp_path, expected_steps=spec["derived"]["expected_steps"], progress=False, command=engine_command(1))
    s = parse_run(tmp_path, tmp_path / "parsed")
    assert s["mode_source"] == FLAT_JOINT_BROKEN
    assert s["bonds_broken"] == s["bonds_broken_series"] > 0  # the plugin's list agrees with nbond/atom
    assert s["bonds_broken_tension"] + s["bonds_broken_shear"] == s["bonds_broken"]
    assert s["peak_stress_Pa"] > 0 and s["youngs_modulus_Pa"] > 0
    assert s["n_bonds_initial"] == spec["derived"]["n_bonds"]
    first = pd.read_csv(tmp_path / "parsed" / "timeseries.csv")["bonds_broken"].iloc[0]
    assert first == 0  # the slit faces are not breaks


def test_set_ranks_sets_deckgens_own_form_and_keeps_user_commands(tmp_path):
    assert set_ranks(["/v/bin/mpirun", "-np", "2", "/v/bin/lmp"], 1) == ["/v/bin/lmp"]
    assert set_ranks(["/v/bin/mpirun", "-np", "1", "/v/bin/lmp"], 3) == ["/v/bin/mpirun", "-np", "3", "/v/bin/lmp"]
    assert set_ranks(["srun", "-n", "4", "lmp"], 1) == ["srun", "-n", "4", "lmp"]  # the user's launcher
    (tmp_path / "lmp").touch()
    assert set_ranks([str(tmp_path / "lmp")], 2) == [str(tmp_path / "lmp")]  # no mpirun beside it
    (tmp_path / "mpirun").touch()
    assert set_ranks([str(tmp_path / "lmp")], 2) == [str(tmp_path / "mpirun"), "-np", "2", str(tmp_path / "lmp")]
    assert set_ranks([str(tmp_path / "lmp")], 1) == [str(tmp_path / "lmp")]


def test_limit_ranks_drops_deckgens_own_mpirun_and_keeps_user_commands():
    assert limit_ranks(["/v/bin/mpirun", "-np", "4", "/v/bin/lmp"], 1) == ["/v/bin/lmp"]
    assert limit_ranks(["/v/bin/mpirun", "-np", "4", "/v/bin/lmp"], 2) == ["/v/bin/mpirun", "-np", "2", "/v/bin/lmp"]
    assert limit_ranks(["/v/bin/mpirun", "-np", "1", "/v/bin/lmp"], 1) == ["/v/bin/mpirun", "-np", "1", "/v/bin/lmp"]
    assert limit_ranks(["srun", "-n", "4", "lmp"], 1) == ["srun", "-n", "4", "lmp"]  # the user's launcher
    assert limit_ranks(["lmp"], 1) == ["lmp"]


@needs_engine
def test_a_flat_joint_deck_given_two_ranks_runs_on_one(tmp_path):
    cmd = engine_command(2)
    if len(cmd) == 1:
        pytest.skip("no mpirun beside lmp: a 2-rank command cannot be built")
    case = load_case(CASES / "tiny_ucs.yaml", overrides=FJ)
    spec = render_case(case, tmp_path, progress=False)
    assert spec["derived"]["max_ranks"] == 1
    res = run_deck(tmp_path, expected_steps=spec["derived"]["expected_steps"], progress=False, command=cmd)
    assert res.command == cmd[3:]
    assert "1 by 1 by 1 MPI processor grid" in (tmp_path / "log.lammps").read_text()
    assert parse_run(tmp_path, tmp_path / "parsed")["peak_stress_Pa"] > 0


@needs_engine
def test_a_crushed_flat_joint_disc_is_read_at_its_split(tmp_path):
    """A coarse Brazilian disc (D 20 mm, ~360 grains of 0.8-1.333 mm) with the flat joint at beta 0, a low
    sigma_c/E_b and a cohesion 19x sigma_c (the point session 13 calibrated concrete to): its bonds crack along the
    loaded diameter and the jaws then crush the broken disc to a peak well above the split. The split reading
    (deckgen.results.split_onset) finds the crack before the peak, with most of the broken bonds on the diameter
    and few of the disc's bonds broken, while at the peak a third or more of them are broken."""
    from deckgen.calibrate import DEFAULT_BTS, DEFAULT_UCS, DemEvaluator

    ev = DemEvaluator({"material": {"density_kg_m3": 2130.0}, "packing": {"radius_min_mm": 0.8, "radius_max_mm": 1.333}},
                      DEFAULT_UCS, {**DEFAULT_BTS, "platen_speed_m_s": 0.06229, "stop_fraction_of_peak": 0.2},
                      tmp_path / "work")
    p = MicroParams(youngs_modulus_GPa=2.829, tensile_strength_MPa=0.6975, shear_strength_MPa=13.53, gap_tolerance=0.4,
                    contact_modulus_ratio=4.0, flat_joint=1, moment_contribution=0.0)
    run = tmp_path / "bts"
    spec = render_case(ev.case(p, "bts"), run, cache=tmp_path / "cache", progress=False)
    run_deck(run, expected_steps=spec["derived"]["expected_steps"], progress=False)
    s = parse_run(run, tmp_path / "parsed")
    n0 = s["n_bonds_initial"]
    print({k: s[k] for k in ("split_stress_Pa", "peak_stress_Pa", "split_localisation_1", "bonds_broken_at_split",
                             "bonds_broken_at_peak", "n_bonds_initial")})
    assert s["split_source"] == "crack"
    assert s["split_stress_Pa"] < 0.8 * s["peak_stress_Pa"], (s["split_stress_Pa"], s["peak_stress_Pa"])
    assert s["split_strain_1"] < s["strain_at_peak_1"]
    assert s["split_localisation_1"] > 0.7
    assert s["bonds_broken_at_split"] / n0 < 0.15 < 0.25 < s["bonds_broken_at_peak"] / n0
