"""Tests of the viewer part of the code."""
