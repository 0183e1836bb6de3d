"""Data shipped with the package: the measured accuracy table (``accuracy.json``)."""
