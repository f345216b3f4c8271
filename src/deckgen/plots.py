"""PNG plots of one parsed run (a folder written by :func:`deckgen.results.parse_run`).

Uses matplotlib's object API with the Agg canvas (no pyplot, no global backend switch, safe in
worker processes). File names are ``<case>_<kind>.png``:

platen tests (UCS, BTS)
    ``stress_strain`` (stress in MPa over strain in %, peak marked, modulus fit window and line),
    ``broken_bonds`` (cumulative broken bonds over time, by failure mode),
    ``damage`` (failure pattern: grains coloured by broken/initial bonds, x-z plane).
cutting
    ``forces_time`` (normal, rolling and side force over time; steady window shaded, its means
    as dashed lines), ``forces_x`` (the same over the cutter x position; over the penetration for
    indentation: ``forces_penetration``), ``broken_bonds`` (cumulative, by failure mode),
    ``damage`` (x-z slice through y = 0, grains coloured by damage).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from deckgen.results import read_table

__all__ = ["plot_run"]

_COLORS = {"force_normal_N": "tab:blue", "force_rolling_N": "tab:red", "force_side_N": "tab:green",
           "tension": "tab:orange", "shear": "tab:purple", "unknown": "tab:gray", "total": "black"}
_LABELS = {"force_normal_N": "normal $F_n = F_z$", "force_rolling_N": "rolling $F_r = -F_x$",
           "force_side_N": "side $F_s = F_y$"}


def _figure() -> tuple[Figure, Any]:
    fig = Figure(figsize=(7.0, 4.5), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot(1, 1, 1)


def _save(fig: Figure, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    return path


def _finite(v: Any) -> bool:
    return isinstance(v, (int, float)) and v is not None and math.isfinite(float(v))


def _title(summary: dict[str, Any], what: str) -> str:
    return f"{summary['case']} ({summary['test']}, {summary['engine']}): {what}"


def _broken_plot(summary: dict[str, Any], bt: pd.DataFrame, path: Path) -> Path:
    fig, ax = _figure()
    t_ms = bt["time_s"].to_numpy() * 1e3
    ax.plot(t_ms, bt["bonds_broken"], color=_COLORS["total"], lw=1.8, label="all")
    for m in ("tension", "shear", "unknown"):
        col = f"bonds_broken_{m}"
        if len(bt) and bt[col].iloc[-1] > 0:
            ax.plot(t_ms, bt[col], color=_COLORS[m], lw=1.2, label=m)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("broken bonds (cumulative)")
    n0 = summary.get("n_bonds_initial")
    if _finite(n0) and n0:
        sec = ax.secondary_yaxis("right", functions=(lambda b: 100.0 * b / n0, lambda p: p * n0 / 100.0))
        sec.set_ylabel("broken fraction (%)")
    src = summary.get("mode_source", "none")
    ax.set_title(_title(summary, "broken bonds" + ("" if src != "none" else " (modes unknown: no bond samples)")))
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    return _save(fig, path)


def _stress_strain(summary: dict[str, Any], ts: pd.DataFrame, path: Path) -> Path:
    fig, ax = _figure()
    strain_pct = ts["strain_1"].to_numpy() * 100.0
    stress_mpa = ts["stress_Pa"].to_numpy() / 1e6
    label = "Brazilian tensile stress 2F/($\\pi$Dt)" if summary["test"] == "bts" else "axial stress"
    ax.plot(strain_pct, stress_mpa, color="tab:blue", lw=1.2, label=label)
    if _finite(summary.get("peak_stress_Pa")):
        ax.plot([summary["strain_at_peak_1"] * 100], [summary["peak_stress_Pa"] / 1e6], "o", color="tab:red",
                label=f"peak {summary['peak_stress_Pa'] / 1e6:.3g} MPa")
    if summary.get("split_source") == "crack" and _finite(summary.get("split_stress_Pa")):
        ax.plot([summary["split_strain_1"] * 100], [summary["split_stress_Pa"] / 1e6], "s", color="tab:green",
                label=f"split {summary['split_stress_Pa'] / 1e6:.3g} MPa (a crack's worth of bonds on the diameter)")
    key = "youngs_modulus_Pa" if summary["test"] == "ucs" else "secant_modulus_Pa"
    E, b = summary.get(key), summary.get("modulus_fit_intercept_Pa")
    if _finite(E) and _finite(b):
        lo, hi = summary["modulus_fit_stress_lo_Pa"], summary["modulus_fit_stress_hi_Pa"]
        ax.axhspan(lo / 1e6, hi / 1e6, color="0.85", alpha=0.6, label="fit window 20-50 % of peak")
        eps = np.array([(lo - b) / E, (hi - b) / E])
        name = "E" if summary["test"] == "ucs" else "secant modulus"
        ax.plot(eps * 100, (E * eps + b) / 1e6, "--", color="black", lw=1.0, label=f"{name} {E / 1e9:.3g} GPa")
    ax.set_xlabel("strain (%)" if summary["test"] == "ucs" else "diametral strain (%)")
    ax.set_ylabel("stress (MPa)")
    ax.set_title(_title(summary, "stress-strain"))
    ax.grid(alpha=0.3)
    ax.legend(loc="best")
    return _save(fig, path)


def _forces_time(summary: dict[str, Any], ts: pd.DataFrame, path: Path) -> Path:
    fig, ax = _figure()
    t_ms = ts["time_s"].to_numpy() * 1e3
    a, b = summary.get("steady_start_s"), summary.get("steady_end_s")
    if _finite(a) and _finite(b):
        ax.axvspan(a * 1e3, b * 1e3, color="0.9", label="steady window")
    for q in ("force_normal_N", "force_rolling_N", "force_side_N"):
        ax.plot(t_ms, ts[q], color=_COLORS[q], lw=0.9, label=_LABELS[q])
        m = summary.get(f"{q}_mean_steady")
        if _finite(m) and _finite(a) and _finite(b):
            ax.hlines(m, a * 1e3, b * 1e3, colors=_COLORS[q], linestyles="--", lw=1.6,
                      label=f"mean {m:.3g} N")
    ax.axhline(0.0, color="black", lw=0.5)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("force on the cutter (N)")
    ax.set_title(_title(summary, "cutting forces"))
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize="small", ncols=2)
    return _save(fig, path)


def _forces_x(summary: dict[str, Any], ts: pd.DataFrame, path: Path) -> Path:
    fig, ax = _figure()
    indent = summary.get("kinematics_mode") == "indentation"
    if indent:
        x = ts["penetration_m"].to_numpy() * 1e3
        ax.set_xlabel("penetration (mm)")
        fail = summary.get("penetration_at_failure_m")
        if _finite(fail):  # the first piece of the block off (deckgen.chips.detachment)
            n = summary.get("detachment_min_grains")
            ax.axvline(fail * 1e3, color="0.4", ls="--", lw=0.8,
                       label=f"first piece of {int(n)}+ grains off" if _finite(n) else "first piece off")
    else:
        x = ts["cutter_x_m"].to_numpy() * 1e3
        ax.set_xlabel("cutter centre x (mm)")
        a, b = summary.get("steady_start_s"), summary.get("steady_end_s")
        t = ts["time_s"].to_numpy()
        mask = (t >= a) & (t <= b) if _finite(a) and _finite(b) else np.zeros(len(t), bool)
        if mask.any():
            ax.axvspan(x[mask].min(), x[mask].max(), color="0.9", label="steady window")
    for q in ("force_normal_N", "force_rolling_N", "force_side_N"):
        ax.plot(x, ts[q], color=_COLORS[q], lw=0.9, label=_LABELS[q])
    ax.axhline(0.0, color="black", lw=0.5)
    ax.set_ylabel("force on the cutter (N)" if not indent else "force on the indenter (N)")
    ax.set_title(_title(summary, "forces vs penetration" if indent else "forces vs cutter position"))
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return _save(fig, path)


def _damage_snapshot(summary: dict[str, Any], dmg: pd.DataFrame, path: Path) -> Path | None:
    """Failure pattern: grains of the final frame as circles (true size) coloured by their damage
    ratio (broken / initial bonds), in the x-z plane: the whole Brazilian disc (its axis is y), a
    slice |y| < 1.5 r_max through the axis of a UCS cylinder or through y = 0 of a cutting block."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle

    d = dmg[np.isfinite(dmg["damage_ratio_1"].to_numpy(dtype=float))]
    if d.empty:
        return None
    if summary["test"] != "bts":
        d = d[np.abs(d["y_m"].to_numpy()) < 1.5 * float(d["radius_m"].max())]
    fig = Figure(figsize=(4.5 if summary["test"] == "ucs" else 6.5, 6.0), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    circles = [Circle((x * 1e3, z * 1e3), r * 1e3) for x, z, r in zip(d["x_m"], d["z_m"], d["radius_m"])]
    pc = PatchCollection(circles, cmap="inferno_r", edgecolor="0.4", linewidth=0.2)
    pc.set_array(d["damage_ratio_1"].to_numpy(dtype=float))
    pc.set_clim(0.0, 1.0)
    ax.add_collection(pc)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z (mm)")
    fig.colorbar(pc, ax=ax, label="damage: broken / initial bonds", shrink=0.8)
    what = "failure pattern (x-z, whole disc)" if summary["test"] == "bts" else "failure pattern (x-z slice through y = 0)"
    ax.set_title(_title(summary, what), fontsize="small")
    return _save(fig, path)


def _split_map(summary: dict[str, Any], ts: pd.DataFrame, broken: pd.DataFrame, path: Path) -> Path | None:
    """Brazilian disc: where its bonds broke, in the x-z plane, those broken by the split reading
    (deckgen.results.split_onset) dark and the later ones light, with the band along the loaded diameter that the
    reading counts (|x| < SPLIT_BAND R, |z - centre| < SPLIT_CORE R)."""
    from matplotlib.patches import Rectangle

    from deckgen.results import SPLIT_BAND, SPLIT_CORE

    if broken.empty or not _finite(summary.get("split_strain_1")):
        return None
    if summary.get("split_step") is not None:
        at = int(summary["split_step"])
    else:  # a summary written before split_step: the sample nearest its strain
        i = int(np.argmin(np.abs(ts["strain_1"].to_numpy(dtype=float) - float(summary["split_strain_1"]))))
        at = int(ts["step"].iloc[i])
    early = broken["step"].to_numpy() <= at
    fig = Figure(figsize=(6.5, 6.0), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    x, z = broken["x_m"].to_numpy() * 1e3, broken["z_m"].to_numpy() * 1e3
    ax.plot(x[~early], z[~early], ".", color="0.75", ms=4, label=f"broken after ({int((~early).sum())})")
    ax.plot(x[early], z[early], ".", color="tab:red", ms=5, label=f"broken by the split ({int(early.sum())})")
    R = 0.5 * float(summary.get("height_m", np.nan)) * 1e3
    if np.isfinite(R):
        # the band split_onset counted (older summaries: the disc standing on z = 0, loaded along x = 0)
        xc = 1e3 * float(summary["split_band_x_m"]) if _finite(summary.get("split_band_x_m")) else 0.0
        zc = 1e3 * float(summary["split_band_z_m"]) if _finite(summary.get("split_band_z_m")) else R
        ax.add_patch(Rectangle((xc - SPLIT_BAND * R, zc - SPLIT_CORE * R), 2 * SPLIT_BAND * R, 2 * SPLIT_CORE * R,
                               fill=False, ls="--", color="tab:green", label="counted band"))
        t = np.linspace(0, 2 * np.pi, 200)
        ax.plot(xc + R * np.cos(t), zc + R * np.sin(t), color="black", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z (mm)")
    ax.legend(loc="upper right", fontsize="small")
    src = summary.get("split_source")
    ax.set_title(_title(summary, f"broken bonds at the split ({src})"), fontsize="small")
    return _save(fig, path)


def plot_run(parsed_dir: str | Path, plots_dir: str | Path) -> list[Path]:
    """Write the PNG plots of one parsed run into ``plots_dir``; return their paths."""
    parsed_dir = Path(parsed_dir)
    plots_dir = Path(plots_dir)
    sp = parsed_dir / "summary.json"
    if not sp.is_file():
        raise FileNotFoundError(f"{sp}: no summary.json (run deckgen parse first)")
    summary = {k: (float("nan") if v is None else v) for k, v in json.loads(sp.read_text()).items()}
    ts = read_table(parsed_dir / "timeseries")
    bt = read_table(parsed_dir / "broken_timeseries")
    case = summary["case"]
    out: list[Path] = []
    if summary["test"] in ("ucs", "bts"):
        out.append(_stress_strain(summary, ts, plots_dir / f"{case}_stress_strain.png"))
    else:
        out.append(_forces_time(summary, ts, plots_dir / f"{case}_forces_time.png"))
        kind = "forces_penetration" if summary.get("kinematics_mode") == "indentation" else "forces_x"
        out.append(_forces_x(summary, ts, plots_dir / f"{case}_{kind}.png"))
    out.append(_broken_plot(summary, bt, plots_dir / f"{case}_broken_bonds.png"))
    if (parsed_dir / "damage.parquet").is_file() or (parsed_dir / "damage.csv").is_file():
        snap = _damage_snapshot(summary, read_table(parsed_dir / "damage"), plots_dir / f"{case}_damage.png")
        if snap is not None:
            out.append(snap)
    if summary["test"] == "bts" and "split_strain_1" in summary:
        split = _split_map(summary, ts, read_table(parsed_dir / "broken"), plots_dir / f"{case}_split.png")
        if split is not None:
            out.append(split)
    return out
