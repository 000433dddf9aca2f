"""Bayesian inference: the likelihood, priors, TMCMC, evidence, posterior summaries."""

#: Where TMCMC's particles start (``identify.TMCMCSettings.start``): all from the prior, or
#: half at the model's MAP (``identify.map_start``). Here, so the command line can offer them
#: without importing the sampler.
TMCMC_STARTS = ("prior", "map")
