# Calibrate: bond micro-parameters of a rock to its UCS, BTS and E (deckgen.calibrate), on demand:
#   snakemake results/calibration/<rock>/card.yaml
# (not part of the default target). Resumable: every virtual test is recorded in
# results/calibration/<rock>/evaluations.csv beside the card; a restarted job replays it.


wildcard_constraints:
    rock="[a-z][a-z0-9_]*",


rule calibrate:
    input:
        targets="cases/materials/{rock}.yaml",
    output:
        card=f"{RESULTS}/calibration/{{rock}}/card.yaml",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/calibrate/{{rock}}.log",
    benchmark:
        f"{RESULTS}/benchmarks/calibrate/{{rock}}.tsv"
    threads: config.get("ranks", 2)
    params:
        out=lambda w, output: str(Path(output.card).parent),
        cache=f"{RESULTS}/.cache",
        engine=engine_args(),
    shell:
        "python -m deckgen.calibrate {input.targets} --out {params.out} --cache {params.cache} "
        "{params.engine} > {log} 2>&1"
