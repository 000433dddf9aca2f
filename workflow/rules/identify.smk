# Bayesian identification: TMCMC per group and model structure, the group's evidence table;
# the paper study's posterior tables and figures (Tables 3, 5, Figures 6, 8) and evidence
# (eqs. 11, 12) from its group's posteriors.


localrules:
    group_evidence,


rule identify:
    input:
        data=lambda w: training_csv(w.group),
        sidecar=lambda w: training_csv(w.group).replace(".csv", ".yaml"),
        priors=lambda w: group_priors_file(w.group),
    output:
        posterior=model_file("{group}", "{model}", "posterior.nc"),
        summary=model_file("{group}", "{model}", "summary.csv"),
        evidence=model_file("{group}", "{model}", "evidence.json"),
        pairs=report(model_file("{group}", "{model}", "posterior_pairs.png"),
                     caption="../report/group_posterior.rst", category=GROUP_PAGE,
                     subcategory="{group}",
                     labels=lambda w: page_labels(w.group, "2. posterior", w.model)),
    wildcard_constraints:
        group=one_of(GENERIC_GROUPS),
    params:
        settings=lambda w: group_params(w.group, "tmcmc"),
    threads: JOB_THREADS
    resources:
        mem_mb=4000,
        runtime=60,
    log:
        "logs/groups/{group}/identify_{model}.log",
    conda:
        ENV
    script:
        "../scripts/identify.py"


rule group_evidence:
    input:
        lambda w: [model_file(w.group, m, "evidence.json") for m in group_models(w.group)],
    output:
        csv=f"{GROUP_DIR}/evidence.csv",
        html=report(f"{GROUP_DIR}/evidence.html", caption="../report/group_evidence.rst",
                    category=GROUP_PAGE, subcategory="{group}",
                    labels=lambda w: page_labels(w.group, "1. evidence", "all")),
    wildcard_constraints:
        group=one_of(GENERIC_GROUPS),
    params:
        models=lambda w: group_models(w.group),
    log:
        "logs/groups/{group}/evidence.log",
    conda:
        ENV
    script:
        "../scripts/group_evidence.py"


rule posterior_table:
    input:
        posterior=lambda w: study_posterior(w.model),
        priors="results/initial/priors.json",
    output:
        report("results/tables/{table}_{model}.csv", caption="../report/posterior_table.rst",
               category="Identification", subcategory="{model}"),
    wildcard_constraints:
        table="table3|table5|table_posterior",
    params:
        rig=config["rig"],
    log:
        "logs/posterior_table_{table}_{model}.log",
    conda:
        ENV
    script:
        "../scripts/posterior_table.py"


rule posterior_figure:
    input:
        posterior=lambda w: study_posterior(w.model),
    output:
        report("results/figures/{fig}_{model}_posterior.png", caption="../report/posterior_figure.rst",
               category="Identification", subcategory="{model}"),
    wildcard_constraints:
        fig="fig06|fig08|fig_posterior",
    params:
        rig=config["rig"],
    log:
        "logs/posterior_figure_{fig}_{model}.log",
    conda:
        ENV
    script:
        "../scripts/posterior_figure.py"


rule evidence:
    input:
        lambda w: [study_posterior(m) for m in MODELS],
    output:
        evidence=report("results/tables/evidence.csv", caption="../report/evidence.rst",
                        category="Model selection"),
        bayes=report("results/tables/bayes_factor.csv", caption="../report/bayes_factor.rst",
                     category="Model selection"),
    params:
        models=MODELS,
    log:
        "logs/evidence.log",
    conda:
        ENV
    script:
        "../scripts/evidence.py"
