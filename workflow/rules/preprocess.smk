# Zero-phase low-pass filtering (paper: 20 Hz) and Figures 4 and 5.


rule lowpass:
    input:
        "results/data/{record}_acc.csv",
    output:
        "results/data/{record}_filtered.csv",
    params:
        cutoff=config["preprocess"]["lowpass_hz"],
        order=config["preprocess"]["filter_order"],
    log:
        "logs/lowpass_{record}.log",
    conda:
        ENV
    script:
        "../scripts/lowpass.py"


rule fig04_psd:
    input:
        raw="results/data/training_acc.csv",
        filtered="results/data/training_filtered.csv",
    output:
        report("results/figures/fig04_psd.png", caption="../report/fig04.rst", category="Data"),
    params:
        cutoff=config["preprocess"]["lowpass_hz"],
    log:
        "logs/fig04_psd.log",
    conda:
        ENV
    script:
        "../scripts/fig04_psd.py"


rule fig05_time_history:
    input:
        raw="results/data/training_acc.csv",
        filtered="results/data/training_filtered.csv",
    output:
        report("results/figures/fig05_time_history.png", caption="../report/fig05.rst", category="Data"),
    params:
        lead_in=config["preprocess"]["training_lead_in"],
        samples=config["preprocess"]["training_samples"],
    log:
        "logs/fig05_time_history.log",
    conda:
        ENV
    script:
        "../scripts/fig05_time_history.py"
