# Raw recordings: regenerate from the seed (bit-for-bit check), verify checksums, convert volts to m/s^2
# (and, for the loaded records, the voltage channel to load volts).


rule regenerate_raw_data:
    output:
        directory("results/regenerated_raw"),
    params:
        rig=config["rig"],
    log:
        "logs/regenerate_raw_data.log",
    conda:
        ENV
    script:
        "../scripts/make_raw_data.py"


rule check_raw_reproduced:
    input:
        committed=config["data"]["checksums"],
        regenerated="results/regenerated_raw",
    output:
        "results/checks/raw_reproduced.txt",
    log:
        "logs/check_raw_reproduced.log",
    conda:
        ENV
    script:
        "../scripts/check_reproduced.py"


rule verify_checksums:
    input:
        sums=config["data"]["checksums"],
        files=[f for r in RECORDS + LOADED_RECORDS for f in raw_files(r).values()]
        + [f"{RAW}/static_friction.csv", f"{RAW}/static_friction.json"],
    output:
        "results/checks/raw_checksums.txt",
    log:
        "logs/verify_checksums.log",
    conda:
        ENV
    script:
        "../scripts/verify_checksums.py"


rule convert:
    input:
        unpack(lambda w: raw_files(w.record)),
        checked="results/checks/raw_checksums.txt",
    output:
        "results/data/{record}_acc.csv",
    wildcard_constraints:
        record="|".join(RECORDS + LOADED_RECORDS),
    log:
        "logs/convert_{record}.log",
    conda:
        ENV
    script:
        "../scripts/convert.py"


rule loaded_data:
    """The loaded records converted: time, base_acc, rel_acc, mass_acc, voltage (V)."""
    input:
        expand("results/data/{record}_acc.csv", record=LOADED_RECORDS),
