"""Clumped grains (bonds.clump_size): deterministic clumps on the bond graph, their own bond types with
stronger (and optionally stiffer) bonds, no change without clumps, and a real engine run in which the
intra-clump bonds hold while others break."""

from __future__ import annotations

import hashlib
import json
import runpy
from pathlib import Path

import numpy as np
import pytest

from deckgen.bonds import (
    bpm_coefficients,
    clump_sizes,
    find_bond_pairs,
    grow_clumps,
    intra_clump,
    make_bond_table,
    section,
    stable_timestep,
)
from deckgen.spec import SpecError, load_case

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "data" / "golden"
CASES = ROOT / "tests" / "data" / "cases"


def _install_fixture(case, cache: Path) -> None:
    """The committed tiny UCS packing as the cached packing of ``case`` (the golden decks' helper)."""
    runpy.run_path(str(GOLDEN / "regenerate.py"))["install_fixture"](case, "tiny_ucs", cache)


@pytest.fixture(scope="module")
def grains():
    """The committed tiny UCS packing: positions, radii and its bond graph at the default gap tolerance."""
    from deckgen.datafile import read_sphere_data

    atoms = read_sphere_data(GOLDEN / "tiny_ucs" / "packing" / "packed.data")
    pairs = find_bond_pairs(atoms.x, atoms.radius, 0.05)
    return atoms.x, atoms.radius, pairs


def _connected(members: np.ndarray, pairs: np.ndarray) -> bool:
    """Are ``members`` one connected component of the bond graph restricted to them?"""
    ms = set(int(m) for m in members)
    sub = [(int(a), int(b)) for a, b in pairs if int(a) in ms and int(b) in ms]
    seen, stack = {int(members[0])}, [int(members[0])]
    while stack:
        k = stack.pop()
        for a, b in sub:
            for u, v in ((a, b), (b, a)):
                if u == k and v not in seen:
                    seen.add(v)
                    stack.append(v)
    return seen == ms


def test_chain_clumps_by_hand():
    """A chain 0-1-2-3-4-5 with clump_size 2: every clump is a bonded pair or a single grain."""
    pairs = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5]])
    lab = grow_clumps(pairs, 6, 2, seed=1)
    assert np.array_equal(lab, grow_clumps(pairs, 6, 2, seed=1))
    for c in np.unique(lab):
        m = np.flatnonzero(lab == c)
        assert len(m) <= 2
        if len(m) == 2:
            assert abs(int(m[0]) - int(m[1])) == 1  # bonded neighbours on the chain
    # one grain alone without bonds stays a clump of one; clump_size 1 labels every grain by itself
    assert sorted(grow_clumps(np.zeros((0, 2), int), 3, 4, seed=5)) == [0, 1, 2]
    assert list(grow_clumps(pairs, 6, 1, seed=1)) == [0, 1, 2, 3, 4, 5]
    # a triangle with clump_size 3 is one clump whatever the seed
    tri = np.array([[0, 1], [1, 2], [0, 2]])
    for seed in (1, 2, 3):
        assert clump_sizes(grow_clumps(tri, 3, 3, seed=seed)) == {3: 1}


def test_clumps_are_deterministic_bounded_and_connected(grains):
    x, r, pairs = grains
    n = len(r)
    a = grow_clumps(pairs, n, 4, seed=12345, x=x)
    b = grow_clumps(pairs, n, 4, seed=12345, x=x)
    c = grow_clumps(pairs, n, 4, seed=777, x=x)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    # every grain in exactly one clump, labels 0..n_clumps-1, sizes 1..4
    assert a.shape == (n,) and a.min() == 0 and set(np.unique(a)) == set(range(a.max() + 1))
    dist = clump_sizes(a)
    assert sum(k * v for k, v in dist.items()) == n
    assert max(dist) == 4 and min(dist) >= 1
    # most grains end up in full clumps (tiny cylinder: 289 grains, ~5 bonds each)
    assert dist[4] * 4 / n > 0.7, dist
    for lab in np.unique(a):
        m = np.flatnonzero(a == lab)
        if len(m) > 1:
            assert _connected(m, pairs)
    # intra-clump bonds: both ends in the same clump; a clump of k grains holds >= k - 1 of them
    intra = intra_clump(pairs, a)
    assert np.all(a[pairs[intra, 0]] == a[pairs[intra, 1]])
    assert np.all(a[pairs[~intra, 0]] != a[pairs[~intra, 1]])
    assert intra.sum() >= sum((k - 1) * v for k, v in dist.items())


def test_grow_clumps_rejects_bad_input():
    with pytest.raises(ValueError, match="clump_size must be >= 1"):
        grow_clumps(np.array([[0, 1]]), 2, 0, seed=1)
    with pytest.raises(ValueError, match="outside 0..1"):
        grow_clumps(np.array([[0, 2]]), 2, 2, seed=1)


def test_intra_clump_bonds_get_their_own_types_and_factors(grains):
    x, r, pairs = grains
    mass = 2650 * 4 / 3 * np.pi * r**3
    lab = grow_clumps(pairs, len(r), 3, seed=12345, x=x)
    intra = intra_clump(pairs, lab)
    kw = dict(E_b=10e9, stiffness_ratio=2.5, sigma_c=30e6, tau_c=60e6, radius_multiplier=1.0, damping_ratio=0.05,
              bins_radius=6, bins_length=4)
    plain = make_bond_table(x, r, mass, pairs, **kw)
    clumped = make_bond_table(x, r, mass, pairs, intra=intra, clump_strength_factor=50.0, clump_stiffness_factor=2.0, **kw)
    assert plain.intra_types == [] and plain.n_plain_types is not None
    nt = clumped.n_plain_types
    assert clumped.intra_types == list(range(nt + 1, clumped.ntypes + 1))
    # ordinary bonds on types 1..nt, intra-clump bonds on the others
    assert np.all(clumped.types[~intra] <= nt) and np.all(clumped.types[intra] > nt)
    # per type: strengths and stiffness against the section and length of the type (factor 1 or 50, 1 or 2)
    A, I, _ = section(clumped.r_bond)
    f_s = clumped.coeffs["F_rc"] / (30e6 * A)
    f_t = clumped.coeffs["F_sc"] / (60e6 * A)
    f_b = clumped.coeffs["tau_bc"] / (30e6 * I / clumped.r_bond)
    f_k = clumped.coeffs["k_r"] / (10e9 * A / clumped.length)
    is_intra = np.arange(1, clumped.ntypes + 1) > nt
    for f in (f_s, f_t, f_b):
        assert np.allclose(f[is_intra], 50.0) and np.allclose(f[~is_intra], 1.0)
    assert np.allclose(f_k[is_intra], 2.0) and np.allclose(f_k[~is_intra], 1.0)
    # each bond's own coefficients: a type's mean bond, as bpm_coefficients gives them with the factors
    t = clumped.ntypes - 1
    c = bpm_coefficients(20e9, 2.5, 1.5e9, 3e9, clumped.r_bond[t], clumped.length[t], 1.0, 1.0, 0.0)
    assert float(clumped.coeffs["F_rc"][t]) == pytest.approx(float(c["F_rc"]))
    assert float(clumped.coeffs["k_b"][t]) == pytest.approx(float(c["k_b"]))
    # stiffer clumps: a shorter stable time step
    assert stable_timestep(x, r, mass, clumped, 0.2)["dt_s"] < stable_timestep(x, r, mass, plain, 0.2)["dt_s"]
    # no intra bond: the table is the plain one
    same = make_bond_table(x, r, mass, pairs, intra=np.zeros(len(pairs), bool), clump_strength_factor=50.0, **kw)
    assert np.array_equal(same.types, plain.types)
    for k in plain.coeffs:
        assert np.array_equal(same.coeffs[k], plain.coeffs[k])
    with pytest.raises(ValueError, match="expected a mask of"):
        make_bond_table(x, r, mass, pairs, intra=intra[:-1], **kw)


def _render(tmp_path, name: str, overrides: dict) -> tuple[Path, dict]:
    from deckgen.deck import render_case

    case = load_case(CASES / "tiny_ucs.yaml", overrides=overrides)
    cache = tmp_path / f"cache_{name}"
    _install_fixture(case, cache)
    out = tmp_path / name
    spec = render_case(case, out, cache=cache, progress=False, command=["false"])
    return out, spec


def test_clump_size_1_changes_nothing(tmp_path):
    a, sa = _render(tmp_path, "default", {})
    b, sb = _render(tmp_path, "one", {"bonds": {"clump_size": 1, "clump_strength_factor": 30.0}})
    for f in ("in.deck", "specimen.data"):
        assert hashlib.sha256((a / f).read_bytes()).hexdigest() == hashlib.sha256((b / f).read_bytes()).hexdigest()
    assert sa["derived"] == sb["derived"] and "clumps" not in sa["derived"]
    assert (a / "in.deck").read_text() == (GOLDEN / "tiny_ucs" / "in.deck").read_text()


def test_clumps_in_the_rendered_specimen(tmp_path):
    _, s0 = _render(tmp_path, "plain", {})
    out, spec = _render(tmp_path, "c4", {"bonds": {"clump_size": 4, "clump_strength_factor": 20.0}})
    d, c = spec["derived"], spec["derived"]["clumps"]
    assert d["n_bonds"] == s0["derived"]["n_bonds"]  # same bonds, other types
    dist = {int(k): v for k, v in c["size_distribution"].items()}
    assert sum(k * v for k, v in dist.items()) == d["n_grains"]
    assert max(dist) <= 4 and c["n_clumps"] == sum(v for k, v in dist.items() if k > 1)
    assert 0.7 < c["grains_in_clumps_fraction"] <= 1.0 and 2.0 <= c["mean_clump_size"] <= 4.0
    types = c["intra_clump_bond_types"]
    assert types == list(range(types[0], d["n_bond_types"] + 1)) and types[0] > 1
    # the data file's intra-clump bonds are c["intra_clump_bonds"]; their strengths are 20x their plain twins'
    from deckgen.datafile import iter_section

    bt = np.array([int(p[1]) for _, p in iter_section(out / "specimen.data", "Bonds")])
    assert int(np.isin(bt, types).sum()) == c["intra_clump_bonds"] > 0
    F = np.array(d["bond_coefficients"]["F_rc"])
    rb = F / (30e6 * np.pi)  # F_rc = sigma_c pi r_b^2 for the plain types
    assert np.all(F[np.array(types) - 1] > 10 * F[: types[0] - 1].min())
    assert np.all(rb[: types[0] - 1] > 0)
    # the deck declares every bond type with its coefficients
    deck = (out / "in.deck").read_text()
    import re

    declared = [int(m) for m in re.findall(r"^bond_coeff\s+(\d+)\s", deck, flags=re.M)]
    assert declared == list(range(1, d["n_bond_types"] + 1))


@pytest.mark.parametrize("bonds, words", [
    ({"clump_size": 0}, "greater than or equal to 1"),
    ({"clump_size": 2.5}, "valid integer"),
    ({"clump_strength_factor": 0.5}, "greater than or equal to 1"),
    ({"clump_stiffness_factor": 0}, "greater than or equal to 0.1"),
    ({"clump_size": 3, "enabled": False}, "clumps are made of bonds"),
    ({"unbonded_fraction": -0.1}, "greater than or equal to 0"),
    ({"unbonded_fraction": 0.95}, "less than or equal to 0.9"),
    ({"unbonded_fraction": 0.3, "enabled": False}, "no bond to leave out"),
    ({"bending_strength_factor": 0.0}, "greater than or equal to 0.1"),
    ({"twisting_strength_factor": "x"}, "valid number"),
])
def test_bond_fields_are_validated(tmp_path, bonds, words):
    """Clump fields here, and the unbonded fraction and torque strength factors of tests/test_unbonded.py."""
    p = tmp_path / "c.yaml"
    p.write_text(json.dumps({"bonds": bonds}))
    with pytest.raises(SpecError) as err:
        load_case(p)
    first = str(err.value).splitlines()[0]
    assert first.startswith(f"{p}: bonds"), first
    assert words in first and "(fix: " in first


@pytest.mark.engine
def test_intra_clump_bonds_hold_while_others_break(tmp_path):
    """Tiny UCS cylinder with clumps of 4 (strength x100): the specimen fails, no intra-clump bond breaks."""
    from deckgen.calibration_studies import intra_clump_broken
    from deckgen.results import parse_run
    from deckgen.runner import engine_available, run_deck

    if not engine_available():  # pragma: no cover
        pytest.skip("no LAMMPS binary")
    out, spec = _render(tmp_path, "run", {"bonds": {"clump_size": 4}})
    run_deck(out, expected_steps=spec["derived"]["expected_steps"], progress=False)
    summary = parse_run(out, tmp_path / "parsed")
    counts = intra_clump_broken(out, tmp_path / "parsed")
    assert counts["intra_bonds"] == spec["derived"]["clumps"]["intra_clump_bonds"] > 100
    assert counts["broken"] == summary["bonds_broken"] > 20
    assert counts["broken_intra"] == 0
    assert counts["broken_other"] == counts["broken"]
    assert summary["peak_stress_Pa"] > 1e6
