"""Measured data for the discrepancy loop: read and validate MEASURED.csv against the base case.

MEASURED.csv has one row per measured test: factor columns named by spec field path (any numeric
or token field of the case spec, e.g. ``kinematics.penetration_mm``, ``cutter.diameter_mm``,
``kinematics.neighbour_spacing_mm``, ``kinematics.rotary_radius_mm``, ``kinematics.speed_m_s``),
response columns named as in deckgen's force tables (:data:`RESPONSE_COLUMNS`, SI: newtons), an
optional ``replicate`` column (rows with equal factor values are replicates of one case either
way) and an optional ``label`` column. Lines starting with ``#`` are comments.

Every problem ends in :class:`GapInputError` (a :class:`deckgen.spec.SpecError`), one line per
problem naming the file, the row (1-based data row and file line) or column, and the fix.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from pydantic import ValidationError

from deckgen.spec import Case, SpecError, _fix_hint, deep_merge, field_and_message, load_case

#: Response columns the loop understands (deckgen.results cutting summary names, newtons).
RESPONSE_COLUMNS = (
    "force_normal_N_mean_steady", "force_rolling_N_mean_steady", "force_side_N_mean_steady",
)
META_COLUMNS = ("replicate", "label")


class GapInputError(SpecError):
    """A problem with MEASURED.csv or the base case: one line per problem, with the fix."""


def flatten(d: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(flatten(v, key + "."))
        else:
            out[key] = v
    return out


def nest(flat: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in flat.items():
        parts = k.split(".")
        d = out
        for p in parts[:-1]:
            d = d.setdefault(p, {})
        d[parts[-1]] = v
    return out


def case_dict(case: Case) -> dict[str, Any]:
    return case.model_dump(mode="json")


def flat_case(case: Case) -> dict[str, Any]:
    return flatten(case_dict(case))


def case_from_flat(flat: dict[str, Any]) -> Case:
    clean = {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in flat.items()}
    return Case.model_validate(nest(clean))


@dataclass
class Measured:
    """Validated measured data."""

    path: Path
    base: Case
    factors: list[str]              # spec paths given in the CSV
    responses: list[str]            # response columns given
    rows: pd.DataFrame              # the CSV rows (factors, responses, case_id)
    cases: pd.DataFrame             # one row per distinct factor setting: flattened full spec
    means: pd.DataFrame             # case means of the responses (index = case id)
    counts: pd.Series               # replicates per case

    @property
    def has_replicates(self) -> bool:
        return bool((self.counts > 1).any())


def _num_or_token(v: Any) -> Any:
    if isinstance(v, str):
        s = v.strip()
        try:
            f = float(s)
        except ValueError:
            return s
        return int(f) if f.is_integer() and "." not in s and "e" not in s.lower() else f
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.floating,)):
        return float(v)
    return v


def read_measured(measured: str | Path, base: str | Path | Case) -> Measured:
    """Read MEASURED.csv and the base case; validate every row as a case. Raises GapInputError."""
    path = Path(measured)
    if isinstance(base, Case):
        base_case = base
    else:
        try:
            base_case = load_case(base)
        except SpecError as exc:
            raise GapInputError(str(exc)) from None
    if base_case.test != "cutting":
        raise GapInputError(f"{base}: specimen.kind: the discrepancy loop needs a cutting case, got {base_case.test} "
                            f"(fix: use specimen.kind: cutting_block)")
    if not path.is_file():
        raise GapInputError(f"{path}: file not found (fix: check the path)")
    try:
        df = pd.read_csv(path, comment="#", dtype=str, skipinitialspace=True, keep_default_na=False)
    except (pd.errors.ParserError, UnicodeDecodeError, pd.errors.EmptyDataError) as exc:
        raise GapInputError(f"{path}: not a readable CSV ({str(exc).splitlines()[0]}) "
                            f"(fix: one header line, comma-separated values)") from None
    df.columns = [c.strip() for c in df.columns]
    if df.empty:
        raise GapInputError(f"{path}: no data rows (fix: one row per measured case below the header)")
    # header lines before the data (for file line numbers)
    with path.open() as fh:
        lines = fh.read().splitlines()
    data_lines = [i + 1 for i, ln in enumerate(lines) if ln.strip() and not ln.lstrip().startswith("#")][1:]

    base_flat = flat_case(base_case)
    problems: list[str] = []
    dup = sorted({c for c in df.columns if list(df.columns).count(c) > 1})
    for c in dup:
        problems.append(f"{path}: column {c}: appears more than once (fix: keep one)")
    factors, responses = [], []
    for c in df.columns:
        if c in RESPONSE_COLUMNS:
            responses.append(c)
        elif c in META_COLUMNS:
            continue
        elif c in base_flat:
            factors.append(c)
        elif "." in c:
            problems.append(f"{path}: column {c}: not a field of the case spec (fix: use a field path such as "
                            f"kinematics.penetration_mm; see workflow/schemas/case.schema.json)")
        else:
            problems.append(f"{path}: column {c}: unknown column (fix: factor columns are spec field paths such as "
                            f"kinematics.penetration_mm; response columns are {', '.join(RESPONSE_COLUMNS)}; "
                            f"optional: replicate, label)")
    if not responses and not problems:
        problems.append(f"{path}: no response column (fix: add at least one of {', '.join(RESPONSE_COLUMNS)})")
    if problems:
        raise GapInputError("\n".join(problems))

    values = pd.DataFrame(index=df.index)
    for i, row in df.iterrows():
        line = data_lines[i] if i < len(data_lines) else "?"
        where = f"{path}: row {i + 1} (line {line})"
        for c in responses:
            s = row[c].strip()
            try:
                v = float(s)
            except ValueError:
                problems.append(f"{where}: column {c}: {s!r} is not a number (fix: write the measured force in N)")
                continue
            if not np.isfinite(v):
                problems.append(f"{where}: column {c}: {s!r} is not finite (fix: drop the row or measure it)")
            values.loc[i, c] = v
        if "replicate" in df.columns and row["replicate"].strip():
            try:
                int(row["replicate"])
            except ValueError:
                problems.append(f"{where}: column replicate: {row['replicate']!r} is not an integer (fix: 1, 2, 3, ...)")
        over: dict[str, Any] = {}
        for c in factors:
            s = row[c].strip()
            if s == "":
                problems.append(f"{where}: column {c}: empty (fix: give the value of every factor in every row)")
                continue
            over[c] = _num_or_token(s)
        if len([p for p in problems if p.startswith(where)]):
            continue
        try:
            Case.model_validate(deep_merge(case_dict(base_case), nest(over)))
        except ValidationError as exc:
            for err in exc.errors():
                field, msg, cross = field_and_message(err)
                fix = "change this row's factors or the base case" if cross else _fix_hint(err)
                col = field if field in factors else f"{field} (set by the base case and this row's factors)"
                problems.append(f"{where}: column {col}: {msg} (fix: {fix})")
        for c, v in over.items():
            values.loc[i, c] = v
    if problems:
        raise GapInputError("\n".join(problems))

    rows = values.copy()
    for c in factors:
        rows[c] = [_num_or_token(v) for v in values[c]] if c in values else None
    key = rows[factors].astype(str).agg("|".join, axis=1) if factors else pd.Series("all", index=rows.index)
    order = list(dict.fromkeys(key))
    rows["case_id"] = [order.index(k) for k in key]
    cases = []
    for cid in range(len(order)):
        r = rows[rows["case_id"] == cid].iloc[0]
        over = {c: r[c] for c in factors}
        case = Case.model_validate(deep_merge(case_dict(base_case), nest(over)))
        cases.append(flat_case(case))
    cases_df = pd.DataFrame(cases)
    means = rows.groupby("case_id")[responses].mean()
    counts = rows.groupby("case_id").size()
    return Measured(path=path, base=base_case, factors=factors, responses=responses, rows=rows,
                    cases=cases_df, means=means, counts=counts)
