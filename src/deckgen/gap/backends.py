"""Backends of the discrepancy loop: ``fast`` (the reduced model) and ``dem`` (real LAMMPS decks).

A backend maps a table of flattened cases (columns = spec paths, one row per case) to the
responses ``force_{normal,rolling,side}_N_mean_steady`` [N].
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from deckgen.gap.data import RESPONSE_COLUMNS, GapInputError, case_from_flat


class FastBackend:
    """The reduced model of :mod:`deckgen.gap.fast`."""

    name = "fast"
    #: grid points per fitted magnitude (predictions are interpolated between them)
    grid_points = 41
    #: relative scatter assumed when MEASURED.csv has no replicates (a lab-test scale: seed 000
    #: Table 4 and seed 001 Table 3 differ from their models by 2-19 %); an assumption, see
    #: docs/discrepancy.md for the much larger packing-seed scatter of tiny DEM blocks
    default_cv = 0.05

    def simulate(self, cases: pd.DataFrame) -> pd.DataFrame:
        from deckgen.gap.fast import FastModelError, predict

        try:
            return predict(cases)
        except FastModelError as exc:
            raise GapInputError(f"fast backend: {exc}") from None


class DemBackend:
    """Render, run and parse every case with deckgen's LAMMPS decks; runs are cached by their spec."""

    name = "dem"
    grid_points = 3
    default_cv = 0.05

    def __init__(self, runs_dir: str | Path, *, command: list[str] | None = None, cache: Path | None = None,
                 progress: bool = False, seeds: list[int] | None = None, jobs: int = 1) -> None:
        self.runs_dir = Path(runs_dir)
        self.command = command
        self.cache = cache
        self.progress = progress
        self.log: list[dict] = []
        #: packing seeds each case is run on (mean reported); None: the case's own packing only
        self.seeds = list(seeds) if seeds else None
        if self.seeds is not None and len(self.seeds) < 2:
            raise GapInputError("--packing-seeds: give at least two seeds (the scatter between them is the model's noise)")
        #: standard error of each simulated mean over the seeds (set by :meth:`simulate` when seeds are given)
        self.last_se: pd.DataFrame | None = None
        #: engine runs at a time (each a subprocess; give each one rank)
        self.jobs = max(1, int(jobs))

    def run_one(self, flat: dict) -> dict:
        from deckgen.deck import render_case
        from deckgen.results import parse_run
        from deckgen.runner import run_deck

        case = case_from_flat(flat)
        blob = json.dumps(case.model_dump(mode="json"), sort_keys=True).encode()
        key = hashlib.sha256(blob).hexdigest()[:12]
        run_dir = self.runs_dir / f"{case.name}-{key}"
        summary_path = run_dir / "parsed" / "summary.json"
        if summary_path.is_file():
            summary = json.loads(summary_path.read_text())
        else:
            print(f"deckgen gap: dem run {run_dir.name}", file=sys.stderr, flush=True)
            spec = render_case(case, run_dir, cache=self.cache, progress=False, command=self.command)
            run_deck(run_dir, expected_steps=spec["derived"].get("expected_steps"), command=self.command,
                     progress=self.progress, label=run_dir.name)
            summary = parse_run(run_dir, run_dir / "parsed")
        self.log.append({"run": run_dir.name, "n_grains": summary.get("n_grains"), "wall_s": summary.get("wall_s")})
        return {r: (np.nan if summary.get(r) is None else float(summary[r])) for r in RESPONSE_COLUMNS}

    def _run_all(self, flats: list[dict]) -> list[dict]:
        """:meth:`run_one` on every flat case, :attr:`jobs` at a time (threads: each run is an engine
        subprocess; the packing cache locks per packing), results in input order."""
        if self.jobs == 1 or len(flats) < 2:
            return [self.run_one(f) for f in flats]
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(max_workers=self.jobs) as pool:
            return list(pool.map(self.run_one, flats))

    def simulate(self, cases: pd.DataFrame) -> pd.DataFrame:
        """Responses of every case; with :attr:`seeds`, the mean over them, and their standard error in
        :attr:`last_se`. The seeds are common to every case, so base and candidate runs share their
        packings and the packing scatter partly cancels in their difference."""
        recs = cases.to_dict("records")
        if self.seeds is None:
            self.last_se = None
            rows = self._run_all(recs)
            return pd.DataFrame(rows, index=cases.index, columns=list(RESPONSE_COLUMNS))
        k = len(self.seeds)
        ys = self._run_all([dict(r, **{"packing.seed": int(s)}) for r in recs for s in self.seeds])
        means, ses = [], []
        for i in range(len(recs)):
            y = pd.DataFrame(ys[i * k:(i + 1) * k], columns=list(RESPONSE_COLUMNS))
            means.append(y.mean().to_dict())
            ses.append((y.std(ddof=1) / np.sqrt(k)).to_dict())
        self.last_se = pd.DataFrame(ses, index=cases.index, columns=list(RESPONSE_COLUMNS))
        return pd.DataFrame(means, index=cases.index, columns=list(RESPONSE_COLUMNS))


def make_backend(name: str, out: Path, *, command: list[str] | None = None, cache: Path | None = None,
                 runs: Path | None = None, seeds: list[int] | None = None, jobs: int = 1):
    if name == "fast":
        if seeds:
            raise GapInputError("--packing-seeds: the fast backend has no packing (fix: drop it, or use --backend dem)")
        return FastBackend()
    if name == "dem":
        return DemBackend(runs or out / "dem_runs", command=command, cache=cache, seeds=seeds, jobs=jobs)
    raise GapInputError(f"--backend {name}: unknown backend (fix: use fast or dem)")
