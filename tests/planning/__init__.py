"""Tests of the planning part of the code."""
