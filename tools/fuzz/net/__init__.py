"""A fuzzer over the network surfaces: mutated HTTP requests against a running viewer server
(:mod:`._mutate_http`) and mutated DICOMweb answers from a hostile archive against the archive client
(:mod:`._mutate_replies`), counted per surface as ok / 4xx / 5xx / hang / crash / over budget (:mod:`._campaign`).

``python -m tools.fuzz.net`` runs a campaign (``make fuzz-net``); ``tests/web/test_net_fuzz.py`` a slice.
Like the readers' fuzzer (:mod:`tools.fuzz.io`), mutant ``k`` of seed ``s`` is decided by ``(s, k)`` alone.
"""

from ._archive import HostileArchive, Reply, dataset_json, endless

__all__ = ["HostileArchive", "Reply", "dataset_json", "endless"]
