# Calibrate: bond micro-parameters of a rock to its UCS, BTS and E (deckgen.calibrate), on demand:
#   snakemake results/calibration/<rock>/card.yaml
# (not part of the default target). Resumable: every virtual test is recorded in
# results/calibration/<rock>/evaluations.csv beside the card; a restarted job replays it.


wildcard_constraints:
    rock="[a-z][a-z0-9_]*",

rule calibrate:
    input:
        targets="cases/materials/{setup}.yaml",
    output:
        card=f"{RESULTS}/calibration/{{setup}}/card.yaml",
    wildcard_constraints:
        # a rock's card, or its set-up at other grains (cases/materials/{coarse,fine}/<rock>.yaml, issue #3 item 6)
        setup="((coarse|fine)/)?[a-z][a-z0-9_]*",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/calibrate/{{setup}}.log",
    benchmark:
        f"{RESULTS}/benchmarks/calibrate/{{setup}}.tsv"
    threads: config.get("ranks", 2)
    priority: 10
    params:
        out=lambda w, output: str(Path(output.card).parent),
        cache=f"{RESULTS}/.cache",
        engine=calib_engine_args(),
    shell:
        "python -m deckgen.calibrate {input.targets} --out {params.out} --cache {params.cache} "
        "{params.engine} > {log} 2>&1"


# packing-seed scatter of a calibrated card: 5 new packings (one UCS + one BTS each)
rule calibration_seeds:
    input:
        card=f"{RESULTS}/calibration/{{rock}}/card.yaml",
    output:
        f"{CAL_STUDIES}/seeds_{{rock}}.csv",
    log:
        f"{RESULTS}/logs/calibration_seeds/{{rock}}.log",
    threads: config.get("ranks", 2)
    conda:
        "../envs/deckgen.yaml"
    params:
        out=lambda w, output: str(Path(output[0]).parent),
        cache=f"{RESULTS}/.cache",
        engine=calib_engine_args(),
    shell:
        "python -m deckgen.calibration_studies seeds {input.card} --out {params.out} --cache {params.cache} "
        "{params.engine} > {log} 2>&1"


# quasi-static check: the calibrated point again at half the platen speeds, on 3 cylinders and 8 discs per speed
# (single specimens scatter by 4-15 %, more than the 3 % the check asks for)
rule calibration_quasistatic:
    input:
        card=f"{RESULTS}/calibration/{{rock}}/card.yaml",
    output:
        f"{CAL_STUDIES}/quasistatic_{{rock}}.csv",
    log:
        f"{RESULTS}/logs/calibration_quasistatic/{{rock}}.log",
    threads: config.get("ranks", 2)
    priority: 5
    conda:
        "../envs/deckgen.yaml"
    params:
        out=lambda w, output: str(Path(output[0]).parent),
        cache=f"{RESULTS}/.cache",
        engine=calib_engine_args(),
    shell:
        "python -m deckgen.calibration_studies quasistatic {input.card} --out {params.out} "
        "--ucs-packings 3 --bts-packings 8 --cache {params.cache} {params.engine} > {log} 2>&1"


# the per-rock results table of issue #3:  snakemake --cores 2 calibration_report
rule calibration_table:
    input:
        cards=expand(f"{RESULTS}/calibration/{{rock}}/card.yaml", rock=CAL_ROCKS),
        seeds=expand(f"{CAL_STUDIES}/seeds_{{rock}}.csv", rock=CAL_ROCKS),
        qs=expand(f"{CAL_STUDIES}/quasistatic_{{rock}}.csv", rock=CAL_ROCKS),
    output:
        f"{RESULTS}/calibration/table.md",
    log:
        f"{RESULTS}/logs/calibration_table.log",
    conda:
        "../envs/deckgen.yaml"
    params:
        out=lambda w, input: str(Path(input.seeds[0]).parent),
    shell:
        "python -m deckgen.calibration_studies table {input.cards} --out {params.out} --write {output} > {log} 2>&1"


rule calibration_report:
    input:
        f"{RESULTS}/calibration/table.md",


# resolution (issue #3, item 6): a rock's calibration set-ups at other grain sizes, cases/materials/coarse/<rock>.yaml
# and/or cases/materials/fine/<rock>.yaml, calibrated by the rule above (results/calibration/{coarse,fine}/<rock>/card.yaml)
# and tabled beside the rock's card, coarsest first (how the micro-parameters move with the grain size):
#   snakemake --cores 2 results/calibration/resolution_sandstone.md
# (inputs: resolution_cards in common.smk)
rule calibration_resolution:
    input:
        resolution_cards,
    output:
        f"{RESULTS}/calibration/resolution_{{rock}}.md",
    log:
        f"{RESULTS}/logs/calibration_resolution/{{rock}}.log",
    conda:
        "../envs/deckgen.yaml"
    shell:
        "python -m deckgen.calibration_studies resolution {input} --write {output} > {log} 2>&1"
