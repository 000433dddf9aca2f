# The paper's own step, automated: the diagnosis of each identified model of a group on its
# training recording, with its first validation recording for the before/after comparison
# (settings: config diagnosis; a group's own: config groups.<group>.diagnosis).


rule diagnose:
    input:
        unpack(lambda w: diagnosis_inputs(w.group, w.model)),
    output:
        json=diagnosis_file("{group}", "{model}"),
        summary=report(diagnosis_file("{group}", "{model}", "summary.html"),
                       caption="../report/diagnosis.rst", category=GROUP_PAGE,
                       subcategory="{group}",
                       labels=lambda w: page_labels(w.group, "4. diagnosis", w.model)),
    wildcard_constraints:
        group=one_of([g for g in GENERIC_GROUPS if DIAGNOSED[g]]),
    params:
        settings=lambda w: group_params(w.group, "diagnosis"),
        links=lambda w: group_links(w.group),
    threads: JOB_THREADS
    resources:
        mem_mb=4000,
        runtime=60,
    log:
        "logs/groups/{group}/diagnose_{model}.log",
    conda:
        ENV
    script:
        "../scripts/diagnose_model.py"
