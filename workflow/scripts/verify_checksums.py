"""Rule verify_checksums: stop the study if a raw file differs from its committed checksum."""

from harvester.data.daq import verify_checksums
from harvester.data.fileio import atomic_path
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    checked = verify_checksums(sm.input.sums)
    with atomic_path(sm.output[0]) as tmp:
        tmp.write_text("".join(f"OK {name}\n" for name in checked))
    log.info("%d raw files match %s", len(checked), sm.input.sums)
