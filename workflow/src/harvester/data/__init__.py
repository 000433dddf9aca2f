"""Recordings: file formats, what a recording measures, signal processing, errors."""
