"""Particle-steps per second of a rendered deck at 1 and 2 MPI ranks, measured in one session.

    .venv/bin/python bench/throughput.py cases/smoke/smoke_ucs.yaml [--steps 5000] [--concurrent]

Renders the case (packing cached), then runs the same deck truncated to ``--steps`` steps with
1 and with 2 ranks, alternating twice, and prints each run and the ratio of the medians. The
machine is shared and noisy: compare ratios from one invocation, not absolute numbers across days.
With ``--concurrent`` it also runs two copies of the 2-rank deck at the same time (4 ranks on the
machine's cores) and prints their rate relative to the solo 2-rank median.
"""

from __future__ import annotations

import argparse
import re
import shutil
import statistics
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from deckgen.deck import render_case
from deckgen.runner import engine_command, run_deck
from deckgen.spec import load_case


def truncate(deck: str, steps: int) -> str:
    """Replace the loading loop / main run by a single run of ``steps`` steps (no stop checks)."""
    deck = re.sub(r"(?m)^variable\s+k loop .*$", "", deck)
    deck = re.sub(r"(?ms)^label\s+loadloop.*?^label\s+loadend\s*$", f"run {steps}", deck)
    deck = re.sub(r"(?m)^run\s+\$\{nsteps\}\s*$", f"run {steps}", deck)
    return deck


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case")
    ap.add_argument("--steps", type=int, default=5000)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--concurrent", action="store_true", help="also run two 2-rank copies at once")
    args = ap.parse_args()
    case = load_case(args.case)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        render_case(case, out, progress=False)
        (out / "in.deck").write_text(truncate((out / "in.deck").read_text(), args.steps))
        rates: dict[int, list[float]] = {1: [], 2: []}
        for _ in range(args.repeat):
            for ranks in (1, 2):
                res = run_deck(out, command=engine_command(ranks), progress=False)
                rates[ranks].append(res.particle_steps_per_s or 0.0)
                print(f"{case.name}: {ranks} rank(s): {res.steps} steps x {res.atoms} atoms in {res.loop_s:.2f} s "
                      f"= {rates[ranks][-1]:.3g} particle-steps/s")
        m1, m2 = statistics.median(rates[1]), statistics.median(rates[2])
        print(f"{case.name}: median 1 rank {m1:.3g}, 2 ranks {m2:.3g} particle-steps/s, ratio 2/1 = {m2 / m1:.2f}")
        if args.concurrent:
            twin = Path(tmp) / "twin"
            shutil.copytree(out, twin)
            with ThreadPoolExecutor(2) as pool:
                jobs = [pool.submit(run_deck, d, command=engine_command(2), progress=False) for d in (out, twin)]
                both = [j.result().particle_steps_per_s or 0.0 for j in jobs]
            print(f"{case.name}: two 2-rank runs at once: {both[0]:.3g} and {both[1]:.3g} particle-steps/s each, "
                  f"{both[0] / m2:.2f} and {both[1] / m2:.2f} of the solo 2-rank median")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
