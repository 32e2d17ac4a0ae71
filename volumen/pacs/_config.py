"""Archives the user talks to: ``servers.toml``, servers given on the command line, and their credentials.

The configuration file is ``$VOLUMEN_CONFIG_DIR/servers.toml`` (else ``$XDG_CONFIG_HOME/volumen/servers.toml``,
else ``~/.config/volumen/servers.toml``), one table per server::

    [servers.archive]                        # DICOMweb (QIDO-RS, WADO-RS, STOW-RS)
    url = "https://pacs.example.org/dicom-web"
    username = "alice"
    password_env = "ARCHIVE_PASSWORD"        # or password = "..." in a file only its owner can read
    ca_bundle = "/etc/ssl/hospital-ca.pem"   # TLS: the authority that signed the server's certificate

    [servers.scanner]                        # DIMSE (C-ECHO, C-FIND, C-GET / C-MOVE, C-STORE)
    ae_title = "ORTHANC"
    host = "pacs.example.org"
    port = 4242

A server with both ``url`` and ``ae_title`` speaks DICOMweb unless ``protocol = "dimse"`` (or the caller's
``protocol=``) says otherwise. Secrets (``password``, ``token``) are read from the file only when nobody but
its owner can read it (``chmod 600``), else from the environment variable the entry names; they are never
part of a :class:`Server`'s repr, its ``to_dict`` or an error message.
"""

from __future__ import annotations

import re
import stat
import tomllib
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Literal
from urllib.parse import urlsplit

from ..errors import ArchiveConfigError
from ..places import cache_dir, config_dir

__all__ = ["Server", "config_dir", "cache_dir", "servers_file", "load_servers", "resolve_server", "PROTOCOLS"]

PROTOCOLS = ("dicomweb", "dimse")
_AE_AT_HOST = re.compile(r"^(?P<aet>[^@\s\\]{1,16})@(?P<host>[^:@\s]+):(?P<port>\d{1,5})$")
_SECRET_KEYS = ("password", "token")


def servers_file() -> Path:
    """The configuration file of the archives (it may not exist)."""
    return config_dir() / "servers.toml"


@dataclass(frozen=True, kw_only=True)
class Server:
    """One archive: DICOMweb (``url``) and / or DIMSE (``ae_title``, ``host``, ``port``).

    Parameters
    ----------
    name : str
        What the user calls it (the table name in ``servers.toml``, or the address given).
    url : str, optional
        DICOMweb service root (``http(s)://host:port/dicom-web``).
    ae_title, host, port : optional
        The archive's DIMSE application entity.
    calling_ae_title : str
        volumen's own AE title (the archive may have to know it).
    store_port : int, optional
        Port of volumen's storage SCP for C-MOVE (the archive must know ``calling_ae_title`` at this port).
    protocol : {"dicomweb", "dimse"}, optional
        Which one to speak when both are configured (default: DICOMweb).
    retrieve : {"get", "move"}
        DIMSE retrieval by C-GET (one association) or C-MOVE (the archive connects back to ``store_port``).
    username : str, optional
        HTTP basic authentication user; the password comes from ``password`` (file readable by its owner
        only), the variable named by ``password_env``, or the caller's prompt.
    token_env : str, optional
        Environment variable holding a bearer token (or ``token`` in the file).
    ca_bundle : str, optional
        PEM file of the certificate authorities to trust for ``https`` (default: the system's).
    timeout : float, s
        Longest wait for a connection or for the next bytes of an answer.
    deadline : float, s
        Longest time one answer (a search's, an instance's, a store's) may take to arrive whole, however slowly
        the server sends it; a DIMSE operation's responses likewise.
    max_answer_mb : float, MiB
        Largest search or store answer read from the server (DICOMweb); a DIMSE search's matches count as
        1 KiB each.
    max_instance_mb : float, MiB
        Largest instance retrieved (DICOMweb).
    """

    name: str
    url: str | None = None
    ae_title: str | None = None
    host: str | None = None
    port: int | None = None
    calling_ae_title: str = "VOLUMEN"
    store_port: int | None = None
    protocol: Literal["dicomweb", "dimse"] | None = None
    retrieve: Literal["get", "move"] = "get"
    username: str | None = None
    password_env: str | None = None
    token_env: str | None = None
    ca_bundle: str | None = None
    timeout: float = 30.0
    deadline: float = 300.0
    max_answer_mb: float = 64.0
    max_instance_mb: float = 2048.0
    password: str | None = field(default=None, repr=False, compare=False)
    token: str | None = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        if self.protocol is not None and self.protocol not in PROTOCOLS:
            raise ArchiveConfigError(self.name, f"protocol must be one of {', '.join(PROTOCOLS)}, got "
                                                f"{self.protocol!r}")
        if self.retrieve not in ("get", "move"):
            raise ArchiveConfigError(self.name, f"retrieve must be 'get' or 'move', got {self.retrieve!r}")
        if self.url is None and self.ae_title is None:
            raise ArchiveConfigError(self.name, "needs a url (DICOMweb) or ae_title, host and port (DIMSE)")
        for key in ("timeout", "deadline", "max_answer_mb", "max_instance_mb"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < float("inf"):
                raise ArchiveConfigError(self.name, f"{key} must be a positive number, got {value!r}")
        if self.url is not None:
            parts = urlsplit(self.url)
            if "@" in parts.netloc:
                raise ArchiveConfigError(self.name, "the url holds credentials: put the user name in username and "
                                                    "the password in servers.toml (readable by you only) or an "
                                                    "environment variable, not in the url")
            if parts.scheme not in ("http", "https") or not parts.hostname:
                raise ArchiveConfigError(self.name, f"url must be http(s)://HOST[:PORT]/PATH, got {self.url!r}")
        if self.ae_title is not None and (self.host is None or self.port is None):
            raise ArchiveConfigError(self.name, "a DIMSE server needs ae_title, host and port")

    @property
    def kind(self) -> str:
        """The protocol spoken: ``"dicomweb"`` or ``"dimse"``."""
        if self.protocol is not None:
            return self.protocol
        return "dicomweb" if self.url is not None else "dimse"

    def speaking(self, protocol: str | None) -> Server:
        """This server set to speak ``protocol`` (None: as configured); a protocol it lacks is an error."""
        if protocol is None:
            return self
        if protocol not in PROTOCOLS:
            raise ArchiveConfigError(self.name, f"protocol must be one of {', '.join(PROTOCOLS)}, got {protocol!r}")
        if protocol == "dicomweb" and self.url is None:
            raise ArchiveConfigError(self.name, "has no url: it does not speak DICOMweb")
        if protocol == "dimse" and self.ae_title is None:
            raise ArchiveConfigError(self.name, "has no ae_title / host / port: it does not speak DIMSE")
        return replace(self, protocol=protocol)

    @property
    def label(self) -> str:
        """The server as errors name it: its name and address (never a credential)."""
        if self.kind == "dicomweb":
            address = self.url
        else:
            address = f"{self.ae_title}@{self.host}:{self.port}"
        return self.name if self.name == address else f"{self.name} ({address})"

    def to_dict(self) -> dict:
        """The settings as JSON-able data, without the secrets."""
        d = asdict(self)
        for key in _SECRET_KEYS:
            d.pop(key)
        return {k: v for k, v in d.items() if v is not None}

    @classmethod
    def from_dict(cls, d: dict) -> Server:
        """The inverse of :meth:`to_dict` (unknown keys are an error naming the valid ones)."""
        valid = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - valid)
        if unknown:
            raise ArchiveConfigError(d.get("name"), f"unknown setting(s) {', '.join(unknown)}; valid: "
                                                    f"{', '.join(sorted(valid - {'name'}))}")
        return cls(**d)


def _check_private(path: Path, name: str, entry: dict) -> None:
    """A secret in the file is accepted only when group and others cannot read it."""
    secrets = [k for k in _SECRET_KEYS if k in entry]
    if not secrets:
        return
    mode = path.stat().st_mode
    if mode & (stat.S_IRWXG | stat.S_IRWXO):
        raise ArchiveConfigError(name, f"{path} holds a {secrets[0]} but others can read it (mode "
                                       f"{stat.S_IMODE(mode):o}); run: chmod 600 {path}")


def load_servers(path: Path | None = None) -> dict[str, Server]:
    """The servers of ``servers.toml`` by name (an empty dict when the file does not exist).

    Raises
    ------
    ArchiveConfigError
        Unreadable TOML, an unknown key, a secret in a file others can read.
    """
    path = Path(path) if path is not None else servers_file()
    if not path.exists():
        return {}
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ArchiveConfigError(None, f"{path}: not readable TOML ({exc})") from None
    tables = data.get("servers", {})
    if not isinstance(tables, dict) or any(not isinstance(v, dict) for v in tables.values()):
        raise ArchiveConfigError(None, f"{path}: servers must be tables, [servers.NAME]")
    out = {}
    for name, entry in tables.items():
        _check_private(path, name, entry)
        out[name] = Server.from_dict({"name": name, **entry})
    return out


def resolve_server(spec: str | Server, *, protocol: str | None = None, path: Path | None = None) -> Server:
    """A server from a name in ``servers.toml``, a DICOMweb URL, or ``AE_TITLE@HOST:PORT`` (DIMSE).

    Raises
    ------
    ArchiveConfigError
        An unknown name (the message lists the configured ones), a URL holding a password.
    """
    if isinstance(spec, Server):
        return spec.speaking(protocol)
    spec = str(spec)
    if "://" in spec:
        parts = urlsplit(spec)
        if "@" in parts.netloc:
            raise ArchiveConfigError(parts.hostname, "credentials in the url: a user name or password on the command "
                                                     "line is visible to other users; name the server in servers.toml "
                                                     "(username, password_env) instead")
        if parts.scheme.lower() not in ("http", "https"):
            raise ArchiveConfigError(None, f"a server's url must be http(s)://HOST[:PORT]/PATH, got {spec!r}")
        return Server(name=spec, url=spec).speaking(protocol)
    m = _AE_AT_HOST.match(spec)
    if m:
        return Server(name=spec, ae_title=m["aet"], host=m["host"], port=int(m["port"])).speaking(protocol)
    known = load_servers(path)
    if spec in known:
        return known[spec].speaking(protocol)
    listed = ", ".join(sorted(known)) or f"none: {path or servers_file()} does not exist or is empty"
    raise ArchiveConfigError(spec, f"is not a configured server (configured: {listed}); give a name from "
                                   "servers.toml, a DICOMweb URL or AE_TITLE@HOST:PORT")
