"""Regression models for disc-cutter forces and spacing design criteria.

The module reproduces, and checks against the published numbers, the two
regression families of the seed papers (see ``/work/shared/seeds/README.md``):

* **Seed 001** (Fattahi et al., linear cutting of Colorado red granite, 17-inch
  CCS disc): the linear model of its eq. 7,

  ``Y = b0 + b1*S + b2*P``  (S spacing in mm, P penetration in mm, Y in kN),

  fitted by OLS to the 16 LS-DYNA points of its Tables 3 and 4; the paper prints
  the result as eq. 8 (normal force) and eq. 9 (rolling force).
  :func:`fit_linear_spacing_penetration` fits it with statsmodels and returns
  coefficients, standard errors, p-values, 95 % CIs, R², adjusted R² and the VIF
  of each predictor.

* **Seed 002** (Farrokh et al., rotary cutting, 58 LS-DYNA runs in its Table 2):
  the ln-linear models of its Table 3 / eqs. 2-4::

      ln Fn = b0 + b1 ln UCS + b2 ln A_con + b3 ln S + b4 ln(1 - exp(-k r))   (eq. 2)
      ln kr = b0 + b1 ln UCS + b2 ln r,   kr = Fr / Fn                        (eq. 3)
      ln ks = b0 + b1 ln UCS + b2 ln r,   ks = Fs / Fn                        (eq. 4)

  with UCS in MPa, A_con in mm², S in mm, r (radial position) in mm and k in
  1/mm (published k = 0.00872, taken by the paper from a simple regression and
  held fixed).  :func:`fit_seed002_model` fits these either with k fixed (plain
  statsmodels OLS, the paper's procedure) or with k free (scipy
  ``least_squares`` on the log scale, Wald standard errors from the Jacobian).
  :func:`compare_seed002_with_published` sets our estimates beside the
  published Table 3 (transcribed in :data:`SEED002_TABLE3`), and
  :func:`predict_rcm_table4` evaluates the equations on the rotary-cutting-
  machine data of the paper's Table 4.

Design criteria (section 3 of the brief):

* :func:`optimal_spacing_capacity_rule` -- seed 001 sec. 6.1: the normal force
  on a cutter must not exceed 80 % of the maximum normal force the disc can
  withstand (215 kN for a 17-inch disc after Roby et al. 2008); the optimal
  spacing is the largest spacing whose predicted normal force stays at or below
  that threshold for the chosen penetration.
* :func:`optimal_spacing_min_specific_energy` -- the classical alternative:
  specific energy ``SE = F_r * L / V`` (work of the rolling force per unit of
  excavated volume; seed 003 eq. 2.9 "power over production", seed 001 sec. 1
  "the amount of [energy] expended to [cut] a unit volume of rock").  For linear
  cutting at spacing S and penetration P the volume per unit cut length is
  ``S*P``, so ``SE = F_r / (S*P)``; with F_r in kN and S, P in mm this is
  ``1000 * F_r / (S*P)`` MJ/m³ (1 kN/mm² = 1 GPa = 1000 MJ/m³).

All tables returned here carry units in their column names (``_kN``, ``_mm``,
``_MPa``, ``_mm2``, ``_pct``, ``_MJ_per_m3``); dimensionless quantities
(coefficients, R², VIF, force ratios) carry none.

The reference CSVs live in ``../shared/data`` relative to the repository root;
see :func:`default_data_dir`.  Regenerate ``docs/regression_check.md`` with::

    .venv/bin/python -m deckgen.analysis.regression --write-doc docs/regression_check.md
"""

from __future__ import annotations

import argparse
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np
import pandas as pd
import statsmodels.api as sm
from scipy import optimize, stats
from statsmodels.stats.outliers_influence import variance_inflation_factor

__all__ = [
    "CUTTER_17IN_DIAMETER_mm",
    "SEED001_CAPACITY_FRACTION",
    "SEED001_CUTTER_CAPACITY_17IN_kN",
    "SEED001_PUBLISHED_LINEAR",
    "SEED002_EQS_2_TO_4",
    "SEED002_PARAM_NAMES",
    "SEED002_PUBLISHED_ACCURACY_TABLE2",
    "SEED002_PUBLISHED_TABLE5",
    "SEED002_RADIAL_K_per_mm",
    "SEED002_RCM_CONDITIONS",
    "SEED002_TABLE3",
    "LinearFit",
    "LogLinearFit",
    "capacity_threshold_kN",
    "compare_seed002_with_published",
    "contact_area_mm2",
    "default_data_dir",
    "fit_linear_spacing_penetration",
    "fit_seed001_equations",
    "fit_seed002_model",
    "force_error_metrics",
    "load_seed001_lsdyna_points",
    "load_seed002_table2",
    "load_seed002_table4",
    "markdown_table",
    "max_penetration_capacity_rule",
    "min_specific_energy_spacing_from_table",
    "optimal_spacing_capacity_rule",
    "optimal_spacing_min_specific_energy",
    "predict_rcm_table4",
    "predict_seed002",
    "published_table3_frame",
    "radial_term",
    "read_seed_csv",
    "regression_check_markdown",
    "seed001_printed_match",
    "seed001_single_value_edits",
    "seed001_table3_error_check",
    "seed001_text_penetration_fit",
    "seed002_comparison_markdown",
    "seed002_fit_metrics",
    "seed002_table4_reproduction",
    "seed002_table5_check",
    "specific_energy_MJ_per_m3",
]

# ---------------------------------------------------------------------------
# Published constants (transcribed from the seeds; cite section/table)
# ---------------------------------------------------------------------------

#: 17-inch disc diameter (exact inch conversion).
CUTTER_17IN_DIAMETER_mm: float = 17 * 25.4

#: Seed 001 sec. 6.1: "the maximum vertical force a 17-inch disk can withstand
#: is 215 kN (Roby et al. 2008)".
SEED001_CUTTER_CAPACITY_17IN_kN: float = 215.0

#: Seed 001 sec. 6.1: "the maximum vertical force applied to these disks should
#: not exceed 80% of this value" (Farrokh et al. 2012).  NB the paper then says
#: "equating to 180 kN", but 0.8 * 215 kN = 172 kN (see regression_check.md).
SEED001_CAPACITY_FRACTION: float = 0.8

#: Seed 001 eqs. 8-9 (sec. 6.2), printed to two decimals:
#:   Fn = 7.39 + 0.84 S + 13.51 P   R^2 = 0.95
#:   Fr = -9.46 + 0.16 S + 2.79 P   R^2 = 0.92   (p = 0.00, VIF = 1.00 for both)
SEED001_PUBLISHED_LINEAR: dict[str, dict[str, float]] = {
    "normal_force_kN": {"const": 7.39, "spacing_mm": 0.84, "penetration_mm": 13.51, "r_squared": 0.95, "vif": 1.00},
    "rolling_force_kN": {"const": -9.46, "spacing_mm": 0.16, "penetration_mm": 2.79, "r_squared": 0.92, "vif": 1.00},
}

#: Seed 002 eq. 2 / Table 3 row 1: k of the radial term (1 - exp(-k r)), 1/mm.
SEED002_RADIAL_K_per_mm: float = 0.00872

#: Parameter names of the three seed-002 models (k_radial_per_mm only for the
#: normal-force model).
SEED002_PARAM_NAMES: dict[str, tuple[str, ...]] = {
    "normal_force": ("b0_intercept", "b1_ln_ucs", "b2_ln_contact_area", "b3_ln_spacing", "b4_ln_radial_term"),
    "rolling_coefficient": ("b0_intercept", "b1_ln_ucs", "b2_ln_radial_position"),
    "side_coefficient": ("b0_intercept", "b1_ln_ucs", "b2_ln_radial_position"),
}

#: Seed 002 Table 3 ("Final regression equations ... derived using natural
#: log-transformed variables"), Farrokh, Rokhy & Lotfi: estimate, SE and 95 % CI
#: of every parameter, and R^2, exactly as printed.  Tuples are
#: (estimate, std_error, ci95_low, ci95_high).
SEED002_TABLE3: dict[str, dict] = {
    "normal_force": {
        "r_squared": 0.8942,
        "k_radial_per_mm": SEED002_RADIAL_K_per_mm,
        "params": {
            "b0_intercept": (-4.6725, 0.0119, -4.697, -4.649),
            "b1_ln_ucs": (0.9997, 0.0038, 0.992, 1.007),
            "b2_ln_contact_area": (0.4996, 0.0030, 0.494, 0.506),
            "b3_ln_spacing": (0.3316, 0.0048, 0.322, 0.341),
            "b4_ln_radial_term": (1.0082, 0.0674, 0.892, 1.162),
        },
    },
    "rolling_coefficient": {
        "r_squared": 0.8026,
        "params": {
            "b0_intercept": (3.8410, 0.0248, 3.791, 3.890),
            "b1_ln_ucs": (-0.5008, 0.0072, -0.515, -0.486),
            "b2_ln_radial_position": (-0.4994, 0.0088, -0.517, -0.482),
        },
    },
    "side_coefficient": {
        "r_squared": 0.9090,
        "params": {
            "b0_intercept": (5.2701, 0.0365, 5.196, 5.342),
            "b1_ln_ucs": (-0.5002, 0.0077, -0.516, -0.485),
            "b2_ln_radial_position": (-0.8004, 0.0054, -0.811, -0.789),
        },
    },
}

#: Seed 002 eqs. 2-4, the "power format" of Table 3 with rounded constants and
#: exponents, written as ln-coefficients so the same code evaluates both:
#:   Fn = 0.009349 UCS A_con^(1/2) S^(1/3) (1 - exp(-0.00872 r))   (eq. 2)
#:   kr = 46.6 / (UCS^(1/2) r^(1/2))                               (eq. 3)
#:   ks = 194.4 / (UCS^(1/2) r^(4/5))                              (eq. 4)
SEED002_EQS_2_TO_4: dict[str, dict] = {
    "normal_force": {
        "k_radial_per_mm": SEED002_RADIAL_K_per_mm,
        "params": {
            "b0_intercept": math.log(0.009349),
            "b1_ln_ucs": 1.0,
            "b2_ln_contact_area": 0.5,
            "b3_ln_spacing": 1.0 / 3.0,
            "b4_ln_radial_term": 1.0,
        },
    },
    "rolling_coefficient": {"params": {"b0_intercept": math.log(46.6), "b1_ln_ucs": -0.5, "b2_ln_radial_position": -0.5}},
    "side_coefficient": {"params": {"b0_intercept": math.log(194.4), "b1_ln_ucs": -0.5, "b2_ln_radial_position": -0.8}},
}

#: Seed 002 sec. 3.3: accuracy of the Table 3 equations on the 58 LS-DYNA runs
#: as stated in the text (RMSE kN, MAE kN, MAPE %).
SEED002_PUBLISHED_ACCURACY_TABLE2: dict[str, tuple[float, float, float]] = {
    "normal_force_kN": (17.70, 13.56, 12.16),
    "rolling_force_kN": (2.39, 1.82, 10.73),
    "side_force_kN": (1.68, 1.15, 18.34),
}

#: Seed 002 Table 5: RMSE (kN), MAE (kN), MAPE (%) of its predictions on the RCM tests.
SEED002_PUBLISHED_TABLE5: dict[str, tuple[float, float, float]] = {
    "normal_force_kN": (6.24, 5.33, 2.17),
    "rolling_force_kN": (7.84, 6.56, 10.79),
    "side_force_kN": (3.00, 2.57, 7.03),
}

#: Seed 002 sec. 3.4: RCM tests of Shin et al. (2024) on Hwandeung granite.
SEED002_RCM_CONDITIONS: dict[str, float] = {
    "ucs_MPa": 205.0,
    "cutter_diameter_mm": CUTTER_17IN_DIAMETER_mm,
    "tip_width_mm": 21.0,
    "spacing_mm": 100.0,
}

_FORCE_COLUMNS = ("normal_force_kN", "rolling_force_kN", "side_force_kN")

# ---------------------------------------------------------------------------
# Data access
# ---------------------------------------------------------------------------


def default_data_dir() -> Path:
    """Folder of the transcribed seed tables.

    ``$DECKGEN_SHARED_DATA`` if set, else ``<repo root>/../shared/data`` (the
    repository root is three levels above this file: ``src/deckgen/analysis``).
    """
    env = os.environ.get("DECKGEN_SHARED_DATA")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[3].parent / "shared" / "data"


def read_seed_csv(name: str, data_dir: str | Path | None = None) -> pd.DataFrame:
    """Read one of the transcribed seed tables (``#`` lines are comments)."""
    path = Path(data_dir) if data_dir is not None else default_data_dir()
    return pd.read_csv(path / name, comment="#")


def load_seed001_lsdyna_points(data_dir: str | Path | None = None) -> pd.DataFrame:
    """The 16 LS-DYNA points seed 001 regresses in eqs. 8-9.

    Nine rows of its Table 3 (``gertsch2007_crg_linear_cutting.csv``, columns
    ``*_lsdyna_kN``, not the measured ones) plus the seven rows of its Table 4
    (``fattahi_lsdyna_extended.csv``).  Columns: ``spacing_mm``,
    ``penetration_mm``, ``normal_force_kN``, ``rolling_force_kN``,
    ``source_table``.
    """
    t3 = read_seed_csv("gertsch2007_crg_linear_cutting.csv", data_dir)
    t4 = read_seed_csv("fattahi_lsdyna_extended.csv", data_dir)
    parts = []
    for df, label in ((t3, "seed001_table3"), (t4, "seed001_table4")):
        parts.append(
            pd.DataFrame(
                {
                    "spacing_mm": df["spacing_mm"].astype(float),
                    "penetration_mm": df["penetration_mm"].astype(float),
                    "normal_force_kN": df["normal_force_lsdyna_kN"].astype(float),
                    "rolling_force_kN": df["rolling_force_lsdyna_kN"].astype(float),
                    "source_table": label,
                }
            )
        )
    return pd.concat(parts, ignore_index=True)


def load_seed002_table2(data_dir: str | Path | None = None) -> pd.DataFrame:
    """Seed 002 Table 2 (58 LS-DYNA rotary-cutting runs), with the force ratios
    ``rolling_coefficient`` = Fr/Fn and ``side_coefficient`` = Fs/Fn added."""
    df = read_seed_csv("farrokh_rotary_lsdyna_58.csv", data_dir)
    df = df.copy()
    df["rolling_coefficient"] = df["rolling_force_kN"] / df["normal_force_kN"]
    df["side_coefficient"] = df["side_force_kN"] / df["normal_force_kN"]
    return df


def load_seed002_table4(data_dir: str | Path | None = None) -> pd.DataFrame:
    """Seed 002 Table 4: RCM measurements (Shin et al. 2024) and the paper's
    predicted forces (``*_predicted_kN``)."""
    return read_seed_csv("shin2024_rcm_hwandeung_granite.csv", data_dir)


# ---------------------------------------------------------------------------
# Generic helpers
# ---------------------------------------------------------------------------


def force_error_metrics(measured: Sequence[float], predicted: Sequence[float]) -> dict[str, float]:
    """RMSE and MAE (units of the input, here kN) and MAPE (%) of predicted vs measured.

    MAPE = 100 * mean(|measured - predicted| / |measured|), as in seed 002 sec. 3.3.
    """
    y = np.asarray(measured, dtype=float)
    p = np.asarray(predicted, dtype=float)
    err = y - p
    return {
        "rmse_kN": float(np.sqrt(np.mean(err**2))),
        "mae_kN": float(np.mean(np.abs(err))),
        "mape_pct": float(100.0 * np.mean(np.abs(err) / np.abs(y))),
    }


def _fmt(value, floatfmt: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return format(float(value), floatfmt)
    return str(value)


def markdown_table(df: pd.DataFrame, floatfmt: str | Mapping[str, str] = ".4g", index: bool = False) -> str:
    """Render a DataFrame as a GitHub-flavoured markdown table (no extra deps).

    ``floatfmt`` is a format spec for floats, or a mapping column -> spec
    (columns not in the mapping use ``.4g``).
    """
    frame = df.reset_index() if index else df
    cols = [str(c) for c in frame.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for _, row in frame.iterrows():
        cells = []
        for c in frame.columns:
            spec = floatfmt.get(str(c), ".4g") if isinstance(floatfmt, Mapping) else floatfmt
            cells.append(_fmt(row[c], spec))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


# ---------------------------------------------------------------------------
# Seed 001: linear model Y = b0 + b1 S + b2 P
# ---------------------------------------------------------------------------


@dataclass
class LinearFit:
    """OLS fit of ``Y = b0 + b1*S + b2*P`` (seed 001 eq. 7).

    Attributes
    ----------
    response:
        Name of the response column (e.g. ``normal_force_kN``).
    n_obs:
        Number of observations.
    coefficients:
        Indexed by term (``const``, ``spacing_mm``, ``penetration_mm``) with
        columns ``estimate``, ``std_error``, ``t_value``, ``p_value``,
        ``ci95_low``, ``ci95_high``, ``vif`` (VIF is NaN for the constant).
        Units: const in response units (kN); slopes in kN/mm.
    r_squared, r_squared_adj:
        Coefficient of determination and its adjusted form.
    result:
        The statsmodels ``RegressionResults`` (for anything else).
    """

    response: str
    n_obs: int
    coefficients: pd.DataFrame
    r_squared: float
    r_squared_adj: float
    result: object = field(repr=False)

    def predict(self, spacing_mm, penetration_mm):
        """Predicted response (kN) at spacing S (mm) and penetration P (mm); broadcasts."""
        b = self.coefficients["estimate"]
        return b["const"] + b["spacing_mm"] * np.asarray(spacing_mm, float) + b["penetration_mm"] * np.asarray(
            penetration_mm, float
        )

    __call__ = predict

    def rounded(self, digits: int = 2) -> dict[str, float]:
        """Coefficients and R² rounded as seed 001 prints them (eqs. 8-9)."""
        b = self.coefficients["estimate"]
        out = {k: round(float(b[k]), digits) for k in ("const", "spacing_mm", "penetration_mm")}
        out["r_squared"] = round(self.r_squared, digits)
        return out


def fit_linear_spacing_penetration(
    data: pd.DataFrame,
    response: str,
    spacing_col: str = "spacing_mm",
    penetration_col: str = "penetration_mm",
) -> LinearFit:
    """Fit seed 001 eq. 7, ``Y = b0 + b1*S + b2*P``, by OLS (statsmodels).

    Returns a :class:`LinearFit` with estimates, standard errors, t and p values,
    95 % confidence intervals, R², adjusted R² and the variance inflation factor
    of S and P (statsmodels ``variance_inflation_factor`` on the design matrix
    with the constant, i.e. the usual centred VIF = 1/(1 - R_j²)).
    """
    X = pd.DataFrame(
        {
            "const": 1.0,
            "spacing_mm": data[spacing_col].astype(float).to_numpy(),
            "penetration_mm": data[penetration_col].astype(float).to_numpy(),
        }
    )
    y = data[response].astype(float).to_numpy()
    res = sm.OLS(y, X).fit()
    ci = res.conf_int(0.05)
    vif = [math.nan] + [float(variance_inflation_factor(X.to_numpy(), i)) for i in (1, 2)]
    coef = pd.DataFrame(
        {
            "estimate": res.params,
            "std_error": res.bse,
            "t_value": res.tvalues,
            "p_value": res.pvalues,
            "ci95_low": ci[0],
            "ci95_high": ci[1],
            "vif": vif,
        }
    )
    coef.index.name = "term"
    return LinearFit(
        response=response,
        n_obs=int(res.nobs),
        coefficients=coef,
        r_squared=float(res.rsquared),
        r_squared_adj=float(res.rsquared_adj),
        result=res,
    )


def fit_seed001_equations(data_dir: str | Path | None = None) -> dict[str, LinearFit]:
    """Fit seed 001 eqs. 8 and 9 on its 16 LS-DYNA points.

    Returns ``{"normal_force_kN": LinearFit, "rolling_force_kN": LinearFit}``.
    """
    pts = load_seed001_lsdyna_points(data_dir)
    return {resp: fit_linear_spacing_penetration(pts, resp) for resp in ("normal_force_kN", "rolling_force_kN")}


def seed001_table3_error_check(data_dir: str | Path | None = None) -> pd.DataFrame:
    """Recompute seed 001 Table 3's "percentage error of force modelling".

    The transcribed CSV does not carry the printed error columns, so the printed
    values are given here (seed 001 Table 3, in row order).  Returns one row per
    case with the recomputed error ``100*(lsdyna - measured)/measured`` beside
    the printed one.
    """
    printed_vertical = [1.6, 9.9, 5.5, -6.1, -1.8, 6.6, 6.2, -2.6, 1.8]
    printed_rolling = [-6.4, -3.5, -3.2, 11.2, 12.9, -7.3, -11.0, 10.5, -5.9]
    t3 = read_seed_csv("gertsch2007_crg_linear_cutting.csv", data_dir)
    out = pd.DataFrame(
        {
            "spacing_mm": t3["spacing_mm"],
            "penetration_mm": t3["penetration_mm"],
            "normal_error_recomputed_pct": 100 * (t3["normal_force_lsdyna_kN"] / t3["normal_force_measured_kN"] - 1),
            "normal_error_printed_pct": printed_vertical,
            "rolling_error_recomputed_pct": 100 * (t3["rolling_force_lsdyna_kN"] / t3["rolling_force_measured_kN"] - 1),
            "rolling_error_printed_pct": printed_rolling,
        }
    )
    return out


def seed001_printed_match(fits: Mapping[str, LinearFit] | None = None, data_dir: str | Path | None = None) -> pd.DataFrame:
    """Every number printed in seed 001 eqs. 8-9 beside ours rounded to the printed 2 decimals.

    Rows: (response, quantity) for const, spacing_mm, penetration_mm, r_squared
    and the VIF (printed once per equation; compared with the larger of the two
    predictor VIFs).  Columns ``printed``, ``ours``, ``ours_rounded_2dp``,
    ``match_2dp``.
    """
    fits = fits if fits is not None else fit_seed001_equations(data_dir)
    rows = []
    for resp, fit in fits.items():
        pub = SEED001_PUBLISHED_LINEAR[resp]
        b = fit.coefficients["estimate"]
        ours = {"const": b["const"], "spacing_mm": b["spacing_mm"], "penetration_mm": b["penetration_mm"],
                "r_squared": fit.r_squared, "vif": float(fit.coefficients["vif"].max())}
        for q, v in ours.items():
            rows.append({"response": resp, "quantity": q, "printed": pub[q], "ours": float(v),
                         "ours_rounded_2dp": round(float(v), 2), "match_2dp": bool(round(float(v), 2) == pub[q])})
    return pd.DataFrame(rows)


def seed001_text_penetration_fit(data_dir: str | Path | None = None) -> dict[str, LinearFit]:
    """Eqs. 8-9 refitted with the penetrations seed 001's *text* lists for Table 3.

    Sec. 5 of seed 001 lists penetrations 2.5, 5.1, 6.4 mm while its Table 3
    prints 1.9, 3.8, 6.4 mm; this maps 1.9 -> 2.5 and 3.8 -> 5.1 in the nine
    Table 3 rows (Table 4 rows unchanged) to test which set the regression used.
    """
    pts = load_seed001_lsdyna_points(data_dir)
    is_t3 = pts["source_table"] == "seed001_table3"
    pts.loc[is_t3, "penetration_mm"] = pts.loc[is_t3, "penetration_mm"].replace({1.9: 2.5, 3.8: 5.1})
    return {resp: fit_linear_spacing_penetration(pts, resp) for resp in ("normal_force_kN", "rolling_force_kN")}


def seed001_single_value_edits(
    response: str = "rolling_force_kN",
    max_change_kN: float = 1.0,
    step_kN: float = 0.1,
    data_dir: str | Path | None = None,
) -> pd.DataFrame:
    """Single-value edits of the 16 points that make *all* printed numbers of one equation match.

    For each point, the response is changed by multiples of ``step_kN`` up to
    ``max_change_kN`` and the model refitted (numpy least squares); rows where
    const, both slopes and R² rounded to 2 decimals equal the printed eq. 8/9
    values are returned (``row``, ``spacing_mm``, ``penetration_mm``,
    ``tabulated_kN``, ``edited_kN``).  Shows how small a data difference would
    explain a non-reproducing printed digit.
    """
    pts = load_seed001_lsdyna_points(data_dir)
    pub = SEED001_PUBLISHED_LINEAR[response]
    target = np.array([pub["const"], pub["spacing_mm"], pub["penetration_mm"]])
    X = np.column_stack([np.ones(len(pts)), pts["spacing_mm"], pts["penetration_mm"]])
    y0 = pts[response].to_numpy(float)
    n_steps = int(round(max_change_kN / step_kN))
    rows = []
    for i in range(len(y0)):
        for j in range(-n_steps, n_steps + 1):
            if j == 0:
                continue
            y = y0.copy()
            y[i] = round(y0[i] + j * step_kN, 10)
            b = np.linalg.lstsq(X, y, rcond=None)[0]
            r2 = 1 - np.sum((y - X @ b) ** 2) / np.sum((y - y.mean()) ** 2)
            if np.allclose(np.round(b, 2), target) and round(r2, 2) == pub["r_squared"]:
                rows.append({"row": i, "spacing_mm": X[i, 1], "penetration_mm": X[i, 2], "tabulated_kN": y0[i], "edited_kN": y[i]})
    return pd.DataFrame(rows, columns=["row", "spacing_mm", "penetration_mm", "tabulated_kN", "edited_kN"])


# ---------------------------------------------------------------------------
# Seed 002: ln-linear models
# ---------------------------------------------------------------------------


def radial_term(radial_position_mm, k_per_mm: float = SEED002_RADIAL_K_per_mm):
    """Seed 002 radial-position term ``1 - exp(-k r)`` (dimensionless), r in mm, k in 1/mm."""
    return 1.0 - np.exp(-k_per_mm * np.asarray(radial_position_mm, dtype=float))


def contact_area_mm2(tip_width_mm, cutter_diameter_mm, penetration_mm):
    """Seed 002 eq. 1: ``A_con = T * sqrt(2 R p)`` in mm² (R = diameter/2, all lengths mm).

    NB seed 002 Table 2's ``A_con`` values were measured graphically on the real
    (non-constant-width) tip profiles and are *not* eq. 1 with a single T; eq. 1
    is what the paper offers for new cases such as its Table 4.
    """
    r = 0.5 * np.asarray(cutter_diameter_mm, float)
    return np.asarray(tip_width_mm, float) * np.sqrt(2.0 * r * np.asarray(penetration_mm, float))


def _seed002_design(model: str, data: pd.DataFrame, k_per_mm: float | None) -> np.ndarray:
    """Columns of ln-predictors (without the constant) for one seed-002 model."""
    ln_ucs = np.log(data["ucs_MPa"].astype(float).to_numpy())
    r = data["radial_position_mm"].astype(float).to_numpy()
    if model == "normal_force":
        if k_per_mm is None:
            raise ValueError("normal_force design needs k_per_mm")
        return np.column_stack(
            [
                ln_ucs,
                np.log(data["contact_area_mm2"].astype(float).to_numpy()),
                np.log(data["spacing_mm"].astype(float).to_numpy()),
                np.log(radial_term(r, k_per_mm)),
            ]
        )
    if model in ("rolling_coefficient", "side_coefficient"):
        return np.column_stack([ln_ucs, np.log(r)])
    raise ValueError(f"unknown seed-002 model {model!r}")


def _params_vector(model: str, params: Mapping[str, float]) -> np.ndarray:
    return np.array([float(params[n]) for n in SEED002_PARAM_NAMES[model]])


def predict_seed002(
    model: str,
    params: Mapping[str, float],
    data: pd.DataFrame,
    k_per_mm: float | None = None,
) -> np.ndarray:
    """Evaluate one seed-002 equation.

    Parameters
    ----------
    model:
        ``"normal_force"`` (returns Fn in kN), ``"rolling_coefficient"`` (kr =
        Fr/Fn, dimensionless) or ``"side_coefficient"`` (ks = Fs/Fn).
    params:
        Mapping of ln-coefficients by name (see ``SEED002_PARAM_NAMES``); values
        may also be the ``(estimate, se, lo, hi)`` tuples of
        :data:`SEED002_TABLE3`.  For ``normal_force`` the mapping may include
        ``k_radial_per_mm``.
    data:
        Columns ``ucs_MPa``, ``radial_position_mm`` and, for the normal force,
        ``contact_area_mm2`` and ``spacing_mm``.
    k_per_mm:
        k of the radial term; default ``params["k_radial_per_mm"]`` or 0.00872.
    """
    flat = {n: (v[0] if isinstance(v, tuple) else v) for n, v in params.items()}
    if model == "normal_force" and k_per_mm is None:
        k_per_mm = float(flat.get("k_radial_per_mm", SEED002_RADIAL_K_per_mm))
    X = _seed002_design(model, data, k_per_mm)
    b = _params_vector(model, flat)
    return np.exp(b[0] + X @ b[1:])


@dataclass
class LogLinearFit:
    """Fit of one seed-002 ln-linear model.

    Attributes
    ----------
    model:
        ``normal_force``, ``rolling_coefficient`` or ``side_coefficient``.
    k_free:
        True when k of the radial term was estimated (normal force only).
    k_radial_per_mm:
        k used (fixed) or estimated (1/mm); NaN for the coefficient models.
    params:
        Indexed by parameter name; columns ``estimate``, ``std_error``,
        ``t_value``, ``p_value``, ``ci95_low``, ``ci95_high``, ``vif``.  When k is
        free it appears as the row ``k_radial_per_mm`` (Wald SE from the
        Jacobian; its VIF is NaN).
    n_obs, dof_resid:
        Observations and residual degrees of freedom.
    ssr_log:
        Residual sum of squares on the ln scale.
    r_squared_log, r_squared_adj_log:
        ``1 - RSS/TSS`` on the ln scale (the R² seed 002 reports) and adjusted.
    mape_pct:
        MAPE (%) of the back-transformed response (Fn, kr or ks) on the fit data.
    k_profile_ci95_per_mm:
        For a free k: 95 % profile-likelihood interval of k, i.e. the k with
        ``RSS(k) <= RSS_min * (1 + F(0.95; 1, dof) / dof)`` (b0..b4 re-fitted by
        OLS at each k).  More trustworthy than the Wald CI in ``params`` because
        the model is strongly non-linear in k.  ``None`` otherwise.
    """

    model: str
    k_free: bool
    k_radial_per_mm: float
    params: pd.DataFrame
    n_obs: int
    dof_resid: int
    ssr_log: float
    r_squared_log: float
    r_squared_adj_log: float
    mape_pct: float
    k_profile_ci95_per_mm: tuple[float, float] | None = None

    def param_dict(self) -> dict[str, float]:
        """Estimates by name (including ``k_radial_per_mm`` for the normal force)."""
        d = {n: float(self.params.loc[n, "estimate"]) for n in SEED002_PARAM_NAMES[self.model]}
        if self.model == "normal_force":
            d["k_radial_per_mm"] = float(self.k_radial_per_mm)
        return d

    def predict(self, data: pd.DataFrame) -> np.ndarray:
        """Fn in kN, or kr / ks (dimensionless), for the rows of ``data``."""
        return predict_seed002(self.model, self.param_dict(), data)


def _vifs(X_no_const: np.ndarray) -> list[float]:
    X = np.column_stack([np.ones(len(X_no_const)), X_no_const])
    return [float(variance_inflation_factor(X, i)) for i in range(1, X.shape[1])]


def fit_seed002_model(
    table2: pd.DataFrame,
    model: str,
    k_per_mm: float | None = SEED002_RADIAL_K_per_mm,
    k_bounds_per_mm: tuple[float, float] = (1e-5, 0.2),
) -> LogLinearFit:
    """Fit one seed-002 ln-linear model to Table 2 (or any frame with its columns).

    Parameters
    ----------
    table2:
        Frame as returned by :func:`load_seed002_table2`.
    model:
        ``"normal_force"`` (ln Fn, eq. 2), ``"rolling_coefficient"`` (ln Fr/Fn,
        eq. 3) or ``"side_coefficient"`` (ln Fs/Fn, eq. 4).
    k_per_mm:
        For ``normal_force`` only.  A number fixes k (default 0.00872 1/mm, the
        paper's procedure) and the fit is plain statsmodels OLS.  ``None``
        estimates k together with b0..b4 by ``scipy.optimize.least_squares`` on
        the ln residuals (start: best k of a profile grid with OLS inside);
        standard errors then come from ``s² (JᵀJ)⁻¹`` with ``s² = RSS/(n-6)``
        and CIs from the t distribution with n-6 dof.
    k_bounds_per_mm:
        Search bounds for a free k.
    """
    if model not in SEED002_PARAM_NAMES:
        raise ValueError(f"unknown seed-002 model {model!r}")
    names = list(SEED002_PARAM_NAMES[model])
    y_col = "normal_force_kN" if model == "normal_force" else model
    y = np.log(table2[y_col].astype(float).to_numpy())
    n = len(y)
    tss = float(np.sum((y - y.mean()) ** 2))

    if model != "normal_force" or k_per_mm is not None:
        k_used = float(k_per_mm) if model == "normal_force" else math.nan
        Xn = _seed002_design(model, table2, k_used if model == "normal_force" else None)
        X = sm.add_constant(Xn, has_constant="add")
        res = sm.OLS(y, X).fit()
        ci = res.conf_int(0.05)
        params = pd.DataFrame(
            {
                "estimate": res.params,
                "std_error": res.bse,
                "t_value": res.tvalues,
                "p_value": res.pvalues,
                "ci95_low": ci[:, 0],
                "ci95_high": ci[:, 1],
                "vif": [math.nan] + _vifs(Xn),
            },
            index=pd.Index(names, name="parameter"),
        )
        fitted = np.asarray(res.fittedvalues)
        ssr = float(res.ssr)
        dof = int(res.df_resid)
        r2 = float(res.rsquared)
        r2_adj = float(res.rsquared_adj)
        k_free = False
        k_profile = None
    else:
        r = table2["radial_position_mm"].astype(float).to_numpy()
        base = _seed002_design(model, table2, 1.0)[:, :3]  # ln UCS, ln A, ln S

        def design(k):
            return np.column_stack([np.ones(n), base, np.log(radial_term(r, k))])

        # profile grid (OLS inside) for a robust start
        grid = np.geomspace(k_bounds_per_mm[0], k_bounds_per_mm[1], 400)
        prof = [np.linalg.lstsq(design(k), y, rcond=None)[1] for k in grid]
        prof = [float(p[0]) if len(p) else np.inf for p in prof]
        k0 = float(grid[int(np.argmin(prof))])
        b_init = np.linalg.lstsq(design(k0), y, rcond=None)[0]

        def resid(theta):
            return design(theta[-1]) @ theta[:-1] - y

        def jac(theta):
            k = theta[-1]
            D = design(k)
            e = np.exp(-k * r)
            dk = theta[4] * r * e / (1.0 - e)
            return np.column_stack([D, dk])

        sol = optimize.least_squares(
            resid,
            np.r_[b_init, k0],
            jac=jac,
            bounds=(np.r_[[-np.inf] * 5, k_bounds_per_mm[0]], np.r_[[np.inf] * 5, k_bounds_per_mm[1]]),
            x_scale="jac",
            xtol=1e-14,
            ftol=1e-14,
            gtol=1e-14,
        )
        theta = sol.x
        J = jac(theta)
        ssr = float(np.sum(sol.fun**2))
        dof = n - len(theta)
        s2 = ssr / dof
        cov = s2 * np.linalg.inv(J.T @ J)
        se = np.sqrt(np.diag(cov))
        tcrit = float(stats.t.ppf(0.975, dof))
        tval = theta / se
        names = names + ["k_radial_per_mm"]
        k_used = float(theta[-1])
        params = pd.DataFrame(
            {
                "estimate": theta,
                "std_error": se,
                "t_value": tval,
                "p_value": 2 * stats.t.sf(np.abs(tval), dof),
                "ci95_low": theta - tcrit * se,
                "ci95_high": theta + tcrit * se,
                "vif": [math.nan] + _vifs(design(k_used)[:, 1:]) + [math.nan],
            },
            index=pd.Index(names, name="parameter"),
        )
        fitted = y + sol.fun

        def ssr_at(k):
            return float(np.sum((design(k) @ np.linalg.lstsq(design(k), y, rcond=None)[0] - y) ** 2))

        limit = ssr * (1.0 + float(stats.f.ppf(0.95, 1, dof)) / dof)
        g = lambda k: ssr_at(k) - limit  # noqa: E731
        lo_k = _root_in_bounds(g, k_bounds_per_mm[0], k_used)
        hi_k = _root_in_bounds(g, k_used, k_bounds_per_mm[1])
        k_profile = (
            lo_k if lo_k is not None else float(k_bounds_per_mm[0]),
            hi_k if hi_k is not None else float(k_bounds_per_mm[1]),
        )
        r2 = 1.0 - ssr / tss
        r2_adj = 1.0 - (1.0 - r2) * (n - 1) / dof
        k_free = True

    yhat = np.exp(fitted)
    ytrue = np.exp(y)
    return LogLinearFit(
        model=model,
        k_free=k_free,
        k_radial_per_mm=k_used,
        params=params,
        n_obs=n,
        dof_resid=dof,
        ssr_log=ssr,
        r_squared_log=r2,
        r_squared_adj_log=r2_adj,
        mape_pct=force_error_metrics(ytrue, yhat)["mape_pct"],
        k_profile_ci95_per_mm=k_profile,
    )


def published_table3_frame() -> pd.DataFrame:
    """Seed 002 Table 3 as a long frame: model, parameter, published estimate/SE/CI, R².

    Also adds two self-consistency columns: ``published_ci_from_se_low/high``
    (estimate ± t(0.975, dof)·SE with dof = 58 - number of parameters), which
    should reproduce the printed CI if the printed numbers are consistent.
    """
    rows = []
    for model, spec in SEED002_TABLE3.items():
        p = len(spec["params"])
        tcrit = float(stats.t.ppf(0.975, 58 - p))
        for name, (est, se, lo, hi) in spec["params"].items():
            rows.append(
                {
                    "model": model,
                    "parameter": name,
                    "published_estimate": est,
                    "published_std_error": se,
                    "published_ci95_low": lo,
                    "published_ci95_high": hi,
                    "published_ci_from_se_low": est - tcrit * se,
                    "published_ci_from_se_high": est + tcrit * se,
                    "published_r_squared": spec["r_squared"],
                }
            )
    return pd.DataFrame(rows)


def _implied_se_from_published_r2(table2: pd.DataFrame, model: str) -> np.ndarray:
    """SEs that the published R² would imply on the Table 2 design matrix.

    With the design fixed, OLS standard errors are ``s * sqrt(diag((XᵀX)⁻¹))``
    and ``s² = (1 - R²) TSS / (n - p)``; TSS of the ln response is a property of
    the data.  Comparing these with the printed SEs tests whether the printed
    SEs and R² can belong to the same fit on this data.
    """
    y_col = "normal_force_kN" if model == "normal_force" else model
    y = np.log(table2[y_col].astype(float).to_numpy())
    k = SEED002_RADIAL_K_per_mm if model == "normal_force" else None
    X = sm.add_constant(_seed002_design(model, table2, k), has_constant="add")
    n, p = X.shape
    tss = float(np.sum((y - y.mean()) ** 2))
    s2 = (1.0 - SEED002_TABLE3[model]["r_squared"]) * tss / (n - p)
    return np.sqrt(s2 * np.diag(np.linalg.inv(X.T @ X)))


def compare_seed002_with_published(table2: pd.DataFrame | None = None, data_dir: str | Path | None = None) -> pd.DataFrame:
    """Our fits of seed 002 Table 3 beside the published numbers.

    One row per (variant, model, parameter).  Variants: ``k_fixed`` (k = 0.00872,
    OLS, the paper's procedure) for all three models and ``k_free`` for the
    normal-force model.  Columns: published estimate/SE/CI, ours
    estimate/SE/CI, ``diff_estimate`` (ours - published), ``diff_in_published_se``
    and ``diff_in_our_se`` (the difference in units of each SE),
    ``se_ratio_ours_to_published`` and ``implied_se_from_published_r2`` (see
    :func:`_implied_se_from_published_r2`; k-fixed rows only).
    """
    if table2 is None:
        table2 = load_seed002_table2(data_dir)
    rows = []
    fits = [(m, fit_seed002_model(table2, m)) for m in SEED002_PARAM_NAMES]
    fits.append(("normal_force", fit_seed002_model(table2, "normal_force", k_per_mm=None)))
    for model, fit in fits:
        pub = SEED002_TABLE3[model]["params"]
        implied = _implied_se_from_published_r2(table2, model) if not fit.k_free else None
        for i, name in enumerate(fit.params.index):
            o = fit.params.loc[name]
            if name in pub:
                pe, pse, plo, phi = pub[name]
            elif name == "k_radial_per_mm":
                pe, pse, plo, phi = SEED002_RADIAL_K_per_mm, math.nan, math.nan, math.nan
            else:  # pragma: no cover
                pe = pse = plo = phi = math.nan
            rows.append(
                {
                    "variant": "k_free" if fit.k_free else "k_fixed",
                    "model": model,
                    "parameter": name,
                    "published_estimate": pe,
                    "published_std_error": pse,
                    "published_ci95_low": plo,
                    "published_ci95_high": phi,
                    "ours_estimate": float(o["estimate"]),
                    "ours_std_error": float(o["std_error"]),
                    "ours_ci95_low": float(o["ci95_low"]),
                    "ours_ci95_high": float(o["ci95_high"]),
                    "ours_p_value": float(o["p_value"]),
                    "ours_vif": float(o["vif"]),
                    "diff_estimate": float(o["estimate"]) - pe,
                    "diff_in_published_se": (float(o["estimate"]) - pe) / pse if pse == pse else math.nan,
                    "diff_in_our_se": (float(o["estimate"]) - pe) / float(o["std_error"]),
                    "se_ratio_ours_to_published": float(o["std_error"]) / pse if pse == pse else math.nan,
                    "implied_se_from_published_r2": float(implied[i]) if implied is not None else math.nan,
                    "published_inside_our_ci95": bool(o["ci95_low"] <= pe <= o["ci95_high"]),
                }
            )
    return pd.DataFrame(rows)


def seed002_fit_metrics(table2: pd.DataFrame | None = None, data_dir: str | Path | None = None) -> pd.DataFrame:
    """Accuracy of the published and of our seed-002 equations on Table 2.

    Rows: equation set (``published_table3``, ``published_eqs2_4``,
    ``ours_k_fixed``, ``ours_k_free``) x force.  For the rolling and side forces
    two predictions are scored: ``chained`` (F = k̂ · F̂n, both from the
    equations, as a designer would use them) and ``given_Fn`` (F = k̂ · Fn with
    the LS-DYNA Fn, isolating the coefficient model).  Columns: ``r_squared_log``
    (of the ln model; for published sets, evaluated on Table 2),
    ``rmse_kN``, ``mae_kN``, ``mape_pct`` and, for reference, the values the
    paper states in sec. 3.3 (``stated_*``).
    """
    if table2 is None:
        table2 = load_seed002_table2(data_dir)
    ours_fixed = {m: fit_seed002_model(table2, m) for m in SEED002_PARAM_NAMES}
    ours_free_n = fit_seed002_model(table2, "normal_force", k_per_mm=None)
    sets: dict[str, dict[str, Mapping[str, float]]] = {
        "published_table3": {
            m: {**{n: v[0] for n, v in s["params"].items()}, **({"k_radial_per_mm": s["k_radial_per_mm"]} if "k_radial_per_mm" in s else {})}
            for m, s in SEED002_TABLE3.items()
        },
        "published_eqs2_4": {m: {**s["params"], **({"k_radial_per_mm": s["k_radial_per_mm"]} if "k_radial_per_mm" in s else {})} for m, s in SEED002_EQS_2_TO_4.items()},
        "ours_k_fixed": {m: f.param_dict() for m, f in ours_fixed.items()},
        "ours_k_free": {"normal_force": ours_free_n.param_dict(), **{m: ours_fixed[m].param_dict() for m in ("rolling_coefficient", "side_coefficient")}},
    }

    def r2_log(model, pred):
        y_col = "normal_force_kN" if model == "normal_force" else model
        y = np.log(table2[y_col].to_numpy(float))
        return 1.0 - np.sum((y - np.log(pred)) ** 2) / np.sum((y - y.mean()) ** 2)

    rows = []
    fn = table2["normal_force_kN"].to_numpy(float)
    for set_name, params in sets.items():
        fn_hat = predict_seed002("normal_force", params["normal_force"], table2)
        st = SEED002_PUBLISHED_ACCURACY_TABLE2["normal_force_kN"]
        rows.append(
            {"equations": set_name, "force": "normal_force_kN", "prediction": "Fn_hat", "r_squared_log": r2_log("normal_force", fn_hat),
             **force_error_metrics(fn, fn_hat), "stated_rmse_kN": st[0], "stated_mae_kN": st[1], "stated_mape_pct": st[2]}
        )
        for model, col in (("rolling_coefficient", "rolling_force_kN"), ("side_coefficient", "side_force_kN")):
            k_hat = predict_seed002(model, params[model], table2)
            st = SEED002_PUBLISHED_ACCURACY_TABLE2[col]
            for how, base in (("chained", fn_hat), ("given_Fn", fn)):
                rows.append(
                    {"equations": set_name, "force": col, "prediction": how, "r_squared_log": r2_log(model, k_hat),
                     **force_error_metrics(table2[col].to_numpy(float), k_hat * base),
                     "stated_rmse_kN": st[0], "stated_mae_kN": st[1], "stated_mape_pct": st[2]}
                )
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------
# Seed 002 Table 4 (RCM tests, Shin et al. 2024)
# ---------------------------------------------------------------------------


def predict_rcm_table4(
    table4: pd.DataFrame | None = None,
    equations: Mapping[str, Mapping] | None = None,
    ucs_MPa: float = SEED002_RCM_CONDITIONS["ucs_MPa"],
    tip_width_mm: float = SEED002_RCM_CONDITIONS["tip_width_mm"],
    cutter_diameter_mm: float = SEED002_RCM_CONDITIONS["cutter_diameter_mm"],
    spacing_mm: float = SEED002_RCM_CONDITIONS["spacing_mm"],
    coefficient_base: str = "predicted",
    data_dir: str | Path | None = None,
) -> pd.DataFrame:
    """Evaluate seed-002 equations at the RCM test conditions of its Table 4.

    ``A_con`` from eq. 1 with the stated tip width and disc radius.
    ``equations`` is :data:`SEED002_EQS_2_TO_4` (default) or
    :data:`SEED002_TABLE3` or a dict of fitted parameter mappings.
    ``coefficient_base`` chooses the Fn multiplied by kr and ks:
    ``"predicted"`` (our Fn̂ -- the self-consistent use) or ``"measured"`` (the
    RCM Fn; this is what reproduces the paper's printed Fr/Fs, see
    :func:`seed002_table4_reproduction`).

    Returns the penetration/radius columns plus ``contact_area_mm2``,
    ``normal_force_ours_kN``, ``rolling_coefficient_ours``,
    ``side_coefficient_ours``, ``rolling_force_ours_kN``, ``side_force_ours_kN``.
    """
    if table4 is None:
        table4 = load_seed002_table4(data_dir)
    if equations is None:
        equations = SEED002_EQS_2_TO_4
    frame = pd.DataFrame(
        {
            "penetration_mm": table4["penetration_mm"].astype(float),
            "radial_position_mm": table4["radial_position_mm"].astype(float),
        }
    )
    frame["ucs_MPa"] = float(ucs_MPa)
    frame["spacing_mm"] = float(spacing_mm)
    frame["contact_area_mm2"] = contact_area_mm2(tip_width_mm, cutter_diameter_mm, frame["penetration_mm"])

    def flat(m):
        spec = equations[m]
        p = spec.get("params", spec)
        out = {n: (v[0] if isinstance(v, tuple) else v) for n, v in p.items()}
        if m == "normal_force" and "k_radial_per_mm" in spec:
            out.setdefault("k_radial_per_mm", spec["k_radial_per_mm"])
        return out

    frame["normal_force_ours_kN"] = predict_seed002("normal_force", flat("normal_force"), frame)
    frame["rolling_coefficient_ours"] = predict_seed002("rolling_coefficient", flat("rolling_coefficient"), frame)
    frame["side_coefficient_ours"] = predict_seed002("side_coefficient", flat("side_coefficient"), frame)
    if coefficient_base == "predicted":
        base = frame["normal_force_ours_kN"]
    elif coefficient_base == "measured":
        base = table4["normal_force_measured_kN"].astype(float)
    else:
        raise ValueError("coefficient_base must be 'predicted' or 'measured'")
    frame["rolling_force_ours_kN"] = frame["rolling_coefficient_ours"] * base
    frame["side_force_ours_kN"] = frame["side_coefficient_ours"] * base
    return frame.drop(columns=["ucs_MPa", "spacing_mm"])


def seed002_table4_reproduction(data_dir: str | Path | None = None) -> dict[str, pd.DataFrame | float]:
    """Check our implementation of eqs. 2-4 against the paper's Table 4 predictions.

    Returns a dict with

    * ``stated``: eqs. 2-4 at the stated conditions (UCS 205 MPa, T 21 mm, 17-inch
      disc, S 100 mm, kr/ks times our Fn̂) beside the printed predictions, with
      ``*_rel_diff_pct`` columns;
    * ``reproduced``: kr and ks with the ln-intercepts of Table 3, exponents of
      eqs. 3-4 (-1/2, -1/2, -4/5), UCS = ``ucs_effective_MPa`` and the *measured*
      RCM Fn -- the combination that reproduces the printed Fr and Fs;
    * ``ucs_effective_MPa``: 121.0 (sqrt = 11.0);
    * ``fn_p_ratio``: Fn(p=5)/Fn(p=4) at each radius for the printed values
      versus eq. 2 (which makes the ratio the same at every radius).
    """
    t4 = load_seed002_table4(data_dir)
    stated = predict_rcm_table4(t4)
    for ours, pub in (
        ("normal_force_ours_kN", "normal_force_predicted_kN"),
        ("rolling_force_ours_kN", "rolling_force_predicted_kN"),
        ("side_force_ours_kN", "side_force_predicted_kN"),
    ):
        stated[pub] = t4[pub]
        stated[pub.replace("predicted_kN", "rel_diff_pct")] = 100 * (stated[ours] / t4[pub] - 1)

    ucs_eff = 121.0
    mixed = {
        "normal_force": SEED002_EQS_2_TO_4["normal_force"],
        "rolling_coefficient": {"params": {"b0_intercept": SEED002_TABLE3["rolling_coefficient"]["params"]["b0_intercept"][0], "b1_ln_ucs": -0.5, "b2_ln_radial_position": -0.5}},
        "side_coefficient": {"params": {"b0_intercept": SEED002_TABLE3["side_coefficient"]["params"]["b0_intercept"][0], "b1_ln_ucs": -0.5, "b2_ln_radial_position": -0.8}},
    }
    rep = predict_rcm_table4(t4, equations=mixed, ucs_MPa=ucs_eff, coefficient_base="measured")
    reproduced = pd.DataFrame(
        {
            "penetration_mm": t4["penetration_mm"],
            "radial_position_mm": t4["radial_position_mm"],
            "normal_force_measured_kN": t4["normal_force_measured_kN"],
            "rolling_force_ours_kN": rep["rolling_force_ours_kN"],
            "rolling_force_predicted_kN": t4["rolling_force_predicted_kN"],
            "rolling_force_abs_diff_kN": (rep["rolling_force_ours_kN"] - t4["rolling_force_predicted_kN"]).abs(),
            "side_force_ours_kN": rep["side_force_ours_kN"],
            "side_force_predicted_kN": t4["side_force_predicted_kN"],
            "side_force_abs_diff_kN": (rep["side_force_ours_kN"] - t4["side_force_predicted_kN"]).abs(),
        }
    )
    piv_pub = t4.pivot(index="radial_position_mm", columns="penetration_mm", values="normal_force_predicted_kN")
    piv_ours = stated.pivot(index="radial_position_mm", columns="penetration_mm", values="normal_force_ours_kN")
    fn_ratio = pd.DataFrame(
        {
            "radial_position_mm": piv_pub.index.astype(float),
            "printed_Fn_p5_over_p4": (piv_pub[5] / piv_pub[4]).to_numpy(),
            "eq2_Fn_p5_over_p4": (piv_ours[5.0] / piv_ours[4.0]).to_numpy(),
        }
    )
    return {"stated": stated, "reproduced": reproduced, "ucs_effective_MPa": ucs_eff, "fn_p_ratio": fn_ratio}


def seed002_table5_check(data_dir: str | Path | None = None) -> pd.DataFrame:
    """Recompute seed 002 Table 5 (RCM error metrics) from the numbers of its Table 4."""
    t4 = load_seed002_table4(data_dir)
    rows = []
    for col in _FORCE_COLUMNS:
        m = force_error_metrics(t4[col.replace("_kN", "_measured_kN")], t4[col.replace("_kN", "_predicted_kN")])
        pub = SEED002_PUBLISHED_TABLE5[col]
        rows.append(
            {
                "force": col,
                "rmse_from_table4_kN": m["rmse_kN"],
                "rmse_printed_kN": pub[0],
                "mae_from_table4_kN": m["mae_kN"],
                "mae_printed_kN": pub[1],
                "mape_from_table4_pct": m["mape_pct"],
                "mape_printed_pct": pub[2],
            }
        )
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------
# Design criteria: optimal spacing
# ---------------------------------------------------------------------------

ForceModel = Callable[[float, float], float]


def capacity_threshold_kN(capacity_kN: float = SEED001_CUTTER_CAPACITY_17IN_kN, fraction: float = SEED001_CAPACITY_FRACTION) -> float:
    """Allowed normal force: ``fraction * capacity`` (seed 001 sec. 6.1: 80 % of 215 kN)."""
    return float(fraction) * float(capacity_kN)


def _root_in_bounds(fun: Callable[[float], float], lo: float, hi: float) -> float | None:
    flo, fhi = fun(lo), fun(hi)
    if flo == 0:
        return lo
    if fhi == 0:
        return hi
    if np.sign(flo) == np.sign(fhi):
        return None
    return float(optimize.brentq(fun, lo, hi, xtol=1e-10))


def optimal_spacing_capacity_rule(
    normal_force_model: ForceModel,
    penetration_mm: float,
    capacity_kN: float = SEED001_CUTTER_CAPACITY_17IN_kN,
    fraction: float = SEED001_CAPACITY_FRACTION,
    spacing_bounds_mm: tuple[float, float] = (1.0, 300.0),
    threshold_kN: float | None = None,
) -> dict[str, float | bool | str]:
    """Spacing at which the predicted normal force reaches ``fraction * capacity``.

    Seed 001 sec. 6.1 proposes, instead of minimum specific energy, to space the
    cutters as widely as possible while the normal force stays at or below 80 %
    of what the disc can withstand (215 kN for a 17-inch disc -> 172 kN).  Since
    the normal force grows with spacing, the optimum is the root of
    ``Fn(S, P) = threshold`` for the chosen penetration.

    Parameters
    ----------
    normal_force_model:
        Callable ``f(spacing_mm, penetration_mm) -> kN`` (a :class:`LinearFit`
        works).
    penetration_mm:
        Penetration per revolution / pass, mm.
    capacity_kN, fraction:
        Cutter load capacity and allowed fraction; ``threshold_kN`` overrides
        their product (e.g. the paper's stated 180 kN).
    spacing_bounds_mm:
        Search interval.  If Fn stays below the threshold across it the
        result is the upper bound with ``status = "below_threshold_in_bounds"``;
        if Fn exceeds it already at the lower bound, ``status =
        "above_threshold_in_bounds"`` and ``optimal_spacing_mm`` is NaN.

    Returns
    -------
    dict with ``optimal_spacing_mm``, ``threshold_kN``,
    ``normal_force_at_optimum_kN``, ``penetration_mm`` and ``status``
    (``"root"`` when the threshold is crossed inside the bounds).
    """
    thr = capacity_threshold_kN(capacity_kN, fraction) if threshold_kN is None else float(threshold_kN)
    lo, hi = spacing_bounds_mm
    f = lambda s: float(normal_force_model(s, penetration_mm)) - thr  # noqa: E731
    root = _root_in_bounds(f, lo, hi)
    if root is not None:
        s, status = root, "root"
    elif f(lo) < 0:
        s, status = hi, "below_threshold_in_bounds"
    else:
        s, status = math.nan, "above_threshold_in_bounds"
    fn = float(normal_force_model(s, penetration_mm)) if s == s else math.nan
    return {"optimal_spacing_mm": s, "threshold_kN": thr, "normal_force_at_optimum_kN": fn, "penetration_mm": float(penetration_mm), "status": status}


def max_penetration_capacity_rule(
    normal_force_model: ForceModel,
    spacing_mm: float,
    capacity_kN: float = SEED001_CUTTER_CAPACITY_17IN_kN,
    fraction: float = SEED001_CAPACITY_FRACTION,
    penetration_bounds_mm: tuple[float, float] = (0.1, 30.0),
    threshold_kN: float | None = None,
) -> dict[str, float | bool | str]:
    """Largest penetration at a given spacing with ``Fn <= fraction * capacity``.

    The companion of :func:`optimal_spacing_capacity_rule` (seed 001 sec. 6.1:
    "at a spacing of 100 mm ... the penetration depth cannot exceed 5.1 mm").
    Returns ``max_penetration_mm``, ``threshold_kN``, ``spacing_mm``, ``status``.
    """
    thr = capacity_threshold_kN(capacity_kN, fraction) if threshold_kN is None else float(threshold_kN)
    lo, hi = penetration_bounds_mm
    f = lambda p: float(normal_force_model(spacing_mm, p)) - thr  # noqa: E731
    root = _root_in_bounds(f, lo, hi)
    if root is not None:
        p, status = root, "root"
    elif f(lo) < 0:
        p, status = hi, "below_threshold_in_bounds"
    else:
        p, status = math.nan, "above_threshold_in_bounds"
    return {"max_penetration_mm": p, "threshold_kN": thr, "spacing_mm": float(spacing_mm), "status": status}


def specific_energy_MJ_per_m3(rolling_force_kN, spacing_mm, penetration_mm):
    """Specific energy of linear cutting, ``SE = F_r * L / V = F_r / (S * P)``.

    Work of the rolling (cutting-direction) force over a cut length L divided by
    the excavated volume ``S * P * L`` (seed 003 eq. 2.9: power / production;
    seed 001 sec. 1 uses the same notion).  Inputs kN and mm; output MJ/m³
    (= 1000 * kN / mm²).
    """
    return 1000.0 * np.asarray(rolling_force_kN, float) / (np.asarray(spacing_mm, float) * np.asarray(penetration_mm, float))


def optimal_spacing_min_specific_energy(
    rolling_force_model: ForceModel,
    penetration_mm: float,
    spacing_bounds_mm: tuple[float, float] = (10.0, 150.0),
) -> dict[str, float | bool]:
    """Spacing that minimises ``SE(S) = 1000 * F_r(S, P) / (S * P)`` for a fixed penetration.

    Bounded scalar minimisation (``scipy.optimize.minimize_scalar``).  Returns
    ``optimal_spacing_mm``, ``specific_energy_MJ_per_m3``, ``penetration_mm``,
    ``spacing_over_penetration``, ``at_bound`` (True when the minimum sits on
    a search bound, i.e. the model has no interior optimum there) and
    ``nonpositive_force_in_bounds`` (True when the model predicts F_r <= 0
    somewhere in the bounds -- an extrapolated linear model can -- in which case
    the "minimum" is meaningless).

    NB with a *linear* rolling-force model ``F_r = a + b S + c P`` one has
    ``dSE/dS = -(a + c P) / (S² P)``: SE is monotonic in S, so eq. 9 of seed 001
    can never give an interior minimum (it decreases with S whenever
    ``a + c P > 0``).  Use a model with curvature, or
    :func:`min_specific_energy_spacing_from_table` on tabulated forces.
    """
    lo, hi = spacing_bounds_mm
    se = lambda s: float(specific_energy_MJ_per_m3(rolling_force_model(s, penetration_mm), s, penetration_mm))  # noqa: E731
    res = optimize.minimize_scalar(se, bounds=(lo, hi), method="bounded", options={"xatol": 1e-8})
    # the bounded method never evaluates exactly at the ends; compare explicitly
    best_val, best_s = min([(se(lo), lo), (float(res.fun), float(res.x)), (se(hi), hi)])
    tol = 1e-4 * (hi - lo)
    grid = np.linspace(lo, hi, 201)
    fr_grid = np.asarray([float(rolling_force_model(g, penetration_mm)) for g in grid])
    return {
        "optimal_spacing_mm": float(best_s),
        "specific_energy_MJ_per_m3": float(best_val),
        "penetration_mm": float(penetration_mm),
        "spacing_over_penetration": float(best_s) / float(penetration_mm),
        "at_bound": bool(abs(best_s - lo) <= tol or abs(best_s - hi) <= tol),
        "nonpositive_force_in_bounds": bool(np.any(fr_grid <= 0)),
    }


def min_specific_energy_spacing_from_table(
    data: pd.DataFrame,
    rolling_col: str = "rolling_force_kN",
    spacing_col: str = "spacing_mm",
    penetration_col: str = "penetration_mm",
) -> pd.DataFrame:
    """Per penetration, the tabulated spacing with the lowest specific energy.

    Adds ``specific_energy_MJ_per_m3`` to each row and returns, for every
    penetration present with at least two spacings, the row of minimum SE.
    """
    df = data[[spacing_col, penetration_col, rolling_col]].copy()
    df["specific_energy_MJ_per_m3"] = specific_energy_MJ_per_m3(df[rolling_col], df[spacing_col], df[penetration_col])
    counts = df.groupby(penetration_col)[spacing_col].transform("count")
    df = df[counts >= 2]
    idx = df.groupby(penetration_col)["specific_energy_MJ_per_m3"].idxmin()
    return df.loc[idx].rename(columns={spacing_col: "optimal_spacing_mm"}).reset_index(drop=True)


# ---------------------------------------------------------------------------
# Reports
# ---------------------------------------------------------------------------

_CMP_FMT = {
    "published_estimate": ".4f",
    "published_std_error": ".4f",
    "ours_estimate": ".4f",
    "ours_std_error": ".4f",
    "diff_estimate": "+.4f",
    "diff_in_published_se": "+.1f",
    "implied_se_from_published_r2": ".4f",
}


def seed002_comparison_markdown(table2: pd.DataFrame | None = None, data_dir: str | Path | None = None) -> str:
    """Markdown report of our seed-002 fits vs the published Table 3.

    Three tables: parameters (estimate, SE, 95 % CI; ours vs published, for k
    fixed at 0.00872 and for k free), accuracy on Table 2 (R² on the ln scale,
    RMSE, MAE, MAPE; published vs ours, with the values stated in the paper),
    and the check of the printed CIs against estimate ± t·SE.  Meant for the CLI.
    """
    if table2 is None:
        table2 = load_seed002_table2(data_dir)
    cmp_ = compare_seed002_with_published(table2)
    cmp_ = cmp_.copy()
    ci = lambda lo, hi, f: "" if (lo != lo) else f"[{lo:{f}}, {hi:{f}}]"  # noqa: E731
    cmp_["published_ci95"] = [ci(a, b, ".3f") for a, b in zip(cmp_["published_ci95_low"], cmp_["published_ci95_high"])]
    cmp_["ours_ci95"] = [ci(a, b, ".4f" if p == "k_radial_per_mm" else ".3f") for a, b, p in zip(cmp_["ours_ci95_low"], cmp_["ours_ci95_high"], cmp_["parameter"])]
    par = cmp_[
        [
            "variant",
            "model",
            "parameter",
            "published_estimate",
            "published_std_error",
            "published_ci95",
            "ours_estimate",
            "ours_std_error",
            "ours_ci95",
            "diff_estimate",
            "diff_in_published_se",
            "implied_se_from_published_r2",
        ]
    ]
    fmt = dict(_CMP_FMT)
    fmt_k = {**fmt, "published_estimate": ".5f", "ours_estimate": ".5f", "ours_std_error": ".5f", "diff_estimate": "+.5f"}
    body = [markdown_table(par[par.parameter != "k_radial_per_mm"], fmt)]
    kk = par[par.parameter == "k_radial_per_mm"]
    if len(kk):
        body.append("\nk of the radial term (1/mm), normal-force model with k free:\n")
        body.append(markdown_table(kk, fmt_k))

    fits = {m: fit_seed002_model(table2, m) for m in SEED002_PARAM_NAMES}
    free = fit_seed002_model(table2, "normal_force", k_per_mm=None)
    r2 = pd.DataFrame(
        [
            {"model": m, "published_r_squared_log": SEED002_TABLE3[m]["r_squared"], "ours_k_fixed_r_squared_log": f.r_squared_log,
             "ours_k_fixed_r_squared_adj_log": f.r_squared_adj_log,
             "ours_k_free_r_squared_log": (free.r_squared_log if m == "normal_force" else math.nan)}
            for m, f in fits.items()
        ]
    )
    met = seed002_fit_metrics(table2)
    ci_chk = published_table3_frame()
    ci_chk["ci_centre_minus_estimate"] = 0.5 * (ci_chk["published_ci95_low"] + ci_chk["published_ci95_high"]) - ci_chk["published_estimate"]
    ci_chk = ci_chk[["model", "parameter", "published_estimate", "published_std_error", "published_ci95_low", "published_ci95_high",
                     "published_ci_from_se_low", "published_ci_from_se_high", "ci_centre_minus_estimate"]]
    kp = free.k_profile_ci95_per_mm
    parts = [
        "### Seed 002 Table 3: parameters, ours vs published\n",
        "Fits to the 58 runs of seed 002 Table 2 (`A_con` from its Table 2 column). "
        "`k_fixed`: k = 0.00872 1/mm as published, OLS (statsmodels); `k_free`: k estimated jointly "
        "(scipy least_squares on ln Fn, Wald SE). `diff_in_published_se` = (ours - published) / published SE. "
        "`implied_se_from_published_r2` = the SE the published R² would give on this design "
        "(s² = (1 - R²)·TSS/(n - p)); compare it with `published_std_error`.\n",
        "\n".join(body),
        f"\nProfile-likelihood 95 % interval of k (b0..b4 re-fitted at each k): [{kp[0]:.5f}, {kp[1]:.5f}] 1/mm "
        f"(published k = {SEED002_RADIAL_K_per_mm} is {'inside' if kp[0] <= SEED002_RADIAL_K_per_mm <= kp[1] else 'outside'}). "
        "k and b4 are strongly correlated, so the Wald interval above is only indicative.\n",
        "\n### R² (ln scale)\n",
        markdown_table(r2, ".4f"),
        "\n### Accuracy on Table 2 (forces in kN)\n",
        "`chained`: F = k̂·F̂n; `given_Fn`: F = k̂·Fn(LS-DYNA). `stated_*`: values printed in seed 002 sec. 3.3 "
        "for its Table 3 equations.\n",
        markdown_table(met, {"r_squared_log": ".4f", "rmse_kN": ".2f", "mae_kN": ".2f", "mape_pct": ".2f",
                             "stated_rmse_kN": ".2f", "stated_mae_kN": ".2f", "stated_mape_pct": ".2f"}),
        "\n### Published CIs vs estimate ± t(0.975, 58 - p)·SE\n",
        markdown_table(ci_chk, {"published_estimate": ".4f", "published_std_error": ".4f", "published_ci95_low": ".3f",
                                "published_ci95_high": ".3f", "published_ci_from_se_low": ".3f",
                                "published_ci_from_se_high": ".3f", "ci_centre_minus_estimate": "+.4f"}),
    ]
    return "\n".join(parts) + "\n"


def regression_check_markdown(data_dir: str | Path | None = None, command: str | None = None) -> str:
    """The full ``docs/regression_check.md`` text, computed from the seed tables."""
    cmd = command or ".venv/bin/python -m deckgen.analysis.regression --write-doc docs/regression_check.md"
    out: list[str] = [
        "# Regression check against the seeds' published numbers",
        "",
        "Generated by `deckgen.analysis.regression` -- do not edit by hand. Command (from the repository root):",
        "",
        f"    {cmd}",
        "",
        "Data: the transcribed seed tables in `../shared/data` (seed 001 = Fattahi et al., seed 002 = Farrokh et al.).",
        "",
        "## 1. Seed 001 eqs. 8-9: Y = b0 + b1·S + b2·P on its 16 LS-DYNA points",
        "",
        "Points: the 9 LS-DYNA rows of Table 3 + the 7 rows of Table 4 (S mm, P mm, forces kN).",
        "",
    ]
    fits = fit_seed001_equations(data_dir)
    for resp, fit in fits.items():
        pub = SEED001_PUBLISHED_LINEAR[resp]
        c = fit.coefficients.reset_index()
        c["printed"] = [pub[t] for t in c["term"]]
        c["ours_rounded_2dp"] = c["estimate"].round(2)
        c["match_2dp"] = np.isclose(c["ours_rounded_2dp"], c["printed"])
        eq = "eq. 8" if resp == "normal_force_kN" else "eq. 9"
        out += [
            f"### {resp} ({eq}), n = {fit.n_obs}",
            "",
            markdown_table(c, {"estimate": ".4f", "std_error": ".4f", "t_value": ".2f", "p_value": ".2e", "ci95_low": ".3f",
                               "ci95_high": ".3f", "vif": ".4f", "printed": ".2f", "ours_rounded_2dp": ".2f"}),
            "",
            f"R² = {fit.r_squared:.4f} (printed {pub['r_squared']:.2f}), adjusted R² = {fit.r_squared_adj:.4f}.",
            "",
        ]
    match = seed001_printed_match(fits)
    bad = match[~match["match_2dp"]]
    fr_fit = fits["rolling_force_kN"]
    fr = fr_fit.coefficients.loc["penetration_mm", "estimate"]
    fr_se = fr_fit.coefficients.loc["penetration_mm", "std_error"]
    edits = seed001_single_value_edits("rolling_force_kN", data_dir=data_dir)
    edit_txt = "; ".join(
        f"{r.tabulated_kN:.1f} -> {r.edited_kN:.1f} kN at S = {r.spacing_mm:.0f}, P = {r.penetration_mm:.1f}" for r in edits.itertuples()
    )
    txt = seed001_text_penetration_fit(data_dir)["normal_force_kN"]
    tb = txt.coefficients["estimate"]
    out += [
        "Every printed number vs ours rounded to the printed 2 decimals (VIF: the larger of the two):",
        "",
        markdown_table(match, {"printed": ".2f", "ours": ".4f", "ours_rounded_2dp": ".2f"}),
        "",
        f"**Result.** {int(match['match_2dp'].sum())} of the {len(match)} printed numbers reproduce. "
        + (
            f"The exception is the P coefficient of eq. 9: ours {fr:.4f} rounds to {round(fr, 2):.2f}, printed 2.79 "
            f"(difference {fr - 2.79:+.4f} kN/mm = {(fr - 2.79) / fr_se:.2f} of its SE). No single rounding rule explains it "
            "(truncation would make the S coefficient 0.1558 into 0.15, printed 0.16). Editing a single tabulated rolling "
            f"force by at most {(edits['edited_kN'] - edits['tabulated_kN']).abs().max():.1f} kN reproduces all printed numbers "
            f"of eq. 9 in {len(edits)} ways ({edit_txt}), so a typo or a slightly "
            "different data value is possible; the test keeps the exact reproduction as a strict xfail instead of tuning. "
            if len(bad) else ""
        )
        + "With the penetrations written in seed 001's text (2.5/5.1/6.4 mm instead of Table 3's 1.9/3.8/6.4) the normal-force "
        f"fit would be Fn = {tb['const']:.2f} + {tb['spacing_mm']:.2f} S + {tb['penetration_mm']:.2f} P (R² {txt.r_squared:.2f}), "
        "which does not match eq. 8 -- the regression used the Table 3 values.",
        "",
        "The intercept of eq. 8 is not significant (p = "
        f"{fits['normal_force_kN'].coefficients.loc['const', 'p_value']:.2f}); the paper's 'P-Value = 0.00' holds for S and P only. "
        "VIF = 1 exactly because S and P are uncorrelated over the 16 points (corr = "
        f"{np.corrcoef(load_seed001_lsdyna_points(data_dir)[['spacing_mm', 'penetration_mm']].to_numpy().T)[0, 1]:.1e}).",
        "",
        "### Seed 001 Table 3 error columns recomputed",
        "",
        markdown_table(seed001_table3_error_check(data_dir), {"spacing_mm": ".0f", "penetration_mm": ".1f",
                       "normal_error_recomputed_pct": "+.2f", "normal_error_printed_pct": "+.1f",
                       "rolling_error_recomputed_pct": "+.2f", "rolling_error_printed_pct": "+.1f"}),
        "",
    ]
    t3 = seed001_table3_error_check(data_dir)
    out += [
        f"Mean |error|: normal {t3['normal_error_recomputed_pct'].abs().mean():.2f} % recomputed / "
        f"{t3['normal_error_printed_pct'].abs().mean():.2f} % from the printed column (paper: 4.67 %); rolling "
        f"{t3['rolling_error_recomputed_pct'].abs().mean():.2f} % recomputed / {t3['rolling_error_printed_pct'].abs().mean():.2f} % "
        f"printed (paper: 7.99 %). The printed rolling-error column differs from the printed forces by more than rounding in "
        f"{int(((t3['rolling_error_recomputed_pct'] - t3['rolling_error_printed_pct']).abs() > 0.06).sum())} of 9 rows; the "
        "printed normal error at S = 51, P = 3.8 has the wrong sign. The abstract's '10 %' and '13 %' are the maximum "
        "errors, the conclusions' 4.67 % / 7.99 % the mean absolute ones.",
        "",
        "## 2. Optimal spacing",
        "",
        "### 80 %-of-capacity rule (seed 001 sec. 6.1)",
        "",
    ]
    fn_fit = fits["normal_force_kN"]
    pub_fn = lambda s, p: 7.39 + 0.84 * s + 13.51 * p  # noqa: E731
    rows = []
    for p in (1.9, 3.8, 5.1, 6.4, 7.6):
        for label, model in (("ours (fit)", fn_fit), ("printed eq. 8", pub_fn)):
            for thr in (None, 180.0):
                r = optimal_spacing_capacity_rule(model, p, threshold_kN=thr)
                rows.append({"normal_force_model": label, "penetration_mm": p, "threshold_kN": r["threshold_kN"],
                             "optimal_spacing_mm": r["optimal_spacing_mm"], "status": r["status"]})
    out += [
        "Capacity 215 kN (Roby et al. 2008, 17-inch disc) x 0.8 = 172 kN; the paper writes '180 kN' (which is 83.7 % of 215), "
        "so both thresholds are shown. Spacing where the eq. 8-type normal force reaches the threshold:",
        "",
        markdown_table(pd.DataFrame(rows), {"penetration_mm": ".1f", "threshold_kN": ".0f", "optimal_spacing_mm": ".1f"}),
        "",
    ]
    rows = []
    for label, model in (("ours (fit)", fn_fit), ("printed eq. 8", pub_fn)):
        for thr in (None, 180.0):
            r = max_penetration_capacity_rule(model, 100.0, threshold_kN=thr)
            rows.append({"normal_force_model": label, "spacing_mm": 100.0, "threshold_kN": r["threshold_kN"], "max_penetration_mm": r["max_penetration_mm"]})
    t4 = read_seed_csv("fattahi_lsdyna_extended.csv", data_dir)
    s100 = t4[t4.spacing_mm == 100].sort_values("penetration_mm")
    interp = {thr: float(np.interp(thr, s100.normal_force_lsdyna_kN, s100.penetration_mm)) for thr in (172.0, 180.0)}
    out += [
        f"At the deepest simulated penetration (7.6 mm) our eq. 8 reaches 172 kN at S = "
        f"{optimal_spacing_capacity_rule(fn_fit, 7.6)['optimal_spacing_mm']:.1f} mm, the value closest to the paper's 76 mm; "
        "at shallower penetrations the rule allows (extrapolated) spacings beyond the simulated 100 mm.",
        "",
        "Largest penetration at S = 100 mm (paper: 'the penetration depth cannot exceed 5.1 mm'):",
        "",
        markdown_table(pd.DataFrame(rows), {"spacing_mm": ".0f", "threshold_kN": ".0f", "max_penetration_mm": ".2f"}),
        "",
        f"Linear interpolation of the paper's own Table 4 (S = 100 mm) gives {interp[172.0]:.2f} mm at 172 kN and "
        f"{interp[180.0]:.2f} mm at 180 kN. None of these is 5.1 mm; the paper does not say how it obtained 5.1 mm.",
        "",
        "### Minimum specific energy, SE = 1000·F_r/(S·P) MJ/m³",
        "",
    ]
    pts = load_seed001_lsdyna_points(data_dir)
    best = min_specific_energy_spacing_from_table(pts)
    out += [
        "From the 16 tabulated LS-DYNA rolling forces (per penetration, the spacing of lowest SE):",
        "",
        markdown_table(best, {"optimal_spacing_mm": ".0f", "penetration_mm": ".1f", "rolling_force_kN": ".1f", "specific_energy_MJ_per_m3": ".2f"}),
        "",
    ]
    fr_fit = fits["rolling_force_kN"]
    rows = [optimal_spacing_min_specific_energy(fr_fit, p, (25.0, 100.0)) for p in (1.9, 3.8, 6.4, 7.6)]
    b = fr_fit.coefficients["estimate"]
    out += [
        "With the linear eq. 9 (our fit) over S in [25, 100] mm:",
        "",
        markdown_table(pd.DataFrame(rows), {"optimal_spacing_mm": ".1f", "specific_energy_MJ_per_m3": ".2f", "penetration_mm": ".1f", "spacing_over_penetration": ".1f"}),
        "",
        f"A linear F_r has dSE/dS = -(b0 + b2·P)/(S²·P): monotonic, so the minimum is always on a bound "
        f"(SE falls with S for P > {-b['const'] / b['penetration_mm']:.2f} mm; at P = 1.9 mm eq. 9 even predicts F_r <= 0 "
        f"for S < {(-b['const'] - b['penetration_mm'] * 1.9) / b['spacing_mm']:.1f} mm, hence the negative SE). The tabulated "
        f"forces have their lowest SE at S = {', '.join(f'{v:.0f}' for v in sorted(set(best['optimal_spacing_mm'])))} mm "
        "(tabulated spacings 25-100 mm) for every penetration, in line with the paper's 76 mm and the 80 mm it quotes from Gertsch.",
        "",
        "## 3. Seed 002 (rotary cutting, 58 LS-DYNA runs)",
        "",
        seed002_comparison_markdown(data_dir=data_dir),
        "",
        "## 4. Seed 002 Table 4 (RCM tests on Hwandeung granite)",
        "",
    ]
    rep = seed002_table4_reproduction(data_dir)
    st = rep["stated"]
    cols = ["penetration_mm", "radial_position_mm", "contact_area_mm2", "normal_force_ours_kN", "normal_force_predicted_kN",
            "normal_force_rel_diff_pct", "rolling_force_ours_kN", "rolling_force_predicted_kN", "rolling_force_rel_diff_pct",
            "side_force_ours_kN", "side_force_predicted_kN", "side_force_rel_diff_pct"]
    out += [
        "Eqs. 2-4 (power form) at the stated conditions: UCS 205 MPa, 17-inch disc (R = 215.9 mm), T = 21 mm, S = 100 mm, "
        "A_con by eq. 1; Fr = k̂r·F̂n, Fs = k̂s·F̂n. `*_predicted_kN` are the paper's printed values.",
        "",
        markdown_table(st[cols], {c: ".2f" for c in cols}),
        "",
        "Fn(p = 5)/Fn(p = 4) at each radius: any equation of the eq. 2 type makes this ratio the same at every radius "
        "((5/4)^(b2/2) = 1.0574); the printed predictions do not:",
        "",
        markdown_table(rep["fn_p_ratio"], {"radial_position_mm": ".0f", "printed_Fn_p5_over_p4": ".4f", "eq2_Fn_p5_over_p4": ".4f"}),
        "",
        "So the printed Fn predictions cannot come from eq. 2 with one set of inputs per row as stated; only the r = 600 mm "
        "pair has the eq. 2 penetration scaling.",
        "",
        f"The printed Fr and Fs *are* reproduced by kr = exp(3.8410)·UCS^-1/2·r^-1/2 and ks = exp(5.2701)·UCS^-1/2·r^-4/5 "
        f"multiplied by the **measured** Fn, with **UCS = {rep['ucs_effective_MPa']:.0f} MPa** instead of the stated 205 MPa:",
        "",
        markdown_table(rep["reproduced"], {c: ".3f" for c in rep["reproduced"].columns}),
        "",
        f"Max |difference|: Fr {rep['reproduced']['rolling_force_abs_diff_kN'].max():.4f} kN, Fs "
        f"{rep['reproduced']['side_force_abs_diff_kN'].max():.4f} kN (printed to 0.01 kN). This confirms the implemented "
        "kr/ks forms (the r-exponents -1/2 and -4/5 reproduce the radial trend to 4 digits) and shows the inputs the paper "
        "actually used for its Table 4 Fr/Fs.",
        "",
        "### Seed 002 Table 5 recomputed from its Table 4",
        "",
        markdown_table(seed002_table5_check(data_dir), ".2f"),
        "",
        "The printed Table 5 does not follow from the printed Table 4 values.",
        "",
    ]
    out += _summary_lines(data_dir)
    return "\n".join(out)


def _summary_lines(data_dir: str | Path | None = None) -> list[str]:
    """Closing summary of ``regression_check_markdown`` (numbers recomputed)."""
    t2 = load_seed002_table2(data_dir)
    cmp_ = compare_seed002_with_published(t2)
    fixed = cmp_[cmp_.variant == "k_fixed"]
    met = seed002_fit_metrics(t2)
    pick = lambda eq, force, how: float(met[(met.equations == eq) & (met.force == force) & (met.prediction == how)]["mape_pct"].iloc[0])  # noqa: E731
    ratio = (fixed["ours_std_error"] / fixed["published_std_error"])
    rep = seed002_table4_reproduction(data_dir)
    st = rep["stated"]
    return [
        "## 5. Summary",
        "",
        "* Seed 001 eqs. 8-9 reproduce from the 16 LS-DYNA points except one digit (eq. 9 P coefficient 2.796 vs printed 2.79).",
        f"* Seed 002 Table 3 is not reproducible from Table 2: with k fixed at 0.00872 our ln-coefficients differ from the "
        f"published ones by {fixed['diff_estimate'].abs().min():.4f} to {fixed['diff_estimate'].abs().max():.4f} "
        f"({fixed['diff_in_our_se'].abs().min():.1f} to {fixed['diff_in_our_se'].abs().max():.1f} of our SEs); "
        f"{int(fixed['published_inside_our_ci95'].sum())} of {len(fixed)} published estimates lie inside our 95 % CIs ("
        + ", ".join(f"{m} {p}" for m, p in fixed.loc[fixed['published_inside_our_ci95'], ['model', 'parameter']].itertuples(index=False))
        + ").",
        f"* The published SEs are {ratio.min():.1f}x to {ratio.max():.1f}x smaller than ours, and the published R² implies SEs "
        "close to ours on this design, so the printed SEs and R² cannot belong to one fit of these 58 runs.",
        f"* MAPE on Table 2: published Fn equation {pick('published_table3', 'normal_force_kN', 'Fn_hat'):.2f} % (paper states 12.16 %), "
        f"ours {pick('ours_k_fixed', 'normal_force_kN', 'Fn_hat'):.2f} % (k fixed) / {pick('ours_k_free', 'normal_force_kN', 'Fn_hat'):.2f} % (k free); "
        f"Fr chained {pick('published_table3', 'rolling_force_kN', 'chained'):.2f} % vs ours {pick('ours_k_fixed', 'rolling_force_kN', 'chained'):.2f} % "
        f"(paper 10.73 %); Fs chained {pick('published_table3', 'side_force_kN', 'chained'):.2f} % vs ours "
        f"{pick('ours_k_fixed', 'side_force_kN', 'chained'):.2f} % (paper 18.34 %).",
        f"* Table 4: eq. 2 at the stated conditions is within {st['normal_force_rel_diff_pct'].min():+.1f} % to "
        f"{st['normal_force_rel_diff_pct'].max():+.1f} % of the printed Fn predictions, which no eq. 2-type form can reproduce "
        f"exactly; the printed Fr/Fs are kr/ks(UCS = {rep['ucs_effective_MPa']:.0f} MPa) x measured Fn to within "
        f"{max(rep['reproduced']['rolling_force_abs_diff_kN'].max(), rep['reproduced']['side_force_abs_diff_kN'].max()):.3f} kN.",
        "* Seed 001: 0.8 x 215 kN = 172 kN, not the stated 180 kN; the stated 5.1 mm limit at S = 100 mm does not follow from "
        "eq. 8 or from Table 4; Table 3's rolling-error column and one normal-error sign disagree with its forces.",
        "",
    ]


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m deckgen.analysis.regression [--data-dir D] [--write-doc PATH]``.

    Prints the full check (or writes it to PATH); ``--seed002-only`` prints just
    :func:`seed002_comparison_markdown`.
    """
    ap = argparse.ArgumentParser(prog="python -m deckgen.analysis.regression", description=__doc__.splitlines()[0])
    ap.add_argument("--data-dir", default=None, help="folder of the seed CSVs (default ../shared/data from the repo root)")
    ap.add_argument("--write-doc", default=None, metavar="PATH", help="write the markdown report to PATH")
    ap.add_argument("--seed002-only", action="store_true", help="only the seed-002 comparison tables")
    a = ap.parse_args(argv)
    if a.seed002_only:
        text = seed002_comparison_markdown(data_dir=a.data_dir)
    else:
        text = regression_check_markdown(a.data_dir)
    if a.write_doc:
        Path(a.write_doc).write_text(text)
    else:
        print(text)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
