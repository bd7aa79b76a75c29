"""Tests of the learning part of the code."""
