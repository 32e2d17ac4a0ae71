"""Tools that work on volumen from outside the package (not installed with it): the fuzzers."""
