"""The electrical half of the harvester: its generator model, its loaded records, and its
identification by TMCMC with the mechanical posterior as prior (``docs/electrical.md``).

``generator``   the quasi-static three-phase generator into a star load: electrical damping,
                the electrical time constant's lag, the line-voltage magnitude, the load power
``records``     loaded records as the likelihood reads them (space-vector magnitude of two
                line voltages, the load per record)
``priors``      priors of the generator's constants and the mechanical posterior as a prior
``problem``     the joint likelihood of acceleration and voltage over several records
``identify``    TMCMC per electrical structure, evidence, Bayesian model averaging weights
"""
