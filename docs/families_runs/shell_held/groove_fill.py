"""How much rock does the disc's groove hold along the cut, in the packing as rendered (session 43)?

A linear cut at penetration p removes the groove: the disc's cross-section profile (``deckgen.deck.cutter_profile``,
its tip p below the block's nominal top) up to the highest grain top, swept along x. With p 0.95 mm (the reduced p 1.9 mm cut) and grains of radius
0.35-0.5 mm (the band) the top layer's roughness is a sizeable part of the groove, so the rock the disc meets may vary
along the cut from the packing alone. This script measures it before any cutting: the grain volume inside the groove
per slice of x (sample points on a regular grid in the groove, each inside a grain or not), as the solid fraction of
the groove, and per window of the cut (``compare.PATCH_WINDOWS``, loaded from there: the contact-patch centre
between ``lo`` and ``lo + 0.2`` of the block length) over three ranges of x (:data:`RANGES`): the rock the patch touches in the window
(the centre's range extended by half the patch chord either side), the centre's range, and the rock the disc's
leading edge enters in the window.

    python docs/families_runs/shell_held/groove_fill.py X [X ...] [--slice-mm 0.1] [--out CSV] [--windows-out CSV] \
        [--pair-windows docs/families_runs/shell_held/linear_grain_pair_windows.csv] [--layers-out CSV]
    python docs/families_runs/shell_held/groove_fill.py --dumps X [X ...] [--ahead-mm 2] [--out CSV]
    python docs/families_runs/shell_held/groove_fill.py --rendered-at-dumps DUMPS_CSV X [X ...] [--out CSV]

``X`` is a rendered run folder (``spec.json`` and ``specimen.data``; ``deckgen render`` alone is enough, no run
needed). The rendered grains are the packing's shrunk by ``bonds.shrink_before_bonding`` (2 %), so the packing's
own ``packed.data`` would overstate the fill by ~6 %. Prints per run the windows' solid fraction and grain volume;
with ``--pair-windows`` (the runs' recorded F_n per window, ``compare.py --pair-windows``) also the rank correlation of
F_n with the fill per penetration (:func:`against_forces`). These correlations describe the recorded runs; the windows
overlap and a trend along the cut shared by the runs can make a link where there is none (the ``two-way`` rows take
it off), so they are not tests of a cause. ``--layers-out`` writes the touched range's fill per layer above the
disc's tip (:func:`layer_fill`). With ``--dumps`` (``X/run`` run, ``X/parsed`` parsed) it follows the cut instead: at
each dump the groove's fill under the disc and just ahead of it, by the body and by every grain
(:func:`body_fill_at_dumps`): where the rock the disc meets next is still part of the body, loose, or gone. With
``--rendered-at-dumps`` (a ``--dumps`` table and the runs' renders) it sets each dump beside the packing as rendered
(:func:`rendered_at_dumps`): the fill ahead of the leading edge over 1-10 mm and under the disc, ranked with F_n.
"""
from __future__ import annotations

import argparse
import functools
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

#: sample spacing [m] of the grid in the groove (0.04 mm: ~9 points across the smallest grain radius, 0.35 mm)
STEP_M = 4e-5
#: nearest grain centres tested per sample point (a point may lie in a large grain whose centre is farther than some
#: small grains' centres; session 43's review found no miss with 8 on the band's 0.35 / 1.0 mm grains, 16 for margin)
NEAREST = 16


def groove_geometry(case) -> dict[str, float | np.ndarray]:
    """The groove's cross-section (profile polygon in (depth below the disc centre, y)), the disc centre height (the
    deck's, ``deck.cutter_path``) and radius [m] of a validated linear cutting case."""
    from deckgen.deck import cutter_path, cutter_profile

    if case.kinematics.mode != "linear":
        raise SystemExit(f"{case.name}: kinematics.mode is {case.kinematics.mode!r}; the groove is a linear cut's")
    if case.cutter.kind not in ("ccs_disc", "v_disc") or case.cutter.tilt_deg != 0:
        raise SystemExit(f"{case.name}: cutter {case.cutter.kind!r} tilted {case.cutter.tilt_deg} deg; the groove is the "
                         "profile of an untilted ccs_disc or v_disc swept along x")
    prof = cutter_profile(case)
    radius = float(prof[:, 0].max())
    return {"profile": prof, "radius_m": radius, "centre_z_m": cutter_path(case, radius)["zc0"]}


def cut_geometry(case) -> tuple[dict, float, float]:
    """(:func:`groove_geometry`, the block's length [m], the contact patch's half chord [m]) of a linear cutting case."""
    from deckgen.families import half_chord_mm

    geo = groove_geometry(case)
    return geo, case.specimen.length_mm * 1e-3, half_chord_mm(geo["radius_m"] * 1e3, case.kinematics.penetration_mm) * 1e-3


def solid_in_groove(x: np.ndarray, r: np.ndarray, geo: dict, length_m: float, slice_m: float = 1e-4,
                    step_m: float = STEP_M, top_m: float | None = None, from_m: float = 0.0) -> pd.DataFrame:
    """Per slice of x along the block (``from_m``, default 0, to ``length_m``): the groove's sample points and how many
    lie inside a grain.

    The groove is every point inside the disc's profile (as ``deck.neighbour_groove_mask`` takes it) and below
    ``top_m`` (default: the highest grain top, as grains standing above the block's nominal top meet the disc too); a
    point is solid when it lies within a grain's radius of the grain's centre.
    """
    rows = []
    for lo, hi, z, solid, area in _sampled_slices(x, r, geo, length_m, slice_m, step_m, top_m, from_m):
        rows.append({"x_lo_m": lo, "x_hi_m": hi, "points": len(z), "solid_points": int(solid.sum()),
                     "groove_area_m2": area})
    t = pd.DataFrame(rows)
    t["solid_fraction_1"] = t["solid_points"] / t["points"]
    t["grain_volume_m3"] = t["solid_fraction_1"] * t["groove_area_m2"] * (t["x_hi_m"] - t["x_lo_m"])
    return t


def _sampled_slices(x: np.ndarray, r: np.ndarray, geo: dict, length_m: float, slice_m: float, step_m: float,
                    top_m: float | None, from_m: float):
    """:func:`solid_in_groove`'s sampling, per slice: (x low, x high, each sample point's z, whether it is solid, the
    groove's sampled cross-section area). A grid of rows (i + 1/2) steps above the disc's tip in the groove's
    cross-section, repeated on evenly spaced planes of x in each slice."""
    from matplotlib.path import Path as MplPath
    from scipy.spatial import cKDTree

    prof, zc, radius = geo["profile"], geo["centre_z_m"], geo["radius_m"]
    top = float((x[:, 2] + r).max()) if top_m is None else top_m
    # y over the disc's whole width: contains_points keeps the groove (the profile's flanks are single edges, so its
    # vertices near the tip would understate the groove's width)
    half_w = float(np.abs(prof[:, 1]).max()) + step_m
    ys = np.arange(-half_w, half_w + step_m / 2, step_m)
    zs = np.arange(zc - radius + step_m / 2, top, step_m)
    yy, zz = np.meshgrid(ys, zs, indexing="ij")
    inside = MplPath(prof).contains_points(np.column_stack([zc - zz.ravel(), yy.ravel()]))
    yz = np.column_stack([yy.ravel()[inside], zz.ravel()[inside]])
    tree = cKDTree(x)
    rmax = float(r.max())
    k = min(NEAREST, len(x))
    # slices of equal length covering from_m to length_m, each sampled on the same number of evenly spaced planes
    edges = np.linspace(from_m, length_m, max(1, round((length_m - from_m) / slice_m)) + 1)
    for lo, hi in zip(edges[:-1], edges[1:]):
        n = max(1, round((hi - lo) / step_m))
        xs = lo + (np.arange(n) + 0.5) * (hi - lo) / n
        pts = np.column_stack([np.repeat(xs, len(yz)), np.tile(yz, (len(xs), 1))])
        d, j = tree.query(pts, k=k, distance_upper_bound=rmax)
        rj = np.where(j < len(x), r[np.minimum(j, len(x) - 1)], 0.0)
        yield lo, hi, pts[:, 2], (d < rj).any(axis=1), len(yz) * step_m**2


#: x ranges of a window [lo, lo + 0.2] of the patch centre (fractions of the block length L; h = the patch's half chord):
#: the rock the patch touches in the window, the patch centre's own range, the rock the disc's leading edge enters
RANGES = {"touched": (-0.5, 0.5), "centre": (0.0, 0.0), "front": (0.5, 0.5)}


@functools.cache
def _patch_windows() -> tuple[float, ...]:
    """compare.py's PATCH_WINDOWS (the windows' contact-patch starts), loaded once."""
    from deckgen.scriptload import load_script

    return tuple(load_script(Path(__file__).resolve().parent / "compare.py", "shell_held_compare").PATCH_WINDOWS)


def range_weights(slices: pd.DataFrame, lo: float, tag: str, length_m: float, half_chord_m: float) -> np.ndarray:
    """Each slice's share inside the range ``tag`` of :data:`RANGES` of the window starting at ``lo`` (from
    lo * L + a * h to (lo + 0.2) * L + b * h)."""
    pa, pb = RANGES[tag]
    return span_weights(slices, lo * length_m + pa * half_chord_m, (lo + 0.2) * length_m + pb * half_chord_m)


def span_weights(slices: pd.DataFrame, a: float, b: float) -> np.ndarray:
    """Each slice's share (0-1) inside x from ``a`` to ``b`` [m]."""
    x0, x1 = slices["x_lo_m"].to_numpy(), slices["x_hi_m"].to_numpy()
    return np.clip(np.minimum(x1, b) - np.maximum(x0, a), 0.0, None) / (x1 - x0)


def weighted_fill(slices: pd.DataFrame, w: np.ndarray) -> float:
    """The groove's solid fraction over the slices, each weighted by ``w`` (its share inside a range)."""
    return float((w * slices["solid_points"]).sum() / (w * slices["points"]).sum())


def window_fill(slices: pd.DataFrame, length_m: float, half_chord_m: float) -> pd.DataFrame:
    """Per window (patch centre from lo to lo + 0.2 of the block), the groove's solid fraction and grain volume over
    each range of :data:`RANGES`, each slice weighted by the part of it inside the range (:func:`range_weights`)."""
    rows = []
    for lo in _patch_windows():
        row = {"patch_lo_1": lo}
        for tag in RANGES:
            w = range_weights(slices, lo, tag, length_m, half_chord_m)
            row[f"solid_fraction_{tag}_1"] = weighted_fill(slices, w)
            row[f"grain_volume_{tag}_mm3"] = float((w * slices["grain_volume_m3"]).sum() * 1e9)
        rows.append(row)
    return pd.DataFrame(rows)


def layer_fill(x: np.ndarray, r: np.ndarray, geo: dict, length_m: float, half_chord_m: float,
               heights_mm: tuple[float, ...] = (0.2, 0.4, 0.6, 0.8), where: str = "touched",
               slice_m: float = 1e-4) -> pd.DataFrame:
    """Per window (:func:`window_fill`'s, over the range ``where`` of :data:`RANGES`), the groove's solid fraction in
    layers above the disc's tip: from the tip to ``heights_mm[0]`` above it, between consecutive heights, and from the
    last height to the groove's top (the highest grain top; ``layer_hi_mm`` NaN). Each layer's fraction is the share
    of :func:`solid_in_groove`'s sample points between its two bounds that lie in a grain, from one pass over the grid
    (each point counted in the layer its z falls in), so the layers' points add up to the whole groove's; ``points``
    is that count weighted by each slice's overlap with the range (fractional). The grid's rows lie at (i + 1/2) grid steps above the
    tip, so the heights must be whole multiples of the step (0.04 mm; no row then sits on a bound), increasing, and
    below the groove's top (session 44: whether the rock standing across the tip plane carries the link of the
    windows' F_n with the fill)."""
    tip = geo["centre_z_m"] - geo["radius_m"]
    top = float((x[:, 2] + r).max())
    if where not in RANGES:
        raise ValueError(f"layer_fill: range {where!r} is not one of {', '.join(RANGES)}")
    h = np.asarray(heights_mm, dtype=float) * 1e-3
    steps = h / STEP_M
    if (len(h) == 0 or np.any(np.abs(steps - np.round(steps)) > 1e-6) or np.any(np.diff(h) <= 0) or h[0] <= 0
            or tip + h[-1] >= top):
        raise ValueError(f"layer_fill: heights {tuple(heights_mm)} mm must be increasing, positive multiples of the "
                         f"grid step {STEP_M * 1e3:g} mm and below the groove's top ({(top - tip) * 1e3:.3f} mm above "
                         "the tip)")
    bounds_m = tip + h
    n_layers = len(h) + 1
    per_slice = []  # per slice: x range, then solid points and points per layer
    for lo, hi, z, solid, _ in _sampled_slices(x, r, geo, length_m, slice_m, STEP_M, None, 0.0):
        layer = np.searchsorted(bounds_m, z)  # 0 below the first bound ... len(h) above the last
        per_slice.append((lo, hi, np.bincount(layer[solid], minlength=n_layers),
                          np.bincount(layer, minlength=n_layers)))
    t = pd.DataFrame({"x_lo_m": [p[0] for p in per_slice], "x_hi_m": [p[1] for p in per_slice]})
    solid_k = np.array([p[2] for p in per_slice], dtype=float)  # slices x layers
    points_k = np.array([p[3] for p in per_slice], dtype=float)
    rows = []
    bounds = (0.0, *heights_mm, float("nan"))
    for lo in _patch_windows():
        w = range_weights(t, lo, where, length_m, half_chord_m)
        solid, pts = w @ solid_k, w @ points_k
        for k in range(n_layers):
            rows.append({"patch_lo_1": lo, "layer_lo_mm": bounds[k], "layer_hi_mm": bounds[k + 1],
                         "points": pts[k], "solid_fraction_1": solid[k] / pts[k]})
    return pd.DataFrame(rows)


def body_fill_at_dumps(run: Path, parsed: Path, ahead_m: float = 2e-3) -> pd.DataFrame:
    """At each dumped step of a run, the groove's solid fraction over two ranges of x: ``under``, from the disc
    centre's x to its leading edge (the centre plus the half chord: the contact patch, where the disc itself fills
    part of the groove), and ``ahead``, from the leading edge to ``ahead_m`` beyond it (the rock the disc meets next);
    each filled by the body (the largest component of the bond graph with the bonds broken so far,
    ``deckgen.chips.bond_components``) and by every rock grain (``all``; all minus body is the detached grains'). The
    groove's top is the rendered packing's highest grain top. With the step's patch centre (fraction of the block) and
    F_n averaged over the series rows since the dump before (``force_normal_N_before``, NaN at the first dump) and up to
    the dump after (``force_normal_N_after``; the last dump's up to the series' end); one row per dump, the case named
    in ``case``."""
    from deckgen.chips import bond_components, initial_bonds
    from deckgen.parse.dump import iter_frames

    case, x0, r0 = load(run)
    top = float((x0[:, 2] + r0).max())
    geo, length_m, hc = cut_geometry(case)
    bonds = initial_bonds(run)
    broken = pd.read_parquet(parsed / "broken.parquet", columns=["step", "id1", "id2"])
    ts = pd.read_parquet(parsed / "timeseries.parquet", columns=["step", "cutter_x_m", "force_normal_N"])
    rows = []
    for fr in iter_frames(run / "atoms.dump.gz", ["id", "type", "radius", "x", "y", "z"]):  # streamed
        rock = fr.data[fr.data["type"] == 1]
        ids = rock["id"].to_numpy(np.int64)
        xyz, rad = rock[["x", "y", "z"]].to_numpy(float), rock["radius"].to_numpy(float)
        pairs = broken.loc[broken["step"] <= fr.timestep, ["id1", "id2"]].to_numpy(np.int64)
        label, _, body = bond_components(bonds, pairs, ids)
        xc = float(np.interp(fr.timestep, ts["step"], ts["cutter_x_m"]))
        row = {"case": case.name, "step": fr.timestep, "patch_centre_1": (xc + hc / 2) / length_m}
        for where, (a, b) in (("under", (xc, xc + hc)), ("ahead", (xc + hc, xc + hc + ahead_m))):
            a, b = max(a, 0.0), min(b, length_m)
            for tag, keep in (("body", label == body), ("all", np.ones(len(ids), bool))):
                if b - a < 1e-4:  # the range is off the block
                    row[f"solid_fraction_{tag}_{where}_1"] = np.nan
                    continue
                t = solid_in_groove(xyz[keep], rad[keep], geo, b, slice_m=b - a, top_m=top, from_m=a)
                row[f"solid_fraction_{tag}_{where}_1"] = float(t["solid_points"].sum() / t["points"].sum())
        rows.append(row)
    d = pd.DataFrame(rows)
    steps, f = ts["step"].to_numpy(), ts["force_normal_N"].to_numpy(float)
    edges = d["step"].to_numpy()
    before, after = [], []
    for i, s0 in enumerate(edges):
        prev = (steps > edges[i - 1]) & (steps <= s0) if i else np.zeros(len(steps), bool)
        nxt = (steps >= s0) & (steps < edges[i + 1]) if i + 1 < len(edges) else steps >= s0
        before.append(float(f[prev].mean()) if prev.any() else np.nan)
        after.append(float(f[nxt].mean()) if nxt.any() else np.nan)
    d.insert(3, "force_normal_N_before", before)
    d.insert(4, "force_normal_N_after", after)
    return d


def rendered_at_dumps(slices: pd.DataFrame, dumps: pd.DataFrame, length_m: float, half_chord_m: float,
                      ahead_mm: tuple[float, ...] = (1.0, 2.0, 5.0, 10.0), from_patch: float = 0.05) -> pd.DataFrame:
    """At each dump of a :func:`body_fill_at_dumps` table past the patch centre ``from_patch`` (fraction of the block),
    the groove's fill AS RENDERED (``slices``, :func:`solid_in_groove` of the run's rendered packing) from the disc's
    leading edge to ``a`` mm beyond it for each ``a`` of ``ahead_mm`` (``solid_fraction_rendered_ahead<a>mm_1``) and
    under the disc, from its centre to its leading edge (``solid_fraction_rendered_under_1``), beside the dump's F_n
    (session 45: whether the rock the disc meets at the moment, not the stretch it crosses in a window, sets F_n). A
    range that does not lie wholly on the block (0 to the block's length) is NaN, so every value of a column is taken
    over the same length. The disc centre is the patch centre minus half the half chord, as
    :func:`body_fill_at_dumps` puts it."""
    d = dumps[dumps["patch_centre_1"] > from_patch].reset_index(drop=True)
    if d.empty:
        raise ValueError(f"rendered_at_dumps: no dump past patch {from_patch}")
    out = d[["case", "step", "patch_centre_1", "force_normal_N_before", "force_normal_N_after"]].copy()
    centre = d["patch_centre_1"].to_numpy() * length_m - half_chord_m / 2
    edge = centre + half_chord_m

    def fill(a: float, b: float) -> float:
        if a < 0.0 or b > length_m:
            return float("nan")
        return weighted_fill(slices, span_weights(slices, a, b))

    for mm in ahead_mm:
        out[f"solid_fraction_rendered_ahead{mm:g}mm_1"] = [fill(e, e + mm * 1e-3) for e in edge]
    out["solid_fraction_rendered_under_1"] = [fill(c, e) for c, e in zip(centre, edge)]
    return out


def dump_links(table: pd.DataFrame, from_patch: float = 0.05) -> pd.DataFrame:
    """Spearman's rho of F_n up to the next dump with each fill column of a :func:`body_fill_at_dumps` or
    :func:`rendered_at_dumps` table, per case, over the dumps past the patch centre ``from_patch`` (before it the
    disc has hardly entered the block) where both are known. The p values are nominal: neighbouring dumps share their
    rock and a loading cycle spans several dumps, so the dumps are not independent."""
    from scipy.stats import spearmanr

    rows = []
    for case, g in table[table["patch_centre_1"] > from_patch].groupby("case", sort=False):
        for col in (c for c in g.columns if c.startswith("solid_fraction_")):
            ok = g[col].notna() & g["force_normal_N_after"].notna()
            rho, p = spearmanr(g.loc[ok, col], g.loc[ok, "force_normal_N_after"])
            rows.append({"case": case, "fill": col, "dumps": int(ok.sum()), "spearman_rho_1": rho, "p_nominal_1": p})
    return pd.DataFrame(rows)


def within_run_permutation(groups: list[tuple[np.ndarray, np.ndarray]], max_exact: int = 10**7,
                           draws: int = 200_000, seed: int = 43) -> tuple[float, float]:
    """The mean over runs of each run's own Spearman rho (fill against F_n over its windows) and its two-sided p under
    the null that within each run F_n is unrelated to the fill: every run's F_n permuted over its windows on its own
    (all orders when their product is at most ``max_exact``, else ``draws`` random ones). Overlapping windows and a
    trend of F_n along the cut common to the runs are allowed for: only the order within each run is exchanged."""
    import itertools

    from scipy.stats import spearmanr

    def rho(x, y):
        return float(spearmanr(x, y)[0])

    obs = float(np.mean([rho(x, y) for x, y in groups]))
    per_run = [np.array([rho(x, np.asarray(perm)) for perm in itertools.permutations(y)]) for x, y in groups]
    sizes = [len(v) for v in per_run]
    if np.prod(sizes, dtype=float) <= max_exact:
        total = np.zeros(1)
        for v in per_run:
            total = np.add.outer(total, v).ravel()
    else:
        rng = np.random.default_rng(seed)
        total = sum(v[rng.integers(0, len(v), draws)] for v in per_run)
    null = total / len(groups)
    return obs, float(np.mean(np.abs(null) >= abs(obs) - 1e-12))


def against_forces(fill: pd.DataFrame, pair_windows: pd.DataFrame) -> pd.DataFrame:
    """The windows' F_n against their fill, per penetration and fill range: Spearman's rho ``pooled`` over every run's
    windows; ``within``, after taking each run's mean over its windows off both (the run's level left out); ``two-way``,
    after also taking each window's mean over the runs off (a trend along the cut common to the runs left out). Their
    p values are nominal: the windows overlap (by half their patch range, more with the touched range) and runs that
    share a packing share its fill. ``within-run`` is the mean of each run's own rho with the permutation p of
    :func:`within_run_permutation` (exact up to 10^7 joint orders, five runs of four windows; from 200 000 random
    ones beyond), which needs neither independence between a run's windows nor no common trend."""
    from scipy.stats import spearmanr

    f = pair_windows[["case", "patch_lo_1", "force_normal_N_mean_steady"]]
    m = fill.merge(f, on=["case", "patch_lo_1"], how="inner", validate="one_to_one")
    missing = sorted(set(fill["case"]) - set(m["case"]))
    if missing:
        raise SystemExit(f"--pair-windows has no windows of {', '.join(missing)} (fix: pass the runs' pair windows)")
    fn = "force_normal_N_mean_steady"
    rows = []
    for pen, g in m.groupby("penetration_mm"):
        for metric in (f"solid_fraction_{tag}_1" for tag in RANGES):
            hows = ("pooled", "within", "two-way", "within-run") if g["case"].nunique() > 1 else ("within-run",)
            for how in hows:
                x, y = g[metric], g[fn]
                if how == "within-run":
                    groups = [(h[metric].to_numpy(), h[fn].to_numpy()) for _, h in g.groupby("case")]
                    rho, p = within_run_permutation(groups)
                else:
                    if how in ("within", "two-way"):
                        x = x - g.groupby("case")[metric].transform("mean")
                        y = y - g.groupby("case")[fn].transform("mean")
                    if how == "two-way":
                        x = x - x.groupby(g["patch_lo_1"]).transform("mean")
                        y = y - y.groupby(g["patch_lo_1"]).transform("mean")
                    rho, p = spearmanr(x, y)
                rows.append({"penetration_mm": pen, "fill": metric, "how": how, "runs": g["case"].nunique(),
                             "windows": len(g), "spearman_rho_1": rho, "p_1": p})
    return pd.DataFrame(rows)


def load(run: Path):
    """(case, rock grain positions [m], radii [m]) of a rendered run folder."""
    from deckgen.datafile import iter_section
    from deckgen.spec import Case

    spec = json.loads((run / "spec.json").read_text())["case"]
    case = Case.model_validate({k: v for k, v in spec.items() if k != "test"})
    # the rendered data file is atom_style bpm/sphere: id molecule type diameter density x y z
    raw = np.array([[float(v) for v in f[:8]] for _, f in iter_section(run / "specimen.data", "Atoms")])
    rock = raw[:, 2] == 1
    return case, raw[rock, 5:8], raw[rock, 3] / 2.0


def _load_render(run: Path):
    """:func:`load` of a folder written by ``deckgen render``, with a clear error where it is not one."""
    for need in ("spec.json", "specimen.data"):
        if not (run / need).is_file():
            raise SystemExit(f"{run}: no {need}; give a folder written by deckgen render")
    return load(run)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", type=Path)
    ap.add_argument("--slice-mm", type=float, default=0.1)
    ap.add_argument("--out", type=Path, help="per-slice table (CSV)")
    ap.add_argument("--windows-out", type=Path, help="per-window table (CSV)")
    ap.add_argument("--pair-windows", type=Path, help="the runs' F_n per window (compare.py --pair-windows CSV)")
    ap.add_argument("--dumps", action="store_true",
                    help="each argument is a folder X with X/run (run) and X/parsed (deckgen parse): the fill under and "
                         "ahead of the disc at each dump (body_fill_at_dumps) instead")
    ap.add_argument("--ahead-mm", type=float, default=2.0, help="--dumps: how far beyond the disc's leading edge")
    ap.add_argument("--rendered-at-dumps", type=Path, metavar="DUMPS_CSV",
                    help="a --dumps table (groove_fill_dumps.csv): for each rendered run X whose case it holds, the "
                         "rendered fill ahead of and under the disc at its dumps and their rank correlation with F_n "
                         "(rendered_at_dumps, dump_links); --out writes the per-dump table")
    ap.add_argument("--layers-out", type=Path,
                    help="per window and layer above the tip (layer_fill, touched range; heights 0.2/0.4/0.6/0.8 mm)")
    a = ap.parse_args(argv)
    if a.dumps:
        tables = []
        for x in a.runs:
            for need in (x / "run" / "spec.json", x / "run" / "atoms.dump.gz", x / "parsed" / "broken.parquet"):
                if not need.is_file():
                    raise SystemExit(f"{need}: missing (fix: deckgen render/run into X/run, deckgen parse X/run --out "
                                     "X/parsed)")
            d = body_fill_at_dumps(x / "run", x / "parsed", a.ahead_mm * 1e-3)
            tables.append(d)
            with pd.option_context("display.width", 250, "display.max_columns", 20):
                print(d.drop(columns="case").round(3).to_string(index=False))
        if a.out:
            pd.concat(tables).to_csv(a.out, index=False, float_format="%.6g")
        return 0
    if a.rendered_at_dumps:
        dumps = pd.read_csv(a.rendered_at_dumps)
        tables = []
        for run in a.runs:
            case, x, r = _load_render(run)
            mine = dumps[dumps["case"] == case.name]
            if mine.empty:
                raise SystemExit(f"{a.rendered_at_dumps}: no dumps of {case.name} (fix: groove_fill.py --dumps on its "
                                 "run, or give its render)")
            geo, length_m, hc = cut_geometry(case)
            tables.append(rendered_at_dumps(solid_in_groove(x, r, geo, length_m, a.slice_mm * 1e-3), mine, length_m, hc))
        t = pd.concat(tables)
        with pd.option_context("display.width", 250):
            print(dump_links(t).to_string(index=False, float_format=lambda v: f"{v:.3f}"))
        if a.out:
            t.to_csv(a.out, index=False, float_format="%.6g")
        return 0
    all_slices, all_windows, all_layers = [], [], []
    for run in a.runs:
        case, x, r = _load_render(run)
        geo, length_m, hc = cut_geometry(case)
        slices = solid_in_groove(x, r, geo, length_m, a.slice_mm * 1e-3)
        win = window_fill(slices, length_m, hc)
        for t in (slices, win):
            t.insert(0, "penetration_mm", case.kinematics.penetration_mm)
            t.insert(0, "packing_seed", case.packing.seed)
            t.insert(0, "case", case.name)
        all_slices.append(slices)
        all_windows.append(win)
        if a.layers_out:
            lay = layer_fill(x, r, geo, length_m, hc, slice_m=a.slice_mm * 1e-3)
            for col, v in (("penetration_mm", case.kinematics.penetration_mm), ("packing_seed", case.packing.seed),
                           ("case", case.name)):
                lay.insert(0, col, v)
            all_layers.append(lay)
        print(f"== {case.name} (packing {case.packing.seed}, {len(x)} rock grains): groove solid fraction "
              f"{slices['solid_points'].sum() / slices['points'].sum():.4f} over the block")
        print(win.drop(columns=["case", "packing_seed", "penetration_mm"]).to_string(
            index=False, float_format=lambda v: f"{v:.4f}"))
    if a.out:
        pd.concat(all_slices).to_csv(a.out, index=False, float_format="%.6g")
    if a.windows_out:
        pd.concat(all_windows).to_csv(a.windows_out, index=False, float_format="%.6g")
    if a.layers_out:
        pd.concat(all_layers).to_csv(a.layers_out, index=False, float_format="%.6g")
    if a.pair_windows:
        print("== F_n of each window against the groove's fill (Spearman)")
        print(against_forces(pd.concat(all_windows), pd.read_csv(a.pair_windows)).to_string(
            index=False, float_format=lambda v: f"{v:.3f}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
