# Posterior predictive on training and unseen data: Figures 7, 9, 10 and validation metrics.


rule predictive:
    input:
        posterior="results/posterior/{model}.nc",
        data="results/data/{record}_filtered.csv",
        priors="results/initial/priors.json",
    output:
        "results/predictive/{model}_{record}.npz",
    params:
        lead_in=lambda w: config["preprocess"][f"{w.record}_lead_in"],
        samples=lambda w: config["preprocess"]["training_samples"] if w.record == "training" else None,
        predictive=config["predictive"],
    wildcard_constraints:
        record="|".join(RECORDS),
    threads: 2
    log:
        "logs/predictive_{model}_{record}.log",
    conda:
        ENV
    script:
        "../scripts/predictive.py"


rule validation_table:
    input:
        expand("results/predictive/{model}_{record}.npz", model=MODELS, record=RECORDS),
    output:
        report("results/tables/validation.csv", caption="../report/validation.rst",
               category="Validation"),
    log:
        "logs/validation_table.log",
    conda:
        ENV
    script:
        "../scripts/validation_table.py"


rule fig07_linear_training:
    input:
        "results/predictive/linear_training.npz",
    output:
        report("results/figures/fig07_linear_training.png", caption="../report/fig07.rst",
               category="Validation"),
    params:
        title="Linear model against the training data (Figure 7)",
        window=None,
    log:
        "logs/fig07.log",
    conda:
        ENV
    script:
        "../scripts/response_figure.py"


rule fig09_tanh_unseen_section:
    input:
        "results/predictive/tanh_validation.npz",
    output:
        report("results/figures/fig09_tanh_unseen_section.png", caption="../report/fig09.rst",
               category="Validation"),
    params:
        title="Hyperbolic tangent model against a section of the unseen data (Figure 9)",
        window=config["predictive"]["short_window_s"],
    log:
        "logs/fig09.log",
    conda:
        ENV
    script:
        "../scripts/response_figure.py"


rule fig10_tanh_unseen_full:
    input:
        "results/predictive/tanh_validation.npz",
    output:
        report("results/figures/fig10_tanh_unseen_full.png", caption="../report/fig10.rst",
               category="Validation"),
    params:
        title="Hyperbolic tangent model against 80 s of unseen data (Figure 10)",
        window=None,
    log:
        "logs/fig10.log",
    conda:
        ENV
    script:
        "../scripts/response_figure.py"
