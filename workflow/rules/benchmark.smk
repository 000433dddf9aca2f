# A public benchmark's own tests: a group trained on the Silverbox benchmark's record
# (SNLS80mV.mat, config/public/recordings.tsv) has every model simulated on the benchmark's
# three tests and its errors set beside the published ones (harvester.study.benchmark).


rule silverbox_benchmark:
    input:
        posteriors=lambda w: [group_posterior(w.group, m) for m in group_models(w.group)],
        record=lambda w: SHEET.file(SHEET.groups[w.group].training),
    output:
        csv=f"{GROUP_DIR}/benchmark.csv",
        html=report(f"{GROUP_DIR}/benchmark.html", caption="../report/benchmark.rst",
                    category=GROUP_PAGE, subcategory="{group}",
                    labels=lambda w: page_labels(w.group, "4. benchmark tests", "all")),
    wildcard_constraints:
        group=one_of(BENCHMARK_GROUPS),
    params:
        models=lambda w: group_models(w.group),
        seed=lambda w: GROUPS[w.group]["predictive"]["seed"],
    threads: JOB_THREADS
    resources:
        mem_mb=4000,
        runtime=30,
    log:
        "logs/groups/{group}/benchmark.log",
    conda:
        ENV
    script:
        "../scripts/silverbox_benchmark.py"
