"""A seeded mutation fuzzer over every volume reader (``python -m tools.fuzz.io``).

Seeds (:mod:`._seeds`) are real files found on the machine and files volumen's writers
produce; mutations (:mod:`._mutate`, :mod:`._fields`) flip bits, overwrite and cut
bytes and edit header fields per format; each mutant is loaded by ``volumen.load`` in
a worker process (:mod:`._worker`) under a memory limit and a timeout, and the
campaign (:mod:`._campaign`) counts the outcomes per family of formats:
ok, typed, untyped, hang, out-of-memory, crash, outside-path.
"""

from ._campaign import OUTCOMES, Finding, Mutant, Report, make_mutant, run_campaign
from ._seeds import FAMILIES, Seed, build_seeds

__all__ = ["OUTCOMES", "FAMILIES", "Finding", "Mutant", "Report", "Seed", "build_seeds", "make_mutant",
           "run_campaign"]
