"""Partially bonded specimens (bonds.unbonded_fraction) and bending/twisting strengths set apart from
sigma_c and tau_c (bonds.bending_strength_factor, bonds.twisting_strength_factor): the selection, the
coefficients, the rendered specimen, validation, and a real engine run where the missing bonds act as
frictional contacts (compression) but not in tension."""

from __future__ import annotations

import hashlib
import runpy
from pathlib import Path

import numpy as np
import pytest

from deckgen.bonds import bpm_coefficients, find_bond_pairs, grow_clumps, intra_clump, unbonded_mask
from deckgen.spec import SpecError, load_case

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "data" / "golden"
CASES = ROOT / "tests" / "data" / "cases"


def _render(tmp_path, name: str, overrides: dict, case_file: str = "tiny_ucs.yaml") -> tuple[Path, dict]:
    from deckgen.deck import render_case

    case = load_case(CASES / case_file, overrides=overrides)
    cache = tmp_path / f"cache_{name}"
    runpy.run_path(str(GOLDEN / "regenerate.py"))["install_fixture"](case, "tiny_ucs", cache)
    out = tmp_path / name
    spec = render_case(case, out, cache=cache, progress=False, command=["false"])
    return out, spec


def test_unbonded_mask_counts_and_is_deterministic():
    m = unbonded_mask(1000, 0.3, seed=7)
    assert m.sum() == 300
    assert np.array_equal(m, unbonded_mask(1000, 0.3, seed=7))
    assert not np.array_equal(m, unbonded_mask(1000, 0.3, seed=8))
    assert unbonded_mask(1000, 0.0, seed=7).sum() == 0
    assert unbonded_mask(7, 0.5, seed=1).sum() == 4  # round(3.5) = 4 (banker's rounding of numpy: 4)
    protect = np.zeros(1000, bool)
    protect[:600] = True
    mp = unbonded_mask(1000, 0.5, seed=7, protect=protect)
    assert mp.sum() == 200 and not mp[:600].any()
    for bad in (-0.1, 1.0):
        with pytest.raises(ValueError, match="unbonded fraction"):
            unbonded_mask(10, bad, seed=1)


def test_strength_factors_scale_only_the_torques():
    base = bpm_coefficients(20e9, 2.5, 60e6, 30e6, 5e-4, 1e-3, 1e-6, 1e-13, 0.05)
    f = bpm_coefficients(20e9, 2.5, 60e6, 30e6, 5e-4, 1e-3, 1e-6, 1e-13, 0.05, bending_factor=10.0, twisting_factor=0.3)
    assert float(f["tau_bc"]) == pytest.approx(10.0 * float(base["tau_bc"]), rel=1e-12)
    assert float(f["tau_tc"]) == pytest.approx(0.3 * float(base["tau_tc"]), rel=1e-12)
    # parallel-bond match at factor 1: tau_b,c = sigma_c I / r_b with I = pi r^4 / 4
    assert float(base["tau_bc"]) == pytest.approx(60e6 * np.pi * 5e-4**3 / 4, rel=1e-12)
    for k in base:
        if k not in ("tau_bc", "tau_tc"):
            assert float(f[k]) == float(base[k]), k


def test_defaults_change_nothing(tmp_path):
    a, sa = _render(tmp_path, "default", {})
    b, sb = _render(tmp_path, "explicit", {"bonds": {"unbonded_fraction": 0.0, "bending_strength_factor": 1.0,
                                                     "twisting_strength_factor": 1.0}})
    for f in ("in.deck", "specimen.data"):
        assert hashlib.sha256((a / f).read_bytes()).hexdigest() == hashlib.sha256((b / f).read_bytes()).hexdigest()
    assert sa == sb  # spec.json leaves the defaults out, so setup keys of existing runs stay
    assert "unbonded_fraction" not in sa["case"]["bonds"] and "unbonded" not in sa["derived"]
    assert (a / "in.deck").read_text() == (GOLDEN / "tiny_ucs" / "in.deck").read_text()


def test_unbonded_specimen_drops_the_drawn_pairs(tmp_path):
    from deckgen.datafile import iter_section, read_sphere_data

    _, s0 = _render(tmp_path, "plain", {})
    out, spec = _render(tmp_path, "half", {"bonds": {"unbonded_fraction": 0.5}})
    d, u = spec["derived"], spec["derived"]["unbonded"]
    n0 = s0["derived"]["n_bonds"]
    assert u["bondable_pairs"] == n0 and u["unbonded_pairs"] == round(0.5 * n0)
    assert d["n_bonds"] == n0 - u["unbonded_pairs"]
    assert spec["case"]["bonds"]["unbonded_fraction"] == 0.5
    bonds = {tuple(sorted((int(p[2]), int(p[3])))) for _, p in iter_section(out / "specimen.data", "Bonds")}
    assert len(bonds) == d["n_bonds"]
    # the kept bonds are a subset of the plain specimen's, chosen by the packing seed
    plain = {tuple(sorted((int(p[2]), int(p[3])))) for _, p in iter_section(tmp_path / "plain" / "specimen.data", "Bonds")}
    assert bonds < plain
    atoms = read_sphere_data(GOLDEN / "tiny_ucs" / "packing" / "packed.data")
    pairs = find_bond_pairs(atoms.x, atoms.radius, 0.05)
    drop = unbonded_mask(len(pairs), 0.5, seed=spec["case"]["packing"]["seed"])
    assert {(int(a) + 1, int(b) + 1) for a, b in pairs[~drop]} == bonds


def test_unbonded_with_clumps_keeps_intra_clump_bonds(tmp_path):
    from deckgen.datafile import read_sphere_data

    _, sc = _render(tmp_path, "c4", {"bonds": {"clump_size": 4}})
    _, spec = _render(tmp_path, "c4u", {"bonds": {"clump_size": 4, "unbonded_fraction": 0.75}})
    n_intra = sc["derived"]["clumps"]["intra_clump_bonds"]
    assert spec["derived"]["clumps"]["intra_clump_bonds"] == n_intra  # none dropped
    n_other = sc["derived"]["n_bonds"] - n_intra
    assert spec["derived"]["unbonded"]["unbonded_pairs"] == round(0.75 * n_other)
    atoms = read_sphere_data(GOLDEN / "tiny_ucs" / "packing" / "packed.data")
    pairs = find_bond_pairs(atoms.x, atoms.radius, 0.05)
    label = grow_clumps(pairs, len(atoms.radius), 4, seed=spec["case"]["packing"]["seed"], x=atoms.x)
    assert int(intra_clump(pairs, label).sum()) == n_intra


def test_bending_factor_reaches_the_deck(tmp_path):
    _, s0 = _render(tmp_path, "plain", {})
    _, s1 = _render(tmp_path, "bend", {"bonds": {"bending_strength_factor": 10.0, "twisting_strength_factor": 0.5}})
    c0, c1 = s0["derived"]["bond_coefficients"], s1["derived"]["bond_coefficients"]
    assert np.allclose(c1["tau_bc"], 10.0 * np.array(c0["tau_bc"]), rtol=1e-12)
    assert np.allclose(c1["tau_tc"], 0.5 * np.array(c0["tau_tc"]), rtol=1e-12)
    assert c1["F_rc"] == c0["F_rc"] and c1["k_b"] == c0["k_b"]


@pytest.mark.parametrize("field, value", [("unbonded_fraction", 0.2), ("strength_weibull_modulus", 3.0)])
def test_liggghts_bonded_deck_refuses_what_it_cannot_express(tmp_path, field, value):
    from deckgen.liggghts import render_liggghts_ucs_bonded

    case = load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {field: value}})
    with pytest.raises(SpecError, match=rf"cannot express bonds\.{field} \(fix: use engine lammps"):
        render_liggghts_ucs_bonded(case, tmp_path / "lig")


@pytest.mark.engine
def test_unbonded_pairs_carry_compression_not_tension(tmp_path):
    """Tiny UCS cylinder (5.7 bonds per grain), 30 % of the pairs unbonded: the specimen is softer and weaker
    (measured: E 2.81 -> 1.48 GPa, UCS 16.8 -> 6.8 MPa; 4.0 bonds per grain is near the rigidity threshold of
    the bond network), and the dropped pairs never appear among the broken bonds."""
    from deckgen.results import parse_run
    from deckgen.runner import engine_available, run_deck
    import pandas as pd

    if not engine_available():  # pragma: no cover
        pytest.skip("no LAMMPS binary")
    peaks, moduli = {}, {}
    for name, ov in (("plain", {}), ("part", {"bonds": {"unbonded_fraction": 0.3}})):
        out, spec = _render(tmp_path, name, ov)
        run_deck(out, expected_steps=spec["derived"]["expected_steps"], progress=False)
        summary = parse_run(out, tmp_path / f"parsed_{name}")
        peaks[name], moduli[name] = summary["peak_stress_Pa"], summary["youngs_modulus_Pa"]
        assert summary["bonds_broken"] > 10
        if name == "part":
            from deckgen.datafile import iter_section

            kept = {tuple(sorted((int(p[2]), int(p[3])))) for _, p in iter_section(out / "specimen.data", "Bonds")}
            broken = pd.read_parquet(tmp_path / f"parsed_{name}" / "broken.parquet", columns=["id1", "id2"])
            assert all(tuple(sorted((int(a), int(b)))) in kept for a, b in zip(broken["id1"], broken["id2"]))
    assert 0.2 * peaks["plain"] < peaks["part"] < 0.7 * peaks["plain"], peaks
    assert 0.3 * moduli["plain"] < moduli["part"] < 0.8 * moduli["plain"], moduli
