"""Stage 1, prepare: what the diagnosis decides before it looks for anything.

``settings``     what the diagnosis spends and where (``DiagnosisSettings``)
``recording``    a recording's file to the diagnosis's input: the device from the sidecar, the
                 low-pass, the validation record, the friction's contact, the priors from the
                 recording (the one place for the command line and Python alike)
``topology``     what the friction acts on when the sidecar does not say (base or ground)
``redundant``    the candidates that would only restate what the baseline identifies (a mass
                 error where no mass is given)
``analysis``     the recording cut into windows for the model, and the baseline's posterior the
                 rounds start from
"""
