"""Chips and specific energy of a cutting run.

Chips are connected components of the bond graph that remains at the end of the run (initial bonds
from ``specimen.data`` minus the broken ones). The component with the most grains is the rock
body; every other component of at least ``min_grains`` grains is a chip; smaller ones (mostly single
grains whose bonds all broke) are debris. Volumes are bulk volumes: the grains' solid volume
divided by the packing's solid fraction.

Specific energy SE = work / volume (J/m^3 = Pa), with the work the cutter did on the rock,
W = -integral(F . v_c dt) - integral(T_y * spin_rate dt) (F, T_y: force and torque of the rock on the
cutter; v_c: velocity of the disc centre), and the volume either from the chips (chips + debris) or
from the kinematics: the groove cross-section of the disc at the nominal depth times the length
cut (travel minus the start clearance; linear and oscillation modes).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from deckgen.datafile import read_bonds
from deckgen.parse.dump import iter_frames
from deckgen.spec import DETACH_MIN_GRAINS

CHIP_COLUMNS = ["chip", "n_grains", "solid_volume_m3", "bulk_volume_m3", "extent_x_m", "extent_y_m",
                "extent_z_m", "centroid_x_m", "centroid_y_m", "centroid_z_m"]


def initial_bonds(run_dir: Path) -> np.ndarray | None:
    """Initial bonds: the data file's Bonds section, else the step-0 frame of bonds.dump.gz."""
    if (run_dir / "specimen.data").is_file():
        return read_bonds(run_dir / "specimen.data")
    sample = run_dir / "bonds.dump.gz"
    if sample.is_file():
        for frame in iter_frames(sample, ["id1", "id2"]):
            if frame.timestep == 0:
                return frame.data[["id1", "id2"]].to_numpy(dtype=np.int64)
            break
    return None


def last_frame(run_dir: Path) -> pd.DataFrame:
    """Final grain state: final.dump.gz, else the last frame of atoms.dump.gz (read frame by frame)."""
    for name in ("final.dump.gz", "atoms.dump.gz"):
        p = run_dir / name
        if p.is_file():
            frame = None
            for frame in iter_frames(p, ["id", "type", "radius", "x", "y", "z"], allow_truncated_tail=True):
                pass
            if frame is not None:
                return frame.data.reset_index(drop=True)
    raise FileNotFoundError(f"{run_dir}: no final.dump.gz or atoms.dump.gz")


def _pair_keys(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One integer per row of two sorted (n, 2) id-pair arrays, on a common base, so numpy set operations (isin)
    compare pairs."""
    m = max(int(a.max()), int(b.max())) + 1
    return a[:, 0] * m + a[:, 1], b[:, 0] * m + b[:, 1]


def bond_components(bonds: np.ndarray, broken: np.ndarray, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Connected components of the bond graph among the grains ``ids`` once the ``broken`` pairs are gone (both
    atom-id pairs, any order): the component label of each grain (in the order of ``ids``), the component sizes and
    the label of the largest one (the rock body; -1 without grains)."""
    ids = np.asarray(ids, dtype=np.int64)
    b = np.sort(np.asarray(bonds, dtype=np.int64).reshape(-1, 2), axis=1)
    if len(broken) and len(b):
        br = np.sort(np.asarray(broken, dtype=np.int64).reshape(-1, 2), axis=1)
        kb, kbr = _pair_keys(b, br)
        b = b[~np.isin(kb, kbr)]
    b = b[np.isin(b[:, 0], ids) & np.isin(b[:, 1], ids)] if len(b) else b
    n = len(ids)
    index = pd.Series(np.arange(n), index=ids)
    i, j = index.loc[b[:, 0]].to_numpy(), index.loc[b[:, 1]].to_numpy()
    graph = coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    ncomp, label = connected_components(graph, directed=False)
    sizes = np.bincount(label, minlength=ncomp)
    return label, sizes, int(np.argmax(sizes)) if n else -1


# DETACH_MIN_GRAINS (imported from deckgen.spec, the schema's default) is the smallest piece whose break-off counts as
# the detachment of an indentation run (detachment()) by default; a case sets its own with outputs.breakoff_min_grains,
# and `deckgen parse --breakoff-min-grains` reads a finished run at another size


#: the first piece's columns (:func:`detachment` with the grains' initial positions)
PIECE_KEYS = ("detached_piece_grains", "detached_piece_volume_m3",
              *(f"detached_piece_{what}_{a}_m" for what in ("extent", "min", "max") for a in "xyz"))


def initial_positions(run_dir: Path) -> pd.DataFrame | None:
    """The grains' positions at the start of the run (id, type, radius, x, y, z): the Atoms section of
    ``specimen.data`` (atom_style bpm/sphere: id molecule type diameter density x y z, as deckgen writes it), else the
    step-0 frame of atoms.dump.gz; None when neither is there."""
    from deckgen.datafile import iter_section
    from deckgen.parse.common import ParseError

    data = run_dir / "specimen.data"
    if data.is_file():
        rows = []
        for lineno, parts in iter_section(data, "Atoms"):
            if len(parts) < 8:
                raise ParseError(data, lineno, f"bpm/sphere atom line needs 8 columns (id molecule type diameter "
                                 f"density x y z), got {len(parts)}")
            try:
                rows.append((int(parts[0]), int(parts[2]), 0.5 * float(parts[3]), *map(float, parts[5:8])))
            except ValueError:
                raise ParseError(data, lineno, "non-numeric value in atom line") from None
        return pd.DataFrame(rows, columns=["id", "type", "radius", "x", "y", "z"])
    dump = run_dir / "atoms.dump.gz"
    if dump.is_file():
        for frame in iter_frames(dump, ["id", "type", "radius", "x", "y", "z"]):
            return frame.data.reset_index(drop=True) if frame.timestep == 0 else None
    return None


def detachment(bonds: np.ndarray, broken: pd.DataFrame, ts: pd.DataFrame,
               min_grains: int = DETACH_MIN_GRAINS, initial: pd.DataFrame | None = None,
               solid_fraction: float | None = None) -> dict[str, Any]:
    """The chip's break-off in an indentation run. Seed 000 pushes the disc "until the material was detached
    entirely" and reports the maximum (destructive) normal force; a reduced run pushes a fixed depth, so its peak over
    the whole push can come after the chip is off, from the disc pressing on into the block.

    Detachment: the first step of the broken-bond record (``broken``: id1, id2, step) at which a component of the bond
    graph other than the body (the largest) holds at least ``min_grains`` grains. A piece can later split below the
    size, so the steps are scanned in order rather than bisected. Returns ``detachment_step``, the penetration then
    (``penetration_at_failure_m``), the largest F_n of the series up to that step (``force_normal_N_destructive``),
    the side force of the same row (``force_side_N_destructive``, when the series has it) and the penetration at it
    (``penetration_at_destructive_m``); all NaN when no such piece breaks off. The forces come from the last series
    row at or before the break-off (rows every ``outputs.series_every`` steps).

    With ``initial`` (the grains' positions at the start: id, radius, x, y, z; :func:`initial_positions`) and the
    packing's ``solid_fraction`` it also gives the first piece (the largest component other than the body at the
    break-off): its grains (``detached_piece_grains``), bulk volume (solid / solid fraction, as :func:`find_chips`)
    and extents along x, y and z of its grains' spheres at their INITIAL positions (``detached_piece_extent_*_m``,
    with the box's corners ``detached_piece_min_*_m`` and ``detached_piece_max_*_m``), i.e. the zone of the block the
    piece came from (seed 000's "destruction zone dimensions"), not where it flew to. NaN without a piece or without
    ``initial``."""
    out: dict[str, Any] = {"detachment_step": float("nan"), "penetration_at_failure_m": float("nan"),
                           "force_normal_N_destructive": float("nan"), "force_side_N_destructive": float("nan"),
                           "penetration_at_destructive_m": float("nan"), **{k: float("nan") for k in PIECE_KEYS}}
    if not len(broken) or not len(ts):
        return out
    ids = np.unique(bonds)
    steps = broken["step"].to_numpy(np.int64)
    pairs = broken[["id1", "id2"]].to_numpy(np.int64)
    s = first_detachment_step(bonds, pairs, steps, min_grains)
    if s is None:
        return out
    out["detachment_step"] = s
    if initial is not None and solid_fraction:
        label, sizes, body = bond_components(bonds, pairs[steps <= s], ids)
        out.update(_piece(ids, label, sizes, body, initial, float(solid_fraction)))
    upto = ts[ts["step"] <= s]
    if not len(upto):  # off before the first series row: no force to read
        return out
    i = int(np.argmax(upto["force_normal_N"].to_numpy()))
    out.update(penetration_at_failure_m=float(upto["penetration_m"].iloc[-1]),
               force_normal_N_destructive=float(upto["force_normal_N"].iloc[i]),
               penetration_at_destructive_m=float(upto["penetration_m"].iloc[i]))
    if "force_side_N" in upto.columns:
        out["force_side_N_destructive"] = float(upto["force_side_N"].iloc[i])
    return out


def first_detachment_step(bonds: np.ndarray, pairs: np.ndarray, steps: np.ndarray,
                          min_grains: int = DETACH_MIN_GRAINS) -> int | None:
    """The first break step at which a component of the bond graph other than the largest holds at least
    ``min_grains`` grains (None if none does): ``bonds`` the initial bonds (n, 2), ``pairs`` the broken pairs and
    ``steps`` their break steps. A pair broken more than once counts from its first step; a pair that is not an
    initial bond is ignored.

    Bonds only break, so the graph after each break step is the final graph plus the bonds broken later. The scan
    runs backwards: the final graph's components once (scipy), then the bonds put back one break step at a time
    with scipy's DisjointSet over the components, keeping the number of components of at least ``min_grains``
    grains. "Another component has ``min_grains``" is "at least two have" (the largest is the body), so each step is
    decided without relabelling the graph. One labelling instead of one per break step (:func:`_first_detachment_scan`,
    the plain definition this is tested against; ``bench/detachment.py`` measures both)."""
    from scipy.cluster.hierarchy import DisjointSet

    b = np.sort(np.asarray(bonds, dtype=np.int64).reshape(-1, 2), axis=1)
    pr = np.sort(np.asarray(pairs, dtype=np.int64).reshape(-1, 2), axis=1)
    st = np.asarray(steps, dtype=np.int64).reshape(-1)
    if not len(b) or not len(pr):
        return None
    if min(int(b.min()), int(pr.min())) < 0:
        raise ValueError("grain ids must not be negative (the engines number atoms from 1)")
    records = np.unique(st)[::-1]  # every break step of the record, latest first (as the plain scan tests them)
    key, bond_key = _pair_keys(pr, b)
    order = np.lexsort((st, key))  # by pair, then step: the first break of each pair first
    key, st, pr = key[order], st[order], pr[order]
    first = np.r_[True, key[1:] != key[:-1]]
    keep = first & np.isin(key, bond_key)
    st, pr = st[keep], pr[keep]
    ids = np.unique(b)
    label, sizes, _ = bond_components(b, pr, ids)
    weight = {i: int(w) for i, w in enumerate(sizes)}
    big = int((sizes >= min_grains).sum())
    back = np.argsort(-st, kind="stable")
    st, ends = st[back], label[np.searchsorted(ids, pr[back])]  # components of each pair's grains, final graph
    ds = DisjointSet(range(len(sizes)))
    found, k = None, 0
    for s in records:  # the graph just after break step s is decided, then its bonds go back
        if big >= 2:
            found = int(s)
        while k < len(st) and st[k] == s:
            ra, rc = ds[int(ends[k, 0])], ds[int(ends[k, 1])]
            k += 1
            if ra == rc:
                continue
            wa, wc = weight.pop(ra), weight.pop(rc)
            big += int(wa + wc >= min_grains) - int(wa >= min_grains) - int(wc >= min_grains)
            ds.merge(ra, rc)
            weight[ds[ra]] = wa + wc
    return found


def _first_detachment_scan(bonds: np.ndarray, pairs: np.ndarray, steps: np.ndarray,
                           min_grains: int = DETACH_MIN_GRAINS) -> int | None:
    """:func:`first_detachment_step` by its definition: label the graph after every break step, in order, until a
    component other than the largest holds ``min_grains`` grains. One labelling per break step (seconds for a
    30 000-bond block); kept to check the backward scan in tests and ``bench/detachment.py``."""
    ids = np.unique(bonds)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    steps = np.asarray(steps, dtype=np.int64).reshape(-1)
    for s in np.unique(steps):
        _, sizes, body = bond_components(bonds, pairs[steps <= s], ids)
        if (np.delete(sizes, body) >= min_grains).any():
            return int(s)
    return None


def sphere_box(x: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners of the axis-aligned box around spheres at ``x`` (n, 3) with radii ``r`` (n)."""
    return (x - r[:, None]).min(axis=0), (x + r[:, None]).max(axis=0)


def _piece(ids: np.ndarray, label: np.ndarray, sizes: np.ndarray, body: int, initial: pd.DataFrame,
           solid_fraction: float) -> dict[str, float]:
    """The largest component other than ``body``: grains, bulk volume and extents at the ``initial`` positions."""
    others = np.where(np.arange(len(sizes)) != body, sizes, -1)
    sel_ids = ids[label == int(np.argmax(others))]
    g = initial.set_index("id")
    missing = np.setdiff1d(sel_ids, g.index.to_numpy())
    if len(missing):
        raise ValueError(f"the initial positions lack {len(missing)} bonded grains of the first piece (ids "
                         f"{missing[:5].tolist()}...) (fix: pass the step-0 positions of every bonded grain)")
    g = g.loc[sel_ids]
    r = g["radius"].to_numpy(float)
    x = g[["x", "y", "z"]].to_numpy(float)
    lo, hi = sphere_box(x, r)
    return {"detached_piece_grains": int(len(sel_ids)),
            "detached_piece_volume_m3": float((4.0 / 3.0 * math.pi * r**3).sum()) / solid_fraction,
            **{f"detached_piece_extent_{a}_m": float(e) for a, e in zip("xyz", hi - lo)},
            **{f"detached_piece_min_{a}_m": float(e) for a, e in zip("xyz", lo)},
            **{f"detached_piece_max_{a}_m": float(e) for a, e in zip("xyz", hi)}}


def find_chips(bonds: np.ndarray, broken: np.ndarray, atoms: pd.DataFrame, solid_fraction: float,
               min_grains: int = 2) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Chips of the remaining bond graph among rock grains (type 1) of ``atoms``.

    ``bonds`` and ``broken`` hold atom-id pairs (any order). Returns the chip table (one row per chip,
    largest first) and summary scalars.
    """
    rock = atoms[atoms["type"] == 1]
    ids = rock["id"].to_numpy(dtype=np.int64)
    label, sizes, body = bond_components(bonds, broken, ids)
    n = len(ids)
    r = rock["radius"].to_numpy(dtype=float)
    x = rock[["x", "y", "z"]].to_numpy(dtype=float)
    vol = 4.0 / 3.0 * math.pi * r**3
    had_bond = np.isin(ids, bonds.ravel())
    rows = []
    debris_grains, debris_solid = 0, 0.0
    for c in np.argsort(-sizes):
        if c == body:
            continue
        sel = label == c
        if sizes[c] < min_grains:
            keep = sel & had_bond
            debris_grains += int(keep.sum())
            debris_solid += float(vol[keep].sum())
            continue
        lo, hi = sphere_box(x[sel], r[sel])
        solid = float(vol[sel].sum())
        cen = (x[sel] * vol[sel, None]).sum(axis=0) / solid
        rows.append([len(rows) + 1, int(sizes[c]), solid, solid / solid_fraction, *(hi - lo), *cen])
    table = pd.DataFrame(rows, columns=CHIP_COLUMNS)
    chips_bulk = float(table["bulk_volume_m3"].sum()) if len(table) else 0.0
    debris_bulk = debris_solid / solid_fraction
    largest = table.iloc[0] if len(table) else None
    summary = {
        "chips_count": int(len(table)),
        "chips_grains": int(table["n_grains"].sum()) if len(table) else 0,
        "chips_volume_m3": chips_bulk,
        "debris_grains": debris_grains,
        "debris_volume_m3": debris_bulk,
        "removed_volume_m3": chips_bulk + debris_bulk,
        "body_grains": int(sizes[body]) if n else 0,
        "largest_chip_grains": int(largest["n_grains"]) if largest is not None else 0,
        "largest_chip_volume_m3": float(largest["bulk_volume_m3"]) if largest is not None else 0.0,
        "largest_chip_extent_x_m": float(largest["extent_x_m"]) if largest is not None else 0.0,
        "largest_chip_extent_y_m": float(largest["extent_y_m"]) if largest is not None else 0.0,
        "largest_chip_extent_z_m": float(largest["extent_z_m"]) if largest is not None else 0.0,
    }
    return table, summary


def cutter_work(ts: pd.DataFrame, spin_rate: float, yaw_rate: float = 0.0) -> float:
    """Work the cutter did on the rock [J]: -int(F . v_c) dt - int(T . Omega) dt (trapezoids).

    Omega = spin_rate about the disc axis (torque_axis_Nm when present, else torque_y_Nm) plus
    yaw_rate about z (rotary path).
    """
    t = ts["time_s"].to_numpy(dtype=float)
    if len(t) < 2:
        return 0.0
    power = np.zeros(len(t))
    for axis in "xyz":
        v = np.gradient(ts[f"cutter_{axis}_m"].to_numpy(dtype=float), t)
        power -= ts[f"force_{axis}_N"].to_numpy(dtype=float) * v
    axis_torque = ts["torque_axis_Nm"] if "torque_axis_Nm" in ts else ts["torque_y_Nm"]
    power -= axis_torque.to_numpy(dtype=float) * spin_rate + ts["torque_z_Nm"].to_numpy(dtype=float) * yaw_rate
    return float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(t)))


def groove_area(profile: np.ndarray, radius: float, depth: float) -> float:
    """Cross-section [m^2] of the groove a disc of this (rho, a) profile cuts at ``depth``.

    The part of the closed profile polygon with rho >= radius - depth (Sutherland-Hodgman clip against
    one half-plane, then the shoelace formula).
    """
    cut = radius - depth
    pts = np.asarray(profile, dtype=float)
    out: list[np.ndarray] = []
    for k in range(len(pts)):
        p, q = pts[k], pts[(k + 1) % len(pts)]
        pin, qin = p[0] >= cut, q[0] >= cut
        if pin:
            out.append(p)
        if pin != qin:
            s = (cut - p[0]) / (q[0] - p[0])
            out.append(p + s * (q - p))
    if len(out) < 3:
        return 0.0
    a = np.asarray(out)
    return float(0.5 * abs(np.dot(a[:, 0], np.roll(a[:, 1], -1)) - np.dot(a[:, 1], np.roll(a[:, 0], -1))))


def kinematic_volume(case: dict[str, Any], derived: dict[str, Any]) -> float:
    """Groove volume [m^3] from the kinematics (NaN for indentation)."""
    from deckgen.deck import cutter_params
    from deckgen.geometry import _coerce_params
    from deckgen.spec import Case

    if case["kinematics"]["mode"] == "indentation":
        return float("nan")
    kind, params = cutter_params(Case.model_validate({k: v for k, v in case.items() if k != "test"}))
    prof = _coerce_params(kind, params).profile()
    cut = derived["cutter"]
    length = max(0.0, cut["travel"] - case["kinematics"]["start_clearance_mm"] * 1e-3)
    return groove_area(prof, cut["radius"], cut["penetration"]) * length


def analyse(run_dir: Path, broken: pd.DataFrame, ts: pd.DataFrame, spec: dict[str, Any],
            min_grains: int = 2) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Chips, removed volume, cutter work and specific energies of a cutting run folder. ``spec`` as
    :func:`deckgen.results.parse_run` passes it: for an indentation run its ``derived`` holds the checked break-off size
    and its source (``breakoff_min_grains``, ``breakoff_min_grains_source``; results._breakoff_size)."""
    derived = spec["derived"]
    bonds = initial_bonds(run_dir)
    if bonds is None:
        raise FileNotFoundError(f"{run_dir}: no specimen.data and no step-0 bond sample: initial bonds unknown")
    atoms = last_frame(run_dir)
    phi = float(derived["packing"]["solid_fraction"])
    table, out = find_chips(bonds, broken[["id1", "id2"]].to_numpy(dtype=np.int64), atoms, phi, min_grains)
    work = cutter_work(ts, float(derived["cutter"].get("spin_rate", 0.0)), float(derived["cutter"].get("yaw_rate", 0.0)))
    v_kin = kinematic_volume(spec["case"], derived)
    if derived.get("kinematics_mode") == "indentation":
        n = int(derived["breakoff_min_grains"])
        out.update(detachment(bonds, broken, ts, min_grains=n, initial=initial_positions(run_dir), solid_fraction=phi))
        out.update(detachment_min_grains=n, detachment_min_grains_source=derived["breakoff_min_grains_source"])
    out.update({
        "cutter_work_J": work,
        "kinematic_volume_m3": v_kin,
        "specific_energy_chips_J_m3": work / out["removed_volume_m3"] if out["removed_volume_m3"] > 0 else float("nan"),
        "specific_energy_kinematic_J_m3": work / v_kin if v_kin and math.isfinite(v_kin) and v_kin > 0 else float("nan"),
    })
    return table, out
