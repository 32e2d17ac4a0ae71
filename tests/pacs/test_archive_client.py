"""Both archive clients offer the one interface ``volumen.pacs`` talks to (:class:`volumen.pacs.ArchiveClient`):
every member, with the same parameters in the same order and the same return annotation; a client missing one,
or taking other parameters, is told apart. No archive needed."""

from __future__ import annotations

import inspect

import pytest

from volumen.pacs import ArchiveClient, Server
from volumen.pacs._dicomweb import DicomWebArchive
from volumen.pacs._dimse import DimseArchive


def _members() -> list[str]:
    return sorted(n for n, v in vars(ArchiveClient).items() if inspect.isfunction(v) and not n.startswith("_"))


def differences(cls) -> list[str]:
    """What ``cls`` lacks or takes differently from :class:`ArchiveClient` (empty: it offers the interface)."""
    out = []
    for name in _members():
        if not callable(getattr(cls, name, None)):
            out.append(f"{name}: missing")
            continue
        want, got = inspect.signature(getattr(ArchiveClient, name)), inspect.signature(getattr(cls, name))
        if [(p.name, p.kind) for p in want.parameters.values()] != [(p.name, p.kind) for p in got.parameters.values()]:
            out.append(f"{name}{got} is not {name}{want}")
        elif want.return_annotation != got.return_annotation:
            out.append(f"{name} returns {got.return_annotation}, not {want.return_annotation}")
    return out


def test_the_interface_names_what_the_api_uses():
    assert _members() == ["close", "echo", "fetch", "find_series", "find_studies", "list_instances", "store"]


@pytest.mark.parametrize("cls", [DicomWebArchive, DimseArchive])
def test_each_client_offers_the_interface(cls):
    assert differences(cls) == []


def test_a_client_missing_a_member_or_taking_other_parameters_is_told_apart():
    class Partial:
        server = None

        def close(self) -> None: ...

        def echo(self, timeout) -> float: ...

    found = differences(Partial)
    assert "echo(self, timeout) -> 'float' is not echo(self) -> 'float'" in found
    assert {f for f in found if f.endswith("missing")} == {f"{n}: missing" for n in _members()
                                                          if n not in ("close", "echo")}
    assert not isinstance(Partial(), ArchiveClient)


def test_a_dimse_client_is_an_archive_client_at_run_time():
    client = DimseArchive(Server(name="pacs", ae_title="PACS", host="127.0.0.1", port=11112, protocol="dimse"))
    assert isinstance(client, ArchiveClient)
