"""Rule silverbox_benchmark: every model of a group trained on SNLS80mV.mat simulated on the
benchmark's tests, beside the published errors (benchmark.csv, benchmark.html)."""

from harvester.data.fileio import atomic_path
from harvester.data.public import SILVERBOX_STUDY_SAMPLES, SILVERBOX_TESTS, silverbox_benchmark
from harvester.inference.posterior import read_posterior
from harvester.runlog import rule_log
from harvester.study.benchmark import benchmark_html, benchmark_table

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    split = silverbox_benchmark(sm.input.record, SILVERBOX_STUDY_SAMPLES)
    posteriors = {m: read_posterior(p) for m, p in zip(sm.params.models, sm.input.posteriors)}
    table = benchmark_table(posteriors, split, seed=int(sm.params.seed))
    with atomic_path(sm.output.csv) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    with atomic_path(sm.output.html) as tmp:
        tmp.write_text(benchmark_html(table, SILVERBOX_STUDY_SAMPLES))
    log.info("\n%s", table[["model", *SILVERBOX_TESTS, "input between samples"]].to_string(
        index=False))
