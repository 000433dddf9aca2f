"""Truth generators: the virtual rig and the concealed-effect scenarios, kept apart from the model on purpose."""
