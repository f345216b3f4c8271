"""Files of a discrepancy run: report.json, report.md, parity and residual-vs-factor plots (PNG)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

SHORT = {"force_normal_N_mean_steady": "normal force [N]", "force_rolling_N_mean_steady": "rolling force [N]",
         "force_side_N_mean_steady": "side force [N]"}


def _safe(v: Any) -> Any:
    if isinstance(v, dict):
        return {str(k): _safe(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_safe(x) for x in v]
    if isinstance(v, (np.floating, float)):
        return float(v) if math.isfinite(v) else None
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, np.bool_):
        return bool(v)
    return v


def plot_parity(report: dict[str, Any], path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pc = pd.DataFrame(report["per_case"])
    rs = report["responses"]
    fig, axes = plt.subplots(1, len(rs), figsize=(4.2 * len(rs), 4.0), squeeze=False)
    for ax, r in zip(axes[0], rs):
        y = pc[f"{r}_measured"]
        for col, mk, lab in ((f"{r}_base", "o", "base model"), (f"{r}_after", "x", "with named effect")):
            if col.endswith("_after") and not report["named_effect"]:
                continue
            for sub, fill in (("fit", True), ("held_out", False)):
                s = pc["subset"] == sub
                ax.scatter(y[s], pc.loc[s, col], marker="+" if mk == "x" and not fill else mk,  # held-out: + / hollow o
                           s=60 if mk == "x" and not fill else None, facecolors=None if fill or mk == "x" else "none",
                           edgecolors="C0" if mk == "o" else None, color="C0" if mk == "o" else "C3",
                           label=f"{lab} ({sub.replace('_', '-')})")
        lo = float(min(y.min(), pc[[f"{r}_base", f"{r}_after"]].min().min()))
        hi = float(max(y.max(), pc[[f"{r}_base", f"{r}_after"]].max().max()))
        pad = 0.05 * (hi - lo or 1.0)
        ax.plot([lo - pad, hi + pad], [lo - pad, hi + pad], "k-", lw=0.8)
        ax.set_xlabel(f"measured {SHORT.get(r, r)}")
        ax.set_ylabel(f"simulated {SHORT.get(r, r)}")
        ax.set_title(SHORT.get(r, r).split(" [")[0])
    axes[0][0].legend(fontsize=7)
    named = report["named_effect"] or f"none ({report['verdict']})"
    fig.suptitle(f"parity before / after, named effect: {named}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_residuals(report: dict[str, Any], path: Path) -> Path | None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pc = pd.DataFrame(report["per_case"])
    facs = [f for f in report["factors"] if pd.to_numeric(pc[f], errors="coerce").notna().all() and pc[f].nunique() > 1]
    if not facs:
        facs = ["case_id"]
    rs = report["responses"]
    fig, axes = plt.subplots(len(rs), len(facs), figsize=(4.0 * len(facs), 2.8 * len(rs)), squeeze=False)
    for i, r in enumerate(rs):
        for k, f in enumerate(facs):
            ax = axes[i][k]
            x = pd.to_numeric(pc[f])
            ax.axhspan(-2, 2, color="0.9", label="|z| < 2 (noise)")
            ax.scatter(x, pc[f"{r}_z_before"], marker="o", color="C0", label="base model")
            if report["named_effect"]:
                ax.scatter(x, pc[f"{r}_z_after"], marker="x", color="C3", label="with named effect")
            ax.axhline(0, color="k", lw=0.6)
            ax.set_xlabel(f)
            ax.set_ylabel(f"z = residual / noise\n{SHORT.get(r, r).split(' [')[0]}", fontsize=8)
    axes[0][0].legend(fontsize=7)
    fig.suptitle("standardised residual (measured - model) vs factor", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _fmt(v: Any, f: str = ".3g") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "–"
    if isinstance(v, (int, float, np.floating)):
        return format(float(v), f)
    return str(v)


def markdown(report: dict[str, Any], measured_path: str, base_path: str) -> str:
    L = [f"# Discrepancy report: {report['named_effect'] or 'no effect named'}", "",
         f"Measured: `{measured_path}` ({report['rows']} rows, {report['cases']} cases); base case: `{base_path}`; "
         f"backend: `{report['backend']}`.", "",
         f"**Verdict: {report['verdict']}.** {report['reason']}.", ""]
    g = report["gap_test"]
    nz = report["noise"]
    L += ["## Find", "",
          f"Noise: {nz['source']}; sigma per response: " + ", ".join(f"{k} {v:.4g} N" for k, v in nz["sigma_N"].items())
          + "." + ("" if "model_se_N" not in nz else
                   f" The model is the mean over packing seeds {nz['backend_packing_seeds']}; its standard error ("
                   + ", ".join(f"{k} {v:.4g} N" for k, v in nz["model_se_N"].items()) + ") joins the noise: sigma "
                   + ", ".join(f"{k} {v:.4g} N" for k, v in nz["sigma_with_model_N"].items()) + "."),
          f"Base-model misfit: chi2 = {g['chi2']:.1f} over {g['cells']} case-response cells, p = {g['p_value']:.3g}.",
          "", "Residual vs factor (weighted least squares of measured - base model on each factor):", "",
          "| response | factor | slope [N/unit] | p-value | R² | ΔAIC vs constant |", "|---|---|---|---|---|---|"]
    for r in report["residual_vs_factor"]:
        L.append(f"| {r['response']} | {r['factor']} | {_fmt(r['slope_N_per_unit'])} | {_fmt(r['p_value'], '.2g')} | "
                 f"{_fmt(r['r_squared'], '.2f')} | {_fmt(r['delta_aic'], '.1f')} |")
    L += ["", "## Name", "", "Candidates ranked by the 5-fold cross-validated share of the base misfit they remove "
          "(magnitude refitted in every fold); ΔAIC = χ²_k − χ²_0 + 2 p_k; lack-of-fit p tests the remaining misfit "
          "against noise.", "",
          "| rank | effect | CV score | explained (all) | ΔAIC | LR p | lack-of-fit p | magnitude |",
          "|---|---|---|---|---|---|---|---|"]
    for i, r in enumerate(report["ranking"], 1):
        mag = f"{_fmt(r['magnitude'], '.4g')} {r['magnitude_unit']}" if r["magnitude_field"] and r["magnitude"] is not None else "–"
        L.append(f"| {i} | {r['id']} | {_fmt(r['score'], '.3f')} | {_fmt(r['explained_fraction'], '.3f')} | "
                 f"{_fmt(r['delta_aic'], '.1f')} | {_fmt(r['lr_p_value'], '.2g')} | {_fmt(r['lack_of_fit_p_value'], '.2g')} | {mag} |")
    for s in report["skipped_candidates"]:
        L.append(f"\nNot a candidate: {s['id']} ({s['reason']}).")
    if report["named_effect"]:
        card = next(c for c in report["catalogue"] if c["id"] == report["named_effect"])
        L += ["", f"### {card['name']}", "", card["explanation"], "", f"Signature: {card['signature']}.", ""]
    if report["residual_forms"]:
        L += ["", "Functional form of the remaining residuals (best AIC per response):", ""]
        L += [f"- {f['description']}" for f in report["residual_forms"]]
    if report.get("residual_forms_after_best_candidate"):
        L += ["", f"What remains once the best candidate ({report['ranking'][0]['id']}) is added:", ""]
        L += [f"- {f['description']}" for f in report["residual_forms_after_best_candidate"]]
    ep = report["effect_parameters"]
    if ep:
        L += ["", "## Add", "", f"Switch: `{json.dumps(ep['switch'])}`" + (
            f"; magnitude `{ep['field']}` = {_fmt(ep['value'], '.4g')} {ep['unit']} fitted on {ep['fitted_on_cases']} "
            f"cases ({_fmt(ep.get('value_all_cases'), '.4g')} on all cases)" if "field" in ep else "") + "."]
    L += ["", "## Show", "", "| response | subset | RMSE before [N] | RMSE after [N] | MAPE before [%] | MAPE after [%] |",
          "|---|---|---|---|---|---|"]
    for r in report["responses"]:
        b, a = report["gap_before"][r], report["gap_after"][r]
        for s in ("all", "fit", "held_out"):
            bb, aa = (b, a) if s == "all" else (b[s], a[s])
            L.append(f"| {r} | {s} | {_fmt(bb['rmse'], '.4g')} | {_fmt(aa['rmse'], '.4g')} | {_fmt(bb['mape'], '.3g')} | "
                     f"{_fmt(aa['mape'], '.3g')} |")
    red = report["gap_standardised"]["reduction"]
    L += ["", "Standardised gap (RMS of residual / noise over all responses) reduction: " +
          ", ".join(f"{s} {_fmt(100 * v if v is not None and math.isfinite(v) else v, '.0f')} %" for s, v in red.items()) + ".",
          "", "![parity](parity.png)", "", "![residuals](residuals.png)", ""]
    return "\n".join(L)


def write_report(report: dict[str, Any], out: Path, measured_path: str, base_path: str) -> dict[str, Path]:
    out.mkdir(parents=True, exist_ok=True)
    files = {"json": out / "report.json", "md": out / "report.md"}
    files["json"].write_text(json.dumps(_safe(report), indent=2) + "\n")
    pd.DataFrame(report["per_case"]).to_csv(out / "per_case.csv", index=False)
    files["parity"] = plot_parity(report, out / "parity.png")
    files["residuals"] = plot_residuals(report, out / "residuals.png")
    files["md"].write_text(markdown(report, measured_path, base_path))
    return files
