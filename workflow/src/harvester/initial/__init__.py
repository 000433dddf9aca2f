"""Initial modelling: priors from static friction tests and frequency responses."""
