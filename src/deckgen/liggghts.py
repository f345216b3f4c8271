r"""LIGGGHTS backend: engine command, capability detection, decks, bond_gran mapping and grammar.

What runs where
---------------
* Debian's ``liggghts`` (LIGGGHTS-PUBLIC 3.8.0, OpenMPI) has granular contact, STL meshes
  (``fix mesh/surface/stress``, ``fix move/mesh``) and ``fix insert/pack``, but no breakable
  bonds (``bond_style harmonic`` only). It runs the *unbonded* decks: :func:`render_liggghts_cut`
  (a granular bed made by LIGGGHTS itself, cut by the case's STL disc).
* Bonded decks target the ``bond/gran`` grammar of the LIGGGHTS_Flexible_Fibers fork
  (github.com/schrummy14/LIGGGHTS_Flexible_Fibers, ``src/bond_gran.cpp``,
  ``src/fix_bond_create_gran.cpp``, ``src/atom_vec_bond_gran.cpp``; see ``docs/liggghts.md``).
  They are rendered and grammar-checked (:func:`check_bond_coeff_line`,
  :func:`check_bonded_deck`); :func:`require_bonds` refuses to run them on a binary without
  ``bond/gran`` with a message saying what to install.

Engine command
--------------
``DECKGEN_LIGGGHTS`` names the binary (``/opt/liggghts-ff/bin/liggghts``) or a whole command
(``mpirun -np 4 /opt/liggghts-ff/bin/liggghts``); default: ``liggghts`` on the PATH (Debian:
``/usr/bin/liggghts``). With more than one rank the binary is wrapped in ``mpirun -np N``, plus
``--allow-run-as-root`` when running as root under OpenMPI (which refuses root otherwise).

bond/gran coefficients (derivation)
-----------------------------------
The fork's ``BondGran::compute`` builds each bond from its two grains at run time:
:math:`r_{out} = r_o \min(r_1, r_2)`, :math:`r_{in} = r_i \min(r_1, r_2)`,
:math:`A = \pi(r_{out}^2 - r_{in}^2)`, :math:`I_p = \tfrac12\pi(r_{out}^4 - r_{in}^4)`,
:math:`I = I_p/2`, and :math:`L` = the grain distance at the first step the bond exists. Its
stiffnesses are :math:`K_n = Y A/L`, :math:`K_t = G A/L`, :math:`K_{tor} = G I_p/L`,
:math:`K_{ben} = Y I/L` (``Sn = Y``, ``St = G`` in the source). The parallel bond of
:mod:`deckgen.bonds` (radius :math:`\bar r = \lambda \min(r_1, r_2)`, solid section) has
:math:`k_r = E_b A/L`, :math:`k_s = E_b A/(\kappa L)`, :math:`k_t = E_b J/(\kappa L)`,
:math:`k_b = E_b I/L`. With :math:`r_o = \lambda`, :math:`r_i = 0` (so :math:`I_p = J`),
:math:`Y = E_b` and :math:`G = E_b/\kappa` the four laws are identical, per bond (the fork needs
no bond types binned by size: one bond type carries every bond exactly).

Strength: break type 1 (``BREAKSTYLE_STRESS``) breaks a bond when
:math:`\sigma_{break} < |F_n|/A + 2|M_b|(r_{out}-r_{in})/I_p` or
:math:`\tau_{break} < |F_t|/A + |M_t|(r_{out}-r_{in})/I_p`. With :math:`r_i = 0`,
:math:`2 r/I_p = r/I` and :math:`r/I_p = r/J`: these are the parallel-bond checks
(seed 000 eqs. 15-16) with :math:`\sigma_{break} = \sigma_c`, :math:`\tau_{break} = \tau_c`.
One difference: the fork takes :math:`|F_n|`, so a *compressed* bond also accumulates normal
stress (the parallel bond counts tension only); LAMMPS ``bpm/rotational`` differs the other way
(signed :math:`f_r`, linear interaction). Documented in docs/liggghts.md.

Damping: damp type 1 (Yu Guo) adds :math:`2\beta\sqrt{M_e K}\,v` to each of the four modes
(:math:`M_e = m_1m_2/(m_1+m_2)`; for the moments :math:`J_s = I_1I_2/(I_1+I_2)`), i.e. the
fraction :math:`\beta` of critical damping of each two-body mode: :math:`\beta` = the case's
``damping_ratio`` (the LAMMPS mapping gives the same ratio, see :mod:`deckgen.bonds`). A damping
ratio of 0 is damp type 0, which still takes one (unused) value.

Traps (from the source): break type 0 calls ``error->all("broken")`` on the first broken bond,
so the run aborts (never rendered); a bond with either grain within the neighbour skin of a box
face is flagged broken at every step (decks use fixed ``f f f`` boundaries with a margin of
several skins around every grain and platen).
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
import os
import re
import shlex
import shutil
import subprocess
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from deckgen import __version__
from deckgen.deck import _round_up, _var, path_variables
from deckgen.runner import EngineError, run_deck, default_ranks
from deckgen.spec import GPA, MM, MPA, BrazilianDisc, Case, CuttingBlock, SpecError, UcsCylinder, resolved_dict

ENV_BINARY = "DECKGEN_LIGGGHTS"
DEBIAN_BINARY = "/usr/bin/liggghts"
DECK = "in.liggghts"
LOG = "log.liggghts"
FORK_URL = "https://github.com/schrummy14/LIGGGHTS_Flexible_Fibers"
#: styles a bonded (bond/gran) deck needs
BOND_STYLES = ("atom bond/gran", "bond gran", "fix bond/create/gran")


class LiggghtsCapabilityError(EngineError):
    """The LIGGGHTS binary lacks a style the deck needs (the message says what to install)."""


class BondGrammarError(ValueError):
    """A bond/gran command that the Flexible_Fibers fork would reject (or that aborts a run)."""


# =============================================================================== command line
def _launcher_is_openmpi(mpirun: str) -> bool:
    try:
        out = subprocess.run([mpirun, "--version"], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return False
    text = out.stdout + out.stderr
    return "Open MPI" in text or "OpenRTE" in text


@functools.lru_cache(maxsize=8)
def _openmpi(mpirun: str) -> bool:
    return _launcher_is_openmpi(mpirun)


def liggghts_binary() -> str:
    """The LIGGGHTS executable: ``DECKGEN_LIGGGHTS`` (if one word), else ``liggghts`` on the PATH."""
    env = os.environ.get(ENV_BINARY)
    if env:
        parts = shlex.split(env)
        return parts[-1]
    found = shutil.which("liggghts") or (DEBIAN_BINARY if os.path.exists(DEBIAN_BINARY) else None)
    if not found:
        raise EngineError("no LIGGGHTS binary: install it (apt-get install -y --no-install-recommends liggghts) "
                          f"or set {ENV_BINARY}")
    return found


def liggghts_command(ranks: int | None = None) -> list[str]:
    """The LIGGGHTS command line (without deck arguments).

    ``DECKGEN_LIGGGHTS`` with several words is used as given (it is a whole command). Otherwise
    the binary runs alone (1 rank) or under ``mpirun -np N`` (``--allow-run-as-root`` when
    running as root with OpenMPI).
    """
    env = os.environ.get(ENV_BINARY)
    if env and len(shlex.split(env)) > 1:
        return shlex.split(env)
    binary = liggghts_binary()
    n = ranks or default_ranks()
    if n <= 1:
        return [binary]
    mpirun = shutil.which("mpirun") or shutil.which("mpiexec")
    if not mpirun:
        return [binary]
    cmd = [mpirun]
    if hasattr(os, "geteuid") and os.geteuid() == 0 and _openmpi(mpirun):
        cmd.append("--allow-run-as-root")
    return cmd + ["-np", str(n), binary]


# =============================================================================== capabilities
_SECTION = {
    "Atom styles": "atom", "Integrate styles": "integrate", "Minimize styles": "minimize",
    "Pair styles": "pair", "Bond styles": "bond", "Angle styles": "angle", "Fix styles": "fix",
    "Compute styles": "compute", "Region styles": "region", "Dump styles": "dump",
    "Command styles": "command", "Normal models for pair gran": "gran_normal",
    "Tangential models for pair gran": "gran_tangential", "Cohesion models for pair gran": "gran_cohesion",
    "Rolling models for pair gran": "gran_rolling", "Surface models for pair gran": "gran_surface",
}


def parse_help(text: str) -> set[str]:
    """Style names from ``liggghts -h``, as ``"<category> <style>"`` (``"fix wall/gran"``)."""
    caps: set[str] = set()
    cat = None
    for line in text.splitlines():
        s = line.strip()
        if s.startswith("*"):
            title = s.lstrip("* ").rstrip(":").strip()
            cat = _SECTION.get(title)
            continue
        if cat and s:
            caps.update(f"{cat} {tok}" for tok in s.split())
    return caps


_BOX = "units si\nboundary f f f\nregion b block -1 1 -1 1 -1 1 units box\ncreate_box 1 b\n"
_GRAN = "atom_style granular\n"
_MOL = "atom_style hybrid granular molecular\n"
_BONDGRAN = "atom_style hybrid granular bond/gran n_bondtypes 1 bonds_per_atom 2\n"
#: styles ``liggghts -h`` does not list (or lists under no section): probed with a tiny deck.
#: name -> (deck text, regex of the error that means "not available")
PROBES: dict[str, tuple[str, str]] = {
    "fix mesh/surface/stress": (_GRAN + _BOX + "fix p all mesh/surface/stress\n", r"Invalid fix style"),
    "fix bond/create/gran": (_GRAN + _BOX + "fix p all bond/create/gran\n", r"Invalid fix style"),
    "atom bond/gran": (_BONDGRAN + _BOX, r"Invalid atom.?style"),
    "bond gran": (_MOL + _BOX + "bond_style gran\n", r"Invalid bond style"),
    "bond harmonic": (_MOL + _BOX + "bond_style harmonic\n", r"Invalid bond style"),
}
_BASELINE = _GRAN + _BOX


def _run_probe(cmd: Sequence[str], deck: str, timeout: float = 120.0) -> str:
    with tempfile.TemporaryDirectory(prefix="deckgen-probe-") as tmp:
        (Path(tmp) / "probe.in").write_text(deck)
        try:
            out = subprocess.run(list(cmd) + ["-in", "probe.in", "-log", "none", "-nocite"], cwd=tmp,
                                 capture_output=True, text=True, errors="replace", timeout=timeout,
                                 stdin=subprocess.DEVNULL)
        except (OSError, subprocess.TimeoutExpired) as exc:
            raise EngineError(f"{' '.join(cmd)}: could not run the LIGGGHTS probe: {exc}") from None
        return out.stdout + "\n" + out.stderr


def _cache_file(cmd: Sequence[str]) -> Path | None:
    root = os.environ.get("DECKGEN_CACHE", ".deckgen-cache")
    binary = shutil.which(cmd[-1]) or cmd[-1]
    try:
        st = os.stat(binary)
    except OSError:
        return None
    key = hashlib.sha256(json.dumps([list(cmd), os.path.realpath(binary), st.st_size, st.st_mtime_ns,
                                     sorted(PROBES)]).encode()).hexdigest()[:16]
    return Path(root) / f"liggghts-capabilities-{key}.json"


@functools.lru_cache(maxsize=8)
def _capabilities(cmd: tuple[str, ...]) -> frozenset[str]:
    cache = _cache_file(cmd)
    if cache is not None and cache.is_file():
        try:
            return frozenset(json.loads(cache.read_text())["capabilities"])
        except (ValueError, KeyError):
            pass
    try:  # in a scratch folder: LIGGGHTS writes log.liggghts even for -h
        with tempfile.TemporaryDirectory(prefix="deckgen-probe-") as tmp:
            out = subprocess.run(list(cmd) + ["-h"], capture_output=True, text=True, errors="replace",
                                 timeout=120, stdin=subprocess.DEVNULL, cwd=tmp)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise EngineError(f"{' '.join(cmd)} -h: could not run LIGGGHTS: {exc}") from None
    if "LIGGGHTS" not in out.stdout:
        raise EngineError(f"{' '.join(cmd)} -h: not a LIGGGHTS binary (no version banner)")
    caps = parse_help(out.stdout)
    base = _run_probe(cmd, _BASELINE)
    if re.search(r"^ERROR", base, re.M):
        line = next(ln for ln in base.splitlines() if ln.startswith("ERROR"))
        raise EngineError(f"{' '.join(cmd)}: the LIGGGHTS probe deck fails: {line}")
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = dict(zip(PROBES, pool.map(lambda p: _run_probe(cmd, p[0]), PROBES.values())))
    for name, (_, absent) in PROBES.items():
        text = results[name]
        if re.search(absent, text):
            caps.discard(name)
        else:
            caps.add(name)
    m = re.search(r"LIGGGHTS \(Version ([^,)]*)", out.stdout)
    caps.add(f"version {m.group(1).strip().replace(' ', '_')}" if m else "version unknown")
    if cache is not None:
        try:
            cache.parent.mkdir(parents=True, exist_ok=True)
            cache.write_text(json.dumps({"command": list(cmd), "capabilities": sorted(caps)}, indent=1) + "\n")
        except OSError:
            pass
    return frozenset(caps)


def capabilities(cmd: Sequence[str] | None = None) -> frozenset[str]:
    """The styles a LIGGGHTS binary has, as ``"<category> <style>"`` strings.

    From ``liggghts -h`` (atom, pair, fix, compute, region, dump, command styles and the pair gran
    sub-models as ``gran_normal hertz`` ...), plus tiny probe decks for styles ``-h`` does not list
    (:data:`PROBES`: ``fix mesh/surface/stress``, the bond/gran styles, ``bond harmonic``).
    Cached per binary (in memory and in ``$DECKGEN_CACHE``). ``cmd`` defaults to the serial
    binary (probes need no MPI).
    """
    cmd = tuple(cmd) if cmd else (liggghts_binary(),)
    return _capabilities(cmd)


def has_bonds(caps: Iterable[str]) -> bool:
    """Whether the binary can run bond/gran decks (atom style, bond style and fix of the fork)."""
    caps = set(caps)
    return all(s in caps for s in BOND_STYLES)


def require_bonds(caps: Iterable[str] | None = None, *, what: str = "this bonded deck") -> None:
    """Raise :class:`LiggghtsCapabilityError` unless the binary has the fork's bond/gran styles."""
    binary = None
    if caps is None:
        binary = liggghts_binary()
        caps = capabilities((binary,))
    caps = set(caps)
    if has_bonds(caps):
        return
    missing = ", ".join(s for s in BOND_STYLES if s not in caps)
    version = next((c.split(" ", 1)[1] for c in caps if c.startswith("version ")), "unknown version")
    raise LiggghtsCapabilityError(
        f"{what} needs breakable granular bonds, but the LIGGGHTS binary {binary or ''} ({version}) lacks "
        f"{missing} (Debian's LIGGGHTS-PUBLIC 3.8 has only bond harmonic). Fix: build the "
        f"LIGGGHTS_Flexible_Fibers fork ({FORK_URL}) by hand outside this repository and point deckgen "
        f"to it: export {ENV_BINARY}=/path/to/liggghts (or '{ENV_BINARY}=mpirun -np 2 /path/to/liggghts')."
    )


def run_liggghts(run_dir: str | Path, *, ranks: int | None = None, command: list[str] | None = None,
                 timeout_s: float | None = None, caps: Iterable[str] | None = None, progress: bool = False):
    """Run ``in.liggghts`` of a rendered run folder; refuse bonded decks on a binary without bond/gran.

    Uses :func:`deckgen.runner.run_deck` (log checked with ``check_log``, ``run.json`` written) with
    the screen output sent to ``screen.liggghts``: LIGGGHTS 3.8 crashes (segfault in
    ``Region::reset_random``, called by ``fix insert/pack``) when run with ``-screen none``.
    Raises :class:`EngineError` on ERROR, lost atoms, NaN or a crash.
    """
    run_dir = Path(run_dir)
    if not (run_dir / DECK).is_file():
        raise EngineError(f"{run_dir / DECK}: deck not found (fix: render it first)")
    spec = json.loads((run_dir / "spec.json").read_text()) if (run_dir / "spec.json").is_file() else {}
    if spec.get("derived", {}).get("bonded"):
        require_bonds(caps if caps is not None else capabilities(), what=str(run_dir / DECK))
    cmd = list(command) if command else liggghts_command(ranks)
    # -screen none makes LIGGGHTS 3.8 segfault in Region::reset_random (fix insert/pack)
    return run_deck(run_dir, DECK, log=LOG, command=cmd, progress=progress, timeout_s=timeout_s,
                    screen="screen.liggghts", label=f"liggghts {run_dir.name}")


# =============================================================================== helpers
def _next_prime(n: int) -> int:
    """Smallest prime >= n (LIGGGHTS wants prime seeds > 10000)."""
    n = max(int(n), 10007)
    while True:
        if n % 2 and all(n % k for k in range(3, int(math.isqrt(n)) + 1, 2)):
            return n
        n += 1


def _seeds(seed: int, count: int) -> list[int]:
    out, n = [], 10007 + (int(seed) * 7919) % 900000
    for _ in range(count):
        p = _next_prime(n)
        out.append(p)
        n = p + 2
    return out


def contact_model(rolling: bool, cohesion: bool) -> list[str]:
    m = ["model", "hertz", "tangential", "history"]
    if cohesion:
        m += ["cohesion", "sjkr"]
    if rolling:
        m += ["rolling_friction", "epsd2"]
    return m


# =============================================================================== cutting deck
SETTLE_G_FACTOR = 30.0      # settling gravity / g (speeds up the fill; the bed then relaxes at 1 g)
FILL_HEIGHT_FACTOR = 2.2    # insertion box height / bed height
RADIUS_CLASSES = 4


BED_DATA = "bed.data"
BEDS = ("settle", "packing")


def write_granular_data(path: str | Path, *, title: str, box: Sequence[float], radius: np.ndarray,
                        density: np.ndarray, x: np.ndarray, n_atom_types: int = 2) -> Path:
    """Write a LIGGGHTS ``atom_style granular`` data file (Atoms: id type diameter density x y z; all type 1)."""
    path = Path(path)
    n = len(radius)
    with open(path, "w") as fh:
        fh.write(f"{title}\n\n{n} atoms\n{int(n_atom_types)} atom types\n\n")
        for k, ax in enumerate("xyz"):
            fh.write(f"{box[2 * k]:.9e} {box[2 * k + 1]:.9e} {ax}lo {ax}hi\n")
        fh.write("\nAtoms\n\n")
        for i in range(n):
            fh.write(f"{i + 1} 1 {2.0 * radius[i]:.9e} {density[i]:.9e} {x[i, 0]:.9e} {x[i, 1]:.9e} {x[i, 2]:.9e}\n")
    return path


def render_liggghts_cut(case: Case, out: str | Path, *, cohesion_energy_density: float = 0.0,
                        radius_classes: int = RADIUS_CLASSES, bed: str = "settle", cache: Path | None = None,
                        command: list[str] | None = None, mesh_dump_every: int = 0) -> dict[str, Any]:
    """Render a LIGGGHTS run folder: an unbonded granular bed cut by the case's STL disc.

    ``bed``: ``settle`` (LIGGGHTS inserts the grains and settles them under gravity, walls on all
    sides, trimmed to the block height) or ``packing`` (the case's packing from
    :func:`deckgen.packing.ensure_packing`, the same grains, radius shrink, fixed faces, time step
    and no gravity as the LAMMPS deck with ``bonds.enabled: false``: the cross-engine bed; ``cache``
    and ``command`` go to ensure_packing). ``cohesion_energy_density`` [J/m^3] > 0 switches on SJKR
    cohesion (grain-grain only). ``mesh_dump_every`` > 0 dumps the moved cutter mesh
    (``cutter_mesh_<step>.stl``). Writes ``in.liggghts``, ``cutter.stl`` (+ ``cutter_shell.stl``,
    unused), ``bed.data`` (bed ``packing``) and ``spec.json``; returns the spec.json content.
    """
    from deckgen.bonds import contact_timestep
    from deckgen.deck import build_cutter_files, cutter_path, fixed_face_boxes
    from deckgen.packing import ensure_packing, load_packing, specimen_region
    from deckgen.render import render

    if bed not in BEDS:
        raise SpecError(f"bed: {bed!r} is not one of {', '.join(BEDS)}")

    sp = case.specimen
    if not isinstance(sp, CuttingBlock):
        raise SpecError(f"specimen.kind: render_liggghts_cut needs a cutting_block, got {sp.kind} "
                        "(fix: use a cutting case)")
    k = case.kinematics
    if not (math.isfinite(cohesion_energy_density) and cohesion_energy_density >= 0):
        raise SpecError("cohesion_energy_density must be a finite number >= 0 J/m^3")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    c, p, run = case.contact, case.packing, case.run
    L, W, H = sp.length_mm * MM, sp.width_mm * MM, sp.height_mm * MM
    rmin, rmax = p.radius_min_mm * MM, p.radius_max_mm * MM
    rho = case.material.density_kg_m3 * run.mass_scaling
    E_c, nu_c = c.youngs_modulus_GPa * GPA, c.poisson_ratio
    E_s, nu_s = c.cutter_youngs_modulus_GPa * GPA, c.cutter_poisson_ratio

    # ---- cutter and path (shared with the LAMMPS decks)
    files = build_cutter_files(case, out)
    R = files["summary"]["diameter_m"] / 2.0
    path = cutter_path(case, R, axis=files["mesh"].metadata.get("deckgen_axis"))
    if case.kinematics.shaft_sense == "backward":  # the stacked move/mesh of this deck orbit in one sense only
        raise SpecError(f"case {case.name}: kinematics.shaft_sense backward is rendered for LAMMPS only "
                        f"(fix: engine lammps, or shaft_sense forward)")
    if "axis_tilt" in path:  # the stacked move/mesh below turn about y only
        raise SpecError(f"case {case.name}: a tilted disc (cutter.tilt_deg or a cone's clearance angle) that spins or "
                        "orbits about its own axis is rendered for LAMMPS only (fix: engine lammps, or tilt 0)")
    half_width = 0.5 * files["summary"]["width_m"]

    # ---- grains: radius classes at the bin centres of [rmin, rmax], equal number fractions
    n_cls = 1 if rmax - rmin < 1e-12 else max(1, int(radius_classes))
    radii = [rmin + (i + 0.5) * (rmax - rmin) / n_cls for i in range(n_cls)] if n_cls > 1 else [rmin]
    seeds = _seeds(p.seed, n_cls + 2)
    fractions = [1.0 / n_cls] * n_cls
    fractions[-1] = 1.0 - sum(fractions[:-1])
    classes = [{"radius": r, "fraction": f, "seed": s} for r, f, s in zip(radii, fractions, seeds)]

    # ---- bed from the case's packing (same grains, shrink and time step as the LAMMPS deck)
    grains = None
    if bed == "packing":
        atoms, packinfo = load_packing(ensure_packing(case, cache, progress=False, command=command))
        r_bed = atoms.radius * (1.0 - case.bonds.shrink_before_bonding)
        grains = {"x": atoms.x, "r": r_bed, "r_full_max": float(atoms.radius.max()), "key": packinfo["key"]}

    # ---- time step and phases
    r_dt = float(grains["r"].min()) if grains else rmin
    dt = run.timestep_s or contact_timestep(r_dt, rho, E_c, nu_c, safety=0.2)
    h_fill = FILL_HEIGHT_FACTOR * H
    fill_fraction = min(0.36, 1.15 * 0.60 * H / h_fill)
    g_settle = SETTLE_G_FACTOR * 9.81
    t_fall = math.sqrt(2.0 * h_fill / g_settle)
    quantum = case.outputs.series_every
    settle_steps = _round_up(int(math.ceil(3.0 * t_fall / dt)), run.thermo_every)
    relax_steps = _round_up(int(math.ceil(0.5 * t_fall / dt)), run.thermo_every)
    nsteps = _round_up(int(math.ceil(path["duration"] / dt)), quantum)
    total = nsteps if grains else settle_steps + 2 * relax_steps + nsteps
    if total > run.max_steps:
        raise SpecError(f"run.max_steps: the LIGGGHTS cut needs {total} steps at dt {dt:.3g} s "
                        "(fix: raise run.max_steps, shorten kinematics.travel_mm or raise speed_m_s)")

    # ---- box: bed fill, whole cutter path, margins
    pad = 4.0 * rmax
    e = path["ecc"]
    xlo = min(-pad, path["xc0"] - R - 2 * e - pad)
    xhi = max(L + pad, path["xc0"] + path["travel"] + R + 2 * e + pad)
    yhi = max(W / 2, half_width) + pad
    zhi = max(h_fill, path["zc0"] + R + 2 * e) + pad
    if grains:  # no walls: room above for the grains the disc throws up (fixed boundaries lose them)
        zhi = max(zhi, H + 2.0 * R + pad)
    if path["rotary_radius"]:  # the curved path drifts toward +y
        yhi = max(yhi, path["rotary_radius"] * (1 - math.cos(path["travel"] / path["rotary_radius"])) + R + pad)
    box = [xlo, xhi, -yhi, yhi, -pad, zhi]
    data_file = None
    fixed_faces: list[dict[str, Any]] = []
    if grains:
        data_file = BED_DATA
        write_granular_data(out / BED_DATA, title=f"deckgen {case.name} packing {grains['key']}", box=box,
                            radius=grains["r"], density=np.full(len(grains["r"]), rho), x=grains["x"])
        fixed_faces = fixed_face_boxes(sp, specimen_region(case), 2.0 * grains["r_full_max"],
                                       3.0 * float(grains["r"].max()))

    walls_all = [("zmin", "zplane", 0.0), ("xmin", "xplane", 0.0), ("xmax", "xplane", L),
                 ("ymin", "yplane", -W / 2), ("ymax", "yplane", W / 2)]
    keep = {"zmin"} | set(sp.fixed_faces)
    settle_walls = [{"id": f"w_{f}", "plane": pl, "position": pos} for f, pl, pos in walls_all]
    cut_walls_off = [f"w_{f}" for f, _, _ in walls_all if f not in keep]

    # spin correction on top of the stacked moves: orbit spins the disc by -omega t about +y
    orbit_spin = -path["omega"] if path["ecc"] > 0 else 0.0
    corr = path["spin_rate"] - orbit_spin
    spin_fix = None
    if abs(corr) > 0:
        spin_fix = {"axis_y": 1.0 if corr > 0 else -1.0, "period": 2 * math.pi / abs(corr)}
    oscillation = path["ecc"] > 0 and path["omega"] > 0

    rolling = c.rolling_friction > 0
    cohesion = cohesion_energy_density > 0
    variables = [
        _var("rho", rho, "grain density (x mass scaling)", "kg/m^3"),
        _var("E_c", E_c, "grain Young's modulus (Hertz)", "Pa"),
        _var("nu_c", nu_c, "grain Poisson's ratio", "1"),
        _var("E_s", E_s, "steel (cutter, walls) Young's modulus", "Pa"),
        _var("nu_s", nu_s, "steel Poisson's ratio", "1"),
        _var("e_rest", c.restitution, "coefficient of restitution (all pairs)", "1"),
        _var("mu_c", c.friction, "grain-grain friction", "1"),
        _var("mu_cut", c.cutter_friction, "grain-steel friction", "1"),
        _var("mu_roll", c.rolling_friction, "grain-grain rolling friction (EPSD2)", "1"),
        _var("coh_ced", cohesion_energy_density, "SJKR cohesion energy density (grain-grain)", "J/m^3"),
        _var("dt", dt, "time step: 0.2 Rayleigh time of the smallest grain", "s"),
        _var("skin", 0.5 * rmax, "neighbour skin", "m"),
        _var("g_settle", g_settle, "settling gravity (%g g)" % SETTLE_G_FACTOR, "m/s^2"),
        _var("fill_fraction", fill_fraction, "insert/pack volume fraction of the fill box", "1"),
        _var("settle_steps", settle_steps, "settling run (3 fall times at g_settle)", "steps"),
        _var("relax_steps", relax_steps, "relaxation runs at 1 g", "steps"),
        *path_variables(path),
        _var("x_shaft", path["xc0"] - path["ecc"], "eccentric shaft axis x at t = 0", "m"),
        _var("period_osc", 2 * math.pi / path["omega"] if oscillation else 1.0, "oscillation period", "s"),
        _var("spin_rate", path["spin_rate"], "net spin of the disc about +y", "rad/s"),
        *([_var("r_rot", path["rotary_radius"], "rotary path radius", "m"),
           _var("yaw_rate", path["yaw_rate"], "yaw rate of the disc on its circular path (v/r)", "rad/s"),
           _var("period_yaw", 2 * math.pi / path["yaw_rate"], "period of the yaw rotation", "s"),
           _var("ax_x", path["axis_x"], "rotary axis x", "m"),
           _var("ax_y", path["axis_y"], "rotary axis y", "m")] if k.mode == "rotary" else []),
        _var("nsteps", nsteps, "steps of the cut", "steps"),
        _var("thermo_every", run.thermo_every, "thermo interval", "steps"),
        _var("series_every", case.outputs.series_every, "time-series interval", "steps"),
        _var("dump_every", case.outputs.dump_every or max(1, nsteps // 10), "per-atom dump interval", "steps"),
    ]
    ctx: dict[str, Any] = {
        "version": __version__, "case_name": case.name, "test": case.test, "deck_name": DECK,
        "title": f"{k.mode} cutting of an unbonded granular bed by a {case.cutter.kind}",
        "template": "cut_bed.liggghts.j2", "variables": variables, "hard_particles": max(E_c, E_s) > 1e9,
        "atom_style": ["granular"], "box": box, "n_atom_types": 2, "rolling": rolling, "cohesion": cohesion,
        "contact_model": contact_model(rolling, cohesion), "settle_walls": settle_walls,
        "cut_walls_off": cut_walls_off, "radius_classes": classes, "n_classes": n_cls,
        "seed_pdd": seeds[n_cls], "seed_ins": seeds[n_cls + 1],
        "fill_bounds": [0.0, L, -W / 2, W / 2, 0.0, h_fill],
        "above_bounds": [box[0], box[1], box[2], box[3], H, box[5]],
        "stl": "cutter.stl", "oscillation": oscillation, "spin_fix": spin_fix, "data_file": data_file,
        "fixed_faces": fixed_faces, "mesh_dump_every": int(mesh_dump_every), "rotary": k.mode == "rotary",
        "indent": k.mode == "indentation",
    }
    (out / DECK).write_text(render("liggghts/cut_bed.liggghts.j2", ctx))
    reg = specimen_region(case)
    mean_v = 4.0 / 3.0 * math.pi * float(np.mean(np.asarray(radii) ** 3))
    derived = {
        "engine": "liggghts", "bonded": False, "dt_s": dt, "dt_contact_s": dt,
        "n_grains": len(grains["r"]) if grains else int(round(0.6 * reg.volume_m3 / mean_v)),
        "n_grains_is_estimate": not grains, "bed": bed, "packing_key": grains["key"] if grains else None,
        "n_bonds": 0, "specimen_volume_m3": reg.volume_m3, "radius_classes_m": None if grains else radii,
        "cohesion_energy_density_J_m3": cohesion_energy_density,
        "settle": None if grains else {"g_m_s2": g_settle, "fill_height_m": h_fill, "fill_fraction": fill_fraction,
                                       "settle_steps": settle_steps, "relax_steps": relax_steps},
        "walls_during_cut": [] if grains else sorted(keep),
        "fixed_faces": [f["name"] for f in fixed_faces],
        "cutter": {kk: float(v) for kk, v in path.items()},
        "cutter_summary": {kk: (float(v) if isinstance(v, (int, float, np.floating)) else v)
                           for kk, v in files["summary"].items()},
        "expected_steps": nsteps, "expected_steps_total": total,
        "steady_window": list(case.outputs.steady_window), "kinematics_mode": k.mode,
        "stacked_moves": (["rotate_yaw"] if k.mode == "rotary" else ["linear"]) + (["rotate_orbit"] if oscillation else [])
        + (["rotate_spin"] if spin_fix else []),
    }
    spec = {"deckgen_version": __version__, "engine": "liggghts", "case": resolved_dict(case), "derived": derived}
    spec["case"]["engine"] = "liggghts"
    (out / "spec.json").write_text(json.dumps(spec, indent=2, sort_keys=True) + "\n")
    return spec


def read_stl_triangles(path: str | Path) -> np.ndarray:
    """Triangles (n, 3, 3) [m] of an ASCII STL (``dump mesh/stl`` output), streamed line by line."""
    from deckgen.parse.common import ParseError, open_text

    path = Path(path)
    verts: list[list[float]] = []
    with open_text(path) as fh:
        for lineno, line in enumerate(fh, 1):
            w = line.split()
            if w and w[0] == "vertex":
                try:
                    verts.append([float(w[1]), float(w[2]), float(w[3])])
                except (IndexError, ValueError):
                    raise ParseError(path, lineno, "bad vertex line") from None
    if len(verts) % 3:
        raise ParseError(path, 0, f"{len(verts)} vertices: not whole triangles")
    return np.asarray(verts, dtype=float).reshape(-1, 3, 3)


def rigid_cutter_position(p0: np.ndarray, path: Mapping[str, float], t: float) -> np.ndarray:
    """Where points ``p0`` (shape (..., 3)) of the disc at rest (centre at the origin, axis y) are at cut time ``t``:
    the LAMMPS deck's rigid motion, :func:`deckgen.deck.cutter_world_points` (the stacked move/mesh of this deck
    reproduce it; spec.json files from before the rotary path lack its keys: no yaw)."""
    from deckgen.deck import cutter_world_points

    p = np.asarray(p0, dtype=float)
    full = {"rotary_radius": 0.0, "yaw_rate": 0.0, "axis_x": 0.0, "axis_y": 0.0, "mode_indent": 0.0, **path}
    return cutter_world_points(p.reshape(-1, 3), full, t).reshape(p.shape)


def render_liggghts(case: Case, out: str | Path, *, bed: str = "packing", cache: Path | None = None,
                    command: list[str] | None = None) -> dict[str, Any]:
    """Render any case for LIGGGHTS, or refuse it in one line (:class:`SpecError`) saying what to change.

    cutting + ``bonds.enabled: false``: :func:`render_liggghts_cut` (``bed`` packing or settle);
    ucs / bts with bonds: :func:`render_liggghts_ucs_bonded` / :func:`render_liggghts_bts_bonded`
    (Flexible_Fibers fork).
    """
    bonded = case.bonds.enabled
    if case.test == "cutting":
        if bonded:
            raise SpecError(f"case {case.name}: engine liggghts renders unbonded cutting beds only (a bonded cutting block "
                            "for the bond/gran fork is not written yet) (fix: bonds.enabled: false, or engine: lammps)")
        return render_liggghts_cut(case, out, bed=bed, cache=cache, command=command)
    if not bonded:
        raise SpecError(f"case {case.name}: engine liggghts renders {case.test} specimens bonded only "
                        "(fix: bonds.enabled: true, or engine: lammps)")
    if case.test == "ucs":
        return render_liggghts_ucs_bonded(case, out)
    return render_liggghts_bts_bonded(case, out)


#: summary quantities compared by :func:`cross_engine_cut` (cutter frame, steady window)
CROSS_QUANTITIES = ("force_normal_N_mean_steady", "force_rolling_N_mean_steady", "force_side_N_mean_steady",
                    "contact_fraction_steady_1")


def cross_engine_cut(case: Case, out: str | Path, *, cache: Path | None = None, ranks: int = 1,
                     timeout_s: float | None = 1800) -> dict[str, Any]:
    """Cut the same unbonded bed with the same disc and motion on LAMMPS and on LIGGGHTS.

    The case must have ``bonds.enabled: false``. LAMMPS: :func:`deckgen.deck.render_case` (the
    case's packing, radii shrunk by ``shrink_before_bonding``, no bond, cutter = rigid shell of
    spheres on the STL offset inward by their radius). LIGGGHTS: :func:`render_liggghts_cut` with
    ``bed="packing"`` (the same grains from the same packing, the same fixed faces, time step and
    motion, no gravity; cutter = the STL mesh itself). Both runs are parsed with
    :func:`deckgen.results.parse_run`; returns ``{"lammps": {...}, "liggghts": {...}, "ratio":
    {q: liggghts / lammps}}`` for :data:`CROSS_QUANTITIES`, plus the folders.
    """
    from deckgen.deck import render_case
    from deckgen.results import parse_run
    from deckgen.runner import engine_command, run_deck

    if case.test != "cutting" or case.bonds.enabled:
        raise SpecError(f"case {case.name}: the cross-engine check needs a cutting case with bonds.enabled: false")
    out = Path(out)
    lmp_cmd = engine_command(ranks)
    res: dict[str, Any] = {}
    for eng in ("lammps", "liggghts"):
        d = out / eng
        c = case.model_copy(update={"engine": eng})
        if eng == "lammps":
            render_case(c, d, cache=cache, progress=False, command=lmp_cmd)
            run_deck(d, "in.deck", command=lmp_cmd, progress=False, timeout_s=timeout_s, label=f"lammps {case.name}")
        else:
            render_liggghts_cut(c, d, bed="packing", cache=cache, command=lmp_cmd)
            run_liggghts(d, ranks=ranks, timeout_s=timeout_s)
        s = parse_run(d, d / "parsed")
        res[eng] = {q: s[q] for q in CROSS_QUANTITIES} | {"n_grains": s["n_grains"], "dir": str(d)}
    res["ratio"] = {q: (res["liggghts"][q] / res["lammps"][q] if res["lammps"][q] else float("nan"))
                    for q in CROSS_QUANTITIES}
    return res


# =============================================================================== bond/gran (fork)
#: damp type -> number of damping values (BondGran::coeff, src/bond_gran.cpp of the fork at
#: commit 0ea55cc3268c25e2fd0d06a0523fa5e1a1dcbc50): 0 none (one unused value), 1 Yu Guo
#: (linear, fraction of critical), 2 non-linear (beta0 beta1 beta2), 3 non-linear reduced,
#: 4 non-linear reduced simplified, 5 non-linear relative (beta0 beta1 beta2)
DAMP_VALUES = {0: 1, 1: 1, 2: 3, 3: 1, 4: 1, 5: 3}
#: break type -> number of break values: 0 simple (r_break), 1 stress (sigma tau), 2 stress +
#: temperature (sigma tau T; needs fix heat/gran). Types 3-5 of the wiki are not in the source.
BREAK_VALUES = {0: 1, 1: 2, 2: 3}
_NUM = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")
_TYPE_RANGE = re.compile(r"^(\d+|\*|\d+\*|\*\d+|\d+\*\d+)$")


def bond_gran_coefficients(E_b: float, stiffness_ratio: float, sigma_c: float, tau_c: float,
                           radius_multiplier: float, damping_ratio: float) -> dict[str, float | int]:
    """bond_coeff values of the fork's ``bond_style gran`` for the parallel-bond inputs (SI).

    ``ro = lambda``, ``ri = 0``, ``Y = E_b``, ``G = E_b / (kn/ks)``, damp type 1 with the damping
    ratio (damp type 0 when it is 0), break type 1 with ``sigma_break = sigma_c`` and
    ``tau_break = tau_c``. Derivation: module docstring. ``ro`` must be in (0, 1]: the fork's docs
    define it as a fraction of the (smaller) grain radius between 0 and 1.
    """
    vals = dict(E_b=E_b, stiffness_ratio=stiffness_ratio, sigma_c=sigma_c, tau_c=tau_c,
                radius_multiplier=radius_multiplier, damping_ratio=damping_ratio)
    for k, v in vals.items():
        if not math.isfinite(v) or v < 0 or (v == 0 and k != "damping_ratio"):
            raise ValueError(f"{k} = {v!r}: must be a finite positive number")
    if radius_multiplier > 1.0:
        raise ValueError(f"radius_multiplier = {radius_multiplier:g}: bond_style gran takes ro in (0, 1] "
                         "(fraction of the smaller grain radius); use bonds.radius_multiplier <= 1")
    damp_type = 1 if damping_ratio > 0 else 0
    return {"ro": float(radius_multiplier), "ri": 0.0, "Y": float(E_b), "G": float(E_b / stiffness_ratio),
            "damp_type": damp_type, "damp": float(damping_ratio), "break_type": 1,
            "sigma_break": float(sigma_c), "tau_break": float(tau_c)}


def bond_coeff_line(btype: int, c: Mapping[str, float | int]) -> str:
    from deckgen.render import f_int, f_num

    return " ".join(["bond_coeff", f_int(btype), f_num(c["ro"]), f_num(c["ri"]), f_num(c["Y"]), f_num(c["G"]),
                     f_int(c["damp_type"]), f_num(c["damp"]), f_int(c["break_type"]),
                     f_num(c["sigma_break"]), f_num(c["tau_break"])])


def _number(tok: str, what: str, line: str) -> float:
    if not _NUM.match(tok):
        raise BondGrammarError(f"{what} {tok!r} is not a number: {line!r}")
    return float(tok)


def _type_code(tok: str, what: str, table: Mapping[int, int], line: str) -> int:
    v = _number(tok, what, line)
    if v not in table:
        raise BondGrammarError(f"{what} {tok} does not exist (allowed: {sorted(table)}): {line!r}")
    return int(v)


def check_bond_coeff_line(line: str, *, allow_abort: bool = False) -> dict[str, Any]:
    """Check one ``bond_coeff`` line against the fork's ``BondGran::coeff`` argument rules.

    Grammar (narg counts the words after ``bond_coeff``, the bond type included)::

        bond_coeff N ro ri Y G damp_type damp_val(s) break_type break_val(s)

    ``ro > ri >= 0`` ("ro must be greater than ri"); damp_type 0-5 with 1 or 3 values
    (:data:`DAMP_VALUES`); break_type 0-2 with narg = 9, 10, 11 (+2 for damp types 2 and 5).
    Break type 0 calls ``error->all("broken")`` on the first broken bond, aborting the run: it is
    refused unless ``allow_abort``. Break type 2 needs ``fix heat/gran`` (a ``Temp`` property).
    Returns the parsed fields; raises :class:`BondGrammarError`.
    """
    words = line.split("#", 1)[0].split()
    if not words or words[0] != "bond_coeff":
        raise BondGrammarError(f"not a bond_coeff line: {line!r}")
    args = words[1:]
    if len(args) < 8:
        raise BondGrammarError("Incorrect args for bond coefficients (ro, ri, sn, st, damp_style, damp_perams, "
                               f"break_style, break_perams): {line!r}")
    if not _TYPE_RANGE.match(args[0]):
        raise BondGrammarError(f"bond type {args[0]!r} is not a type or type range: {line!r}")
    ro, ri = _number(args[1], "ro", line), _number(args[2], "ri", line)
    Y, G = _number(args[3], "Y", line), _number(args[4], "G", line)
    if ro <= ri:
        raise BondGrammarError(f"ro must be greater than ri: {line!r}")
    if ri < 0 or Y <= 0 or G <= 0:
        raise BondGrammarError(f"ri must be >= 0 and Y, G > 0: {line!r}")
    dtype = _type_code(args[5], "damp type", DAMP_VALUES, line)
    nd = DAMP_VALUES[dtype]
    extra = 2 if nd == 3 else 0
    if len(args) < 6 + nd + 1:
        raise BondGrammarError(f"Incorrect args for bond coefficients (damp type {dtype} takes {nd} values): {line!r}")
    damp = [_number(t, "damp value", line) for t in args[6:6 + nd]]
    btype = _type_code(args[6 + nd], "break type", BREAK_VALUES, line)
    want = {0: 9, 1: 10, 2: 11}[btype] + extra
    if len(args) != want:
        raise BondGrammarError(f"Incorrect args for bond coefficients: damp type {dtype} and break type {btype} "
                               f"need {want} arguments after bond_coeff, got {len(args)}: {line!r}")
    brk = [_number(t, "break value", line) for t in args[7 + nd:]]
    if btype == 0 and not allow_abort:
        raise BondGrammarError("break type 0 (simple) calls error->all('broken') when a bond breaks: the run aborts "
                               f"(use break type 1): {line!r}")
    if any(v < 0 for v in damp) or (btype >= 1 and any(v <= 0 for v in brk[:2])):
        raise BondGrammarError(f"damping values must be >= 0 and break stresses > 0: {line!r}")
    return {"type": args[0], "ro": ro, "ri": ri, "Y": Y, "G": G, "damp_type": dtype, "damp": damp,
            "break_type": btype, "break": brk}


def check_bond_create_line(line: str) -> dict[str, Any]:
    """Check ``fix ID group bond/create/gran every itype jtype cutoff btype newperts [iparam M T]
    [jparam M T] [prob frac seed]`` (FixBondCreateGran constructor, src/fix_bond_create_gran.cpp)."""
    w = line.split("#", 1)[0].split()
    if len(w) < 9 or w[0] != "fix" or w[3] != "bond/create/gran":
        raise BondGrammarError(f"Illegal fix bond/create command (needs 6 values after the style): {line!r}")
    every, itype, jtype, btype, newperts = (int(_number(t, n, line)) for t, n in
                                           zip((w[4], w[5], w[6], w[8], w[9] if len(w) > 9 else "x"),
                                               ("every", "itype", "jtype", "btype", "newperts")))
    cutoff = _number(w[7], "cutoff", line)
    if every <= 0 or itype < 1 or jtype < 1 or btype < 1 or newperts < 1 or cutoff < 0:
        raise BondGrammarError(f"Illegal fix bond/create command: {line!r}")
    i = 10
    while i < len(w):
        if w[i] in ("iparam", "jparam", "prob") and i + 3 <= len(w):
            i += 3
        else:
            raise BondGrammarError(f"Illegal fix bond/create command: unknown keyword {w[i]!r}: {line!r}")
    return {"id": w[1], "every": every, "itype": itype, "jtype": jtype, "cutoff": cutoff, "btype": btype,
            "newperts": newperts}


def check_bonded_deck(text: str) -> dict[str, Any]:
    """Grammar of a whole bonded deck: atom style, bond style, every bond_coeff, bond creation switched
    off after a run (``fix_modify ID every 0``), fixed boundaries. Raises :class:`BondGrammarError`."""
    lines = [" ".join(ln.split("#", 1)[0].split()) for ln in text.splitlines()]
    lines = [ln for ln in lines if ln]
    # substitute index-style variables (the deck's parameter block), as the engine would
    values = {w[1]: w[3] for w in (ln.split() for ln in lines) if len(w) == 4 and w[0] == "variable" and w[2] == "index"}
    lines = [re.sub(r"\$\{(\w+)\}", lambda m: values.get(m.group(1), m.group(0)), ln) for ln in lines]
    atom = [ln for ln in lines if ln.startswith("atom_style")]
    if len(atom) != 1:
        raise BondGrammarError("a bonded deck needs exactly one atom_style line")
    aw = atom[0].split()
    if "bond/gran" not in aw:
        raise BondGrammarError(f"atom_style must include bond/gran: {atom[0]!r}")
    k = aw.index("bond/gran")
    rest = aw[k + 1:]
    if len(rest) < 4 or rest[0] != "n_bondtypes" or rest[2] != "bonds_per_atom":
        raise BondGrammarError(f"atom_style bond/gran expects 'n_bondtypes k bonds_per_atom m': {atom[0]!r}")
    ntypes, per_atom = int(_number(rest[1], "n_bondtypes", atom[0])), int(_number(rest[3], "bonds_per_atom", atom[0]))
    if len(rest) > 4 and (len(rest) != 6 or rest[4] != "disableNormalContact" or rest[5] not in ("0", "1")):
        raise BondGrammarError(f"atom_style bond/gran: optional 'disableNormalContact 0|1' only: {atom[0]!r}")
    if ntypes < 1 or per_atom < 1:
        raise BondGrammarError(f"n_bondtypes and bonds_per_atom must be > 0: {atom[0]!r}")
    if not any(ln.split() == ["bond_style", "gran"] for ln in lines):
        raise BondGrammarError("a bonded deck needs 'bond_style gran'")
    coeffs = [check_bond_coeff_line(ln) for ln in lines if ln.startswith("bond_coeff")]
    if not coeffs:
        raise BondGrammarError("no bond_coeff line")
    creates = [(i, check_bond_create_line(ln)) for i, ln in enumerate(lines) if "bond/create/gran" in ln.split()[:4]]
    for i, c in creates:
        if c["btype"] > ntypes:
            raise BondGrammarError(f"Invalid bond type {c['btype']} in fix bond/create (n_bondtypes {ntypes})")
        off = [j for j, ln in enumerate(lines) if j > i and ln.split()[:4] == ["fix_modify", c["id"], "every", "0"]]
        runs = [j for j, ln in enumerate(lines) if j > i and ln.startswith("run")]
        if not off or not runs or runs[0] > off[0]:
            raise BondGrammarError(f"fix {c['id']} bond/create/gran must run once and then be switched off with "
                                   f"'fix_modify {c['id']} every 0' before the loading run")
    bnd = [ln for ln in lines if ln.startswith("boundary")]
    if bnd != ["boundary f f f"]:
        raise BondGrammarError("bonded decks use 'boundary f f f' with margins (bonds near a box face are flagged broken)")
    return {"n_bondtypes": ntypes, "bonds_per_atom": per_atom, "bond_coeffs": coeffs, "bond_create": [c for _, c in creates]}


def _platen_stl(path: Path, radius: float, z: float, thickness: float, down: bool) -> None:
    import trimesh

    from deckgen.geometry import write_stl

    box = trimesh.creation.box(extents=[2.4 * radius, 2.4 * radius, thickness])
    box.apply_translation([0.0, 0.0, z - thickness / 2 if down else z + thickness / 2])
    write_stl(box, path)


def render_liggghts_ucs_bonded(case: Case, out: str | Path) -> dict[str, Any]:
    """Render a bonded UCS deck for the Flexible_Fibers fork (golden-tested and grammar-checked only).

    Grains are inserted into the cylinder and settled on the bottom platen by LIGGGHTS, trimmed
    to the height (centres above H - r_max deleted; the top platen mesh is placed only then), bonded
    once with ``fix bond/create/gran`` (cutoff (1 + gap_tolerance) x the mean grain diameter: the
    fork's bond creation has one cutoff, it is not radius-aware), then loaded by the top platen.
    """
    if not isinstance(case.specimen, UcsCylinder):
        raise SpecError(f"specimen.kind: render_liggghts_ucs_bonded needs ucs_cylinder, got {case.specimen.kind}")
    return _render_platen_bonded(case, out)


def render_liggghts_bts_bonded(case: Case, out: str | Path) -> dict[str, Any]:
    """Render a bonded Brazilian test deck for the Flexible_Fibers fork (golden-tested and grammar-checked only).

    The disc (axis y, centre (0, R) in x-z, as :func:`deckgen.packing.specimen_region`) is made by
    insertion and settling in a box 2R wide between y walls, trimmed to the disc (grains with their
    centre above 2R - r_max or farther than R - r_max from the axis are deleted, so no grain crosses
    the platens), bonded once as the UCS deck, and loaded across its diameter by flat platen meshes
    (bottom at z = 0, top at z = 2R moving down). Stress = F / (pi D t / 2) (the Brazilian tensile
    stress 2F/(pi D t), as the LAMMPS deck); strain = platen displacement / D.
    """
    if not isinstance(case.specimen, BrazilianDisc):
        raise SpecError(f"specimen.kind: render_liggghts_bts_bonded needs brazilian_disc, got {case.specimen.kind}")
    return _render_platen_bonded(case, out)


def _render_platen_bonded(case: Case, out: str | Path) -> dict[str, Any]:
    """The bonded platen decks (UCS cylinder, Brazilian disc) for the Flexible_Fibers fork."""
    from deckgen.render import render

    sp = case.specimen
    bts = isinstance(sp, BrazilianDisc)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    b, c, p, run = case.bonds, case.contact, case.packing, case.run
    if bts:
        Rc, Hc, thick = sp.diameter_mm * MM / 2, sp.diameter_mm * MM, sp.thickness_mm * MM
    else:
        Rc, Hc = sp.diameter_mm * MM / 2, sp.height_mm * MM
    rmin, rmax = p.radius_min_mm * MM, p.radius_max_mm * MM
    rho = case.material.density_kg_m3 * run.mass_scaling
    E_b = b.youngs_modulus_GPa * GPA
    unsupported = [f"bonds.{n}" for n in ("clump_size", "unbonded_fraction", "bending_strength_factor",
                                          "twisting_strength_factor", "strength_weibull_modulus", "model",
                                          "joint_friction", "moment_contribution", "bond_friction")
                   if getattr(b, n) != type(b).model_fields[n].default]
    if unsupported:  # bond/gran bonds every grain pair in range with one bond type: none of these maps onto it
        raise SpecError(f"case {case.name}: the LIGGGHTS bonded deck (one bond/gran type for all pairs) cannot express "
                        f"{', '.join(unsupported)} (fix: use engine lammps, or leave them at their defaults)")
    try:
        bond = bond_gran_coefficients(E_b, b.stiffness_ratio, b.tensile_strength_MPa * MPA,
                                      b.shear_strength_MPa * MPA, b.radius_multiplier, b.damping_ratio)
    except ValueError as exc:
        raise SpecError(f"bonds: {exc}") from None
    # time step: rotational bond mode of the smallest grain with ~6 bonds (deckgen.bonds, ENGINE_NOTES)
    from deckgen.bonds import bpm_coefficients

    Lb = 2 * rmin
    m = rho * 4 / 3 * math.pi * rmin**3
    cf = bpm_coefficients(E_b, b.stiffness_ratio, b.tensile_strength_MPa * MPA, b.shear_strength_MPa * MPA,
                          b.radius_multiplier * rmin, Lb, m / 2, 0.2 * m * rmin**2, b.damping_ratio)
    k_r, k_s, k_b = (float(cf[k]) for k in ("k_r", "k_s", "k_b"))
    w = max(math.sqrt(6 * k_r / m), math.sqrt(6 * (0.75 * k_s * Lb**2 + k_b) / (0.4 * m * rmin**2)))
    dt = run.timestep_s or run.timestep_safety * 2.0 / w
    skin = 0.3 * rmax
    n_cls = 1 if rmax - rmin < 1e-12 else RADIUS_CLASSES
    radii = [rmin + (i + 0.5) * (rmax - rmin) / n_cls for i in range(n_cls)] if n_cls > 1 else [rmin]
    seeds = _seeds(p.seed, n_cls + 2)
    fr = [1.0 / n_cls] * n_cls
    fr[-1] = 1.0 - sum(fr[:-1])
    classes = [{"radius": r, "fraction": f, "seed": s} for r, f, s in zip(radii, fr, seeds)]
    fill_h = 2.0 * Hc
    g_settle = SETTLE_G_FACTOR * 9.81
    from deckgen.bonds import contact_timestep

    dt_settle = max(dt, contact_timestep(rmin, rho, c.youngs_modulus_GPa * GPA, c.poisson_ratio, safety=0.2))
    settle_steps = _round_up(int(math.ceil(3.0 * math.sqrt(2 * fill_h / g_settle) / dt_settle)), run.thermo_every)
    v = sp.platen_speed_m_s
    nsteps = _round_up(int(math.ceil(sp.max_strain * Hc / v / dt)), case.outputs.series_every)
    margin = 2 * rmax + 6 * skin      # every grain stays > skin away from the box faces
    box = [-Rc - margin, Rc + margin, -Rc - margin, Rc + margin, -margin, fill_h + margin]
    area = math.pi * Rc**2
    if bts:
        box[2:4] = [-thick / 2 - margin, thick / 2 + margin]
        area = math.pi * (2 * Rc) * thick / 2.0  # sigma_t = F / area = 2F/(pi D t)
    _platen_stl(out / "platen_bottom.stl", Rc, 0.0, 2 * rmax, down=True)
    _platen_stl(out / "platen_top.stl", Rc, Hc, 2 * rmax, down=False)
    per_atom = 16
    variables = [
        _var("rho", rho, "grain density (x mass scaling)", "kg/m^3"),
        _var("E_c", c.youngs_modulus_GPa * GPA, "grain Young's modulus (Hertz)", "Pa"),
        _var("nu_c", c.poisson_ratio, "grain Poisson's ratio", "1"),
        _var("E_s", c.cutter_youngs_modulus_GPa * GPA, "platen (steel) Young's modulus", "Pa"),
        _var("nu_s", c.cutter_poisson_ratio, "platen Poisson's ratio", "1"),
        _var("e_rest", c.restitution, "coefficient of restitution", "1"),
        _var("mu_c", c.friction, "grain-grain friction", "1"),
        _var("mu_cut", c.platen_friction, "grain-platen friction", "1"),
        _var("mu_roll", c.rolling_friction, "grain-grain rolling friction (EPSD2)", "1"),
        _var("dt", dt, "time step: rotational bond mode of the smallest grain", "s"),
        _var("dt_settle", dt_settle, "time step of the unbonded settling (0.2 Rayleigh time)", "s"),
        _var("skin", skin, "neighbour skin", "m"),
        _var("radius", Rc, "specimen radius", "m"),
        _var("height", Hc, "specimen height (top platen start)", "m"),
        _var("fill_height", fill_h, "insertion cylinder height", "m"),
        _var("fill_fraction", 0.33, "insert/pack volume fraction", "1"),
        _var("g_settle", g_settle, "settling gravity", "m/s^2"),
        _var("settle_steps", settle_steps, "settling run", "steps"),
        _var("bond_cutoff", (1 + b.gap_tolerance) * (rmin + rmax), "bond creation cutoff (centre distance)", "m"),
        _var("v_platen", v, "top platen speed (down)", "m/s"),
        _var("area", area, "stress area (UCS pi R^2, BTS pi D t / 2)", "m^2") if bts else
        _var("area", area, "stress area pi R^2", "m^2"),
        *([_var("thickness", thick, "disc thickness (y)", "m"),
           _var("trim_radius", Rc - rmax, "grains with their centre farther from the disc axis are deleted", "m")]
          if bts else []),
        _var("nsteps", nsteps, "loading steps (max strain)", "steps"),
        _var("thermo_every", run.thermo_every, "thermo interval", "steps"),
        _var("series_every", case.outputs.series_every, "time-series interval", "steps"),
    ]
    rolling = c.rolling_friction > 0
    ctx = {
        "version": __version__, "case_name": case.name, "test": case.test, "deck_name": DECK,
        "title": "Brazilian test of a bonded disc (bond/gran fork)" if bts else
        "uniaxial compression of a bonded cylinder (bond/gran fork)",
        "template": "bts_bonded.liggghts.j2" if bts else "ucs_bonded.liggghts.j2",
        "variables": variables, "hard_particles": True, "box": box, "n_atom_types": 2,
        "atom_style": ["hybrid", "granular", "bond/gran", "n_bondtypes", 1, "bonds_per_atom", per_atom,
                       "disableNormalContact", 1],
        "rolling": rolling, "cohesion": False, "contact_model": contact_model(rolling, False), "bond": bond,
        "bonds_per_atom": per_atom, "radius_classes": classes, "n_classes": n_cls, "seed_pdd": seeds[n_cls],
        "seed_ins": seeds[n_cls + 1], "platen_bottom": "platen_bottom.stl", "platen_top": "platen_top.stl",
        "above_bounds": [box[0], box[1], box[2], box[3], Hc - rmax, box[5]],
    }
    if bts:
        ctx.update({
            "fill_bounds": [-Rc, Rc, -thick / 2, thick / 2, 0.0, fill_h],
            "mould_walls": [{"id": f"w_{n}", "plane": pl, "position": pos} for n, pl, pos in
                            (("xmin", "xplane", -Rc), ("xmax", "xplane", Rc), ("ymin", "yplane", -thick / 2),
                             ("ymax", "yplane", thick / 2))],
            "trim_y": [box[2], box[3]],
        })
    text = render("liggghts/" + ctx["template"], ctx)
    check_bonded_deck(text)
    (out / DECK).write_text(text)
    derived = {"engine": "liggghts", "bonded": True, "dt_s": dt, "bond_gran": bond, "n_bonds": 0,
               "n_grains": 0, "expected_steps": nsteps, "expected_steps_total": settle_steps + run.thermo_every + 1 + nsteps,
               "height_m": Hc, "area_m2": area, "platen_speed_m_s": v}
    spec = {"deckgen_version": __version__, "engine": "liggghts", "case": resolved_dict(case), "derived": derived}
    spec["case"]["engine"] = "liggghts"
    (out / "spec.json").write_text(json.dumps(spec, indent=2, sort_keys=True) + "\n")
    return spec
