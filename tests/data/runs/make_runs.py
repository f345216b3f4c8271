"""Regenerate the reference run folders of tests/test_results.py with the real engine.

Usage (from the repository root; a few minutes on 2 idle cores: the cut is ~40k steps)::

    DECKGEN_RANKS=2 .venv/bin/python tests/data/runs/make_runs.py [--only NAME] [--work DIR]

Two tiny cases are built with the Python API (``deckgen.spec.Case``), rendered with
:func:`deckgen.deck.render_case` (packing cache in a temporary folder unless ``--cache``), run with
:func:`deckgen.runner.run_deck`, and only the files the tests read are copied next to this script
into ``<name>/``:  spec.json, specimen.data (from the next regeneration on), series.txt, log.lammps, run.json, atoms.dump.gz, final.dump.gz (if the
run wrote it), broken.dump.gz, bonds.dump.gz.  The full run folders stay in ``--work`` (default: a
temporary folder that is removed).

Output intervals are aligned with the end of the run: LAMMPS writes ``fix print`` rows and
``dump`` frames only on multiples of their interval, so bonds broken after the last multiple would
be missing from series.txt and broken.dump.gz while final.dump.gz has them. A probe render gives the
run's step count (cutting: ``nsteps``; platen tests: ``chunk``, the stop-check interval every run
ends on), ``series_every = broken_every`` becomes a divisor of it near 100, and, for a cut whose
step count has none, ``run.timestep_s`` is set a hair below the computed time step so that the cut
takes a multiple of 100 steps. ``bond_state_every`` (the costly bond samples) is a multiple of that
interval chosen to keep each folder near 400 KB.

After regenerating, update the ``REF`` constants of tests/test_results.py (grains, bonds, broken
bonds: printed by this script and in the new spec.json/series.txt) and tests/data/runs/README.md;
every other check cross-checks the files against each other and holds for any regenerated run.
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import re
import shutil
import sys
import tempfile
import time
from pathlib import Path

from deckgen.deck import render_case
from deckgen.runner import run_deck
from deckgen.spec import Case

HERE = Path(__file__).resolve().parent

KEEP = ("spec.json", "specimen.data", "series.txt", "log.lammps", "run.json", "atoms.dump.gz", "final.dump.gz",
        "broken.dump.gz", "bonds.dump.gz")

#: UCS cylinder of ~300 grains. dump_every is larger than the run, so atoms.dump.gz holds only the
#: initial frame (the final state is final.dump.gz); bond states are sampled every 500 steps.
REF_UCS = {
    "name": "ref_ucs",
    "packing": {"radius_min_mm": 0.6, "radius_max_mm": 0.9},
    "specimen": {"kind": "ucs_cylinder", "diameter_mm": 8.0, "height_mm": 16.0, "platen_speed_m_s": 0.2},
    "bonds": {"youngs_modulus_GPa": 10.0},
    "outputs": {"bond_state_every": 500, "dump_every": 10_000_000, "series_every": 100, "broken_every": 100},
}

#: Short linear cut of a 16 x 12 x 8 mm block by a 12 mm V disc. atoms.dump.gz holds a frame every 7000 steps
#: (7 frames over the 42 000-step cut) for the cutter-contact census (tests/test_contacts.py).
REF_CUT = {
    "name": "ref_cut",
    "packing": {"radius_min_mm": 0.6, "radius_max_mm": 0.9},
    "specimen": {"kind": "cutting_block", "length_mm": 16.0, "width_mm": 12.0, "height_mm": 8.0},
    "cutter": {"kind": "v_disc", "diameter_mm": 12.0, "hub_width_mm": 4.0, "tip_radius_mm": 0.3,
               "shell_radius_mm": 0.25},
    # start 0.2 mm from the block (default 1 mm): more of the 3 mm travel is spent cutting
    "kinematics": {"mode": "linear", "speed_m_s": 2.0, "penetration_mm": 1.5, "travel_mm": 3.0,
                   "start_clearance_mm": 0.2},
    "bonds": {"youngs_modulus_GPa": 10.0},
    "contact": {"youngs_modulus_GPa": 10.0},
    "outputs": {"bond_state_every": 500, "dump_every": 7000, "series_every": 100, "broken_every": 100},
}

CASES = {c["name"]: c for c in (REF_UCS, REF_CUT)}  # the output intervals are set by aligned_case()

#: bond-state samples per run (UCS: over the run to max_strain; it stops earlier, after the peak)
BOND_SAMPLES = {"ref_ucs": 14, "ref_cut": 6}


def _divisor_near(n: int, target: int = 100, lo: int = 50, hi: int = 250) -> int | None:
    ds = [d for d in range(lo, hi + 1) if n % d == 0]
    return min(ds, key=lambda d: abs(d - target)) if ds else None


def aligned_case(name: str, work: Path, cache: Path) -> Case:
    """The case with output intervals that divide the steps every run ends on (see module doc)."""
    data = copy.deepcopy(CASES[name])
    probe = work / f"{name}.probe"
    spec = render_case(Case.model_validate(data), probe, cache=cache, progress=False)
    d = spec["derived"]
    if "cutter" in d:
        n = int(d["expected_steps"])
        every = _divisor_near(n)
        if every is None:
            m = 100 * math.ceil((n + 1) / 100)  # dt = duration / (m - 0.5) < the computed dt
            data.setdefault("run", {})["timestep_s"] = d["cutter"]["duration"] / (m - 0.5)
            every, n = 100, m
        run_steps = n
    else:
        deck = (probe / "in.deck").read_text()
        chunk = int(re.search(r"^variable\s+chunk\s+index\s+(\d+)", deck, re.M).group(1))
        every = _divisor_near(chunk) or 10
        run_steps = int(d["expected_steps"])  # to max_strain; the run stops earlier, after the peak
    shutil.rmtree(probe)
    out = data["outputs"]
    out["series_every"] = out["broken_every"] = every
    out["bond_state_every"] = every * max(1, round(run_steps / BOND_SAMPLES[name] / every))
    return Case.model_validate(data)


def make(name: str, work: Path, cache: Path) -> dict:
    case = aligned_case(name, work, cache)
    run_dir = work / name
    if run_dir.exists():
        shutil.rmtree(run_dir)
    t0 = time.perf_counter()
    spec = render_case(case, run_dir, cache=cache)
    t_render = time.perf_counter() - t0
    res = run_deck(run_dir, expected_steps=spec["derived"].get("expected_steps"), label=name)
    dest = HERE / name
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir()
    copied = []
    for f in KEEP:
        src = run_dir / f
        if src.is_file():
            shutil.copy2(src, dest / f)
            copied.append(f)
    size = sum((dest / f).stat().st_size for f in copied)
    d = spec["derived"]
    info = {"name": name, "test": case.test, "n_grains": d["n_grains"], "n_bonds": d["n_bonds"],
            "steps": res.steps, "wall_s": round(res.wall_s, 1), "render_s": round(t_render, 1),
            "outputs": case.outputs.model_dump(mode="json"), "timestep_s": case.run.timestep_s,
            "files": copied, "size_bytes": size}
    print(json.dumps(info), flush=True)
    return info


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", choices=sorted(CASES), action="append", help="make only this case (repeatable)")
    ap.add_argument("--work", type=Path, help="keep the full run folders here")
    ap.add_argument("--cache", type=Path, help="packing cache (default: a temporary folder)")
    args = ap.parse_args(argv)
    names = args.only or list(CASES)
    with tempfile.TemporaryDirectory(prefix="deckgen-refruns-") as tmp:
        work = args.work or Path(tmp) / "work"
        cache = args.cache or Path(tmp) / "cache"
        work.mkdir(parents=True, exist_ok=True)
        for n in names:
            make(n, work, cache)
    return 0


if __name__ == "__main__":
    sys.exit(main())
