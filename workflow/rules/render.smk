# Render: bonded specimen, cutter STL and the LAMMPS deck into the run folder.


rule render:
    input:
        case=case_file,
        packing=f"{RESULTS}/{{case}}/pack/packing.json",
    output:
        deck=f"{RESULTS}/{{case}}/run/in.deck",
        spec=f"{RESULTS}/{{case}}/run/spec.json",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/render/{{case}}.log",
    params:
        run_dir=lambda w, output: str(Path(output[0]).parent),
        cache=f"{RESULTS}/.cache",
    shell:
        "deckgen render {input.case} --out {params.run_dir} --cache {params.cache} --no-progress > {log} 2>&1"
