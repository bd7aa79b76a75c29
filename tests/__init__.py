"""The test suite: one subpackage per part of the code (geometry, envs, planning, learning,
evaluation, viewer, cli, benchmarks).  A package so test modules are named by their path
(``tests.planning.test_oracle``) and shared helpers import as ``tests.oracle``."""
