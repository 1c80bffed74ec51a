"""Benchmarks: variants compared side by side in one run, reported as ratios."""
