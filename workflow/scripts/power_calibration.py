"""Rule power_calibration: predicted power on the held-out loaded records against the
measured, coverage beside the nominal rate (harvester.power.calibration)."""

from harvester.data.fileio import atomic_path
from harvester.power import figures
from harvester.power.run import held_out_study, load_posteriors
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    posteriors, weights, device = load_posteriors(sm.input.samples, sm.input.weights)
    windows, coverage = held_out_study(posteriors, weights, device, sm.input.records,
                                       sm.input.metas, sm.params.power, sm.params.preprocess)
    with atomic_path(sm.output.windows) as tmp:
        windows.to_csv(tmp, index=False, float_format="%.6g")
    with atomic_path(sm.output.coverage) as tmp:
        coverage.to_csv(tmp, index=False, float_format="%.4g")
    levels = sm.params.power["calibration"]["levels"]
    figures.held_out_coverage(windows, max(levels), sm.output.figure)
    log.info("\n%s", coverage.to_string(index=False))
