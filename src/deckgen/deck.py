"""Build a run folder for a case: bonded specimen data file, cutter STL, deck, resolved spec.

Data flow: case -> packing (cached) -> bonds + time step -> test geometry -> jinja2 deck.
The resolved spec (every field, defaults included) and the derived SI quantities the parsers
need (areas, lengths, time step, cutter path) are written beside the deck as ``spec.json``.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from deckgen import __version__, plugins
from deckgen.bonds import (
    COEFF_NAMES,
    binning_error,
    clump_sizes,
    contact_timestep,
    find_bond_pairs,
    grow_clumps,
    intra_clump,
    make_bond_table,
    stable_timestep,
    unbonded_mask,
    weibull_cov,
    weibull_strength_factors,
)
from deckgen.datafile import write_bpm_data
from deckgen.packing import ensure_packing, load_packing, specimen_region
from deckgen.render import render
from deckgen.spec import GPA, MM, MPA, BrazilianDisc, Case, CuttingBlock, SpecError, UcsCylinder, resolved_dict

DECK = "in.deck"
DATA = "specimen.data"
#: Broken bonds of a flat-joint deck, one line each (step id1 id2 mode x y z; mode 1 tension, 2 shear).
FLAT_JOINT_BROKEN = "broken_joints.txt"
SHELL_DENSITY = 7850.0 * 1000.0  # cutter shell spheres: heavy, so contact m_eff ~ grain mass


def effective_modulus(E1: float, nu1: float, E2: float, nu2: float, nu_deck: float) -> float:
    """E to give ``hertz/material`` for an i-j pair of different materials.

    LAMMPS uses E_eff = E / (2 (1 - nu^2)) for an explicit i-j pair; the Hertz contact of two
    materials needs 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2, so E = 2 (1 - nu^2) E*.
    """
    e_star = 1.0 / ((1 - nu1**2) / E1 + (1 - nu2**2) / E2)
    return 2.0 * (1.0 - nu_deck**2) * e_star


def path_variables(path: dict[str, float]) -> list[dict[str, Any]]:
    """Deck variables of the cutter path (:func:`cutter_path`), shared by the LAMMPS and LIGGGHTS decks."""
    return [
        _var("xc0", path["xc0"], "cutter centre start x", "m"),
        _var("yc0", path["yc0"], "cutter centre start y", "m"),
        _var("zc0", path["zc0"], "cutter centre start z", "m"),
        _var("v_cut", path["V"], "forward (or push) speed", "m/s"),
        _var("ecc", path["ecc"], "eccentricity e", "m"),
        _var("omega", path["omega"], "oscillation angular frequency", "rad/s"),
    ]


def _round_up(n: int, quantum: int) -> int:
    return -(-int(n) // quantum) * quantum


def _var(name: str, value: float | int, comment: str, unit: str) -> dict[str, Any]:
    return {"name": name, "value": value, "comment": comment, "unit": unit}


def cutter_params(case: Case) -> tuple[str, dict[str, float]]:
    """The geometry-module parameters (SI) of the case's cutter."""
    c = case.cutter
    if c.kind == "v_disc":
        p = dict(diameter=c.diameter_mm * MM, edge_angle_deg=c.edge_angle_deg, tip_radius=c.tip_radius_mm * MM,
                 hub_width=c.hub_width_mm * MM)
    elif c.kind == "ccs_disc":
        p = dict(diameter=c.diameter_mm * MM, tip_width=c.tip_width_mm * MM, tip_radius=c.tip_radius_mm * MM,
                 flank_angle_deg=c.flank_angle_deg, hub_width=c.hub_width_mm * MM)
    elif c.kind == "asymmetric_disc":
        p = dict(diameter=c.diameter_mm * MM, blade_angle_deg=c.blade_angle_deg, tip_radius=c.tip_radius_mm * MM,
                 hub_width=c.hub_width_mm * MM)
    else:
        p = dict(small_diameter=c.small_diameter_mm * MM, large_diameter=c.diameter_mm * MM,
                 clearance_angle_deg=c.clearance_angle_deg, rake_angle_deg=c.rake_angle_deg,
                 tip_radius=c.tip_radius_mm * MM)
    return c.kind, p


def cutter_modifications(case: Case) -> dict[str, float]:
    """Wear flat and axis tilt of the case's cutter (:func:`deckgen.geometry.build_cutter` keywords)."""
    return {"wear": case.cutter.wear_flat_mm * MM, "tilt_deg": case.cutter.tilt_deg}


def cutter_profile(case: Case) -> np.ndarray:
    """The (worn) cross-section profile of the case's cutter: (radius, axial) vertices [m] of the revolved body."""
    from deckgen.geometry import _coerce_params, wear_flat

    kind, prm = cutter_params(case)
    return wear_flat(_coerce_params(kind, prm).profile(), case.cutter.wear_flat_mm * MM)


def neighbour_groove_mask(case: Case, x: np.ndarray) -> np.ndarray:
    """Grains whose centres lie in the grooves of the same (worn) disc cut at y = +-S beforehand.

    Relieved cutting (seed 001): the neighbouring cuts ran the whole block length at the same
    penetration, so their groove is the disc's cross-section profile at depth p swept along x.
    """
    from matplotlib.path import Path as MplPath

    S = case.kinematics.neighbour_spacing_mm
    sp = case.specimen
    if S is None or not isinstance(sp, CuttingBlock):
        return np.zeros(len(x), bool)
    prof = cutter_profile(case)
    R = float(prof[:, 0].max())
    zc = sp.height_mm * MM - case.kinematics.penetration_mm * MM + R
    poly = MplPath(prof)
    out = np.zeros(len(x), bool)
    for y0 in (-S * MM, S * MM):
        pts = np.column_stack([zc - x[:, 2], x[:, 1] - y0])
        out |= poly.contains_points(pts) & (x[:, 2] > zc - R)
    return out


def confining_faces(case: Case, x: np.ndarray, bounds: Any, fixed: list[dict[str, Any]], slab: float,
                    pad: float) -> list[dict[str, Any]]:
    """Side faces (y min, y max, unless held fixed) loaded by ``specimen.confining_stress_MPa``.

    The face load s3 * (length * height) is shared equally by the face's boundary grains (centres
    within one grain diameter of the face, not held fixed) as a constant inward ``fix addforce``.
    """
    sp = case.specimen
    if not isinstance(sp, CuttingBlock) or sp.confining_stress_MPa <= 0:
        return []
    bb = np.asarray(bounds, dtype=float).reshape(3, 2)
    held = np.zeros(len(x), bool)
    for f in fixed:
        lo, hi = np.asarray(f["bounds"]).reshape(3, 2).T
        held |= ((x >= lo) & (x <= hi)).all(axis=1)
    out = []
    area = sp.length_mm * MM * sp.height_mm * MM
    for name, sign in (("ymin", 1.0), ("ymax", -1.0)):
        if name in sp.fixed_faces:
            continue
        box = bb.copy()
        box[0] = (bb[0, 0] - pad, bb[0, 1] + pad)
        box[2] = (bb[2, 0] - pad, bb[2, 1] + pad)
        box[1] = (bb[1, 0] - pad, bb[1, 0] + slab) if name == "ymin" else (bb[1, 1] - slab, bb[1, 1] + pad)
        inside = ((x >= box[:, 0]) & (x <= box[:, 1])).all(axis=1) & ~held
        n = int(inside.sum())
        if n:
            out.append({"name": name, "bounds": [float(v) for v in box.ravel()], "n": n,
                        "force": sign * sp.confining_stress_MPa * MPA * area / n})
    return out


def build_cutter_files(case: Case, out: Path) -> dict[str, Any]:
    """Write cutter.stl (true surface) and cutter_shell.stl (inward offset by the shell radius)."""
    from deckgen.geometry import build_cutter, cutter_summary, write_stl

    kind, p = cutter_params(case)
    rs = case.cutter.shell_radius_mm * MM
    mods = cutter_modifications(case)
    try:
        true = build_cutter(kind, p, **mods)
        shell = build_cutter(kind, p, offset=rs, **mods)
    except ValueError as exc:
        raise SpecError(f"cutter: {exc}") from None
    write_stl(true, out / "cutter.stl")
    write_stl(shell, out / "cutter_shell.stl")
    return {"mesh": true, "shell_mesh": shell, "summary": cutter_summary(true)}


def cutter_world_points(rel: np.ndarray, path: dict[str, float], t: float) -> np.ndarray:
    """Where points fixed to the cutter (``rel``: offsets from the start centre) are at time ``t``.

    The same rigid motion as the ``fix move variable`` block of ``templates/lammps/cutting.lmp.j2``:
    centre path plus spin about y, and for the rotary path a yaw about the vertical axis (ax_x, ax_y).
    """
    X, Y, Z = rel[:, 0], rel[:, 1], rel[:, 2]
    th = path["spin_rate"] * t
    # a tilted disc (cutter_path's axis_tilt a: axis (0, cos a, sin a)) spins about its own axis and orbits in its
    # plane: untilt, spin about y, tilt back. a = 0 (every untilted path) gives exactly the plain formulas
    alpha = path.get("axis_tilt", 0.0)
    ca, sa = math.cos(alpha), math.sin(alpha)
    Yu, Zu = ca * Y + sa * Z, -sa * Y + ca * Z  # into the disc frame (axis along y)
    X1 = X * math.cos(th) + Zu * math.sin(th)
    Z1 = -X * math.sin(th) + Zu * math.cos(th)
    if path["rotary_radius"]:  # never tilted (cutter_path refuses it)
        r, phi = path["rotary_radius"], path["yaw_rate"] * t
        qx = X1 * math.cos(phi) - (Y - r) * math.sin(phi)
        qy = X1 * math.sin(phi) + (Y - r) * math.cos(phi)
        return np.column_stack([path["axis_x"] + qx, path["axis_y"] + qy, path["zc0"] + Z1])
    V, e, w, ind = path["V"], path["ecc"], path["omega"], path["mode_indent"]
    oz = (1 - ind) * path.get("sense", 1.0) * e * math.sin(w * t)  # the orbit's offset along the disc frame's z
    xc = path["xc0"] + (1 - ind) * (V * t + e * (math.cos(w * t) - 1.0))
    yc = path["yc0"] - sa * oz
    zc = path["zc0"] - ind * V * t + ca * oz
    return np.column_stack([xc + X1, yc + ca * Yu - sa * Z1, zc + sa * Yu + ca * Z1])


def near_rock_mask(rel: np.ndarray, path: dict[str, float], lo: np.ndarray, hi: np.ndarray, margin: float) -> np.ndarray:
    """Cutter-fixed points that come within ``margin`` of the box [lo, hi] at some time of the motion.

    The motion is sampled so that no point moves more than margin/4 between samples; a point that
    never comes that close cannot touch a grain of the block (or a chip lifted less than ``margin``).
    """
    rmax = float(np.sqrt((rel**2).sum(axis=1)).max()) if len(rel) else 0.0
    speed = (path["V"] + path["ecc"] * path["omega"] + abs(path["spin_rate"]) * rmax
             + path["yaw_rate"] * (path["rotary_radius"] + rmax))
    n = int(min(20000, math.ceil(speed * path["duration"] / (0.25 * margin)))) + 2
    keep = np.zeros(len(rel), bool)
    for t in np.linspace(0.0, path["duration"], n):
        p = cutter_world_points(rel, path, float(t))
        d = np.maximum(np.maximum(lo - p, p - hi), 0.0)
        keep |= (d * d).sum(axis=1) < margin * margin
    return keep


def shell_points(shell_mesh, spacing: float, seed: int) -> np.ndarray:
    """Sphere centres on the offset surface, no two closer than ``spacing``, gaps ~<= 1.5 spacing.

    Dense random surface samples (trimesh) are thinned greedily (Poisson-disc by dart throwing on
    a hash grid). Written here because ``trimesh.sample.sample_surface_even`` drops both points of
    every close pair and left gaps wider than a grain on the test discs.
    """
    import trimesh

    area = float(shell_mesh.area)
    target = area / (spacing**2 * math.sqrt(3) / 2)
    cand, _ = trimesh.sample.sample_surface(shell_mesh, int(30 * target) + 1000, seed=seed)
    cell = spacing / math.sqrt(3)
    grid: dict[tuple[int, int, int], int] = {}
    keep: list[np.ndarray] = []
    s2 = spacing * spacing
    keys = np.floor(np.asarray(cand) / cell).astype(np.int64)
    for p, key in zip(np.asarray(cand), keys):
        k0, k1, k2 = int(key[0]), int(key[1]), int(key[2])
        ok = True
        for a in range(k0 - 2, k0 + 3):
            for b in range(k1 - 2, k1 + 3):
                for c in range(k2 - 2, k2 + 3):
                    j = grid.get((a, b, c))
                    if j is not None and float(((keep[j] - p) ** 2).sum()) < s2:
                        ok = False
                        break
                if not ok:
                    break
            if not ok:
                break
        if ok:
            grid[(k0, k1, k2)] = len(keep)
            keep.append(p)
    return np.asarray(keep)


def fixed_face_boxes(sp: CuttingBlock, reg: Any, slab: float, pad: float) -> list[dict[str, Any]]:
    """Boxes of the grains held fixed: a slab ``slab`` thick inside each of ``sp.fixed_faces``,
    reaching ``pad`` beyond the block on every other side (shared by the LAMMPS and LIGGGHTS decks)."""
    faces = []
    for f in sp.fixed_faces:
        bb = np.asarray(reg.bounds).reshape(3, 2).copy()
        k = "xyz".index(f[0])
        if f.endswith("min"):
            bb[k] = (bb[k, 0] - pad, bb[k, 0] + slab)
        else:
            bb[k] = (bb[k, 1] - slab, bb[k, 1] + pad)
        for kk in range(3):
            if kk != k:
                bb[kk] = (bb[kk, 0] - pad, bb[kk, 1] + pad)
        faces.append({"name": f, "bounds": [float(v) for v in bb.ravel()]})
    return faces


def smooth_cone_variables(case: Case, mesh: Any, path: dict[str, float],
                          r_grain_max: float) -> tuple[list[dict[str, Any]], str | None]:
    """Deck variables of ``cutter.surface: smooth``: the cone disc as a LAMMPS ``region cone`` along y (large face
    at the disc centre, small face at +thickness), turned into place by the region's ``rotate``: by the constant
    tilt of the built disc's axis about x, or, upright, by the spin angle. A region turns about one axis only, so a
    tilted smooth cone carries no spin; the spec admits that only without cutter friction or with spin none, where a
    surface of revolution turning about its own axis exerts the same forces as a still one.

    Returns the deck variables and what the region's ``rotate`` turns by: ``"tilt"``, ``"spin"`` or None."""
    prof = np.asarray(cutter_profile(case), dtype=float)
    a_lo, a_hi = float(prof[:, 1].min()), float(prof[:, 1].max())
    r_lo = float(prof[np.isclose(prof[:, 1], a_lo), 0].max())
    r_hi = float(prof[np.isclose(prof[:, 1], a_hi), 0].max())
    if abs(a_lo) > 1e-12 or not r_lo > r_hi > 0:
        raise SpecError("cutter.surface: smooth needs the cone disc's large face at its centre (fix: tip_radius_mm 0)")
    # LAMMPS 22Jul2025 gives an exterior cone contact the wall radius -2 rho (rho: the cone's local radius), and the
    # granular wall model takes R_eff = r (-2 rho) / (r - 2 rho): a grain as wide as the cone is there divides by
    # zero. Keep the cone's smallest radius at least two grain diameters (then R_eff is at most 8/7 of r).
    if r_hi < 4.0 * r_grain_max:
        raise SpecError(f"cutter.surface: smooth: the cone's small face (radius {r_hi / MM:.3g} mm) is less than two "
                        f"grain diameters ({4 * r_grain_max / MM:.3g} mm); the engine's cone wall is not reliable there "
                        "(fix: larger small_diameter_mm, smaller grains or surface shell)")
    ax = np.asarray(mesh.metadata.get("deckgen_axis", (0.0, 1.0, 0.0)), dtype=float)
    if abs(ax[0]) > 1e-12:
        raise SpecError("cutter.surface: smooth: the disc axis leans along x, which a region about x cannot follow "
                        "(fix: surface shell)")
    tilt = math.atan2(ax[2], ax[1])
    out = [_var("cone_r_lo", r_lo, "smooth cone: radius of the large face (the rim)", "m"),
           _var("cone_r_hi", r_hi, "smooth cone: radius of the small face", "m"),
           _var("cone_h", a_hi - a_lo, "smooth cone: thickness along the axis", "m")]
    if abs(tilt) > 1e-12:
        out.append(_var("cone_tilt", tilt, "smooth cone: constant turn of the region about x (the disc's tilt)", "rad"))
        return out, "tilt"
    return out, ("spin" if path["spin_rate"] != 0 else None)


def cutter_path(case: Case, R: float, axis: np.ndarray | None = None) -> dict[str, float]:
    """Initial centre, duration and motion parameters of the cutter (SI).

    ``axis``: the disc axis of the built cutter (``mesh.metadata["deckgen_axis"]``). When it is tilted about x
    (a cone's clearance angle, ``cutter.tilt_deg``) and the disc spins or orbits, the path carries ``axis_tilt``
    (the angle α of the axis (0, cos α, sin α) from y): the disc then spins about its own axis and its centre
    orbits in the disc's plane, as a disc on bearings on an eccentric shaft parallel to it (a real ODC, the
    whole tool tilted by the clearance angle). Untilted paths do not carry the key.
    """
    sp = case.specimen
    k = case.kinematics
    assert isinstance(sp, CuttingBlock)
    L, W, H = sp.length_mm * MM, sp.width_mm * MM, sp.height_mm * MM
    p, V = k.penetration_mm * MM, k.speed_m_s
    clear = k.start_clearance_mm * MM
    e = k.eccentricity_mm * MM if k.mode == "oscillation" else 0.0
    w = 2 * math.pi * k.frequency_hz if k.mode == "oscillation" else 0.0
    if k.mode == "indentation":
        xc0, yc0, zc0 = L / 2, -W / 2 + k.edge_distance_mm * MM, H + R + clear
        duration = (clear + p) / V
        travel = clear + p
    else:
        if p >= R:
            raise SpecError(f"kinematics.penetration_mm: {k.penetration_mm:g} mm is not less than the cutter radius "
                            f"{R / MM:g} mm (fix: shallower cut or larger disc)")
        half_chord = math.sqrt(R**2 - (R - p) ** 2)
        xc0, yc0, zc0 = -half_chord - clear, 0.0, H - p + R
        travel = k.travel_mm * MM
        duration = travel / V
        if xc0 + travel + half_chord > L:
            raise SpecError(
                f"kinematics.travel_mm: the cutter would leave the block (needs length >= "
                f"{(travel + 2 * half_chord + clear) / MM:.1f} mm; fix: shorter travel or longer block)")
    sense = 1.0 if k.shaft_sense == "forward" else -1.0  # the eccentric circle's sense (z = sense e sin(w t))
    spin_rate = {"none": 0.0, "rolling": V / R, "shaft": -sense * w}[k.spin]
    out = dict(xc0=xc0, yc0=yc0, zc0=zc0, V=V, ecc=e, omega=w, spin_rate=spin_rate, duration=duration,
               travel=travel, penetration=p, radius=R, mode_indent=1.0 if k.mode == "indentation" else 0.0,
               yaw_rate=0.0, rotary_radius=0.0, axis_x=0.0, axis_y=0.0)
    if sense < 0:  # only the mirrored circle carries the key (spec.json of forward cuts unchanged)
        out["sense"] = sense
    if axis is not None:
        a = np.asarray(axis, dtype=float)
        alpha = math.atan2(float(a[2]), float(a[1]))
        if abs(float(a[0])) > 1e-9:
            raise SpecError(f"cutter: the disc axis {a.tolist()} leaves the y-z plane; only tilts about the cut "
                            "direction x are supported (fix: cutter.tilt_deg / clearance_angle_deg only)")
        if abs(alpha) > 1e-12 and (spin_rate != 0.0 or e > 0.0):
            if k.mode in ("rotary", "indentation"):
                raise SpecError(f"case {case.name}: a tilted disc (cutter.tilt_deg or a cone's clearance angle) that "
                                f"spins in {k.mode} is not rendered (fix: tilt 0, or kinematics.spin none)")
            out["axis_tilt"] = alpha
    if k.orbit_lift > 0 and e > 0:  # orbit_bottom: p is the deepest cut of the orbit, not the start depth
        lift = k.orbit_lift * e * math.cos(out.get("axis_tilt", 0.0))
        out["zc0"] = zc0 + lift
        out["orbit_lift"] = lift
    if k.mode == "rotary":
        r = k.rotary_radius_mm * MM
        phi_end = travel / r
        if phi_end > math.pi / 2:
            raise SpecError(f"kinematics.travel_mm: {k.travel_mm:g} mm is more than a quarter of the rotary path "
                            f"(radius {k.rotary_radius_mm:g} mm) (fix: shorter travel or larger rotary_radius_mm)")
        y_end = r * (1.0 - math.cos(phi_end))
        if y_end + half_chord > W / 2:
            raise SpecError(f"kinematics.rotary_radius_mm: the curved path drifts {y_end / MM:.1f} mm sideways and leaves "
                            f"the block (fix: wider block, larger radius or shorter travel)")
        out.update(yaw_rate=V / r, rotary_radius=r, axis_x=xc0, axis_y=yc0 + r)
    return out


def jaw_positions(x: np.ndarray, r: np.ndarray, R: float, ratio: float) -> dict[str, float]:
    """Axes of the two curved Brazilian jaws (axis y, radius ``ratio * R``) touching the extreme grains.

    The disc (axis y) lies inside both jaw cylinders; the bottom jaw's axis sits above the disc centre
    and its arc touches the lowest grain, the top jaw's axis sits below and its arc touches the highest
    grain, so loading starts at t = 0 without a gap or an initial overlap (to 1e-12 m).
    """
    from scipy.optimize import brentq

    R_jaw = ratio * R
    xc = 0.5 * (float((x[:, 0] - r).min()) + float((x[:, 0] + r).max()))
    zc = 0.5 * (float((x[:, 2] - r).min()) + float((x[:, 2] + r).max()))

    def reach(z: float) -> float:  # > 0 when some grain sticks out of the jaw cylinder with axis at z
        return float((np.hypot(x[:, 0] - xc, x[:, 2] - z) + r).max()) - R_jaw

    d = R_jaw - R
    zc_top = brentq(reach, zc - d - 0.5 * R, zc - d + 0.5 * R, xtol=1e-13)
    zc_bot = brentq(reach, zc + d - 0.5 * R, zc + d + 0.5 * R, xtol=1e-13)
    return {"R_jaw": R_jaw, "x": xc, "zc_top": float(zc_top), "zc_bot": float(zc_bot)}


def render_case(case: Case, out: str | Path, *, cache: Path | None = None, progress: bool = True,
                command: list[str] | None = None) -> dict[str, Any]:
    """Render the run folder ``out`` for ``case`` (packing it first if needed). Returns spec.json content."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    pack_folder = ensure_packing(case, cache, progress=progress, command=command)
    atoms, packinfo = load_packing(pack_folder)
    b, c, run = case.bonds, case.contact, case.run
    grooves = neighbour_groove_mask(case, atoms.x)
    if grooves.any():  # relieved cutting: the neighbours' grooves are not in the block
        keep = ~grooves
        atoms = type(atoms)(ids=np.arange(1, int(keep.sum()) + 1), types=atoms.types[keep], radius=atoms.radius[keep],
                            density=atoms.density[keep], x=atoms.x[keep], box=atoms.box)

    # ---- bonded specimen
    r_full = atoms.radius
    fz = case.packing.fine_zone
    # a two-size packing (packing.fine_zone): the band's grains, told from the block's by the gap between their radius
    # ranges (both scaled by the packing's one radius scale)
    fine = None if fz is None else (
        r_full <= 0.5 * (fz.radius_max_mm + case.packing.radius_min_mm) * MM * float(packinfo["stats"]["radius_scale"]))
    grain_class = None if fine is None else fine.astype(np.int64)
    pairs = find_bond_pairs(atoms.x, r_full, b.gap_tolerance)
    r = r_full * (1.0 - b.shrink_before_bonding)
    rho = case.material.density_kg_m3 * run.mass_scaling
    mass = rho * 4.0 / 3.0 * math.pi * r**3
    clumps = None
    intra = None
    if b.clump_size > 1 and b.enabled:  # clumps grown on the bond graph from the packing seed
        clumps = grow_clumps(pairs, len(r_full), b.clump_size, seed=case.packing.seed, x=atoms.x)
        intra = intra_clump(pairs, clumps)
    n_unbonded = 0
    slits = pairs[:0]
    all_pairs = pairs
    if b.unbonded_fraction > 0 and b.enabled:  # closed cohesionless contacts ("cracks"), from the packing seed
        drop = unbonded_mask(len(pairs), b.unbonded_fraction, seed=case.packing.seed, protect=intra)
        n_unbonded = int(drop.sum())
        if b.model == "flat_joint":  # the flat joint keeps them as slit faces: broken from the start
            slits = pairs[drop]
        pairs = pairs[~drop]
        if intra is not None:
            intra = intra[~drop]
    gapped = pairs[:0]
    if b.model == "flat_joint" and b.face_gap_tolerance > 0 and b.enabled:  # faces that close under load
        wide = find_bond_pairs(atoms.x, r_full, b.face_gap_tolerance)
        n_full = len(r_full)
        gapped = wide[~np.isin(wide[:, 0] * n_full + wide[:, 1], all_pairs[:, 0] * n_full + all_pairs[:, 1])]
    strength = None
    if b.strength_weibull_modulus > 0 and b.enabled:  # weakest-link flaws: per-bond strength factors, mean 1
        strength = weibull_strength_factors(len(pairs), b.strength_weibull_modulus, seed=case.packing.seed)
        if intra is not None:
            strength[intra] = 1.0
    table = make_bond_table(
        atoms.x, r, mass, pairs, E_b=b.youngs_modulus_GPa * GPA, stiffness_ratio=b.stiffness_ratio,
        sigma_c=b.tensile_strength_MPa * MPA, tau_c=b.shear_strength_MPa * MPA,
        radius_multiplier=b.radius_multiplier, damping_ratio=b.damping_ratio,
        bins_radius=b.type_bins_radius, bins_length=b.type_bins_length,
        intra=intra, clump_strength_factor=b.clump_strength_factor, clump_stiffness_factor=b.clump_stiffness_factor,
        bending_factor=b.bending_strength_factor, twisting_factor=b.twisting_strength_factor,
        strength_factor=strength, bins_strength=b.type_bins_strength,
        grain_class=grain_class)
    dt_info = stable_timestep(atoms.x, r, mass, table, run.timestep_safety)
    # flat joint: the slit and the gapped faces are bonds of one type each, after the bond table's types
    slit_type = table.ntypes + 1 if len(slits) else None
    gapped_type = table.ntypes + 1 + (1 if len(slits) else 0) if len(gapped) else None
    if len(slits) or len(gapped):  # slit and gapped faces are as stiff as bonds in compression: the time step counts them
        dt_info = stable_timestep(atoms.x, r, mass, make_bond_table(
            atoms.x, r, mass, np.concatenate([all_pairs, gapped]), E_b=b.youngs_modulus_GPa * GPA, stiffness_ratio=b.stiffness_ratio,
            sigma_c=b.tensile_strength_MPa * MPA, tau_c=b.shear_strength_MPa * MPA,
            radius_multiplier=b.radius_multiplier, damping_ratio=b.damping_ratio,
            bins_radius=b.type_bins_radius, bins_length=b.type_bins_length,
            grain_class=grain_class), run.timestep_safety)
    E_c, nu_c = c.youngs_modulus_GPa * GPA, c.poisson_ratio
    E_s, nu_s = c.cutter_youngs_modulus_GPa * GPA, c.cutter_poisson_ratio
    dt_contact = contact_timestep(float(r.min()), rho, E_c, nu_c, safety=0.2)
    dt = run.timestep_s or min(dt_info["dt_s"], dt_contact)
    if not b.enabled:  # unbonded granular specimen: bond types stay declared (same deck), no bond exists
        pairs = pairs[:0]
        table = dataclasses.replace(table, pairs=pairs, types=table.types[:0], per_atom=np.zeros_like(table.per_atom))
        dt = run.timestep_s or dt_contact

    # ---- contact constants
    # with a fine band, from the block's own (coarse) grains: the band leaves the rest of the block's rolling
    # stiffness and damping as they are without it (the band's grains take the same values)
    block = slice(None) if fine is None else ~fine
    r_mean = float(r[block].mean())
    m_mean = float(mass[block].mean())
    e_star = E_c / (2 * (1 - nu_c**2))
    k_n_char = 2.0 * e_star * math.sqrt(0.5 * r_mean * 0.005 * r_mean)  # Hertz stiffness at 0.5 % overlap
    k_roll = k_n_char
    g_roll = 2.0 * 0.1 * math.sqrt(m_mean * k_roll)
    reg = specimen_region(case)
    r_max = float(r.max())
    skin = 0.3 * r_max
    ghost = 2.0 * float(r_full.max()) * (1.0 + b.gap_tolerance) + 2 * skin

    quantum = math.lcm(case.outputs.series_every, case.outputs.broken_every)
    variables = [
        _var("rho", rho, "grain density (x mass scaling)", "kg/m^3"),
        _var("E_c", E_c, "grain Young's modulus, Hertz contact", "Pa"),
        _var("nu_c", nu_c, "grain Poisson's ratio", "1"),
        _var("e_rest", c.restitution, "restitution (damping tsuji maps it to the Tsuji et al. 1992 coefficient)", "1"),
        _var("mu_c", c.friction, "grain-grain sliding friction", "1"),
        _var("mu_roll", c.rolling_friction, "grain-grain rolling friction (SDS)", "1"),
        _var("k_roll", k_roll, "rolling stiffness (Hertz stiffness at 0.5 pct overlap)", "N/m"),
        _var("g_roll", g_roll, "rolling damping (0.1 of critical)", "N s/m"),
        _var("dt", dt, "time step: min(bond %.3g, contact %.3g)" % (dt_info["dt_s"], dt_contact), "s"),
        _var("skin", skin, "neighbour skin", "m"),
        _var("ghost_cut", ghost, "ghost cutoff (longest bond + 2 skins)", "m"),
        _var("thermo_every", run.thermo_every, "thermo interval", "steps"),
        _var("series_every", case.outputs.series_every, "time-series interval", "steps"),
        _var("broken_every", case.outputs.broken_every, "broken-bond flush interval", "steps"),
    ]
    pair_coeffs = [dict(i=1, j=1, E="E_c", mu="mu_c", mu_roll="mu_roll")]
    ctx: dict[str, Any] = {
        "version": __version__, "case_name": case.name, "test": case.test, "deck_name": DECK,
        "data_file": DATA, "integrate_group": "rock", "pair_coeffs": pair_coeffs,
        "bond_coeffs": table.coeff_rows(), "bond_state_every": case.outputs.bond_state_every,
        "jaws": False, "flat_joint": None,
    }
    if b.model == "flat_joint":  # deckgen's own bond style, a plugin copied into the run folder
        try:
            plugin = plugins.install(out, "flatjoint")
        except plugins.PluginError as exc:
            raise SpecError(f"case {case.name}: bonds.model: flat_joint: {exc}") from None
        coeffs = [b.youngs_modulus_GPa * GPA, b.stiffness_ratio, b.radius_multiplier,
                  b.tensile_strength_MPa * MPA, b.shear_strength_MPa * MPA, b.joint_friction, b.damping_ratio,
                  b.moment_contribution]
        ctx["flat_joint"] = {"library": plugin, "broken_file": FLAT_JOINT_BROKEN, "coeffs": coeffs,
                             "slit_type": slit_type, "gapped_type": gapped_type,
                             "elements": [b.face_sectors, b.face_rings] if b.face_sectors > 1 else []}
        if b.bond_friction is not None:  # the plugin's 13th argument, after the slit flag, sectors and rings
            ctx["flat_joint"]["elements"] = [b.face_sectors, b.face_rings, b.bond_friction]
    derived: dict[str, Any] = {
        "dt_s": dt, "dt_bond_s": dt_info["dt_s"], "dt_contact_s": dt_contact,
        "omega_translational_rad_s": dt_info["omega_translational_rad_s"],
        "omega_rotational_rad_s": dt_info["omega_rotational_rad_s"],
        "n_grains": int(len(r)), "n_bonds": int(len(pairs)), "n_bond_types": table.ntypes,
        "bonds_per_grain": float(2 * len(pairs) / len(r)), "bond_type_max_stiffness_error": binning_error(atoms.x, r, table, b.radius_multiplier),
        "specimen_volume_m3": reg.volume_m3, "packing_key": packinfo["key"], "packing": packinfo["stats"],
        "bond_coefficients": {n: [float(v) for v in table.coeffs[n]] for n in COEFF_NAMES},
    }
    if ctx["flat_joint"] is not None:
        derived["max_ranks"] = 1  # the flat-joint plugin refuses more ranks; run_deck lowers deckgen's mpirun -np
    if not b.enabled:
        derived["bonded"] = False
    if n_unbonded:
        derived["unbonded"] = {"fraction": b.unbonded_fraction, "unbonded_pairs": n_unbonded,
                               "bondable_pairs": n_unbonded + int(len(pairs))}
        if len(slits):
            derived["unbonded"]["slit_faces"] = int(len(slits))  # flat joint: written as bonds of the slit type
    if len(gapped):
        derived["gapped_faces"] = int(len(gapped))  # flat joint: bonds of the gapped type, open at the start
    if strength is not None:
        plain = np.ones(len(pairs), bool) if intra is None else ~intra
        binned = table.strength_factor[table.types[plain] - 1]  # the factor each bond gets in the deck: its type's mean
        derived["strength_heterogeneity"] = {
            "weibull_modulus": b.strength_weibull_modulus, "cov_distribution": weibull_cov(b.strength_weibull_modulus),
            "cov_drawn": float(strength[plain].std() / strength[plain].mean()),
            "cov_binned": float(binned.std() / binned.mean()),
            "factor_min": float(strength[plain].min()), "factor_max": float(strength[plain].max()),
            "bins_strength": b.type_bins_strength}
    if clumps is not None and intra is not None:
        dist = clump_sizes(clumps)
        multi = {k: v for k, v in dist.items() if k > 1}
        derived["clumps"] = {
            "clump_size": b.clump_size, "size_distribution": {str(k): v for k, v in dist.items()},
            "n_clumps": int(sum(multi.values())), "grains_in_clumps": int(sum(k * v for k, v in multi.items())),
            "grains_in_clumps_fraction": float(sum(k * v for k, v in multi.items()) / len(r)),
            "mean_clump_size": float(sum(k * v for k, v in multi.items()) / max(1, sum(multi.values()))),
            "intra_clump_bonds": int(intra.sum()), "intra_clump_bond_types": table.intra_types,
            "strength_factor": b.clump_strength_factor, "stiffness_factor": b.clump_stiffness_factor,
        }
    types = np.ones(len(r), dtype=int)
    x_all, r_all, rho_all = atoms.x, r, np.full(len(r), rho)
    n_atom_types = 1
    box = np.asarray(reg.bounds, dtype=float).reshape(3, 2)
    pad = 3.0 * r_max
    box = box + np.array([[-pad, pad]] * 3)

    if isinstance(case.specimen, (UcsCylinder, BrazilianDisc)):
        sp = case.specimen
        if isinstance(sp, UcsCylinder):
            area, lateral = math.pi * (sp.diameter_mm * MM / 2) ** 2, sp.diameter_mm * MM
            title = "uniaxial compression of a bonded cylinder"
        else:
            lateral = sp.diameter_mm * MM
            area = math.pi * sp.diameter_mm * MM * sp.thickness_mm * MM / 2.0  # sigma_t = F / area = 2F/(pi D t)
            title = "Brazilian test of a bonded disc"
        # platens touch the extreme grains (after the shrink before bonding): loading starts at t = 0
        z_bot = float((atoms.x[:, 2] - r).min())
        z_top = float((atoms.x[:, 2] + r).max())
        height = z_top - z_bot
        if isinstance(sp, BrazilianDisc) and sp.loading == "jaws":
            jaws = jaw_positions(atoms.x, r, sp.diameter_mm * MM / 2.0, sp.jaw_radius_ratio)
            ctx["jaws"] = True
            variables += [
                _var("R_jaw", jaws["R_jaw"], "jaw radius (jaw_radius_ratio x disc radius)", "m"),
                _var("jaw_x", jaws["x"], "jaw axes: x (disc centre)", "m"),
                _var("zc_bot", jaws["zc_bot"], "bottom jaw axis z (its arc touches the lowest grain)", "m"),
                _var("zc_top", jaws["zc_top"], "top jaw axis z at the start (its arc touches the highest grain)", "m"),
            ]
            derived["jaws"] = jaws
        if isinstance(sp, UcsCylinder):
            # lateral strain: mean radial displacement of the outer grains of the middle third / R
            R_s = sp.diameter_mm * MM / 2.0
            variables += [
                _var("R_spec", R_s, "cylinder radius (lateral strain = mean radial displacement / R)", "m"),
                _var("r_skin_in", R_s - 2.0 * r_max, "outer grains for the lateral strain: centre beyond this radius", "m"),
                _var("z_mid_lo", z_bot + height / 3.0, "middle third of the height: from", "m"),
                _var("z_mid_hi", z_top - height / 3.0, "middle third of the height: to", "m"),
            ]
        v = sp.platen_speed_m_s
        # stop check every ~0.01 % strain, on a multiple of the output intervals so nothing is lost
        chunk = _round_up(max(100, int(1e-4 * height / v / dt)), quantum)
        # velocity ramp: 10 round trips of a P-wave at the bond modulus (an upper bound of the speed)
        c_wave = math.sqrt(b.youngs_modulus_GPa * GPA / rho)
        t_ramp = sp.ramp_time_s if sp.ramp_time_s is not None else 10.0 * 2.0 * height / c_wave
        total = int(math.ceil((sp.max_strain * height / v + 0.5 * t_ramp) / dt))
        if total > run.max_steps:
            raise SpecError(f"run.max_steps: the test needs {total} steps at dt {dt:.3g} s "
                            f"(fix: raise run.max_steps, platen_speed_m_s or mass_scaling)")
        nchunks = max(1, math.ceil(total / chunk))
        box[2] = (z_bot - pad, z_top + pad)
        variables += [
            _var("z_bot", z_bot, "bottom platen position (lowest grain)", "m"),
            _var("z_top", z_top, "top platen start position (highest grain)", "m"),
            _var("v_platen", v, "top platen speed (down)", "m/s"),
            _var("t_ramp", t_ramp, "platen velocity ramp time (10 P-wave round trips)", "s"),
            _var("area", area, "stress area (UCS pi R^2, BTS pi D t / 2)", "m^2"),
            _var("height", height, "specimen height along the load (between the platens)", "m"),
            _var("E_platen", effective_modulus(E_c, nu_c, E_s, nu_s, nu_c), "platen-grain Hertz modulus", "Pa"),
            _var("mu_platen", c.platen_friction, "platen friction", "1"),
            _var("chunk", chunk, "steps between stop checks", "steps"),
            _var("nchunks", nchunks, "stop checks at most (max strain)", "1"),
            _var("stop_frac", sp.stop_fraction_of_peak, "stop below this fraction of the peak", "1"),
            _var("nb_stop", math.floor(0.995 * len(pairs)), "and only once 0.5 pct of the bonds broke", "1"),
            _var("dump_every", case.outputs.dump_every or max(1, nchunks * chunk // 10), "per-atom dump interval", "steps"),
        ]
        derived.update({"height_m": height, "area_m2": area, "lateral_size_m": lateral, "platen_speed_m_s": v, "platen_ramp_s": t_ramp,
                        "expected_steps": nchunks * chunk})
        template = {"ucs_cylinder": "lammps/ucs.lmp.j2", "brazilian_disc": "lammps/bts.lmp.j2"}[sp.kind]
    else:
        sp = case.specimen
        assert isinstance(sp, CuttingBlock)
        title = f"{case.kinematics.mode} cutting of a bonded block by a {case.cutter.kind}"
        files = build_cutter_files(case, out)
        R = files["summary"]["diameter_m"] / 2.0
        path = cutter_path(case, R, axis=files["mesh"].metadata.get("deckgen_axis"))
        rs = case.cutter.shell_radius_mm * MM
        smooth = case.cutter.surface == "smooth"
        if smooth:
            rs = 0.0
        elif rs > 0.5 * float(r.min()):
            raise SpecError(f"cutter.shell_radius_mm: {case.cutter.shell_radius_mm:g} mm is more than half the smallest "
                            f"grain radius (fix: use <= {0.5 * float(r.min()) / MM:.3g} mm)")
        pts = (np.empty((0, 3)) if smooth
               else shell_points(files["shell_mesh"], case.cutter.shell_spacing * 2 * rs, seed=case.packing.seed))
        n_shell_full = len(pts)
        if case.cutter.shell_coverage == "near_rock" and not smooth:
            margin = (case.cutter.shell_margin_mm * MM if case.cutter.shell_margin_mm is not None
                      else 6.0 * float(r_full.max()))
            lo_b, hi_b = (atoms.x - r[:, None]).min(axis=0), (atoms.x + r[:, None]).max(axis=0)
            pts = pts[near_rock_mask(pts, path, lo_b, hi_b, margin + rs)]
            if len(pts) == 0:
                raise SpecError("cutter.shell_coverage: near_rock keeps no shell sphere: the cutter never comes within "
                                f"{margin / MM:g} mm of the block (fix: check kinematics.penetration_mm and travel_mm)")
            derived.update(shell_margin_m=margin, n_shell_full_cover=n_shell_full)
        centre = np.array([path["xc0"], path["yc0"], path["zc0"]])
        pts = pts + centre
        n_shell = len(pts)
        x_all = np.vstack([atoms.x, pts])
        r_all = np.concatenate([r, np.full(n_shell, rs)])
        rho_all = np.concatenate([np.full(len(r), rho), np.full(n_shell, SHELL_DENSITY)])
        types = np.concatenate([types, np.full(n_shell, 2)])
        n_atom_types = 2
        body = pts if n_shell else np.asarray(files["mesh"].vertices) + centre  # the smooth cone: its own vertices
        lo = np.minimum(box[:, 0], body.min(axis=0) - pad)
        hi = np.maximum(box[:, 1], body.max(axis=0) + pad)
        # room for the whole motion
        lo[0] = min(lo[0], path["xc0"] - R - 2 * path["ecc"] - pad)
        hi[0] = max(hi[0], path["xc0"] + (0 if path["mode_indent"] else path["travel"]) + R + 2 * path["ecc"] + pad)
        if path["rotary_radius"]:
            hi[1] = max(hi[1], path["rotary_radius"] * (1 - math.cos(path["travel"] / path["rotary_radius"])) + R + pad)
        lo[2] = min(lo[2], -pad)
        hi[2] = max(hi[2], path["zc0"] + R + 2 * path["ecc"] + pad)
        box = np.stack([lo, hi], axis=1)
        debris_every = run.debris_removal_every
        if debris_every:  # the cut runs in chunks of debris_every steps, so its outputs must divide the chunk
            quantum = math.lcm(quantum, debris_every)
        steps = _round_up(int(math.ceil(path["duration"] / dt)), quantum)
        if steps > run.max_steps:
            raise SpecError(f"run.max_steps: the cut needs {steps} steps at dt {dt:.3g} s "
                            f"(fix: raise run.max_steps, shorten kinematics.travel_mm or raise speed_m_s)")
        E_rc = effective_modulus(E_c, nu_c, E_s, nu_s, nu_c)
        variables += [
            _var("E_cut", E_rc, "cutter-grain Hertz modulus (steel on rock)", "Pa"),
            _var("mu_cut", c.cutter_friction, "cutter-grain friction", "1"),
            _var("mu_roll_cut", 0.0, "cutter-grain rolling friction", "1"),
            *path_variables(path),
            _var("spin_rate", path["spin_rate"], "spin about the disc's own (tilted) axis" if "axis_tilt" in path
                 else "spin about the disc axis (y)", "rad/s"),
            *([_var("ca", math.cos(path["axis_tilt"]), "cos of the disc axis tilt about x", "1"),
               _var("sa", math.sin(path["axis_tilt"]), "sin of the disc axis tilt about x", "1")]
              if "axis_tilt" in path else []),
            _var("indent", path["mode_indent"], "1 = push along -z (indentation), 0 = cut along +x", "1"),
            *([_var("r_rot", path["rotary_radius"], "rotary path radius", "m"),
               _var("yaw_rate", path["yaw_rate"], "yaw rate of the disc on its circular path (v/r)", "rad/s"),
               _var("ax_x", path["axis_x"], "rotary axis x", "m"),
               _var("ax_y", path["axis_y"], "rotary axis y", "m")] if case.kinematics.mode == "rotary" else []),
            _var("nsteps", steps, "steps of the cut", "steps"),
            _var("dump_every", case.outputs.dump_every or max(1, steps // 10), "per-atom dump interval", "steps"),
            *([_var("debris_every", debris_every, "delete grains without bonds every this many steps", "steps"),
               _var("debris_chunks", steps // debris_every, "chunks of the cut", "1")] if debris_every else []),
        ]
        ctx["debris_removal"] = bool(debris_every)
        if debris_every:
            derived["debris_removal_every"] = debris_every
        ctx["smooth"], ctx["smooth_rotate"] = smooth, None
        if smooth:
            cone_vars, ctx["smooth_rotate"] = smooth_cone_variables(case, files["mesh"], path, float(r_full.max()))
            variables += cone_vars
            derived["smooth_cone"] = {v["name"]: float(v["value"]) for v in cone_vars}
        fixed_slab = 2.0 * float(r_full.max())
        faces = fixed_face_boxes(sp, reg, fixed_slab, pad)
        ctx["fixed_faces"] = faces
        ctx["confine"] = confining_faces(case, atoms.x, reg.bounds, faces, fixed_slab, pad)
        if grooves.any():
            derived["neighbour_groove_grains_removed"] = int(grooves.sum())
        ctx["rotary"] = case.kinematics.mode == "rotary"
        ctx["shaft_backward"] = case.kinematics.shaft_sense == "backward"  # the mirrored eccentric circle
        ctx["tilted"] = "axis_tilt" in path  # tilted disc: spin about its own axis, orbit in its plane
        ctx["integrate_group"] = "mobile"
        pair_coeffs += [dict(i=1, j=2, E="E_cut", mu="mu_cut", mu_roll="mu_roll_cut"),
                        dict(i=2, j=2, E="E_cut", mu="mu_cut", mu_roll="mu_roll_cut")]
        derived.update({
            "cutter": {k: float(v) for k, v in path.items()}, "cutter_summary": {k: (float(v) if isinstance(v, (int, float, np.floating)) else v) for k, v in files["summary"].items()},
            "n_shell": int(n_shell), "shell_radius_m": rs, "expected_steps": steps,
            "steady_window": list(case.outputs.steady_window), "kinematics_mode": case.kinematics.mode,
        })
        template = "lammps/cutting.lmp.j2"

    write_bpm_data(out / DATA, title=f"deckgen {case.name}", box=box, types=types, radius=r_all, density=rho_all,
                   x=x_all, n_atom_types=n_atom_types, bonds=np.concatenate([table.pairs, slits, gapped]),
                   bond_types=np.concatenate([table.types, np.full(len(slits), slit_type or 0, table.types.dtype),
                                              np.full(len(gapped), gapped_type or 0, table.types.dtype)]),
                   n_bond_types=gapped_type or slit_type or table.ntypes, extra_bond_per_atom=2)
    ctx.update({"title": title, "template": template.split("/", 1)[1], "variables": variables})
    (out / DECK).write_text(render(template, ctx))
    spec = {"deckgen_version": __version__, "engine": "lammps", "case": resolved_dict(case), "derived": derived}
    (out / "spec.json").write_text(json.dumps(spec, indent=2, sort_keys=True) + "\n")
    return spec
