# Recordings: the rig's raw data (regenerated from the seed and compared bit for bit, checksums
# verified), raw DAQ volts converted to m/s^2, and every recording of the sheet prepared for its
# group: copied with its sidecar beside it and checked as an instrument would check it.


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
        files=[f"{RAW}/{r}.{ext}" for r in RECORDS + LOADED_RECORDS for ext in ("csv", "json")]
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
    """Volts -> m/s^2 and z'' = x'' - y'' (a loaded record's voltage channel -> load volts):
    the rig's records and every raw_daq recording of the sheet."""
    input:
        unpack(lambda w: raw_files(w.record)),
    output:
        "results/data/{record}_acc.csv",
    wildcard_constraints:
        record=one_of(RECORDS + LOADED_RECORDS + SHEET.recordings(kind="raw_daq")),
    log:
        "logs/convert_{record}.log",
    conda:
        ENV
    script:
        "../scripts/convert.py"


rule convert_public:
    """A public benchmark's .mat file (sheet kind public) read into the recording format with
    the sidecar its source gives (harvester.data.public; the files are never modified)."""
    input:
        lambda w: SHEET.file(w.record),
    output:
        csv="results/data/{record}_public.csv",
        sidecar="results/data/{record}_public.yaml",
    wildcard_constraints:
        record=one_of(SHEET.recordings(kind="public")),
    log:
        "logs/convert_public_{record}.log",
    conda:
        ENV
    script:
        "../scripts/convert_public.py"


rule prepare_recording:
    """A recording of the sheet as its group uses it: copied with its sidecar (filtered_at_hz
    set) beside it, checked; what the checks found in RECORDING.check.json."""
    input:
        unpack(prepare_inputs),
    output:
        csv=f"{GROUP_DIR}/data/{{recording}}.csv",
        sidecar=f"{GROUP_DIR}/data/{{recording}}.yaml",
        check=report(f"{GROUP_DIR}/data/{{recording}}.check.json",
                     caption="../report/group_recording.rst", category=GROUP_PAGE,
                     subcategory="{group}",
                     labels=lambda w: page_labels(w.group, "0. recording", "-", w.recording)),
    wildcard_constraints:
        group=one_of(GENERIC_GROUPS),
        recording=one_of(generic_recordings()),
    params:
        lowpass=lambda w: lowpass_settings(w.recording),
    log:
        "logs/groups/{group}/prepare_{recording}.log",
    conda:
        ENV
    script:
        "../scripts/prepare_recording.py"


rule loaded_data:
    """The loaded records converted: time, base_acc, rel_acc, mass_acc, voltage (V)."""
    input:
        expand("results/data/{record}_acc.csv", record=LOADED_RECORDS),
