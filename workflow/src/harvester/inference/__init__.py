"""Bayesian inference: the likelihood, priors, TMCMC, evidence, posterior summaries."""
