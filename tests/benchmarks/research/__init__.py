"""Tests of the solver research (benchmarks/research/): experiments no user path reaches."""
