"""Stage 3, name: which library term the baseline is missing, confirmed by evidence.

``fits``         what is carried from step to step: a model sampled under its likelihood
                 (``ModelFit``), a candidate's priors on this device, the scan's start
``rank``         the candidates ranked cheaply by their signatures
``screen``       the candidates' best fits (MAP), which bound the evidence each can gain
``smoothness``   whether a candidate's likelihood is smooth enough to sample
``results``      a confirmation's settings and each candidate's result (its evidence, what
                 holds it back from a name)
``skips``        which screened candidates are sampled, in what order, and what the time
                 budget left that could have reached a name
``confirm``      TMCMC of the augmented structures, their evidence, ties
``limits``       where a candidate stands for another term (a bound of its prior, a
                 displacement the record does not resolve, a resonance above the band), and
                 where the record tells it from them
``budget``       the search's time budget: its deadline, what it left unfinished
``plausibility`` a candidate's implied device (masses, stiffness) against the sidecar's
                 measurements: a name whose device contradicts them is not given
``simulable``    a candidate whose posterior diverges over the record is withdrawn
``sensor``       an accepted mode held against a resonance of the output's sensor
``rounds``       detect -> rank -> screen -> confirm, one effect added per round
``separate``     the measurement that would tell two tied effects apart
``verdict``      what is concluded: the verdict, the names, the ties, what is withheld
"""
