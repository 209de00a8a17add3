"""Shipped data files (scenes), read with :mod:`importlib.resources`."""
