"""Benchmarks of sensorplan-gym (run as modules, e.g. ``python -m benchmarks.regions``)."""
