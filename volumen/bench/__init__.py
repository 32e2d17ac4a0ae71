"""Benchmarks (``volumen bench ...``): print a table and write it as JSON. Never run as tests."""

from ._table import Table, machine_info, median_time

__all__ = ["Table", "machine_info", "median_time"]
