"""Tests of the geometry part of the code."""
