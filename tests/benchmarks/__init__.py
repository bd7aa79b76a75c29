"""Tests of the benchmarks part of the code."""
