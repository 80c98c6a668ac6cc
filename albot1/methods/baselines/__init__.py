"""Wrapped baselines, each behind the mapper protocol of :mod:`albot1.contract`."""
