"""Tests of the envs part of the code."""
