# Zero-phase low-pass filtering of the measured output (paper: 20 Hz; a group's: config
# groups.<group>.lowpass_hz) and the paper's Figures 4 and 5.


rule lowpass:
    input:
        lambda w: converted_file(w.record),
    output:
        "results/data/{record}_filtered.csv",
    wildcard_constraints:
        record=one_of(RECORDS + [r for r in generic_recordings() if lowpass_settings(r)[0]]),
    params:
        cutoff=lambda w: lowpass_settings(w.record)[0],
        order=lambda w: lowpass_settings(w.record)[1],
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
