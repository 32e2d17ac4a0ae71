"""The secret of a server: from ``servers.toml`` (checked private when read), an environment variable, or a prompt.

A password typed at the prompt is remembered for the rest of the process (one command, one notebook kernel) so a
command that opens several connections (the series of a study, then each series) asks once; one the server
refuses is forgotten (:func:`forget`) and asked again. Nothing here prints, logs or puts a secret into an
exception.
"""

from __future__ import annotations

import os
from collections.abc import Callable

from ..errors import ArchiveConfigError
from ._config import Server

__all__ = ["password", "token", "forget", "unlock", "Prompt"]

#: asks the user for the password of ``user`` on ``server`` (its label); returns it, or None to give up
Prompt = Callable[[str, str], "str | None"]

_asked: dict[tuple[str, str], str] = {}  # passwords typed at a prompt, by (server label, user)


def _from_env(server: Server, variable: str | None, what: str) -> str | None:
    if variable is None:
        return None
    value = os.environ.get(variable)
    if not value:
        raise ArchiveConfigError(server.label, f"the environment variable {variable} meant to hold the {what} "
                                               "is not set")
    return value


def password(server: Server, ask: Prompt | None = None) -> str | None:
    """The HTTP basic password of ``server`` (None when it has no ``username``).

    Order: ``password`` in ``servers.toml`` (the file was checked private), the variable named by
    ``password_env``, one typed earlier in this process, then ``ask(label, username)``.

    Raises
    ------
    ArchiveConfigError
        A username without any way to get its password.
    """
    if server.username is None:
        return None
    if server.password:
        return server.password
    found = _from_env(server, server.password_env, "password")
    if found:
        return found
    key = (server.label, server.username)
    if key in _asked:
        return _asked[key]
    answer = ask(server.label, server.username) if ask is not None else None
    if answer:
        _asked[key] = answer
        return answer
    raise ArchiveConfigError(server.label, f"user {server.username} has no password: set password_env (the name "
                                           "of an environment variable) or password in servers.toml (chmod 600), "
                                           "or run in a terminal to be asked")


def token(server: Server) -> str | None:
    """The bearer token of ``server``: ``token`` in ``servers.toml`` or the variable named by ``token_env``."""
    if server.token:
        return server.token
    return _from_env(server, server.token_env, "token")


def forget(server: Server) -> None:
    """Drop the password typed for ``server`` (it refused it): the next connection asks again."""
    _asked.pop((server.label, server.username), None)


def unlock(server: Server, ask: Prompt | None) -> None:
    """Have the secret of a DICOMweb ``server`` at hand now, asking with ``ask`` if it must (the answer is
    remembered): for a caller that can prompt on one thread and connects on another (the app's dialog).

    Raises
    ------
    ArchiveConfigError
        As :func:`password` and :func:`token`.
    """
    if server.kind == "dicomweb" and not token(server):
        password(server, ask)
