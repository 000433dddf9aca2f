"""Rule posterior_figure: Figures 6 and 8 (pairwise posterior samples)."""

from harvester.study import paper
from harvester.plots.posterior import pair_plot
from harvester.inference.posterior import parameter_names, posterior_truth, read_posterior, samples
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    idata = read_posterior(sm.input.posterior)
    names = parameter_names(idata)
    model = sm.wildcards.model
    pair_plot(samples(idata, names), names, sm.output[0],
              f"Posterior samples, {model} model (TMCMC, {idata.posterior.sizes['chain']} chains)",
              paper=paper.POSTERIOR_MEANS.get(model), truth=posterior_truth(sm.params.rig, model))
