"""Stage 2, detect: is there a mismatch between the recording and the baseline, and where.

``spectral``     the frequency-domain frame: analysis window, passband, noise spectrum and the
                 noise replicates that calibrate every test
``signatures``   how each candidate term would change the output (its signature), and the
                 candidates a baseline can take
``scores``       the calibrated score tests and prior conflicts (``Detection``)
``locate``       where the mismatch lies: time windows, state regions, frequency bands
``floor``        the recording's own noise floor, measured where the model has no say
``quick``        detection and location alone with a MAP baseline, for screening (seconds)
"""
