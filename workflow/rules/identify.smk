# Bayesian identification: TMCMC per model structure, posterior tables and figures, evidence.


rule tmcmc:
    input:
        data="results/data/training_filtered.csv",
        priors="results/initial/priors.json",
    output:
        "results/posterior/{model}.nc",
    params:
        rig=config["rig"],
        tmcmc=config["tmcmc"],
        lead_in=config["preprocess"]["training_lead_in"],
        samples=config["preprocess"]["training_samples"],
        lowpass_hz=config["preprocess"]["lowpass_hz"],
        filter_order=config["preprocess"]["filter_order"],
    threads: 2
    resources:
        mem_mb=4000,
        runtime=60,
    log:
        "logs/tmcmc_{model}.log",
    conda:
        ENV
    script:
        "../scripts/tmcmc.py"


rule posterior_table:
    input:
        posterior="results/posterior/{model}.nc",
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
        posterior="results/posterior/{model}.nc",
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
        expand("results/posterior/{model}.nc", model=MODELS),
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
