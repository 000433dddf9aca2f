# The report's first page: the paper's headline numbers beside ours.


rule headline:
    input:
        table1="results/tables/table1_initial_estimates.csv",
        posteriors=[posterior_table(m) for m in MODELS],
        bayes="results/tables/bayes_factor.csv",
        validation="results/tables/validation.csv",
        sticking="results/tables/figure7_sticking.csv",
        unseen="results/predictive/tanh_validation.npz",
    output:
        csv="results/tables/headline.csv",
        html=report("results/tables/headline.html", caption="../report/headline.rst",
                    category="0. Headline numbers"),
    params:
        models=MODELS,
    log:
        "logs/headline.log",
    conda:
        ENV
    script:
        "../scripts/headline.py"
