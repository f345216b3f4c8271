# Packing: cached by a hash of its inputs under <results>/.cache, so cases with the same rock
# specimen share one packing.


rule pack:
    input:
        case=case_file,
    output:
        info=f"{RESULTS}/{{case}}/pack/packing.json",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/pack/{{case}}.log",
    threads: config.get("ranks", 2)
    params:
        engine=engine_args(),
        cache=f"{RESULTS}/.cache",
    shell:
        "deckgen pack {input.case} --info {output.info} --cache {params.cache} {params.engine} --no-progress > {log} 2>&1"
