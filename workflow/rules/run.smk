# Run: the engine on the rendered deck; fails with the engine's own error line.


rule run:
    input:
        deck=f"{RESULTS}/{{case}}/run/in.deck",
    output:
        log=f"{RESULTS}/{{case}}/run/log.lammps",
        series=f"{RESULTS}/{{case}}/run/series.txt",
        result=f"{RESULTS}/{{case}}/run/run.json",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/run/{{case}}.log",
    benchmark:
        f"{RESULTS}/benchmarks/run/{{case}}.tsv"
    threads: config.get("ranks", 2)
    params:
        run_dir=lambda w, output: str(Path(output[0]).parent),
        engine=engine_args(),
    shell:
        "deckgen run {params.run_dir} {params.engine} --no-progress > {log} 2>&1"
