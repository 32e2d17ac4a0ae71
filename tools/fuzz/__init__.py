"""Seeded fuzzers: :mod:`tools.fuzz.io` over every volume reader (``make fuzz``), :mod:`tools.fuzz.net` over the
viewer server and the archive clients (``make fuzz-net``); the suite runs a bounded slice of each
(``tests/io/test_fuzz.py``, ``tests/web/test_net_fuzz.py``)."""
