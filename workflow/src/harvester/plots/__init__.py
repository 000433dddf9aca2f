"""Figures in the paper's style."""
