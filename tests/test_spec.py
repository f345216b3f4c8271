"""Case spec: defaults, documentation of every field, the committed schema, clear errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from deckgen.cli import main
from deckgen.spec import Case, SpecError, load_case, schema_text

ROOT = Path(__file__).resolve().parents[1]


def write(tmp_path: Path, text: str, name: str = "case.yaml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_defaults_validate_and_are_a_ucs_test():
    case = Case()
    assert case.test == "ucs"
    assert case.specimen.height_mm / case.specimen.diameter_mm == pytest.approx(2.0)
    assert case.engine == "lammps"


def test_committed_schema_is_current():
    committed = (ROOT / "workflow" / "schemas" / "case.schema.json").read_text()
    assert committed == schema_text(), "stale schema: run `make schema` (deckgen schema --out workflow/schemas/case.schema.json)"


def _walk_properties(schema: dict):
    defs = schema.get("$defs", {})
    for model in [schema, *defs.values()]:
        for name, prop in model.get("properties", {}).items():
            yield model.get("title", "Case"), name, prop


def test_every_field_has_description_and_unit():
    schema = json.loads(schema_text())
    missing = []
    for model, name, prop in _walk_properties(schema):
        optional_model = any("$ref" in a for a in prop.get("anyOf", []))  # e.g. packing.fine_zone: model | None
        if "$ref" in prop or "discriminator" in prop or "oneOf" in prop or optional_model or name == "kind":
            continue  # nested models are documented on their own
        if not prop.get("description") or not prop.get("unit"):
            missing.append(f"{model}.{name}")
    assert not missing, f"fields without description or unit: {missing}"


def test_case_files_hold_overrides_only(tmp_path):
    p = write(tmp_path, "specimen:\n  kind: brazilian_disc\n  diameter_mm: 30\n")
    case = load_case(p)
    assert case.test == "bts"
    assert case.specimen.diameter_mm == 30
    assert case.specimen.thickness_mm == 10.0  # documented default
    assert case.bonds.youngs_modulus_GPa == 40.0
    assert case.name == "case"  # from the file name


@pytest.mark.parametrize(
    "text, field, words",
    [
        ("bondz:\n  x: 1\n", "bondz", "Extra inputs are not permitted"),
        ("packing:\n  radius_min_mm: abc\n", "packing.radius_min_mm", "valid number"),
        ("packing:\n  radius_min_mm: -0.5\n", "packing.radius_min_mm", "greater than 0"),
        ("specimen:\n  kind: cutting_block\n  height_mm: 10\nkinematics:\n  penetration_mm: 12\n",
         "kinematics.penetration_mm", "not less than the block height"),
        ("specimen:\n  kind: cylinder\n", "specimen", "does not match any of the expected tags"),
        ("name: 'a; shell rm -rf /'\n", "name", "lower-case letters"),
        ("kinematics:\n  mode: oscillation\nspecimen:\n  kind: cutting_block\n", "kinematics",
         "needs eccentricity_mm > 0"),
        ("packing:\n  radius_min_mm: 2\n  radius_max_mm: 1\n", "packing", "radius_max_mm must be >= radius_min_mm"),
        ("run:\n  debris_removal_every: 1000\n", "run.debris_removal_every", "a LAMMPS cutting diagnostic"),
        ("run:\n  debris_removal_every: -5\n", "run.debris_removal_every", "greater than or equal to 0"),
        ("bonds:\n  model: flat_joint\nengine: liggghts\n", "bonds.model", "flat_joint is a LAMMPS plugin"),
        ("outputs:\n  breakoff_min_grains: 1\n", "outputs.breakoff_min_grains", "greater than or equal to 2"),
        ("outputs:\n  breakoff_min_grains: 50\n", "outputs.breakoff_min_grains",
         "read for indentation runs only, this case is a ucs test"),
        ("specimen:\n  kind: cutting_block\noutputs:\n  breakoff_min_grains: 50\n", "outputs.breakoff_min_grains",
         "read for indentation runs only, this case is kinematics.mode linear"),
        ("specimen:\n  kind: cutting_block\npacking:\n  radius_min_mm: 0.35\n  radius_max_mm: 0.5\n", "cutter.shell_radius_mm",
         "more than half the largest grain radius a packing can have (0.245 mm)"),
    ],
)
def test_bad_input_gives_one_clear_line(tmp_path, text, field, words):
    p = write(tmp_path, text)
    with pytest.raises(SpecError) as err:
        load_case(p)
    msg = str(err.value)
    first = msg.splitlines()[0]
    assert first.startswith(f"{p}: {field}:"), msg
    assert words in first
    assert first.count("(fix: ") == 1


def test_shell_radius_is_refused_before_packing_only_where_no_packing_can_pass(tmp_path):
    """The deck holds cutter.shell_radius_mm to half the packing's smallest grain radius after packing; the case check
    refuses only radii above half the largest grain a packing can have (r_max x (1 - shrink_before_bonding)), so it
    never refuses a case the deck would take."""
    grains = "specimen:\n  kind: cutting_block\npacking:\n  radius_min_mm: 0.35\n  radius_max_mm: 0.5\n"
    assert load_case(write(tmp_path, grains + "cutter:\n  shell_radius_mm: 0.245\n")).cutter.shell_radius_mm == 0.245
    with pytest.raises(SpecError, match=r"cutter\.shell_radius_mm: 0\.246 mm .*\(fix: at most half the smallest grain radius, about 0\.171 mm; the packed grains set the exact limit\)"):
        load_case(write(tmp_path, grains + "cutter:\n  shell_radius_mm: 0.246\n"))
    # the LIGGGHTS decks cut with the STL mesh, not a shell of spheres
    assert load_case(write(tmp_path, grains + "engine: liggghts\nbonds:\n  enabled: false\n")).engine == "liggghts"


def test_breakoff_size_is_an_indentation_field_and_old_specs_resolve_to_its_default(tmp_path):
    """outputs.breakoff_min_grains: any whole number >= 2 on an indentation case; elsewhere only the default (a
    resolved case carries it); a spec.json case written before the field existed resolves to 25 again."""
    from deckgen.spec import DETACH_MIN_GRAINS, resolve_recorded, resolved_dict

    indent = "specimen:\n  kind: cutting_block\nkinematics:\n  mode: indentation\n"
    assert load_case(write(tmp_path, indent + "outputs:\n  breakoff_min_grains: 100\n")).outputs.breakoff_min_grains == 100
    assert load_case(write(tmp_path, indent)).outputs.breakoff_min_grains == DETACH_MIN_GRAINS == 25
    assert load_case(write(tmp_path, "outputs:\n  breakoff_min_grains: 25\n")).test == "ucs"  # the default is no claim
    with pytest.raises(SpecError, match="breakoff_min_grains"):
        load_case(write(tmp_path, indent + "outputs:\n  breakoff_min_grains: 2.5\n"))
    full = resolved_dict(load_case(write(tmp_path, indent)))
    old = json.loads(json.dumps(full))
    del old["outputs"]["breakoff_min_grains"]
    assert resolve_recorded(old) == full
    refused = {**old, "specimen": {**old["specimen"], "height_mm": -1}}
    assert resolve_recorded(refused) is refused


def test_missing_file_and_bad_yaml(tmp_path):
    with pytest.raises(SpecError, match=r"nope\.yaml: file not found \(fix: check the path\)"):
        load_case(tmp_path / "nope.yaml")
    p = write(tmp_path, "specimen: [unclosed\n")
    with pytest.raises(SpecError, match=r"case\.yaml: line \d+: not valid YAML"):
        load_case(p)


def test_cli_validate_reports_without_traceback(tmp_path, capsys):
    good = write(tmp_path, "name: good_one\n", "good.yaml")
    bad = write(tmp_path, "packing:\n  radius_min_mm: -1\n", "bad.yaml")
    assert main(["validate", str(good)]) == 0
    assert "good.yaml: ok (ucs" in capsys.readouterr().out
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.yaml: packing.radius_min_mm: Input should be greater than 0" in err
    assert "Traceback" not in err


def test_embedded_cases_validate():
    for p in sorted((ROOT / "cases").rglob("*.yaml")):
        if "materials" in p.parts:
            continue
        load_case(p)
