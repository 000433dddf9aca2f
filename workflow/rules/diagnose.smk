# The paper's own step, automated: diagnose each identified model against the training record,
# with the unseen record for the before/after comparison (issue: diagnosis of model discrepancy).


rule diagnose_model:
    input:
        data="results/data/training_filtered.csv",
        validation="results/data/validation_filtered.csv",
        posterior="results/posterior/{model}.nc",
        priors="results/initial/priors.json",
    output:
        json=report("results/diagnosis/{model}/diagnosis.json", caption="../report/diagnosis.rst",
                    category="Diagnosis", subcategory="{model}"),
    params:
        lead_in=config["preprocess"]["training_lead_in"],
        samples=config["preprocess"]["training_samples"],
        lowpass_hz=config["preprocess"]["lowpass_hz"],
        filter_order=config["preprocess"]["filter_order"],
        diagnosis=config["diagnosis"],
    threads: 2
    resources:
        mem_mb=4000,
        runtime=60,
    log:
        "logs/diagnose_{model}.log",
    conda:
        ENV
    script:
        "../scripts/diagnose_model.py"
