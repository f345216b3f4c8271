"""The discrepancy loop: find -> name -> add -> show.

Statistics (all on case means, weighted by replicates / noise variance; ``docs/discrepancy.md``):

* **Noise.** Pooled within-case standard deviation of each response from the replicates
  (``replicate`` rows, or rows with equal factors), with nu = sum(n_i - 1) degrees of freedom;
  without replicates, an assumed relative scatter (the backend's packing-seed scatter, or
  ``noise_cv``) of each response, at least of half the largest response (a side force near zero
  scatters with the cutting forces), nu = infinity. A backend that averages each case over several
  packing seeds (``dem`` with ``--packing-seeds``) reports the standard error of its means; its
  mean square joins each response's variance (sigma^2 + mean_i n_i SE_i^2), with nu unchanged.
* **Find.** X0 = sum_ij n_i (y_ij - m_ij)^2 / s_j^2 over the M = cases x responses cells; the gap
  is *within noise* when X0 / M is not significant against F(M, nu) (chi2(M) when nu is infinite)
  at ``alpha_gap``. Per cell z-scores; per response and factor a weighted least-squares fit of the
  residual on the factor (statsmodels WLS: slope, p-value, R^2, AIC against the constant model).
* **Name.** Each applicable catalogue effect is simulated on a grid of its magnitude (if it has one
  and MEASURED.csv does not give it) and its magnitude fitted by weighted least squares
  (grid, then bounded scalar refinement on the interpolated predictions). Candidates are ranked by
  the K-fold cross-validated fraction of the base model's misfit they remove
  (score = 1 - CV-X_k / X0; K = min(5, cases), folds over cases), and also reported with the nested
  comparison Delta AIC = X_k - X0 + 2 p_k and the likelihood-ratio p-value. The best candidate is
  *named* only if it improves the AIC by more than 2 and its remaining misfit passes the
  lack-of-fit test (X_k / (M - p_k) against F(M - p_k, nu)) at ``alpha_lof`` and it removes at least
  :data:`EXCESS_SHARE` of the misfit above noise out of sample ((X0 - CV-X_k) / (X0 - M)); otherwise the loop
  says that no candidate explains the residuals and gives the factor and functional form the
  residuals follow (best AIC among linear, logarithmic, inverse and quadratic forms per response).
* **Add / show.** The named effect's magnitude is refitted on the fit subset only (two thirds of
  the cases, spread over the first factor's range), and the gap before and after (RMSE and MAPE
  per response) is reported on the fit cases, the held-out cases and all cases.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
import statsmodels.api as sm
from scipy import optimize, stats

from deckgen.gap.catalogue import CATALOGUE, BY_ID, Effect
from deckgen.gap.data import GapInputError, Measured

ALPHA_GAP = 0.01
ALPHA_LOF = 0.001
AIC_MARGIN = 2.0
#: share of the misfit above noise (X0 - M) a named effect must remove out of sample
EXCESS_SHARE = 0.75


@dataclass
class Candidate:
    effect: Effect
    grid: np.ndarray | None          # magnitude values (None: nothing to fit)
    preds: np.ndarray                # (G, m, J)

    @property
    def n_params(self) -> int:
        return 0 if self.grid is None else 1

    def at(self, u: float) -> tuple[float | None, np.ndarray]:
        """Magnitude and predictions at continuous grid index u (linear interpolation)."""
        if self.grid is None:
            return None, self.preds[0]
        G = len(self.grid)
        u = min(max(u, 0.0), G - 1.0)
        i = min(int(math.floor(u)), G - 2) if G > 1 else 0
        t = u - i if G > 1 else 0.0
        if G == 1:
            return float(self.grid[0]), self.preds[0]
        lo, hi = self.grid[i], self.grid[i + 1]
        mag = self.effect.magnitude
        theta = float(lo * (hi / lo) ** t) if mag is not None and mag.scale == "log" else float(lo + t * (hi - lo))
        return theta, (1 - t) * self.preds[i] + t * self.preds[i + 1]


def _x(Y: np.ndarray, P: np.ndarray, W: np.ndarray, rows: np.ndarray) -> float:
    d = (Y[rows] - P[rows]) ** 2 * W[rows]
    return float(np.nansum(d))


def fit_candidate(c: Candidate, Y: np.ndarray, W: np.ndarray, rows: np.ndarray) -> tuple[float | None, float, np.ndarray]:
    """Least-squares magnitude on ``rows``: (theta, X on rows, predictions for all cases)."""
    if c.grid is None:
        P = c.preds[0]
        return None, _x(Y, P, W, rows), P
    xs = np.array([_x(Y, c.preds[g], W, rows) for g in range(len(c.grid))])
    xs = np.where(np.isfinite(xs), xs, np.inf)
    g = int(np.argmin(xs))
    if len(c.grid) > 1:
        a, b = max(g - 1, 0), min(g + 1, len(c.grid) - 1)
        res = optimize.minimize_scalar(lambda u: _x(Y, c.at(u)[1], W, rows), bounds=(a, b), method="bounded",
                                       options={"xatol": 1e-4})
        if res.fun < xs[g]:
            theta, P = c.at(float(res.x))
            return theta, float(res.fun), P
    theta, P = c.at(float(g))
    return theta, float(xs[g]), P


def _folds(m: int, seed: int) -> list[np.ndarray]:
    k = min(5, m)
    perm = np.random.default_rng(seed).permutation(m)
    return [np.sort(perm[i::k]) for i in range(k)]


def _split(measured: Measured) -> np.ndarray:
    """Held-out mask: every third case in the order of the first numeric factor (none below 4 cases)."""
    m = len(measured.cases)
    held = np.zeros(m, bool)
    if m < 4:
        return held
    num = [f for f in measured.factors if pd.api.types.is_numeric_dtype(pd.to_numeric(measured.cases[f], errors="coerce"))
           and measured.cases[f].nunique() > 1]
    order = np.argsort(pd.to_numeric(measured.cases[num[0]]).to_numpy(), kind="stable") if num else np.arange(m)
    held[order[1::3]] = True
    return held


def _gap(Y: np.ndarray, P: np.ndarray, rows: np.ndarray, responses: list[str]) -> dict[str, dict[str, float]]:
    out = {}
    for j, r in enumerate(responses):
        y, p = Y[rows, j], P[rows, j]
        if len(y) == 0:
            out[r] = {"rmse": math.nan, "mape": math.nan}
            continue
        rmse = float(np.sqrt(np.mean((y - p) ** 2)))
        big = np.abs(y) >= 0.05 * np.abs(Y[:, j]).max() if np.abs(Y[:, j]).max() > 0 else np.zeros(len(y), bool)
        mape = float(100 * np.mean(np.abs(y[big] - p[big]) / np.abs(y[big]))) if big.any() else math.nan
        out[r] = {"rmse": rmse, "mape": mape}
    return out


def _std_gap(Y, P, sigma, rows) -> float:
    if not rows.any():
        return math.nan
    return float(np.sqrt(np.mean(((Y[rows] - P[rows]) / sigma) ** 2)))


def _numeric_factors(measured: Measured) -> list[str]:
    out = []
    for f in measured.factors:
        v = pd.to_numeric(measured.cases[f], errors="coerce")
        if v.notna().all() and v.nunique() > 1:
            out.append(f)
    return out


def residual_factor_stats(measured: Measured, Y, P, n, sigma, responses) -> list[dict[str, Any]]:
    """WLS of residual on each numeric factor, per response (slope, p-value, R^2, AIC vs constant)."""
    rows = []
    for f in _numeric_factors(measured):
        x = pd.to_numeric(measured.cases[f]).to_numpy(float)
        for j, r in enumerate(responses):
            res = Y[:, j] - P[:, j]
            w = n / sigma[j] ** 2
            m0 = sm.WLS(res, np.ones_like(x), weights=w).fit()
            m1 = sm.WLS(res, sm.add_constant(x), weights=w).fit()
            rows.append({"response": r, "factor": f, "slope_N_per_unit": float(m1.params[1]),
                         "p_value": float(m1.pvalues[1]), "r_squared": float(m1.rsquared),
                         "delta_aic": float(m1.aic - m0.aic)})
    return rows


FORMS = {
    "linear": lambda x: x[:, None],
    "logarithmic": lambda x: np.log(x)[:, None],
    "inverse": lambda x: (1.0 / x)[:, None],
    "quadratic": lambda x: np.column_stack([x, x**2]),
}


def functional_forms(measured: Measured, Y, P, n, sigma, responses, alpha: float) -> list[dict[str, Any]]:
    """For responses whose residuals exceed noise: the factor and form the residual follows best.

    The residual is relative, ln(y / m), where y and m share a sign and |m| is not tiny (so the
    logarithmic form is a power law y/m ~ f^b), else absolute y - m; weighted least squares,
    the (factor, form) with the lowest AIC wins.
    """
    out = []
    facs = [f for f in _numeric_factors(measured) if (pd.to_numeric(measured.cases[f]) > 0).all()]
    for j, r in enumerate(responses):
        z2 = float(np.sum(n * (Y[:, j] - P[:, j]) ** 2 / sigma[j] ** 2))
        p_resp = float(stats.chi2.sf(z2, len(Y)))
        if p_resp >= alpha:
            continue
        rel = (np.sign(Y[:, j]) == np.sign(P[:, j])).all() and (np.abs(P[:, j]) > 0.05 * np.abs(Y[:, j]).max()).all()
        q = np.log(Y[:, j] / P[:, j]) if rel else Y[:, j] - P[:, j]
        w = n * (P[:, j] / sigma[j]) ** 2 if rel else n / sigma[j] ** 2
        best = None
        for f in facs:
            x = pd.to_numeric(measured.cases[f]).to_numpy(float)
            if np.unique(x).size < 3:
                continue
            for name, g in FORMS.items():
                X = sm.add_constant(g(x), has_constant="add")
                if X.shape[1] >= len(x):
                    continue
                fit = sm.WLS(q, X, weights=w).fit()
                cand = {"response": r, "residual": "ln(measured/model)" if rel else "measured - model [N]",
                        "factor": f, "form": name, "coefficients": [float(v) for v in fit.params],
                        "p_value": float(fit.f_pvalue) if np.isfinite(fit.f_pvalue) else math.nan,
                        "r_squared": float(fit.rsquared), "aic": float(fit.aic)}
                if best is None or cand["aic"] < best["aic"]:
                    best = cand
        if best and best["p_value"] < alpha:
            out.append(best)
        else:  # significant misfit that no factor explains: a constant offset or ratio
            c0 = float(np.average(q, weights=w))
            out.append({"response": r, "residual": "ln(measured/model)" if rel else "measured - model [N]",
                        "factor": None, "form": "constant", "coefficients": [c0], "p_value": p_resp,
                        "r_squared": 0.0, "aic": math.nan})
    return out


def _describe_form(f: dict[str, Any]) -> str:
    c = f["coefficients"]
    x = f["factor"]
    if f["form"] == "constant":
        what = (f"measured/model = {math.exp(c[0]):.3g}" if f["residual"].startswith("ln")
                else f"measured - model = {c[0]:.4g} N")
        return (f"{f['response']}: {what} in every case, no factor dependence (misfit p {f['p_value']:.2g}): "
                f"a level error, not a factor effect")
    if f["residual"].startswith("ln"):
        lhs = f"measured/model of {f['response']}"
        forms = {"linear": f"exp({c[0]:.3g} + {c[1]:.3g} {x})", "logarithmic": f"{math.exp(c[0]):.3g} * {x}^{c[1]:.3g}",
                 "inverse": f"exp({c[0]:.3g} + {c[1]:.3g} / {x})",
                 "quadratic": f"exp({c[0]:.3g} + {c[1]:.3g} {x} + {c[2]:.3g} {x}^2)" if len(c) > 2 else ""}
    else:
        lhs = f"measured - model of {f['response']} [N]"
        forms = {"linear": f"{c[0]:.3g} + {c[1]:.3g} {x}", "logarithmic": f"{c[0]:.3g} + {c[1]:.3g} ln {x}",
                 "inverse": f"{c[0]:.3g} + {c[1]:.3g} / {x}",
                 "quadratic": f"{c[0]:.3g} + {c[1]:.3g} {x} + {c[2]:.3g} {x}^2" if len(c) > 2 else ""}
    return f"{lhs} ~ {forms[f['form']]} ({f['form']} in {x}, R^2 {f['r_squared']:.2f}, p {f['p_value']:.2g})"


def run_gap(measured: Measured, backend: Any, *, candidates: list[str] | None = None, noise_cv: float | None = None,
            alpha_gap: float = ALPHA_GAP, alpha_lof: float = ALPHA_LOF, seed: int = 0) -> dict[str, Any]:
    """Run the loop; returns the report dict (see :mod:`deckgen.gap.report` for the files)."""
    responses = measured.responses
    J = len(responses)
    cases = measured.cases
    m = len(cases)
    Y = measured.means[responses].to_numpy(float)
    n = measured.counts.to_numpy(float)
    # ---- noise
    rows = measured.rows
    nu = float((measured.counts - 1).sum())
    if nu >= 2:
        dev = rows[responses].to_numpy(float) - measured.means.loc[rows["case_id"], responses].to_numpy(float)
        sigma = np.sqrt((dev**2).sum(axis=0) / nu)
        noise = {"source": "replicates", "dof": nu}
    else:
        cv = noise_cv if noise_cv is not None else backend.default_cv
        rms = np.sqrt(np.mean(Y**2, axis=0))
        sigma = cv * np.maximum(rms, 0.5 * rms.max())  # a side force near 0 scatters like the others
        nu = math.inf
        noise = {"source": f"assumed relative scatter {cv:g} (no replicates)", "dof": None}
    scale_floor = 1e-6 * max(float(np.abs(Y).max()), 1e-12)
    sigma = np.maximum(sigma, scale_floor)
    noise["sigma_N"] = {r: float(s) for r, s in zip(responses, sigma)}
    allr = np.ones(m, bool)
    M = m * J

    def lof_p(X: float, dof: float) -> float:
        dof = max(dof, 1.0)
        return float(stats.f.sf(X / dof, dof, nu)) if math.isfinite(nu) else float(stats.chi2.sf(X, dof))

    # ---- find
    B = backend.simulate(cases)[responses].to_numpy(float)
    if not np.isfinite(B).all():
        raise GapInputError("backend: the base model gave no value for some case (see the runs)")
    model_se = getattr(backend, "last_se", None)  # a backend averaging over packing seeds: its own noise
    if model_se is not None and len(model_se) == m:
        S = model_se[responses].to_numpy(float)
        # the model mean's variance joins the measured one: n_i/sigma_eff^2 = 1/(sigma^2/n_i + S_i^2), pooled
        # per response (sigma_eff^2 = sigma^2 + mean_i n_i S_i^2), so every statistic below sees both
        sigma = np.sqrt(sigma**2 + np.mean(n[:, None] * S**2, axis=0))
        noise["model_se_N"] = {r: float(v) for r, v in zip(responses, np.sqrt(np.mean(S**2, axis=0)))}
        noise["backend_packing_seeds"] = list(getattr(backend, "seeds", []) or [])
        noise["sigma_with_model_N"] = {r: float(s) for r, s in zip(responses, sigma)}
    W = n[:, None] / sigma[None, :] ** 2
    X0 = _x(Y, B, W, allr)
    p_gap = lof_p(X0, M)
    z0 = (Y - B) / (sigma[None, :] / np.sqrt(n[:, None]))
    held = _split(measured)
    fit_rows = ~held

    # ---- name
    base_rows = cases.to_dict("records")
    wanted = candidates or [e.id for e in CATALOGUE]
    unknown = [c for c in wanted if c not in BY_ID]
    if unknown:
        raise GapInputError(f"--candidates: unknown effect(s) {', '.join(unknown)} (fix: use ids from "
                            f"{', '.join(BY_ID)})")
    cands: list[Candidate] = []
    skipped: list[dict[str, str]] = []
    for eid in wanted:
        e = BY_ID[eid]
        if all(e.is_on(r) for r in base_rows):
            skipped.append({"id": eid, "reason": "already switched on in the base model (or given per case)"})
            continue
        if e.magnitude is not None and not e.given(measured.factors):
            grid = e.magnitude.grid(backend.grid_points)
        else:
            grid = None
        vals = [None] if grid is None else list(grid)
        preds, keep = [], []
        for g, th in enumerate(vals):
            try:
                P = backend.simulate(e.apply(cases, th, measured.factors))[responses].to_numpy(float)
            except GapInputError as exc:
                if grid is None:
                    skipped.append({"id": eid, "reason": str(exc)})
                continue
            if np.isfinite(P).all():
                preds.append(P)
                keep.append(g)
        if not preds:
            if grid is not None:
                skipped.append({"id": eid, "reason": "no magnitude in its range could be simulated"})
            continue
        cands.append(Candidate(e, None if grid is None else np.asarray(grid)[keep], np.stack(preds)))

    folds = _folds(m, seed) if m >= 3 else []
    ranking = []
    fits = {}
    for c in cands:
        theta, Xk, Pk = fit_candidate(c, Y, W, allr)
        fits[c.effect.id] = (theta, Xk, Pk)
        cvx = 0.0
        for te in folds:
            tr = np.ones(m, bool)
            tr[te] = False
            tmask = ~tr
            _, _, Pf = fit_candidate(c, Y, W, tr)
            cvx += _x(Y, Pf, W, tmask)
        cv_score = 1.0 - cvx / X0 if folds and X0 > 0 else math.nan
        k = c.n_params
        ranking.append({
            "id": c.effect.id, "score": float(cv_score), "cv_chi2": float(cvx) if folds else math.nan,
            "chi2": Xk, "delta_aic": float(Xk - X0 + 2 * k), "n_params": k,
            "lr_p_value": float(stats.chi2.sf(max(X0 - Xk, 0.0), max(k, 1))),
            "lack_of_fit_p_value": lof_p(Xk, M - k), "explained_fraction": float(1 - Xk / X0) if X0 > 0 else math.nan,
            "excess_explained_cv": float((X0 - cvx) / (X0 - M)) if folds and X0 > M else math.nan,
            "magnitude": theta, "magnitude_field": c.effect.magnitude.field if c.effect.magnitude else None,
            "magnitude_unit": c.effect.magnitude.unit if c.effect.magnitude else None,
        })
    ranking.sort(key=lambda r: (-(r["score"] if math.isfinite(r["score"]) else -math.inf), r["delta_aic"]))

    # ---- decide
    named, verdict = None, ""
    best = ranking[0] if ranking else None
    if p_gap >= alpha_gap:
        verdict = "within_noise"
        reason = (f"the base model's misfit is within noise (chi2 {X0:.1f} over {M} cells, p = {p_gap:.3g} >= "
                  f"{alpha_gap}): no effect is named")
    elif (best and best["score"] > 0 and best["delta_aic"] < -AIC_MARGIN and best["lack_of_fit_p_value"] >= alpha_lof
          and best["excess_explained_cv"] >= EXCESS_SHARE):
        named, verdict = best["id"], "named"
        reason = (f"{best['id']} removes {100 * best['score']:.0f} % of the misfit ({100 * best['excess_explained_cv']:.0f} % "
                  f"of the misfit above noise) out of sample (5-fold CV), Delta AIC {best['delta_aic']:.1f}, and leaves "
                  f"residuals consistent with noise (lack-of-fit p = {best['lack_of_fit_p_value']:.3g})")
    else:
        verdict = "unexplained"
        if best:
            reason = (f"no catalogued effect explains the residuals: the best, {best['id']}, removes "
                      f"{100 * max(best['excess_explained_cv'], 0):.0f} % of the misfit above noise out of sample "
                      f"(needed: {100 * EXCESS_SHARE:.0f} %) with lack-of-fit p = {best['lack_of_fit_p_value']:.2g} "
                      f"(needed: >= {alpha_lof})")
        else:
            reason = "no catalogued effect applies to this base case"

    # ---- add / show
    effect_parameters: dict[str, Any] = {}
    A = B
    if named is not None:
        c = next(c for c in cands if c.effect.id == named)
        theta, _, A = fit_candidate(c, Y, W, fit_rows)
        effect_parameters = {"id": named, "switch": dict(c.effect.switch),
                             "fitted_on_cases": int(fit_rows.sum()), "held_out_cases": int(held.sum())}
        if c.effect.magnitude is not None:
            mg = c.effect.magnitude
            effect_parameters.update({"field": mg.field, "unit": mg.unit,
                                      "value": theta if c.grid is not None else "given per case in MEASURED.csv",
                                      "value_all_cases": fits[named][0] if c.grid is not None else None,
                                      "range": [mg.lo, mg.hi]})
    forms = functional_forms(measured, Y, A if named else B, n, sigma, responses, alpha_gap) if verdict != "within_noise" else []
    forms_best = []
    if verdict == "unexplained" and best is not None:
        forms_best = functional_forms(measured, Y, fits[best["id"]][2], n, sigma, responses, alpha_gap)
    subsets = {"all": allr, "fit": fit_rows, "held_out": held}

    def gaps(P):
        out = {r: dict(v) for r, v in _gap(Y, P, allr, responses).items()}
        for s in ("fit", "held_out"):
            for r, v in _gap(Y, P, subsets[s], responses).items():
                out[r][s] = v
        return out

    std_before = {s: _std_gap(Y, B, sigma, rr) for s, rr in subsets.items()}
    std_after = {s: _std_gap(Y, A, sigma, rr) for s, rr in subsets.items()}
    zA = (Y - A) / (sigma[None, :] / np.sqrt(n[:, None]))
    per_case = []
    for i in range(m):
        row: dict[str, Any] = {"case_id": i, "subset": "held_out" if held[i] else "fit", "replicates": int(n[i])}
        for f in measured.factors:
            row[f] = cases.iloc[i][f]
        for j, r in enumerate(responses):
            row[f"{r}_measured"] = float(Y[i, j])
            row[f"{r}_base"] = float(B[i, j])
            row[f"{r}_after"] = float(A[i, j])
            row[f"{r}_z_before"] = float(z0[i, j])
            row[f"{r}_z_after"] = float(zA[i, j])
            row[f"{r}_exceeds_noise"] = bool(abs(z0[i, j]) > stats.norm.isf(alpha_gap / 2))
        per_case.append(row)
    return {
        "named_effect": named,
        "verdict": verdict,
        "reason": reason,
        "ranking": ranking,
        "skipped_candidates": skipped,
        "effect_parameters": effect_parameters,
        "gap_before": gaps(B),
        "gap_after": gaps(A),
        "gap_standardised": {"before": std_before, "after": std_after,
                             "reduction": {s: (1 - std_after[s] / std_before[s]) if std_before[s] else math.nan
                                           for s in subsets}},
        "gap_test": {"chi2": X0, "cells": M, "p_value": p_gap, "alpha": alpha_gap},
        "noise": noise,
        "residual_vs_factor": residual_factor_stats(measured, Y, B, n, sigma, responses),
        "residual_forms": [dict(f, description=_describe_form(f)) for f in forms],
        "residual_forms_after_best_candidate": [dict(f, description=_describe_form(f)) for f in forms_best],
        "per_case": per_case,
        "responses": responses,
        "factors": measured.factors,
        "cases": m,
        "rows": int(len(measured.rows)),
        "backend": backend.name,
        "catalogue": [e.card() for e in CATALOGUE],
    }
