"""The Snakemake workflow: a dry run plans every stage for the smoke cases, and the linter is clean."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"

pytestmark = pytest.mark.skipif(not SNAKEMAKE.exists() and not shutil.which("snakemake"), reason="snakemake not installed")


def _snakemake(*args: str) -> subprocess.CompletedProcess:
    exe = str(SNAKEMAKE) if SNAKEMAKE.exists() else "snakemake"
    return subprocess.run([exe, *args], cwd=ROOT, capture_output=True, text=True, timeout=300)


def test_dry_run_plans_every_stage(tmp_path):
    res = _snakemake("-n", "--config", f"results={tmp_path / 'results'}")
    assert res.returncode == 0, res.stderr[-2000:]
    text = res.stdout + res.stderr
    for rule, count in [("pack", 3), ("render", 3), ("run", 3), ("parse", 3), ("aggregate", 1), ("plot", 3)]:
        assert f"{rule:<13}{count}" in text or f"{rule} {count}" in " ".join(text.split()), (rule, text[-1500:])


def test_lint_is_clean():
    res = _snakemake("--lint")
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-2000:]
    assert "Congratulations, your workflow is in a good condition" in res.stdout + res.stderr


def test_dry_run_plans_the_resolution_study(tmp_path):
    """A rock's card and its set-up at the other grain size (sandstone: coarse/, granite: fine/), then the table."""
    for rock, other in (("sandstone", "coarse"), ("colorado_red_granite", "fine")):
        res = _snakemake("-n", f"{tmp_path}/results/calibration/resolution_{rock}.md", "--config",
                         f"results={tmp_path / 'results'}")
        assert res.returncode == 0, res.stderr[-2000:]
        text = " ".join((res.stdout + res.stderr).split())
        for rule in ("calibrate 2", "calibration_resolution 1"):
            assert rule in text, (rule, text[-1500:])
        for setup in (f"{rock}.yaml", f"{other}/{rock}.yaml"):
            assert f"input: cases/materials/{setup}" in text, (setup, text[-1500:])
