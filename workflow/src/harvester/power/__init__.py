"""How much power the harvester would make, with its uncertainty (``docs/electrical.md``).

``excitations``  base-acceleration records the device never saw: a JONSWAP sea state,
                 band-limited white noise, a user's CSV
``predict``      posterior draws averaged across electrical structures by their evidence,
                 and the load power each draw predicts per load resistance
``design``       summaries per load, the loads that maximise expected power and a low
                 quantile, and the gain of a mechanical change
``calibration``  held-out coverage of the predicted power and recovery of the rig's constants
``figures``      the power-vs-load figure with its band, the energy distribution, coverage
"""
