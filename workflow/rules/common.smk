# Path helpers, case loading and wildcard constraints shared by every stage.
from pathlib import Path

RESULTS = config.get("results", "results")
CASE_FILES = {Path(p).stem: p for p in config["cases"]}
TABLE_KINDS = [
    "forces_timeseries",
    "forces_summary",
    "platen_timeseries",
    "platen_summary",
    "damage_summary",
    "broken_bonds_timeseries",
]


wildcard_constraints:
    case="[a-z][a-z0-9_\-]*",


def case_file(wildcards):
    return CASE_FILES[wildcards.case]


def engine_args():
    cmd = config.get("engine_cmd") or ""
    if cmd:
        return f"--engine-cmd '{cmd}'"
    return f"--ranks {config.get('ranks', 2)}"


def tables():
    return expand(
        f"{RESULTS}/tables/{{kind}}.{{ext}}", kind=TABLE_KINDS, ext=["csv", "parquet"]
    )


def plots():
    return expand(f"{RESULTS}/{{case}}/plots/done.txt", case=list(CASE_FILES))


#: the rocks of issue #3 (cases/materials/<rock>.yaml)
CAL_ROCKS = ["savonniere_limestone", "concrete", "sandstone", "colorado_red_granite"]
CAL_STUDIES = f"{RESULTS}/calibration/studies"


def calib_engine_args():
    """UCS and BTS of a point side by side on half the ranks each (1-rank runs share 2 cores best)."""
    if config.get("engine_cmd"):
        return engine_args()
    ranks = int(config.get("ranks", 2))
    return f"--jobs 2 --ranks {max(1, ranks // 2)}" if ranks >= 2 else "--ranks 1"
