"""Rule check_raw_reproduced: the raw files regenerated from the seed equal the committed ones."""

from pathlib import Path

from harvester.data.daq import compare_checksums
from harvester.data.fileio import atomic_path
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    regenerated = Path(sm.input.regenerated) / Path(sm.input.committed).name
    report = compare_checksums(sm.input.committed, regenerated)
    with atomic_path(sm.output[0]) as tmp:
        tmp.write_text(report)
    log.info("\n%s", report)
