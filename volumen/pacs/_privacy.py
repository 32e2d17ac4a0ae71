"""Keep patient identity out of the logs of the libraries the archive clients use.

A search's matching values (a patient's name or ID, an accession number, a description) travel in the URL of
a QIDO-RS request, and ``urllib3`` and ``dicomweb-client`` log URLs at DEBUG level. :func:`redact_logs` puts a
filter on those loggers that replaces each such value by ``...`` before a handler sees the record; the DIMSE
client turns off pynetdicom's identifier logging itself (``_dimse``).
"""

from __future__ import annotations

import logging
import re

__all__ = ["redact_logs", "RedactFilter", "IDENTIFYING_KEYS"]

#: matching keys whose values may identify a patient
IDENTIFYING_KEYS = ("PatientName", "PatientID", "PatientBirthDate", "AccessionNumber", "StudyDescription",
                    "ReferringPhysicianName", "00100010", "00100020", "00100030", "00080050", "00081030",
                    "00080090")
_VALUE = re.compile(r"(\b(?:" + "|".join(IDENTIFYING_KEYS) + r")=)[^&\s\"']*")
_LOGGERS = ("urllib3.connectionpool", "urllib3.connection", "dicomweb_client", "dicomweb_client.web")


class RedactFilter(logging.Filter):
    """Rewrites a record's message with identifying query values replaced by ``...``."""

    def filter(self, record: logging.LogRecord) -> bool:
        try:
            message = record.getMessage()
        except (TypeError, ValueError):
            return True
        redacted = _VALUE.sub(r"\1...", message)
        if redacted != message:
            record.msg, record.args = redacted, ()
        return True


_FILTER = RedactFilter()


def redact_logs() -> None:
    """Install the filter on the loggers of urllib3 and dicomweb-client (once; idempotent)."""
    for name in _LOGGERS:
        logger = logging.getLogger(name)
        if _FILTER not in logger.filters:
            logger.addFilter(_FILTER)
