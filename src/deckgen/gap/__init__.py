"""The discrepancy workflow (issue #5): find where simulation and measurement disagree, name the
missing effect from a catalogue, add it as a spec switch, show the gap shrink.

Modules: :mod:`~deckgen.gap.catalogue` (effects), :mod:`~deckgen.gap.fast` (reduced model),
:mod:`~deckgen.gap.backends` (fast, dem), :mod:`~deckgen.gap.data` (MEASURED.csv),
:mod:`~deckgen.gap.loop` (statistics), :mod:`~deckgen.gap.report` (files),
:mod:`~deckgen.gap.synth` (hidden-effect battery).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["gap"]


def gap(measured: str | Path, base: str | Path, out: str | Path, *, backend: str = "fast",
        candidates: list[str] | None = None, noise_cv: float | None = None, command: list[str] | None = None,
        cache: Path | None = None, runs: Path | None = None, packing_seeds: list[int] | None = None,
        jobs: int = 1, write: bool = True) -> dict[str, Any]:
    """Run the whole loop and write ``out/report.json``, ``report.md`` and the plots."""
    from deckgen.gap.backends import make_backend
    from deckgen.gap.data import read_measured
    from deckgen.gap.loop import run_gap
    from deckgen.gap.report import write_report

    out = Path(out)
    m = read_measured(measured, base)
    be = make_backend(backend, out, command=command, cache=cache, runs=runs, seeds=packing_seeds, jobs=jobs)
    report = run_gap(m, be, candidates=candidates, noise_cv=noise_cv)
    if write:
        write_report(report, out, str(measured), str(base))
    return report
