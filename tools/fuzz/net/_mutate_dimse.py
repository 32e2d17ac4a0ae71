"""Mutated C-FIND responses from a hostile DIMSE archive against ``volumen pacs find`` (``--protocol dimse``).

:class:`HostileScp` is a pynetdicom storage-less SCP on a free local port answering every C-FIND with the
responses it is given: ``(status, identifier)`` pairs, optionally with a pause between them. Reply ``k`` of seed
``s`` (:func:`make_dimse_reply`) takes three study matches and spoils them: hostile text in a field, values of
the wrong kind, odd statuses (failures, cancels, warnings, unknown codes), a pending response without an
identifier, thousands of matches, a pause past the deadline. :func:`run_dimse_reply` runs the study or series
search and says how it ended, as :func:`._mutate_replies.run_reply` does.
"""

from __future__ import annotations

import random
import time
import warnings

__all__ = ["HostileScp", "make_dimse_reply", "run_dimse_reply"]

_PENDING, _OK = 0xFF00, 0x0000
_TEXT = ["\x1b]0;pwned\x07", "\x1b[2J", "ID\r\nForged^Row", "\u202eevil", "\x00", "A" * 3000, "é中", "\\\\", ""]
_STATUSES = [0x0000, 0xA700, 0xA900, 0xC000, 0xC3FF, 0xFE00, 0xFF01, 0x1234, 0xB000, 0x0107]
_KEYS = ["PatientName", "PatientID", "StudyDescription", "AccessionNumber", "StudyDate", "StudyInstanceUID",
         "ModalitiesInStudy", "NumberOfStudyRelatedSeries", "SeriesNumber", "Modality", "SeriesInstanceUID"]


def _match(i: int):
    from pydicom import Dataset

    ds = Dataset()
    ds.QueryRetrieveLevel = "STUDY"
    ds.PatientName, ds.PatientID, ds.StudyDate = f"Doe^Jane{i}", f"P{i}", "20240102"
    ds.StudyInstanceUID = f"1.2.826.0.1.3680043.8.498.1{i}"
    ds.ModalitiesInStudy, ds.NumberOfStudyRelatedSeries = "CT", 2
    return ds


def _spoil(rng, ds) -> None:
    key = rng.choice(_KEYS)
    kind = rng.randrange(3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if kind == 0:
            ds.add_new(key, "LO" if key not in ("PatientName",) else "PN", rng.choice(_TEXT))
        elif kind == 1:
            raw = bytes(rng.randrange(256) for _ in range(9))
            vr, value = rng.choice([("UN", raw), ("OB", raw), ("IS", "abc"), ("DA", "2024-13-45"), ("DS", "1e999"),
                                    ("UI", "not.a.uid!"), ("US", 7)])
            try:
                ds.add_new(key, vr, value)
            except (ValueError, TypeError):   # pydicom will not hold it: a hostile text instead
                ds.add_new(key, "LO", rng.choice(_TEXT))
        else:
            ds.add_new(key, "LO", [rng.choice(_TEXT), rng.choice(_TEXT)])


def make_dimse_reply(seed: int, k: int) -> tuple[str, str, list, float]:
    """``(name, operation, responses, pause s)`` of DIMSE reply ``k`` of campaign ``seed``."""
    with warnings.catch_warnings():   # pydicom warns of the odd values made here
        warnings.simplefilter("ignore")
        return _make(random.Random(f"dimse:{seed}:{k}"))


def _make(rng) -> tuple[str, str, list, float]:
    op = rng.choice(["find", "series"])
    responses = [(_PENDING, _match(i)) for i in range(3)]
    kind = rng.choice(["text", "text", "values", "status", "no-identifier", "many", "slow"])
    pause = 0.0
    if kind in ("text", "values"):
        for _ in range(rng.randint(1, 3)):
            ds = rng.choice(responses)[1]
            (_spoil(rng, ds) if kind == "values" or rng.random() < 0.5 else
             ds.add_new(rng.choice(_KEYS[:4]), "LO", rng.choice(_TEXT)))
    elif kind == "status":
        responses.insert(rng.randrange(len(responses) + 1), (rng.choice(_STATUSES), None))
    elif kind == "no-identifier":
        responses.append((_PENDING, None))
    elif kind == "many":
        responses = [(_PENDING, _match(i % 10)) for i in range(rng.choice([500, 9000]))]
    else:
        pause = 1.2
    return f"dimse-{kind} ({op})", op, responses + [(_OK, None)], pause


class HostileScp:
    """A C-FIND SCP answering :attr:`responses` (``(status, identifier)``), :attr:`pause` s apart."""

    def __init__(self):
        from pydicom import config
        from pynetdicom import AE, evt
        from pynetdicom.sop_class import StudyRootQueryRetrieveInformationModelFind, Verification

        self.responses, self.pause = [(_OK, None)], 0.0
        self._writing = config.settings.writing_validation_mode
        config.settings.writing_validation_mode = config.IGNORE   # the archive sends what it likes, unwarned
        ae = AE(ae_title="FUZZ")
        ae.add_supported_context(StudyRootQueryRetrieveInformationModelFind)
        ae.add_supported_context(Verification)
        ae.network_timeout = ae.acse_timeout = ae.dimse_timeout = 5
        self._server = ae.start_server(("127.0.0.1", 0), block=False,
                                       evt_handlers=[(evt.EVT_C_FIND, self._find)])
        self.port = self._server.server_address[1]

    def _find(self, event):
        for status, identifier in self.responses:
            if self.pause:
                time.sleep(self.pause)
            yield status, identifier

    def close(self) -> None:
        from pydicom import config

        self._server.shutdown()
        config.settings.writing_validation_mode = self._writing


def run_dimse_reply(scp: HostileScp, server: str, op: str, responses: list, pause: float) -> tuple[str, str]:
    """``(outcome, detail)`` of the study (``find``) or series search against ``scp``; see
    :func:`._mutate_replies.run_reply` for the outcomes."""
    from volumen.errors import ArchiveError
    from volumen.pacs import find, printable, series

    scp.responses, scp.pause = responses, pause
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            if op == "find":
                text = "\n".join("  ".join(row) for row in find(server).rows())
            else:
                text = "\n".join("  ".join(printable(v) for v in (s.number, s.modality, s.description, s.uid))
                                 for s in series(server, "1.2.826.0.1.3680043.8.498.1"))
    except ArchiveError as exc:
        return ("refused", str(exc)[:160]) if str(exc).isprintable() else ("crash", repr(str(exc)[:100]))
    except BaseException as exc:  # noqa: BLE001 - anything else escaping is what the fuzzer looks for
        return "crash", f"{type(exc).__name__}: {str(exc)[:100]!r}"
    if any(not (c.isprintable() or c in "\n ") for c in text):
        return "escape", repr(text[:100])
    return "ok", ""
