"""Bond strength heterogeneity (bonds.strength_weibull_modulus): the Weibull draw, the strength bins of the
bond table, the rendered specimen, validation, and a real engine run in which the weak bonds break first."""

from __future__ import annotations

import hashlib
import math

import numpy as np
import pytest

from deckgen.bonds import binning_error, make_bond_table, weibull_cov, weibull_strength_factors
from deckgen.spec import SpecError, load_case
from test_unbonded import CASES, GOLDEN, _render


def test_weibull_factors_have_mean_one_and_the_distribution_cov():
    # CoV of a Weibull of shape m: sqrt(G(1+2/m)/G(1+1/m)^2 - 1); m = 1 is the exponential (CoV 1)
    assert weibull_cov(1.0) == pytest.approx(1.0, rel=1e-12)
    assert weibull_cov(3.0) == pytest.approx(0.3634, abs=1e-4)
    for m in (2.0, 3.0, 5.0):
        w = weibull_strength_factors(100_000, m, seed=11)
        assert w.mean() == pytest.approx(1.0, abs=0.01)
        assert w.std() / w.mean() == pytest.approx(weibull_cov(m), rel=0.02)
        assert (w > 0).all()
    a = weibull_strength_factors(50, 3.0, seed=5)
    assert np.array_equal(a, weibull_strength_factors(50, 3.0, seed=5))
    assert not np.array_equal(a, weibull_strength_factors(50, 3.0, seed=6))
    with pytest.raises(ValueError, match="Weibull modulus"):
        weibull_strength_factors(10, 0.0, seed=1)


def _grains(n: int = 300, seed: int = 3):
    """A chain of touching grains (bond length = r_i + r_j) with bonds to both next neighbours' partners."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(4e-4, 6e-4, size=n)
    x = np.zeros((n, 3))
    x[1:, 0] = np.cumsum(r[:-1] + r[1:])
    pairs = np.array([(i, i + 1) for i in range(n - 1)])
    mass = 2500 * 4 / 3 * math.pi * r**3
    return x, r, mass, pairs


def test_bond_table_bins_the_strength_factor_and_keeps_stiffness_and_clumps():
    x, r, mass, pairs = _grains()
    kw = dict(E_b=20e9, stiffness_ratio=2.5, sigma_c=60e6, tau_c=30e6, radius_multiplier=1.0, damping_ratio=0.05,
              bins_radius=2, bins_length=2)
    w = weibull_strength_factors(len(pairs), 3.0, seed=9)
    intra = np.zeros(len(pairs), bool)
    intra[:40] = True
    plain = make_bond_table(x, r, mass, pairs, intra=intra, **kw)
    het = make_bond_table(x, r, mass, pairs, intra=intra, strength_factor=w, bins_strength=5, **kw)
    assert het.ntypes > plain.ntypes
    t = het.types - 1
    # each ordinary type carries the mean factor of its bonds: F_rc / (sigma_c A_type) and F_sc / (tau_c A_type)
    area = math.pi * het.r_bond**2
    f_type = het.coeffs["F_rc"] / (60e6 * area)
    assert np.allclose(het.coeffs["F_sc"] / (30e6 * area), f_type, rtol=1e-12)
    for k in np.unique(t[~intra]):
        assert f_type[k] == pytest.approx(w[~intra][t[~intra] == k].mean(), rel=1e-12)
    # the bins sort by strength: the weakest type's bonds are all weaker than the strongest type's
    lo, hi = np.argmin(f_type[: het.n_plain_types]), np.argmax(f_type[: het.n_plain_types])
    assert w[t == lo].max() < w[t == hi].min()
    # intra-clump bonds ignore the factors: strength x clump factor 1 here, exactly the plain table's
    assert set(het.intra_types) and np.allclose(f_type[np.array(het.intra_types) - 1], 1.0, rtol=1e-12)
    # stiffness unchanged up to binning: the strength sub-bins move the worst k_r error of the coarse 2 x 2
    # radius-length bins (19 % here) by a few per cent at most
    assert binning_error(x, r, het, 1.0) < 1.25 * binning_error(x, r, plain, 1.0)
    # no factor: strength bins are ignored, the table is the plain one
    same = make_bond_table(x, r, mass, pairs, intra=intra, bins_strength=5, **kw)
    assert np.array_equal(same.types, plain.types)
    with pytest.raises(ValueError, match="strength_factor"):
        make_bond_table(x, r, mass, pairs, strength_factor=np.zeros(len(pairs)), **kw)


def test_zero_modulus_changes_nothing(tmp_path):
    a, sa = _render(tmp_path, "default", {})
    b, sb = _render(tmp_path, "explicit", {"bonds": {"strength_weibull_modulus": 0.0, "type_bins_strength": 8}})
    for f in ("in.deck", "specimen.data"):
        assert hashlib.sha256((a / f).read_bytes()).hexdigest() == hashlib.sha256((b / f).read_bytes()).hexdigest()
    assert sa == sb and "strength_weibull_modulus" not in sa["case"]["bonds"]
    assert "strength_heterogeneity" not in sa["derived"]
    assert (a / "in.deck").read_text() == (GOLDEN / "tiny_ucs" / "in.deck").read_text()


def test_rendered_specimen_carries_the_scatter(tmp_path):
    from deckgen.datafile import iter_section

    _, s0 = _render(tmp_path, "plain", {})
    out, s = _render(tmp_path, "w3", {"bonds": {"strength_weibull_modulus": 3.0}})
    h = s["derived"]["strength_heterogeneity"]
    assert h["weibull_modulus"] == 3.0 and h["cov_distribution"] == pytest.approx(weibull_cov(3.0))
    # about 800 bonds: the sample CoV within 15 % of the distribution's, binning keeps 90 % of it
    assert h["cov_drawn"] == pytest.approx(h["cov_distribution"], rel=0.15)
    assert 0.9 * h["cov_drawn"] < h["cov_binned"] <= h["cov_drawn"]
    assert s["derived"]["n_bonds"] == s0["derived"]["n_bonds"]
    assert s["derived"]["n_bond_types"] > s0["derived"]["n_bond_types"]
    # mean strength over the bonds of the deck stays that of the plain specimen within the sampling error
    f_rc = np.array(s["derived"]["bond_coefficients"]["F_rc"])
    f_rc0 = np.array(s0["derived"]["bond_coefficients"]["F_rc"])
    types = np.array([int(p[1]) for _, p in iter_section(out / "specimen.data", "Bonds")])
    types0 = np.array([int(p[1]) for _, p in iter_section(tmp_path / "plain" / "specimen.data", "Bonds")])
    assert f_rc[types - 1].mean() == pytest.approx(f_rc0[types0 - 1].mean(), rel=3 * h["cov_drawn"] / math.sqrt(len(types)))
    assert f_rc[types - 1].std() / f_rc[types - 1].mean() > 0.3  # the deck's bonds scatter (plain: radii only)


@pytest.mark.parametrize("value", [0.5, -1, 101])
def test_modulus_is_validated(value):
    with pytest.raises(SpecError, match="strength_weibull_modulus"):
        load_case(CASES / "tiny_ucs.yaml", overrides={"bonds": {"strength_weibull_modulus": value}})


@pytest.mark.engine
def test_weak_bonds_break_first_and_the_cylinder_is_weaker(tmp_path):
    """Tiny UCS cylinder, Weibull m 2 (CoV 0.52): the bonds that broke are weaker than the average bond (their
    mean factor well below 1). The peak stress is not asserted: measured 16.8 MPa plain and 19.8 MPa with the
    scatter (one 289-grain cylinder). Measured: mean factor of the broken bonds 0.733, of all bonds 1.002."""
    import pandas as pd

    from deckgen.datafile import iter_section
    from deckgen.results import parse_run
    from deckgen.runner import engine_available, run_deck

    if not engine_available():  # pragma: no cover
        pytest.skip("no LAMMPS binary")
    for name, ov in (("plain", {}), ("w2", {"bonds": {"strength_weibull_modulus": 2.0}})):
        out, spec = _render(tmp_path, name, ov)
        run_deck(out, expected_steps=spec["derived"]["expected_steps"], progress=False)
        summary = parse_run(out, tmp_path / f"parsed_{name}")
        assert summary["bonds_broken"] > 10
        if name == "w2":
            c = spec["derived"]["bond_coefficients"]
            f_rc, tau_bc = np.array(c["F_rc"]), np.array(c["tau_bc"])
            # a type's factor: F_rc = w sigma_c pi r^2 and tau_bc = w sigma_c pi r^3 / 4 give r = 4 tau_bc / F_rc
            r_type = 4.0 * tau_bc / f_rc
            factor = f_rc / (spec["case"]["bonds"]["tensile_strength_MPa"] * 1e6 * math.pi * r_type**2)
            bonds = {tuple(sorted((int(p[2]), int(p[3])))): int(p[1]) for _, p in iter_section(out / "specimen.data", "Bonds")}
            broken = pd.read_parquet(tmp_path / f"parsed_{name}" / "broken.parquet", columns=["id1", "id2"])
            fb = np.array([factor[bonds[tuple(sorted((int(a), int(b))))] - 1] for a, b in zip(broken["id1"], broken["id2"])])
            f_all = factor[np.array(list(bonds.values())) - 1]
            assert f_all.mean() == pytest.approx(1.0, abs=0.1)
            assert fb.mean() < 0.8 * f_all.mean(), (fb.mean(), f_all.mean())
