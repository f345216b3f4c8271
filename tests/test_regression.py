"""Tests of deckgen.analysis.regression against the seeds' own published numbers.

The seed tables are read from ``../shared/data`` relative to the repository
root; the whole module is skipped when that folder is absent.  Expected values
that are *not* printed in the seeds (our fitted numbers, differences to the
published ones) were measured once with this code and are asserted with tight
tolerances so that a regression in the implementation fails the test.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from deckgen.analysis import regression as reg

DATA_DIR = Path(__file__).resolve().parents[2] / "shared" / "data"
REPO_ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(
    not DATA_DIR.is_dir(),
    reason=f"seed tables not found: {DATA_DIR} (expected ../shared/data next to the repository)",
)


# ---------------------------------------------------------------------------
# fixtures (module scope: every fit is done once)
# ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def seed001_fits():
    return reg.fit_seed001_equations(DATA_DIR)


@pytest.fixture(scope="module")
def table2():
    return reg.load_seed002_table2(DATA_DIR)


@pytest.fixture(scope="module")
def comparison(table2):
    return reg.compare_seed002_with_published(table2)


@pytest.fixture(scope="module")
def metrics(table2):
    return reg.seed002_fit_metrics(table2)


@pytest.fixture(scope="module")
def free_fit(table2):
    return reg.fit_seed002_model(table2, "normal_force", k_per_mm=None)


# ---------------------------------------------------------------------------
# Seed 001: eqs. 8-9 on the 16 LS-DYNA points
# ---------------------------------------------------------------------------


def test_seed001_points_are_the_16_lsdyna_rows():
    pts = reg.load_seed001_lsdyna_points(DATA_DIR)
    assert len(pts) == 16
    assert (pts["source_table"] == "seed001_table3").sum() == 9
    assert (pts["source_table"] == "seed001_table4").sum() == 7
    assert {"spacing_mm", "penetration_mm", "normal_force_kN", "rolling_force_kN"} <= set(pts.columns)


def test_seed001_eq8_normal_force_reproduces_printed(seed001_fits):
    """Fn = 7.39 + 0.84 S + 13.51 P, R² = 0.95 (seed 001 eq. 8), to the printed 2 decimals."""
    fit = seed001_fits["normal_force_kN"]
    assert fit.n_obs == 16
    assert fit.rounded(2) == {"const": 7.39, "spacing_mm": 0.84, "penetration_mm": 13.51, "r_squared": 0.95}


def test_seed001_eq9_rolling_force_reproduces_printed_except_one_digit(seed001_fits):
    """Fr = -9.46 + 0.16 S + 2.79 P, R² = 0.92 (seed 001 eq. 9).

    const, the S slope and R² reproduce after rounding.  The P slope comes out
    2.7964 (-> 2.80), not 2.79: the published digit is 0.0064 off, a fortieth
    of the coefficient's SE.  Asserted as measured; the exact reproduction is
    the strict xfail below.
    """
    fit = seed001_fits["rolling_force_kN"]
    r = fit.rounded(2)
    assert (r["const"], r["spacing_mm"], r["r_squared"]) == (-9.46, 0.16, 0.92)
    b_p = fit.coefficients.loc["penetration_mm", "estimate"]
    assert b_p == pytest.approx(2.79643, abs=1e-4)
    assert abs(b_p - reg.SEED001_PUBLISHED_LINEAR["rolling_force_kN"]["penetration_mm"]) < 0.0065


@pytest.mark.xfail(strict=True, reason="seed 001 eq. 9 prints 2.79 for the P slope; the 16 tabulated points give 2.7964 (rounds to 2.80)")
def test_seed001_eq9_penetration_slope_exact(seed001_fits):
    assert round(seed001_fits["rolling_force_kN"].coefficients.loc["penetration_mm", "estimate"], 2) == 2.79


def test_seed001_printed_match_table(seed001_fits):
    m = reg.seed001_printed_match(seed001_fits)
    assert len(m) == 10
    bad = m[~m["match_2dp"]]
    assert list(zip(bad["response"], bad["quantity"])) == [("rolling_force_kN", "penetration_mm")]


def test_seed001_single_value_edit_explains_the_digit():
    edits = reg.seed001_single_value_edits("rolling_force_kN", data_dir=DATA_DIR)
    assert len(edits) == 4
    assert (edits["edited_kN"] - edits["tabulated_kN"]).abs().max() <= 0.2 + 1e-9
    assert ((edits["spacing_mm"] == 76) & (edits["penetration_mm"] == 6.4) & np.isclose(edits["edited_kN"], 17.9)).any()


def test_seed001_text_penetrations_do_not_reproduce_eq8():
    fit = reg.seed001_text_penetration_fit(DATA_DIR)["normal_force_kN"]
    assert fit.rounded(2)["penetration_mm"] == pytest.approx(14.82, abs=1e-9)
    assert fit.rounded(2) != {"const": 7.39, "spacing_mm": 0.84, "penetration_mm": 13.51, "r_squared": 0.95}


def test_seed001_vif_of_spacing_and_penetration_is_one(seed001_fits):
    """The 16 (S, P) points are exactly uncorrelated, so VIF(S) = VIF(P) = 1 (printed 1.00)."""
    for fit in seed001_fits.values():
        assert fit.coefficients.loc["spacing_mm", "vif"] == pytest.approx(1.0, abs=1e-12)
        assert fit.coefficients.loc["penetration_mm", "vif"] == pytest.approx(1.0, abs=1e-12)
        assert math.isnan(fit.coefficients.loc["const", "vif"])


def test_vif_matches_definition_on_correlated_design(table2):
    """VIF_j = 1/(1 - R²_j) from regressing predictor j on the others (seed-002 Fn design)."""
    fit = reg.fit_seed002_model(table2, "normal_force")
    X = np.column_stack(
        [
            np.log(table2["ucs_MPa"]),
            np.log(table2["contact_area_mm2"]),
            np.log(table2["spacing_mm"]),
            np.log(reg.radial_term(table2["radial_position_mm"])),
        ]
    )
    for j, name in enumerate(reg.SEED002_PARAM_NAMES["normal_force"][1:]):
        others = np.column_stack([np.ones(len(X)), np.delete(X, j, axis=1)])
        coef = np.linalg.lstsq(others, X[:, j], rcond=None)[0]
        r2 = 1 - np.sum((X[:, j] - others @ coef) ** 2) / np.sum((X[:, j] - X[:, j].mean()) ** 2)
        assert fit.params.loc[name, "vif"] == pytest.approx(1 / (1 - r2), rel=1e-9)
    assert fit.params["vif"].dropna().max() == pytest.approx(1.0665, abs=1e-3)


def test_seed001_fit_statistics_as_measured(seed001_fits):
    fn = seed001_fits["normal_force_kN"]
    c = fn.coefficients
    assert c["std_error"].to_numpy() == pytest.approx([8.20443, 0.0885215, 1.11375], rel=1e-4)
    assert c.loc["const", "p_value"] == pytest.approx(0.38407, abs=1e-4)
    assert c.loc["spacing_mm", "p_value"] < 1e-6 and c.loc["penetration_mm", "p_value"] < 1e-7
    assert (c.loc["spacing_mm", "ci95_low"], c.loc["spacing_mm", "ci95_high"]) == pytest.approx((0.651035, 1.033513), abs=1e-5)
    assert fn.r_squared == pytest.approx(0.94807, abs=1e-4)
    assert fn.r_squared_adj == pytest.approx(0.94008, abs=1e-4)
    fr = seed001_fits["rolling_force_kN"]
    assert fr.r_squared == pytest.approx(0.91819, abs=1e-4)
    assert fr.coefficients.loc["penetration_mm", "std_error"] == pytest.approx(0.282777, rel=1e-4)
    # predict() is the fitted plane
    assert fn.predict(76, 6.4) == pytest.approx(7.39068 + 0.842274 * 76 + 13.5055 * 6.4, rel=1e-5)


def test_seed001_table3_error_columns():
    t = reg.seed001_table3_error_check(DATA_DIR)
    assert t["normal_error_printed_pct"].abs().mean() == pytest.approx(4.678, abs=1e-3)  # paper: 4.67 %
    assert t["rolling_error_printed_pct"].abs().mean() == pytest.approx(7.989, abs=1e-3)  # paper: 7.99 %
    assert t["rolling_error_recomputed_pct"].abs().mean() == pytest.approx(8.537, abs=1e-3)
    row = t[(t.spacing_mm == 51) & (t.penetration_mm == 3.8)].iloc[0]
    assert row["normal_error_recomputed_pct"] > 0 > row["normal_error_printed_pct"]


# ---------------------------------------------------------------------------
# Optimal spacing
# ---------------------------------------------------------------------------


def test_capacity_rule_hand_example():
    """Fn = 10 + S + 10 P, capacity 200 kN -> threshold 160 kN; at P = 5 mm, S* = 100 mm."""
    model = lambda s, p: 10 + 1.0 * s + 10.0 * p  # noqa: E731
    assert reg.capacity_threshold_kN(200, 0.8) == pytest.approx(160)
    r = reg.optimal_spacing_capacity_rule(model, 5.0, capacity_kN=200)
    assert r["status"] == "root"
    assert r["optimal_spacing_mm"] == pytest.approx(100.0, abs=1e-8)
    assert r["normal_force_at_optimum_kN"] == pytest.approx(160.0, abs=1e-7)
    m = reg.max_penetration_capacity_rule(model, 50.0, capacity_kN=200)
    assert m["max_penetration_mm"] == pytest.approx(10.0, abs=1e-8)
    # threshold never reached / exceeded everywhere in the bounds
    low = reg.optimal_spacing_capacity_rule(model, 1.0, capacity_kN=1000, spacing_bounds_mm=(1, 50))
    assert low["status"] == "below_threshold_in_bounds" and low["optimal_spacing_mm"] == 50
    high = reg.optimal_spacing_capacity_rule(model, 20.0, capacity_kN=100, spacing_bounds_mm=(1, 50))
    assert high["status"] == "above_threshold_in_bounds" and math.isnan(high["optimal_spacing_mm"])


def test_capacity_rule_on_seed001_eq8(seed001_fits):
    """80 % of 215 kN = 172 kN; printed eq. 8 at P = 7.6 mm: S* = (172 - 7.39 - 13.51*7.6)/0.84."""
    eq8 = lambda s, p: 7.39 + 0.84 * s + 13.51 * p  # noqa: E731
    r = reg.optimal_spacing_capacity_rule(eq8, 7.6)
    assert r["threshold_kN"] == pytest.approx(172.0)
    assert r["optimal_spacing_mm"] == pytest.approx((172 - 7.39 - 13.51 * 7.6) / 0.84, abs=1e-8)
    ours = reg.optimal_spacing_capacity_rule(seed001_fits["normal_force_kN"], 7.6)
    assert ours["optimal_spacing_mm"] == pytest.approx((172 - 7.390680 - 13.505539 * 7.6) / 0.842274, abs=1e-4)  # 73.57 mm
    # paper: "cannot exceed 5.1 mm" at S = 100 mm -- eq. 8 gives ~6 mm at 172 kN
    m = reg.max_penetration_capacity_rule(seed001_fits["normal_force_kN"], 100.0)
    assert m["max_penetration_mm"] == pytest.approx(5.95, abs=0.01)


def test_specific_energy_units_and_hand_minimum():
    # 12 kN over S*P = 76*6.4 mm² -> 1000*12/486.4 MJ/m³
    assert reg.specific_energy_MJ_per_m3(12.0, 76.0, 6.4) == pytest.approx(24.671, abs=1e-3)
    # F_r = 2 + 0.001 S² at P = 1 mm -> SE = 1000 (2/S + 0.001 S), minimum at S = sqrt(2000)
    model = lambda s, p: 2.0 + 0.001 * s**2  # noqa: E731
    r = reg.optimal_spacing_min_specific_energy(model, 1.0, (10.0, 150.0))
    assert r["optimal_spacing_mm"] == pytest.approx(math.sqrt(2000), abs=1e-4)
    assert r["specific_energy_MJ_per_m3"] == pytest.approx(1000 * 2 * math.sqrt(0.002), rel=1e-7)
    assert r["at_bound"] is False and r["nonpositive_force_in_bounds"] is False


def test_specific_energy_linear_model_has_no_interior_minimum(seed001_fits):
    fr = seed001_fits["rolling_force_kN"]
    r = reg.optimal_spacing_min_specific_energy(fr, 6.4, (25.0, 100.0))
    assert r["at_bound"] is True and r["optimal_spacing_mm"] == pytest.approx(100.0)
    r_shallow = reg.optimal_spacing_min_specific_energy(fr, 1.9, (25.0, 100.0))
    assert r_shallow["nonpositive_force_in_bounds"] is True  # eq. 9 extrapolates to F_r <= 0 near S = 25, P = 1.9


def test_min_specific_energy_from_tabulated_forces_is_76mm():
    best = reg.min_specific_energy_spacing_from_table(reg.load_seed001_lsdyna_points(DATA_DIR))
    assert sorted(best["penetration_mm"]) == [1.9, 3.8, 6.4, 7.6]
    assert (best["optimal_spacing_mm"] == 76).all()
    assert best.set_index("penetration_mm").loc[6.4, "specific_energy_MJ_per_m3"] == pytest.approx(1000 * 18.0 / (76 * 6.4))


# ---------------------------------------------------------------------------
# Seed 002: functional form on Table 4 (RCM)
# ---------------------------------------------------------------------------


def test_contact_area_eq1():
    assert reg.contact_area_mm2(21.0, reg.CUTTER_17IN_DIAMETER_mm, 4.0) == pytest.approx(21 * math.sqrt(431.8 * 4))


def test_published_power_form_equals_table3_intercepts():
    """Eqs. 2-4 constants are exp(b0) of Table 3 to the printed digits."""
    t3 = reg.SEED002_TABLE3
    assert math.exp(t3["normal_force"]["params"]["b0_intercept"][0]) == pytest.approx(0.009349, abs=5e-7)
    assert math.exp(t3["rolling_coefficient"]["params"]["b0_intercept"][0]) == pytest.approx(46.6, abs=0.05)
    assert math.exp(t3["side_coefficient"]["params"]["b0_intercept"][0]) == pytest.approx(194.4, abs=0.05)


def test_table4_rolling_and_side_predictions_reproduced():
    """Printed Fr/Fs of seed 002 Table 4 = kr/ks(UCS, r) x measured Fn, reproduced to 0.01 kN.

    This pins the implemented kr/ks forms: r^-1/2 and r^-4/5 reproduce the
    printed radial trend, but only with UCS = 121 MPa (not the stated 205 MPa)
    and the measured (not predicted) normal force.
    """
    rep = reg.seed002_table4_reproduction(DATA_DIR)
    assert rep["ucs_effective_MPa"] == 121.0
    d = rep["reproduced"]
    assert d["rolling_force_abs_diff_kN"].max() < 0.01
    assert d["side_force_abs_diff_kN"].max() < 0.01


def test_table4_stated_conditions_differ_as_measured():
    rep = reg.seed002_table4_reproduction(DATA_DIR)
    st = rep["stated"]
    assert st["normal_force_rel_diff_pct"].to_numpy() == pytest.approx([-3.57, -4.43, -1.27, -1.77, 1.75, 1.75], abs=0.01)
    # stated UCS 205 MPa and our Fn-hat: Fr, Fs 20-29 % below the printed predictions
    assert st["rolling_force_rel_diff_pct"].between(-29.1, -20.1).all()
    assert st["side_force_rel_diff_pct"].between(-29.2, -20.2).all()
    # eq. 2 scales Fn with A^(1/2) ~ p^(1/4) at every radius; the printed values only at r = 600 mm
    ratio = rep["fn_p_ratio"].set_index("radial_position_mm")
    assert ratio["eq2_Fn_p5_over_p4"].to_numpy() == pytest.approx(1.25**0.25, abs=1e-12)
    assert ratio.loc[600.0, "printed_Fn_p5_over_p4"] == pytest.approx(1.25**0.25, abs=1e-4)
    assert ratio.loc[200.0, "printed_Fn_p5_over_p4"] == pytest.approx(1.0669, abs=1e-4)
    assert ratio.loc[300.0, "printed_Fn_p5_over_p4"] == pytest.approx(1.0627, abs=1e-4)


def test_table4_eq2_value_by_hand():
    """One value of eq. 2 by hand: UCS 205, T 21 mm, 17-inch, p 4 mm, S 100 mm, r 600 mm."""
    pred = reg.predict_rcm_table4(reg.load_seed002_table4(DATA_DIR))
    a = 21 * math.sqrt(431.8 * 4)
    hand = 0.009349 * 205 * math.sqrt(a) * 100 ** (1 / 3) * (1 - math.exp(-0.00872 * 600))
    row = pred[(pred.penetration_mm == 4) & (pred.radial_position_mm == 600)].iloc[0]
    assert row["normal_force_ours_kN"] == pytest.approx(hand, rel=1e-12)
    assert row["rolling_coefficient_ours"] == pytest.approx(46.6 / math.sqrt(205 * 600), rel=1e-12)
    assert row["side_coefficient_ours"] == pytest.approx(194.4 / (math.sqrt(205) * 600**0.8), rel=1e-12)


def test_table5_not_consistent_with_table4():
    t5 = reg.seed002_table5_check(DATA_DIR).set_index("force")
    assert t5.loc["normal_force_kN", "rmse_from_table4_kN"] == pytest.approx(7.363, abs=1e-3)  # printed 6.24
    assert t5.loc["normal_force_kN", "mape_from_table4_pct"] == pytest.approx(2.231, abs=1e-3)  # printed 2.17
    assert t5.loc["rolling_force_kN", "mape_from_table4_pct"] == pytest.approx(8.263, abs=1e-3)  # printed 10.79
    assert t5.loc["side_force_kN", "mape_from_table4_pct"] == pytest.approx(10.570, abs=1e-3)  # printed 7.03


# ---------------------------------------------------------------------------
# Seed 002: fits to Table 2 vs published Table 3
# ---------------------------------------------------------------------------

# measured with this implementation (k fixed at 0.00872): estimate, SE
OURS_K_FIXED = {
    ("normal_force", "b0_intercept"): (-2.10508, 0.428055),
    ("normal_force", "b1_ln_ucs"): (0.971775, 0.041088),
    ("normal_force", "b2_ln_contact_area"): (0.191194, 0.059261),
    ("normal_force", "b3_ln_spacing"): (0.219708, 0.032021),
    ("normal_force", "b4_ln_radial_term"): (1.728036, 0.313389),
    ("rolling_coefficient", "b0_intercept"): (2.721907, 0.326956),
    ("rolling_coefficient", "b1_ln_ucs"): (-0.545127, 0.052207),
    ("rolling_coefficient", "b2_ln_radial_position"): (-0.283984, 0.027615),
    ("side_coefficient", "b0_intercept"): (6.821390, 0.565481),
    ("side_coefficient", "b1_ln_ucs"): (-0.618561, 0.090294),
    ("side_coefficient", "b2_ln_radial_position"): (-0.964574, 0.047762),
}


def test_seed002_k_fixed_fit_vs_published(comparison):
    fixed = comparison[comparison.variant == "k_fixed"].set_index(["model", "parameter"])
    assert len(fixed) == 11
    for key, (est, se) in OURS_K_FIXED.items():
        row = fixed.loc[key]
        assert row["ours_estimate"] == pytest.approx(est, abs=2e-5), key
        assert row["ours_std_error"] == pytest.approx(se, rel=1e-4), key
        pub = reg.SEED002_TABLE3[key[0]]["params"][key[1]][0]
        assert row["diff_estimate"] == pytest.approx(est - pub, abs=2e-5), key
    # size of the disagreement, in our SEs: 0.7 (Fn UCS exponent) to 7.8 (kr radial exponent)
    d = fixed["diff_in_our_se"].abs()
    assert d.min() == pytest.approx(0.680, abs=0.01) and d.max() == pytest.approx(7.80, abs=0.01)
    # only the three UCS exponents are inside our 95 % CIs
    inside = fixed.index[fixed["published_inside_our_ci95"]].tolist()
    assert inside == [("normal_force", "b1_ln_ucs"), ("rolling_coefficient", "b1_ln_ucs"), ("side_coefficient", "b1_ln_ucs")]


def test_seed002_published_se_inconsistent_with_published_r2(comparison):
    """SEs implied by the published R² on this design are 2.9x-42x the printed SEs."""
    fixed = comparison[comparison.variant == "k_fixed"]
    ratio = fixed["implied_se_from_published_r2"] / fixed["published_std_error"]
    assert ratio.min() == pytest.approx(2.913, abs=0.01)
    assert ratio.max() == pytest.approx(41.70, abs=0.05)
    assert (fixed["se_ratio_ours_to_published"] > 3.0).all()


def test_seed002_r_squared(table2):
    r2 = {m: reg.fit_seed002_model(table2, m).r_squared_log for m in reg.SEED002_PARAM_NAMES}
    assert r2["normal_force"] == pytest.approx(0.92126, abs=1e-4)  # published 0.8942
    assert r2["rolling_coefficient"] == pytest.approx(0.77089, abs=1e-4)  # published 0.8026
    assert r2["side_coefficient"] == pytest.approx(0.88451, abs=1e-4)  # published 0.9090


def test_seed002_free_k_fit(free_fit):
    """k estimated jointly: 0.00334 1/mm; profile 95 % interval [0.00103, 0.00921] contains the published 0.00872."""
    assert free_fit.k_free
    assert free_fit.k_radial_per_mm == pytest.approx(0.003345, abs=2e-6)
    assert free_fit.ssr_log == pytest.approx(0.644593, abs=1e-5)
    assert free_fit.r_squared_log == pytest.approx(0.92651, abs=1e-4)
    lo, hi = free_fit.k_profile_ci95_per_mm
    assert lo == pytest.approx(0.001030, abs=2e-6) and hi == pytest.approx(0.009206, abs=2e-6)
    assert lo < reg.SEED002_RADIAL_K_per_mm < hi
    p = free_fit.params
    assert list(p.index) == list(reg.SEED002_PARAM_NAMES["normal_force"]) + ["k_radial_per_mm"]
    assert p.loc["b4_ln_radial_term", "estimate"] == pytest.approx(0.42325, abs=1e-3)
    assert p.loc["k_radial_per_mm", "std_error"] == pytest.approx(0.002141, abs=2e-5)
    assert np.isfinite(p[["std_error", "ci95_low", "ci95_high"]].to_numpy()).all()


def test_seed002_free_k_is_the_least_squares_optimum(table2, free_fit):
    """No k on a fine grid (with OLS inside) beats the joint fit."""
    for k in np.linspace(0.0005, 0.03, 60):
        assert reg.fit_seed002_model(table2, "normal_force", k_per_mm=float(k)).ssr_log >= free_fit.ssr_log - 1e-10


def test_seed002_mape_published_vs_ours(metrics):
    m = metrics.set_index(["equations", "force", "prediction"])
    # published Table 3 equation on Table 2: MAPE 11.32 % (paper states 12.16 %)
    assert m.loc[("published_table3", "normal_force_kN", "Fn_hat"), "mape_pct"] == pytest.approx(11.320, abs=0.005)
    assert m.loc[("published_table3", "normal_force_kN", "Fn_hat"), "rmse_kN"] == pytest.approx(14.310, abs=0.005)
    assert m.loc[("published_table3", "normal_force_kN", "Fn_hat"), "r_squared_log"] == pytest.approx(0.8499, abs=1e-4)
    assert m.loc[("ours_k_fixed", "normal_force_kN", "Fn_hat"), "mape_pct"] == pytest.approx(8.730, abs=0.005)
    assert m.loc[("ours_k_free", "normal_force_kN", "Fn_hat"), "mape_pct"] == pytest.approx(7.946, abs=0.005)
    assert m.loc[("published_table3", "rolling_force_kN", "chained"), "mape_pct"] == pytest.approx(17.283, abs=0.005)
    assert m.loc[("ours_k_fixed", "rolling_force_kN", "chained"), "mape_pct"] == pytest.approx(12.200, abs=0.005)
    assert m.loc[("published_table3", "side_force_kN", "chained"), "mape_pct"] == pytest.approx(23.726, abs=0.005)
    assert m.loc[("ours_k_fixed", "side_force_kN", "chained"), "mape_pct"] == pytest.approx(20.856, abs=0.005)
    # published kr equation explains far less of ln kr on Table 2 than the printed R² = 0.8026
    assert m.loc[("published_table3", "rolling_force_kN", "chained"), "r_squared_log"] == pytest.approx(0.4601, abs=1e-4)
    # ours is never worse than the published set on its own fit data (Fn)
    assert m.loc[("ours_k_fixed", "normal_force_kN", "Fn_hat"), "mape_pct"] < m.loc[("published_table3", "normal_force_kN", "Fn_hat"), "mape_pct"]


def test_published_table3_ci_self_consistency():
    t = reg.published_table3_frame()
    centre_shift = 0.5 * (t["published_ci95_low"] + t["published_ci95_high"]) - t["published_estimate"]
    b4 = (t.model == "normal_force") & (t.parameter == "b4_ln_radial_term")
    # b4's printed CI [0.892, 1.162] is centred 0.019 above its estimate 1.0082; all others within rounding
    assert centre_shift[b4].iloc[0] == pytest.approx(0.0188, abs=1e-4)
    assert centre_shift[~b4].abs().max() < 0.0012
    width_ratio = (t["published_ci95_high"] - t["published_ci95_low"]) / (t["published_ci_from_se_high"] - t["published_ci_from_se_low"])
    assert width_ratio.between(0.96, 1.04).all()


def test_predict_seed002_reproduces_fitted_values(table2):
    fit = reg.fit_seed002_model(table2, "side_coefficient")
    pred = fit.predict(table2)
    resid = np.log(table2["side_coefficient"]) - np.log(pred)
    assert np.sum(resid**2) == pytest.approx(fit.ssr_log, rel=1e-10)


# ---------------------------------------------------------------------------
# Reports
# ---------------------------------------------------------------------------


def test_seed002_comparison_markdown(table2):
    md = reg.seed002_comparison_markdown(table2)
    assert "| variant | model | parameter | published_estimate |" in md
    assert "| k_fixed | normal_force | b4_ln_radial_term | 1.0082 | 0.0674 | [0.892, 1.162] | 1.7280 |" in md
    assert "k_radial_per_mm" in md and "Profile-likelihood" in md
    # every table row has the header's column count
    for block in md.split("\n\n"):
        rows = [ln for ln in block.splitlines() if ln.startswith("|")]
        if rows:
            assert len({ln.count("|") for ln in rows}) == 1


def test_markdown_table_units_in_headers():
    df = pd.DataFrame({"normal_force_kN": [1.23456], "ok": [True]})
    assert reg.markdown_table(df, ".2f") == "| normal_force_kN | ok |\n|---|---|\n| 1.23 | yes |"


def test_docs_regression_check_is_current():
    doc = REPO_ROOT / "docs" / "regression_check.md"
    if not doc.is_file():
        pytest.skip("docs/regression_check.md not generated")
    assert doc.read_text() == reg.regression_check_markdown(DATA_DIR), (
        "docs/regression_check.md is stale; regenerate with "
        "`.venv/bin/python -m deckgen.analysis.regression --write-doc docs/regression_check.md`"
    )
