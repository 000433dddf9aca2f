"""Stage 4, size: the missing force, and how big each named effect is and whether it matters.

``latent``          the missing force as a latent force with its uncertainty (a Kalman
                    smoother over the baseline's dynamics)
``views``           the missing force against the states (restoring-force views, with bands)
``shapes``          what the missing force looks like: a dictionary of shapes fitted to it
``shape_terms``     the periodic shape fitted as a term of the model, along its own motion
``lines``           a line the missing force leaves in the recording (mains hum, a clock)
``relevance``       each named effect's own force in newtons, its share of the missing force
                    and of the drive, and the floor below which it is negligible
``missing_force``   all of the above in one call (``MissingForce``)
``figures``         the missing force's figures
``estimate``        the stage as the diagnosis runs it: the missing force beside the names the
                    rounds concluded, the periodic shape's fit, a mass's unfixed size
"""
