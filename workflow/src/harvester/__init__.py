"""Bayesian system identification of friction-dominated mechanical devices."""
