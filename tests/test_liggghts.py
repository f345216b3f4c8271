"""LIGGGHTS backend: command line, capabilities, a real Debian LIGGGHTS cut of an unbonded bed,
bond/gran mapping and grammar (Flexible_Fibers fork), filters on every deck value."""

from __future__ import annotations

import math
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from deckgen import liggghts as lg
from deckgen.bonds import bpm_coefficients, section
from deckgen.parse.log import check_log
from deckgen.parse.series import read_series
from deckgen.spec import GPA, MPA, load_case
from helpers import load_script

DATA = Path(__file__).parent / "data"
BED = DATA / "liggghts" / "tiny_bed_cut.yaml"
HAVE_LIGGGHTS = bool(shutil.which("liggghts") or os.environ.get(lg.ENV_BINARY))
needs_liggghts = pytest.mark.skipif(
    not HAVE_LIGGGHTS,
    reason="no LIGGGHTS binary: apt-get install -y --no-install-recommends liggghts (or set DECKGEN_LIGGGHTS)")
needs_fork = pytest.mark.skipif(
    not os.environ.get(lg.ENV_BINARY),
    reason="no bond-capable LIGGGHTS: build the LIGGGHTS_Flexible_Fibers fork and set DECKGEN_LIGGGHTS")


# ------------------------------------------------------------------------------- command line
def test_command_serial_and_mpi(monkeypatch):
    monkeypatch.delenv(lg.ENV_BINARY, raising=False)
    if not HAVE_LIGGGHTS:
        pytest.skip("no liggghts on the PATH")
    assert lg.liggghts_command(1) == [lg.liggghts_binary()]
    cmd = lg.liggghts_command(2)
    if shutil.which("mpirun"):
        assert cmd[-3:] == ["-np", "2", lg.liggghts_binary()]
        assert ("--allow-run-as-root" in cmd) == (os.geteuid() == 0 and lg._openmpi(cmd[0]))


def test_command_from_environment(monkeypatch):
    monkeypatch.setenv(lg.ENV_BINARY, "mpirun -np 3 /opt/ff/bin/liggghts")
    assert lg.liggghts_command(2) == ["mpirun", "-np", "3", "/opt/ff/bin/liggghts"]
    monkeypatch.setenv(lg.ENV_BINARY, "/opt/ff/bin/liggghts")
    assert lg.liggghts_binary() == "/opt/ff/bin/liggghts"
    assert lg.liggghts_command(1) == ["/opt/ff/bin/liggghts"]


# ------------------------------------------------------------------------------- capabilities
def test_parse_help_sections():
    text = ("* Atom styles:\n\natomic   granular\n\n* Fix styles\n\nwall/gran   move/mesh\n"
            "* Normal models for pair gran:\n\nhertz  hooke\n")
    assert lg.parse_help(text) == {"atom atomic", "atom granular", "fix wall/gran", "fix move/mesh",
                                   "gran_normal hertz", "gran_normal hooke"}


@needs_liggghts
def test_capabilities_debian(tmp_path, monkeypatch):
    monkeypatch.setenv("DECKGEN_CACHE", str(tmp_path))
    monkeypatch.delenv(lg.ENV_BINARY, raising=False)
    lg._capabilities.cache_clear()
    caps = lg.capabilities()
    for style in ("atom granular", "pair gran", "fix wall/gran", "fix move/mesh", "fix insert/pack",
                  "fix mesh/surface", "gran_normal hertz", "gran_cohesion sjkr", "gran_rolling epsd2"):
        assert style in caps, style
    # not listed by -h, found by the probe deck
    assert "fix mesh/surface/stress" in caps
    assert "bond harmonic" in caps
    assert not lg.has_bonds(caps)
    assert list(tmp_path.glob("liggghts-capabilities-*.json"))  # cached on disk
    lg._capabilities.cache_clear()
    assert lg.capabilities() == caps  # from the disk cache


def test_require_bonds_message():
    caps = {"atom granular", "fix mesh/surface/stress", "bond harmonic", "version LIGGGHTS-PUBLIC_3.8.0"}
    with pytest.raises(lg.LiggghtsCapabilityError) as exc:
        lg.require_bonds(caps, what="runs/ucs/in.liggghts")
    msg = str(exc.value)
    assert "runs/ucs/in.liggghts" in msg and "LIGGGHTS_Flexible_Fibers" in msg and lg.ENV_BINARY in msg
    assert "atom bond/gran, bond gran, fix bond/create/gran" in msg
    lg.require_bonds(caps | set(lg.BOND_STYLES))  # no error


@needs_liggghts
def test_run_refuses_bonded_deck_on_debian(tmp_path, monkeypatch):
    monkeypatch.setenv("DECKGEN_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv(lg.ENV_BINARY, raising=False)
    case = load_case(DATA / "cases" / "tiny_ucs.yaml")
    lg.render_liggghts_ucs_bonded(case, tmp_path / "ucs")
    with pytest.raises(lg.LiggghtsCapabilityError, match="Flexible_Fibers"):
        lg.run_liggghts(tmp_path / "ucs", ranks=1)
    assert not (tmp_path / "ucs" / lg.LOG).exists()  # refused before the engine started


# ------------------------------------------------------------------------------- real cut
@pytest.fixture(scope="module")
def bed_run(tmp_path_factory):
    if not HAVE_LIGGGHTS:
        pytest.skip("no LIGGGHTS binary: apt-get install -y --no-install-recommends liggghts")
    out = tmp_path_factory.mktemp("bed_cut")
    case = load_case(BED)
    spec = lg.render_liggghts_cut(case, out)
    res = lg.run_liggghts(out, ranks=2, timeout_s=300)
    return out, spec, res


def test_bed_cut_runs_and_parses(bed_run):
    out, spec, res = bed_run
    health = check_log(out / lg.LOG)
    assert health.ok, health.failure()
    assert health.completed_runs == 4  # settle, relax, relax after trimming, cut
    assert res.steps == spec["derived"]["expected_steps_total"]
    assert 150 < res.atoms < 800
    d = read_series(out / "series.txt")
    cut = spec["derived"]["cutter"]
    assert list(d.columns[:11]) == ["step", "time_s", "cutter_x_m", "cutter_y_m", "cutter_z_m", "force_x_N",
                                    "force_y_N", "force_z_N", "torque_x_Nm", "torque_y_Nm", "torque_z_Nm"]
    assert len(d) == spec["derived"]["expected_steps"] // spec["case"]["outputs"]["series_every"]
    # position column = x0 + v t, and the mesh's own reference point moved the same way
    np.testing.assert_allclose(d["cutter_x_m"], cut["xc0"] + cut["V"] * d["time_s"], atol=1e-9)
    np.testing.assert_allclose(d["ref_x_m"], d["cutter_x_m"], atol=1e-9)
    np.testing.assert_allclose(d["ref_z_m"], cut["zc0"], atol=1e-9)
    # no force before the rim reaches the bed face (x = 0: grains were walled in at x >= 0)
    advance = d["cutter_x_m"] - cut["xc0"]
    clearance = spec["case"]["kinematics"]["start_clearance_mm"] * 1e-3
    before = advance < clearance - 1e-6
    assert before.sum() >= 5
    assert (d.loc[before, ["force_x_N", "force_y_N", "force_z_N"]].abs().to_numpy() == 0).all()
    # cutting: the bed pushes back (F_x < 0 against +x motion) and up (F_z > 0)
    cutting = advance > clearance + 1e-3
    fc = d[cutting]
    assert (fc["force_x_N"] != 0).mean() > 0.15
    assert fc["force_x_N"].mean() < 0
    assert fc["force_z_N"].mean() > 0


def test_bed_cut_parse_run(bed_run, tmp_path):
    from deckgen.results import parse_run

    out, spec, _ = bed_run
    summary = parse_run(out, tmp_path / "parsed")
    assert summary["engine"] == "liggghts"
    assert summary["n_bonds_initial"] == 0
    assert summary["force_rolling_N_mean_steady"] > 0  # rolling = -F_x
    assert summary["force_normal_N_mean_steady"] > 0


# ------------------------------------------------------------------------------- deck hygiene
def test_every_value_passes_a_filter(tmp_path):
    case = load_case(BED, overrides={"name": "x-rm_rf"})
    lg.render_liggghts_cut(case, tmp_path, cohesion_energy_density=5e4)
    text = (tmp_path / "in.liggghts").read_text()
    # the case name token appears only on the comment header line
    assert [ln for ln in text.splitlines() if "x-rm_rf" in ln] == ["# case: x-rm_rf   test: cutting   engine: liggghts"]
    assert "cohesion sjkr" in text and "cohesionEnergyDensity" in text
    assert "{{" not in text and "}}" not in text
    for ln in text.splitlines():
        if ln.startswith("variable") and " index " in ln:
            float(ln.split()[3])  # every parameter is a plain number
    # values that are not finite numbers or whitelisted tokens cannot reach a deck
    from deckgen.render import DeckError, f_num, f_tok
    from deckgen.spec import SpecError

    with pytest.raises(SpecError):
        lg.render_liggghts_cut(case, tmp_path / "bad", cohesion_energy_density=float("nan"))
    with pytest.raises(DeckError):
        f_num(float("inf"))
    with pytest.raises(DeckError):
        f_tok("1; shell rm -rf /")
    # every non-comment line is built from filtered values: no stray text from the case
    for ln in text.splitlines():
        assert not re.search(r"[;&|`]", ln.split("#", 1)[0]), ln


def test_oscillation_stacked_moves(tmp_path):
    case = load_case(DATA / "cases" / "tiny_cut.yaml")  # oscillation, rolling spin
    spec = lg.render_liggghts_cut(case, tmp_path)
    text = (tmp_path / "in.liggghts").read_text()
    cut = spec["derived"]["cutter"]
    assert "fix             mv2 all move/mesh mesh cad rotate origin ${x_shaft} ${yc0} ${zc0} axis 0.0 -1.0 0.0 period ${period_osc}" in text
    # rolling in oscillation: spin correction = V/R + omega about +y
    m = re.search(r"fix +mv3 all move/mesh mesh cad rotate origin \$\{xc0\} \$\{yc0\} \$\{zc0\} axis 0.0 1 0.0 period (\S+)", text)
    assert m, text
    assert float(m.group(1)) == pytest.approx(2 * math.pi / (cut["spin_rate"] + cut["omega"]), rel=1e-9)
    assert spec["derived"]["stacked_moves"] == ["linear", "rotate_orbit", "rotate_spin"]


# ------------------------------------------------------------------------------- bond/gran mapping
def test_bond_gran_mapping_matches_parallel_bond():
    E_b, kappa, sc, tc, lam, zeta = 40 * GPA, 2.5, 30 * MPA, 60 * MPA, 0.8, 0.05
    c = lg.bond_gran_coefficients(E_b, kappa, sc, tc, lam, zeta)
    assert c == {"ro": 0.8, "ri": 0.0, "Y": E_b, "G": E_b / kappa, "damp_type": 1, "damp": zeta,
                 "break_type": 1, "sigma_break": sc, "tau_break": tc}
    # the fork's per-bond stiffnesses (BondGran::compute) equal the LAMMPS parallel-bond mapping
    r1, r2, L = 0.7e-3, 0.9e-3, 1.55e-3
    rout = c["ro"] * min(r1, r2)
    A = math.pi * rout**2
    Ip = 0.5 * math.pi * rout**4
    I = 0.5 * Ip
    fork = {"k_r": c["Y"] * A / L, "k_s": c["G"] * A / L, "k_t": c["G"] * Ip / L, "k_b": c["Y"] * I / L}
    lmp = bpm_coefficients(E_b, kappa, sc, tc, lam * min(r1, r2), L, 1.0, 1.0, zeta)
    for k, v in fork.items():
        assert v == pytest.approx(float(lmp[k]), rel=1e-12), k
    # strength: the fork's stress checks at pure tension / bending / shear / twist = sigma_c, tau_c
    A_, I_, J_ = section(rout)
    F_rc, tau_bc = float(lmp["F_rc"]), float(lmp["tau_bc"])
    assert F_rc / A == pytest.approx(c["sigma_break"])                       # |F_n|/A
    assert 2 * tau_bc / Ip * rout == pytest.approx(c["sigma_break"])         # 2|M_b|(ro-ri)/J
    assert float(lmp["F_sc"]) / A == pytest.approx(c["tau_break"])           # |F_t|/A
    assert float(lmp["tau_tc"]) / Ip * rout == pytest.approx(c["tau_break"])  # |M_t|(ro-ri)/J
    # damping 0 -> damp type 0 (one unused value)
    assert lg.bond_gran_coefficients(E_b, kappa, sc, tc, 1.0, 0.0)["damp_type"] == 0
    with pytest.raises(ValueError, match="ro in"):
        lg.bond_gran_coefficients(E_b, kappa, sc, tc, 1.2, zeta)


@pytest.mark.parametrize("line", [
    "bond_coeff 1 1.0 0.0 1.5e9 1.0e9 1 1.0 1 1.5e6 1.0e6",
    "bond_coeff 1 1.0 0.0 1.5e9 1.0e9 1 1.0 2 1.5e6 1.0e6 330.0",
    "bond_coeff 1 1.0 0.0 1.5e9 1.0e9 2 0.0 0.01 0.0 1 1.5e6 1.0e6",
    "bond_coeff * 0.8 0.0 4e10 1.6e10 0 0 1 3e7 6e7",
])
def test_bond_coeff_grammar_accepts(line):
    lg.check_bond_coeff_line(line)


@pytest.mark.parametrize("line,msg", [
    ("bond_coeff 1 1.0 0.0 1.5e9 1.0e9 1 1.0 0 0.01", "aborts"),               # break type 0 (fork docs' own example)
    ("bond_coeff 1 1.0 0.0 1.5e9 1.0e9 2 0.0 0.01 0.0 5 1.5e6 1.0e6", "does not exist"),  # break type 5: wiki only
    ("bond_coeff 1 1.0 0.0 1.5e9 1.0e9 1 1.0 1 1.5e6", "Incorrect args"),
    ("bond_coeff 1 0.5 0.5 1.5e9 1.0e9 1 1.0 1 1.5e6 1.0e6", "ro must be greater than ri"),
    ("bond_coeff 1 1.0 0.0 1.5e9 1.0e9 6 1.0 1 1.5e6 1.0e6", "damp type"),
    ("bond_coeff 1 1.0 0.0 ${Y} 1.0e9 1 1.0 1 1.5e6 1.0e6", "not a number"),
    ("bond_coeff 1 1 0 1e9", "Incorrect args"),
])
def test_bond_coeff_grammar_rejects(line, msg):
    with pytest.raises(lg.BondGrammarError, match=msg):
        lg.check_bond_coeff_line(line)
    if msg == "aborts":
        assert lg.check_bond_coeff_line(line, allow_abort=True)["break_type"] == 0


def test_bond_create_grammar():
    c = lg.check_bond_create_line("fix bondcr all bond/create/gran 1 1 1 0.0051 1 6")
    assert c == {"id": "bondcr", "every": 1, "itype": 1, "jtype": 1, "cutoff": 0.0051, "btype": 1, "newperts": 6}
    with pytest.raises(lg.BondGrammarError):
        lg.check_bond_create_line("fix bondcr all bond/create/gran 1 1 1 0.0051 1")
    with pytest.raises(lg.BondGrammarError):
        lg.check_bond_create_line("fix bondcr all bond/create/gran 1 1 1 0.0051 1 6 maxbond 3")


def test_bonded_ucs_deck_golden_and_grammar(tmp_path):
    case = load_case(DATA / "cases" / "tiny_ucs.yaml")
    spec = lg.render_liggghts_ucs_bonded(case, tmp_path)
    text = (tmp_path / "in.liggghts").read_text()
    g = lg.check_bonded_deck(text)
    assert g["n_bondtypes"] == 1 and len(g["bond_coeffs"]) == 1
    bc = g["bond_coeffs"][0]
    b = case.bonds
    assert bc["Y"] == b.youngs_modulus_GPa * GPA and bc["G"] == pytest.approx(bc["Y"] / b.stiffness_ratio)
    assert bc["break_type"] == 1 and bc["break"] == [b.tensile_strength_MPa * MPA, b.shear_strength_MPa * MPA]
    assert "atom_style      hybrid granular bond/gran n_bondtypes 1 bonds_per_atom 16 disableNormalContact 1" in text
    assert spec["derived"]["bonded"] is True
    # broken-bond output: the fork's per-bond broken flag, sampled with the series
    assert "compute         bst all property/local batom1 batom2 btype bbondbroken" in text
    assert "dump            bst all local ${series_every} bonds.dump" in text
    golden = DATA / "liggghts" / "tiny_ucs_bonded.in.liggghts"
    if os.environ.get("DECKGEN_REGEN_GOLDEN"):
        golden.write_text(text)
    assert text == golden.read_text(), "bonded LIGGGHTS deck changed: DECKGEN_REGEN_GOLDEN=1 pytest to accept"
    # a deck whose bond creation is never switched off is refused
    bad = text.replace("fix_modify      bc every 0\n", "")
    with pytest.raises(lg.BondGrammarError, match="every 0"):
        lg.check_bonded_deck(bad)
    with pytest.raises(lg.BondGrammarError, match="boundary f f f"):
        lg.check_bonded_deck(text.replace("boundary        f f f", "boundary        m m m"))


@needs_fork
def test_bonded_ucs_runs_on_fork(tmp_path):
    caps = lg.capabilities()
    if not lg.has_bonds(caps):
        pytest.skip(f"{lg.ENV_BINARY} has no bond/gran")
    case = load_case(DATA / "cases" / "tiny_ucs.yaml", overrides={"specimen": {"max_strain": 0.002}})
    lg.render_liggghts_ucs_bonded(case, tmp_path)
    lg.run_liggghts(tmp_path, ranks=1, timeout_s=1800)
    d = read_series(tmp_path / "series.txt")
    assert (d["bonds"] > 0).all()


# ------------------------------------------------------------------------------- oscillation, run
def _install_packing(case, name, cache):
    """The committed packing fixture of golden case ``name`` as ``case``'s cached packing (no engine)."""
    load_script(DATA / "golden" / "regenerate.py", "regen").install_fixture(case, name, cache)


@needs_liggghts
def test_oscillation_stacked_moves_run(tmp_path):
    """Eccentric oscillation + rolling spin on Debian LIGGGHTS: the mesh reference point follows
    x_c = x_c0 + V t + e (cos wt - 1), z_c = z_c0 + e sin wt, and every dumped mesh vertex is the
    rest disc turned by spin_rate t about +y and carried by the centre (the orbit's own spin is
    cancelled by the correction move)."""
    case = load_case(DATA / "cases" / "tiny_cut.yaml", overrides={"engine": "liggghts", "bonds": {"enabled": False},
                                                                 "kinematics": {"travel_mm": 2.0}})
    cache = tmp_path / "cache"
    _install_packing(case, "tiny_cut", cache)
    spec = lg.render_liggghts_cut(case, tmp_path / "run", bed="packing", cache=cache, command=["false"],
                                  mesh_dump_every=1000)
    path, dt = spec["derived"]["cutter"], spec["derived"]["dt_s"]
    assert path["ecc"] > 0 and path["omega"] > 0 and path["spin_rate"] > 0
    lg.run_liggghts(tmp_path / "run", ranks=1, timeout_s=300)
    d = read_series(tmp_path / "run" / "series.txt")
    t = d["time_s"].to_numpy()
    assert t[-1] * path["omega"] > 2 * math.pi  # more than one oscillation period
    xc = path["xc0"] + path["V"] * t + path["ecc"] * (np.cos(path["omega"] * t) - 1)
    zc = path["zc0"] + path["ecc"] * np.sin(path["omega"] * t)
    err_ref = max(np.abs(d["ref_x_m"] - xc).max(), np.abs(d["ref_z_m"] - zc).max(), np.abs(d["ref_y_m"] - path["yc0"]).max())
    assert err_ref < 1e-9, err_ref
    import trimesh

    rest = np.asarray(trimesh.load_mesh(tmp_path / "run" / "cutter.stl", process=False).triangles)  # binary STL
    dumps = sorted((tmp_path / "run").glob("cutter_mesh_*.stl"), key=lambda p: int(p.stem.rsplit("_", 1)[1]))
    assert len(dumps) >= 4
    errs = []
    for f in dumps:
        step = int(f.stem.rsplit("_", 1)[1])
        tri = lg.read_stl_triangles(f)
        assert tri.shape == rest.shape
        errs.append(np.abs(tri - lg.rigid_cutter_position(rest, path, step * dt)).max())
    # the dump's ASCII precision bounds the agreement; a spin error of one time step would be ~R spin_rate dt
    R = spec["derived"]["cutter_summary"]["diameter_m"] / 2
    print(f"oscillation: reference point error {err_ref:.2e} m, mesh vertex error {max(errs):.2e} m "
          f"(R spin_rate dt = {R * path['spin_rate'] * dt:.2e} m)")
    assert max(errs) < 1e-7, errs


def test_bonded_bts_deck_golden_and_grammar(tmp_path):
    case = load_case(DATA / "cases" / "tiny_bts.yaml")
    spec = lg.render_liggghts(case, tmp_path)
    text = (tmp_path / "in.liggghts").read_text()
    g = lg.check_bonded_deck(text)
    assert g["bond_coeffs"][0]["Y"] == case.bonds.youngs_modulus_GPa * GPA
    D, t = case.specimen.diameter_mm * 1e-3, case.specimen.thickness_mm * 1e-3
    assert spec["derived"]["area_m2"] == pytest.approx(math.pi * D * t / 2)   # sigma_t = 2F/(pi D t)
    assert spec["derived"]["height_m"] == pytest.approx(D)
    # disc trimmed from the settled box: centres within R - r_max of the axis (0, R), below 2R - r_max
    assert re.search(r"region +outside cylinder y 0.0 \$\{radius\} \$\{trim_radius\} \S+ \S+ side out units box", text)
    # the top platen exists only after the specimen is made (no grain settles on top of it)
    assert text.index("delete_atoms    region above") < text.index("fix             top all mesh/surface/stress")
    golden = DATA / "liggghts" / "tiny_bts_bonded.in.liggghts"
    if os.environ.get("DECKGEN_REGEN_GOLDEN"):
        golden.write_text(text)
    assert text == golden.read_text(), "bonded LIGGGHTS BTS deck changed: DECKGEN_REGEN_GOLDEN=1 pytest to accept"


@pytest.mark.parametrize("name,overrides,match", [
    ("tiny_ucs", {"bonds": {"enabled": False}}, "bonded only"),        # unbonded UCS
    ("tiny_bts", {"bonds": {"enabled": False}}, "bonded only"),
    ("tiny_cut", {}, "unbonded cutting beds only"),                     # bonded cutting block
])
def test_render_liggghts_refuses_in_one_line(tmp_path, name, overrides, match):
    from deckgen.spec import SpecError

    case = load_case(DATA / "cases" / f"{name}.yaml", overrides=overrides)
    with pytest.raises(SpecError, match=match) as exc:
        lg.render_liggghts(case, tmp_path)
    assert "\n" not in str(exc.value) and "fix:" in str(exc.value)


def test_cli_render_liggghts_every_family(tmp_path, capsys):
    """deckgen render --engine liggghts: bonded UCS and BTS decks, unbonded linear / oscillation /
    rotary / indentation cuts of the case's packing; unsupported combinations end in one line."""
    from deckgen.cli import main

    cache = tmp_path / "cache"
    for name in ("tiny_ucs", "tiny_bts"):
        assert main(["render", str(DATA / "cases" / f"{name}.yaml"), "--engine", "liggghts", "--out",
                     str(tmp_path / name)]) == 0
    for name in ("tiny_cut", "tiny_rotary", "tiny_indent"):
        src = DATA / "cases" / f"{name}.yaml"
        case_file = tmp_path / f"{name}.yaml"
        case_file.write_text(src.read_text().replace("bonds:\n", "bonds:\n  enabled: false\n") + "engine: liggghts\n")
        case = load_case(case_file)
        fixture = "tiny_cut" if name == "tiny_indent" else name
        if name == "tiny_indent":  # no committed packing: render the settled bed instead (no engine)
            assert main(["render", str(case_file), "--out", str(tmp_path / name), "--bed", "settle"]) == 0
        else:
            _install_packing(case, fixture, cache)
            assert main(["render", str(case_file), "--out", str(tmp_path / name), "--cache", str(cache),
                         "--engine-cmd", "false"]) == 0
        deck = (tmp_path / name / "in.liggghts").read_text()
        assert "{{" not in deck
        if name == "tiny_rotary":
            assert re.search(r"fix +mv1 all move/mesh mesh cad rotate origin \$\{ax_x\} \$\{ax_y\} \$\{zc0\} axis 0.0 0.0 1.0 period \$\{period_yaw\}", deck)
            assert "path_angle_rad" in deck and "read_data       bed.data" in deck
        if name == "tiny_indent":
            assert "linear 0.0 0.0 -${v_cut}" in deck and "variable        zc equal ${zc0}-${v_cut}*v_t" in deck
    out = capsys.readouterr().out
    assert out.count("for LIGGGHTS") == 5
    # a bonded cutting block on liggghts: one line, exit code 2
    assert main(["render", str(DATA / "cases" / "tiny_cut.yaml"), "--engine", "liggghts", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("deckgen: error:") and "bonds.enabled: false" in err and "\n" not in err


# ------------------------------------------------------------------------------- cross-engine (small)
@needs_liggghts
def test_cross_engine_small(tmp_path):
    """The same unbonded bed (the committed tiny_cut packing, ~450 grains), disc and linear motion on
    LAMMPS and LIGGGHTS: both see the bed resist (F_r > 0, F_n > 0) and the steady means agree within
    the tolerance of one tiny bed (factor 2.5; the statistical tolerance is measured by
    bench/cross_engine.py, see docs/liggghts.md)."""
    case = load_case(DATA / "cases" / "tiny_cut.yaml", overrides={
        "bonds": {"enabled": False}, "contact": {"rolling_friction": 0.0},
        "kinematics": {"mode": "linear", "spin": "none", "travel_mm": 3.0}})
    cache = tmp_path / "cache"
    _install_packing(case, "tiny_cut", cache)
    r = lg.cross_engine_cut(case, tmp_path, cache=cache, ranks=1, timeout_s=300)
    print({k: {q: round(v, 4) for q, v in r[k].items() if isinstance(v, float)} for k in ("lammps", "liggghts", "ratio")})
    assert r["lammps"]["n_grains"] == r["liggghts"]["n_grains"]
    for eng in ("lammps", "liggghts"):
        assert r[eng]["force_rolling_N_mean_steady"] > 0 and r[eng]["force_normal_N_mean_steady"] > 0
        assert r[eng]["contact_fraction_steady_1"] > 0.1  # measured: LAMMPS 0.125, LIGGGHTS 0.46 (tiny, stiff, loose)
    for q in ("force_rolling_N_mean_steady", "force_normal_N_mean_steady"):
        assert 1 / 2.5 < r["ratio"][q] < 2.5, (q, r["ratio"][q])
