"""Dense polydisperse packings made by the engine, cached by a hash of their inputs.

Algorithm (documented in docs/model.md, "Packing"):
1. Radii are drawn uniformly in [r_min, r_max] (seeded) until the grain volume reaches
   ``solid_fraction_target`` x specimen volume (with ``packing.fine_zone``: the band's radii fill the band's
   volume and the packing's radii the rest, each to that fraction).
2. Grains are placed at random inside the specimen at ``insertion_scale`` of their size; overlapping
   draws are re-drawn until none overlap (random sequential addition, seeded).
3. LAMMPS grows the radii back to full size in ``growth_stages`` separate runs (``fix adapt``,
   radius ramp, so the neighbour cutoff follows) inside frictionless granular walls of the specimen
   shape, with viscous drag, then relaxes. The count in step 1 over-fills the specimen slightly
   (the jamming fraction depends on the specimen size, walls pack looser), so
4. the radii then deflate (each step followed by relaxation) until the internal pressure from the
   contact virial is within 1.3x the pressure at which the mean relative overlap would be
   ``target_overlap`` (Hertz contacts, Z = 6); the step size follows the overlap estimated from the
   pressure (P ~ eps^1.5). Radius contraction to a target stress, as in PFC practice. All radii
   share the final scale factor, which is reported.
4. deckgen reads the result and reports solid fraction, mean coordination number (contacts per grain
   with and without rattlers) and mean overlap.

The packing depends only on the specimen geometry, the packing block and the grain density, so
one packing serves every bond/contact parameter set of the same rock specimen (calibration).
"""

from __future__ import annotations

import hashlib
import json
import math
import re
import shutil
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from deckgen import __version__
from deckgen.bonds import contact_timestep
from deckgen.datafile import Atoms, read_sphere_data
from deckgen.render import render
from deckgen.spec import GPA, MM, BrazilianDisc, Case, CuttingBlock, UcsCylinder

PACK_DECK = "in.pack"
PACKING_FORMAT = 4  # bump when the packing algorithm changes, so caches are not reused
# 4: packings are made on packing.ranks MPI ranks (default 1) whatever the run uses; format 3 caches could hold
#    packings made on 2 ranks under the same key, which differ from 1-rank ones (docs/model.md, "Packing")


@dataclass
class Region:
    """The specimen as a LAMMPS region (SI units) and its volume."""

    shape: str              # cylinder | block
    axis: str               # cylinder axis
    c1: float
    c2: float
    radius: float
    lo: float
    hi: float
    bounds: tuple[float, float, float, float, float, float]  # xlo xhi ylo yhi zlo zhi
    volume_m3: float

    def contains(self, x: np.ndarray, margin: np.ndarray) -> np.ndarray:
        """True where a sphere at x with radius ``margin`` lies fully inside the region."""
        if self.shape == "block":
            b = np.asarray(self.bounds).reshape(3, 2)
            return np.all((x - margin[:, None] >= b[:, 0]) & (x + margin[:, None] <= b[:, 1]), axis=1)
        k = "xyz".index(self.axis)
        o = [a for a in range(3) if a != k]
        rho = np.hypot(x[:, o[0]] - self.c1, x[:, o[1]] - self.c2)
        return (rho + margin <= self.radius) & (x[:, k] - margin >= self.lo) & (x[:, k] + margin <= self.hi)


def specimen_region(case: Case) -> Region:
    sp = case.specimen
    if isinstance(sp, UcsCylinder):
        R, H = sp.diameter_mm * MM / 2, sp.height_mm * MM
        return Region("cylinder", "z", 0.0, 0.0, R, 0.0, H, (-R, R, -R, R, 0.0, H), math.pi * R * R * H)
    if isinstance(sp, BrazilianDisc):
        R, t = sp.diameter_mm * MM / 2, sp.thickness_mm * MM
        # axis y; centre (x, z) = (0, R) so that the disc rests on z = 0
        return Region("cylinder", "y", 0.0, R, R, -t / 2, t / 2, (-R, R, -t / 2, t / 2, 0.0, 2 * R), math.pi * R * R * t)
    if isinstance(sp, CuttingBlock):
        L, W, H = sp.length_mm * MM, sp.width_mm * MM, sp.height_mm * MM
        return Region("block", "z", 0, 0, 0, 0, 0, (0.0, L, -W / 2, W / 2, 0.0, H), L * W * H)
    raise TypeError(f"unknown specimen {sp!r}")


def packing_inputs(case: Case) -> dict[str, Any]:
    """Everything a packing depends on (its cache key)."""
    sp = case.specimen.model_dump(mode="json")
    geometry = {k: v for k, v in sp.items() if k in {"kind", "diameter_mm", "height_mm", "thickness_mm", "length_mm", "width_mm"}}
    return {
        "format": PACKING_FORMAT,
        "specimen": geometry,
        "packing": case.packing.model_dump(mode="json"),
        "density_kg_m3": case.material.density_kg_m3,
        "poisson_ratio": case.contact.poisson_ratio,
    }


def packing_key(case: Case) -> str:
    blob = json.dumps(packing_inputs(case), sort_keys=True).encode()
    return hashlib.sha256(blob).hexdigest()[:16]


def draw_radii(case: Case, volume: float, rng: np.random.Generator,
               radii_mm: tuple[float, float] | None = None) -> np.ndarray:
    """Radii (m), uniform in [r_min, r_max] (the packing's, or ``radii_mm``), until their volume fills
    ``solid_fraction_target`` of ``volume``."""
    p = case.packing
    rmin, rmax = (p.radius_min_mm * MM, p.radius_max_mm * MM) if radii_mm is None else (radii_mm[0] * MM, radii_mm[1] * MM)
    mean_v = 4.0 / 3.0 * math.pi * (rmin**3 + rmin**2 * rmax + rmin * rmax**2 + rmax**3) / 4.0
    n_guess = int(p.solid_fraction_target * volume / mean_v * 1.2) + 16
    r = rng.uniform(rmin, rmax, n_guess)
    cum = np.cumsum(4.0 / 3.0 * math.pi * r**3)
    n = int(np.searchsorted(cum, p.solid_fraction_target * volume))
    if n < 8:
        raise ValueError("packing: fewer than 8 grains fit; enlarge the specimen or use smaller grains")
    return r[:n]


def fine_zone_box(case: Case) -> np.ndarray | None:
    """The band of :class:`~deckgen.spec.FineZone` as a (3, 2) box in m (x over the whole block), or None."""
    fz = case.packing.fine_zone
    if fz is None:
        return None
    b = np.asarray(specimen_region(case).bounds, dtype=float).reshape(3, 2).copy()
    b[1] = ((fz.centre_y_mm - fz.half_width_mm) * MM, (fz.centre_y_mm + fz.half_width_mm) * MM)
    b[2, 0] = b[2, 1] - fz.depth_mm * MM
    return b


def _in_box(x: np.ndarray, box: np.ndarray) -> np.ndarray:
    return np.all((x >= box[:, 0]) & (x <= box[:, 1]), axis=1)


def insert_grains(case: Case, max_rounds: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Random non-overlapping positions of grains at ``insertion_scale`` of their radius.

    With ``packing.fine_zone`` the band's volume is filled with the band's radii, centres drawn inside it, and the rest
    of the block with the packing's radii, centres drawn outside it; the growth and the deflation then treat all
    grains alike (one radius scale). Returns (x [m], r_full [m]). Deterministic for a given seed.
    """
    reg = specimen_region(case)
    rng = np.random.default_rng(case.packing.seed)
    fz, zone = case.packing.fine_zone, fine_zone_box(case)
    if zone is None:
        r = draw_radii(case, reg.volume_m3, rng)
        fine = np.zeros(len(r), dtype=bool)
    else:
        v_zone = float(np.prod(zone[:, 1] - zone[:, 0]))
        r_coarse = draw_radii(case, reg.volume_m3 - v_zone, rng)
        r_fine = draw_radii(case, v_zone, rng, (fz.radius_min_mm, fz.radius_max_mm))
        r = np.concatenate([r_coarse, r_fine])
        fine = np.arange(len(r)) >= len(r_coarse)
    ri = r * case.packing.insertion_scale
    b = np.asarray(reg.bounds).reshape(3, 2)
    x = np.empty((len(r), 3))
    todo = np.arange(len(r))
    draws = 0
    for _ in range(max_rounds):
        # draw inside the bounding box (a fine grain inside its band), keep draws fully inside the region (and a
        # coarse grain's centre outside the band)
        while len(todo):
            draws += 1
            if draws > 100_000:  # the case checks leave room for every grain; this guards against a hang
                raise RuntimeError(f"packing: {len(todo)} grains found no place inside the specimen (or their part of "
                                   "it) in 100000 draws; enlarge the specimen or its part, or use smaller grains")
            if zone is None:
                cand = rng.uniform(b[:, 0], b[:, 1], size=(len(todo), 3))
                ok = reg.contains(cand, ri[todo])
            else:
                f = fine[todo]
                cand = np.where(f[:, None], rng.uniform(zone[:, 0], zone[:, 1], size=(len(todo), 3)),
                                rng.uniform(b[:, 0], b[:, 1], size=(len(todo), 3)))
                ok = reg.contains(cand, ri[todo]) & (f | ~_in_box(cand, zone))
            x[todo[ok]] = cand[ok]
            todo = todo[~ok]
        pairs = cKDTree(x).query_pairs(2 * ri.max(), output_type="ndarray")
        if len(pairs):
            d = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
            bad = pairs[d < ri[pairs[:, 0]] + ri[pairs[:, 1]]]
        else:
            bad = pairs
        if len(bad) == 0:
            return x, r
        todo = np.unique(bad.max(axis=1))
    raise RuntimeError("packing: could not place grains without overlap; lower insertion_scale")


@dataclass
class PackingStats:
    n_grains: int
    solid_fraction: float
    coordination_mean: float
    coordination_mean_no_rattlers: float
    rattler_fraction: float
    overlap_mean_rel: float
    overlap_max_rel: float
    radius_min_m: float
    radius_max_m: float


def packing_stats(atoms: Atoms, volume_m3: float) -> PackingStats:
    """Solid fraction and contact statistics (contact: centre distance <= r_i + r_j)."""
    x, r = atoms.x, atoms.radius
    pairs = cKDTree(x).query_pairs(2 * r.max(), output_type="ndarray")
    d = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    s = r[pairs[:, 0]] + r[pairs[:, 1]]
    c = d <= s
    z = np.bincount(pairs[c].ravel(), minlength=len(r))
    rattler = z < 4  # fewer than 4 contacts cannot be mechanically stable in 3D
    ov = ((s - d) / s)[c]
    return PackingStats(
        n_grains=len(r),
        solid_fraction=float((4.0 / 3.0 * np.pi * r**3).sum() / volume_m3),
        coordination_mean=float(z.mean()),
        coordination_mean_no_rattlers=float(z[~rattler].mean()) if (~rattler).any() else 0.0,
        rattler_fraction=float(rattler.mean()),
        overlap_mean_rel=float(ov.mean()) if len(ov) else 0.0,
        overlap_max_rel=float(ov.max()) if len(ov) else 0.0,
        radius_min_m=float(r.min()),
        radius_max_m=float(r.max()),
    )


def write_insertion_data(path: Path, case: Case, x: np.ndarray, r: np.ndarray) -> None:
    reg = specimen_region(case)
    b = np.asarray(reg.bounds).reshape(3, 2)
    pad = 0.05 * (b[:, 1] - b[:, 0]).max()
    ri = r * case.packing.insertion_scale
    with open(path, "w") as fh:
        fh.write(f"deckgen insertion {case.name}\n\n{len(r)} atoms\n1 atom types\n\n")
        for k, ax in enumerate("xyz"):
            fh.write(f"{b[k, 0] - pad:.9e} {b[k, 1] + pad:.9e} {ax}lo {ax}hi\n")
        fh.write("\nAtoms # sphere\n\n")
        for i in range(len(r)):
            fh.write(f"{i + 1} 1 {2 * ri[i]:.9e} {case.material.density_kg_m3:.9e} {x[i, 0]:.9e} {x[i, 1]:.9e} {x[i, 2]:.9e}\n")


def pack_context(case: Case) -> dict[str, Any]:
    p = case.packing
    reg = specimen_region(case)
    E = p.contact_modulus_GPa * GPA
    nu = case.contact.poisson_ratio
    r_small = p.fine_zone.radius_min_mm if p.fine_zone is not None else p.radius_min_mm
    rmin = r_small * MM * p.insertion_scale
    dt = contact_timestep(rmin, case.material.density_kg_m3, E, nu, safety=0.2)
    ratio = (1.0 / p.insertion_scale) ** (1.0 / p.growth_stages)
    # target pressure: Hertz contact at mean relative overlap eps (delta = eps * 2 r), Z = 6,
    # P = phi Z f / (pi d^2) (Rothenburg-Bathurst mean stress of a packing of spheres of diameter d); f ~ d^2 at a
    # given relative overlap, so P does not depend on d and a fine zone needs no other target
    r_mean = 0.5 * (p.radius_min_mm + p.radius_max_mm) * MM
    e_star = E / (2 * (1 - nu**2))
    delta = p.target_overlap * 2 * r_mean
    f = 4.0 / 3.0 * e_star * math.sqrt(0.5 * r_mean) * delta**1.5
    p_target = p.solid_fraction_target * 6.0 * f / (math.pi * (2 * r_mean) ** 2)
    variables = [
        ("E_pack", E, "Young's modulus of the soft packing contact", "Pa"),
        ("nu_c", nu, "grain Poisson's ratio", "1"),
        # damping tsuji reads this as a restitution (LAMMPS turns it into alpha ~ 0.1 for 1.2728, which was
        # meant as the alpha of e = 0); the drag settles the packing; kept so cached packings stay valid
        ("damp_alpha", 1.2728, "Tsuji input, read as a restitution (see packing.py)", "1"),
        ("drag_time", p.drag_time_s, "viscous drag relaxation time", "s"),
        ("seed", 1 + p.seed % 900_000_000, "random seed of the drag fix", "1"),
        ("dt", dt, "time step (0.2 x Rayleigh time of the smallest grain at insertion size)", "s"),
        ("stage_ratio", ratio, "radius growth factor per stage", "1"),
        ("steps_per_stage", p.steps_per_stage, "steps per growth stage", "steps"),
        ("relax_steps", p.relax_steps, "relaxation steps", "steps"),
        ("skin", 0.3 * p.radius_max_mm * MM, "neighbour skin", "m"),
        ("v_spec", reg.volume_m3, "specimen volume", "m^3"),
        ("p_target", p_target, "deflate until the contact pressure is below this", "Pa"),
        ("target_overlap", p.target_overlap, "target mean relative overlap", "1"),
        ("deflate_steps", max(100, p.steps_per_stage // 4), "steps per deflation step", "steps"),
        ("max_deflate", p.max_deflate_steps, "deflation steps at most", "1"),
        ("thermo_every", 1000, "thermo interval", "steps"),
    ]
    return {
        "version": __version__,
        "title": f"packing of {reg.shape} specimen",
        "case_name": case.name,
        "test": "packing",
        "template": "pack.lmp.j2",
        "deck_name": PACK_DECK,
        "data_file": "insert.data",
        "variables": [dict(name=n, value=v, comment=c, unit=u) for n, v, c, u in variables],
        "region": asdict(reg),
        "growth_stages": p.growth_stages,
        "expected_steps": p.growth_stages * p.steps_per_stage + p.relax_steps,
        "p_target": p_target,
    }


def render_pack(case: Case, folder: Path) -> dict[str, Any]:
    """Write insert.data and in.pack into ``folder``; returns the render context."""
    folder.mkdir(parents=True, exist_ok=True)
    x, r = insert_grains(case)
    write_insertion_data(folder / "insert.data", case, x, r)
    ctx = pack_context(case)
    (folder / PACK_DECK).write_text(render("lammps/pack.lmp.j2", ctx))
    (folder / "packing_inputs.json").write_text(json.dumps(packing_inputs(case), indent=2, sort_keys=True) + "\n")
    return ctx


def cache_root() -> Path:
    import os

    env = os.environ.get("DECKGEN_CACHE")
    if env:
        return Path(env)
    from deckgen.render import repo_root

    return repo_root() / ".deckgen-cache"


def packing_dir(case: Case, root: Path | None = None) -> Path:
    return (root or cache_root()) / "packings" / packing_key(case)


def ensure_packing(case: Case, root: Path | None = None, *, progress: bool = True, command: list[str] | None = None) -> Path:
    """Return the folder holding packed.data and packing.json, running the engine if not cached."""
    import fcntl

    folder = packing_dir(case, root)
    if (folder / "packing.json").is_file() and (folder / "packed.data").is_file():
        return folder
    # Two jobs that need the same packing (e.g. cases that differ only in their cutter) would share the
    # .tmp folder and kill each other's engine run: the second waits on a per-key lock, then reuses it.
    folder.parent.mkdir(parents=True, exist_ok=True)
    with open(folder.with_name(folder.name + ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if (folder / "packing.json").is_file() and (folder / "packed.data").is_file():
            return folder
        return _make_packing(case, folder, progress=progress, command=command)


def _make_packing(case: Case, folder: Path, *, progress: bool, command: list[str] | None) -> Path:
    from deckgen.runner import engine_command, run_deck, set_ranks

    tmp = folder.with_name(folder.name + ".tmp")
    if tmp.exists():
        shutil.rmtree(tmp)
    ctx = render_pack(case, tmp)
    # The domain decomposition changes the packing (lin_red_s100_p6p4: 2388 grains on 1 rank, 2384 on 2), so the
    # packing runs on packing.ranks whatever the run's command asks for; a user's own launcher is kept as given.
    ranks = case.packing.ranks
    cmd = set_ranks(list(command) if command else engine_command(ranks), ranks)
    result = run_deck(tmp, PACK_DECK, expected_steps=ctx["expected_steps"], progress=progress, command=cmd,
                      label=f"pack {case.name}")
    atoms = read_sphere_data(tmp / "packed.data")
    stats = asdict(packing_stats(atoms, specimen_region(case).volume_m3))
    stats.update(deflation_result(tmp / "log.lammps"))
    info = {"key": packing_key(case), "inputs": packing_inputs(case), "stats": stats,
            "engine": {k: v for k, v in result.as_dict().items() if k not in ("run_dir", "command")},
            "command": [Path(c).name for c in cmd]}
    (tmp / "packing.json").write_text(json.dumps(info, indent=2, sort_keys=True) + "\n")
    if folder.exists():
        shutil.rmtree(folder)
    tmp.rename(folder)
    return folder


_DEFLATED = re.compile(r"^deckgen: radius scale (\S+) contact pressure (\S+) Pa target (\S+) Pa")


def deflation_result(log: Path) -> dict[str, float]:
    """Final radius scale and contact pressure printed by the pack deck."""
    with open(log, errors="replace") as fh:
        for line in fh:
            m = _DEFLATED.match(line)
            if m:
                return {"radius_scale": float(m.group(1)), "contact_pressure_Pa": float(m.group(2)),
                        "contact_pressure_target_Pa": float(m.group(3))}
    raise RuntimeError(f"{log}: no 'deckgen: radius scale' line: the pack deck did not finish its deflation")


def load_packing(folder: Path) -> tuple[Atoms, dict[str, Any]]:
    return read_sphere_data(folder / "packed.data"), json.loads((folder / "packing.json").read_text())
