"""``volumen pacs echo|find|get|send``: talk to a PACS or research archive (DICOMweb or DIMSE).

SERVER is a name in ``servers.toml`` (``volumen.pacs.servers_file()``), a DICOMweb URL, or
``AE_TITLE@HOST:PORT``. Passwords never come from the command line: ``servers.toml`` (readable by its owner
only), the environment variable it names, or a prompt in a terminal. ``find`` prints one row per study with
the patient's name and ID, because the user asked for them; nothing else prints them.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
from pathlib import Path

from ._common import ask_password, load_from_args, progress_bar

__all__ = ["register", "run"]


def register(sub):
    p = sub.add_parser("pacs", help="query and retrieve studies from a PACS (DICOMweb or DIMSE); send results back")
    acts = p.add_subparsers(dest="action", metavar="ACTION")
    acts.required = True
    echo = acts.add_parser("echo", help="check that a server answers (C-ECHO, or a DICOMweb search)")
    find = acts.add_parser("find", help="search studies (one row per study) or, with --study, list its series")
    get = acts.add_parser("get", help="retrieve a series (or every series of a study) into the cache")
    send = acts.add_parser("send", help="store DICOM files, a SEG of labels, or a picture on the server")
    for q in (echo, find, get, send):
        q.add_argument("server", help="a name in servers.toml, a DICOMweb URL, or AE_TITLE@HOST:PORT")
        q.add_argument("--protocol", choices=["dicomweb", "dimse"], help="which protocol, when the server has both")
    find.add_argument("--patient", help="patient name; wildcards * and ? (e.g. 'Doe*')")
    find.add_argument("--patient-id", help="patient ID")
    find.add_argument("--date", help="study date YYYYMMDD or range YYYYMMDD-YYYYMMDD (either end may be open)")
    find.add_argument("--modality", help="a modality in the study (CT, MR, SEG...)")
    find.add_argument("--accession", help="accession number")
    find.add_argument("--description", help="study description; wildcards allowed")
    find.add_argument("--limit", type=int, help="at most this many studies")
    find.add_argument("--study", metavar="STUDY_UID", help="list the series of this study instead")
    find.add_argument("--json", action="store_true", help="print JSON instead of a table")
    get.add_argument("study", help="Study Instance UID")
    get.add_argument("series", nargs="?", help="Series Instance UID (default: every series of the study)")
    get.add_argument("-o", "--out", metavar="FOLDER", help="also copy the series into FOLDER/SERIES_UID/")
    get.add_argument("--refresh", action="store_true", help="fetch again even if the cache holds the series")
    get.add_argument("--no-progress", action="store_true", help="no progress bar")
    send.add_argument("files", nargs="*", help="DICOM files or folders to store as they are")
    send.add_argument("--scan", help="the scan the result belongs to: a DICOM folder or dicomweb://SERVER/STUDY/SERIES")
    send.add_argument("--labels", help="labels (anything volumen.load_labels reads, e.g. a lumen mask) to send as "
                                       "a DICOM SEG in the scan's study")
    send.add_argument("--picture", help="a PNG / JPEG rendering to send as a secondary capture in the scan's study")
    send.add_argument("--save", metavar="DCM", help="also write the SEG / capture to this file")
    return p


def _table(rows: list[list[str]], header: list[str]) -> str:
    from volumen.pacs import printable

    rows = [[printable(v) for v in r] for r in rows]  # a server's fields cannot move the cursor or forge a row
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(str(v).ljust(w) for v, w in zip(r, widths, strict=True)).rstrip() for r in [header, *rows]]
    return "\n".join(lines)


def _find(args, pacs) -> int:
    common = {"protocol": args.protocol, "ask": ask_password}
    if args.study:
        found = pacs.series(args.server, args.study, **common)
        if args.json:
            print(json.dumps([s.__dict__ for s in found], indent=2))
            return 0
        rows = [[s.number or "-", s.modality, s.n_instances if s.n_instances is not None else "?",
                 s.description or "-", s.uid] for s in found]
        print(_table(rows, ["#", "modality", "instances", "description", "SeriesInstanceUID"]))
        return 0
    found = pacs.find(args.server, patient_name=args.patient, patient_id=args.patient_id, study_date=args.date,
                      modality=args.modality, accession=args.accession, description=args.description,
                      limit=args.limit, **common)
    if args.json:
        print(json.dumps([{**s.__dict__, "modalities": list(s.modalities)} for s in found], indent=2))
        return 0
    print(_table(found.rows(), list(pacs.STUDY_COLUMNS)))
    print(f"{len(found)} stud{'y' if len(found) == 1 else 'ies'}", file=sys.stderr)
    return 0


def _copy_out(folder: Path, out: Path) -> Path:
    """Copy a cached series to ``out/SERIES_UID`` through a temporary name (never half a series there)."""
    out.mkdir(parents=True, exist_ok=True)
    dest = out / folder.name
    tmp = out / f".{folder.name}.copying"
    if tmp.exists():
        shutil.rmtree(tmp)
    shutil.copytree(folder, tmp)
    if dest.exists():
        shutil.rmtree(dest)
    os.replace(tmp, dest)
    return dest


def _get(args, pacs) -> int:
    common = {"protocol": args.protocol, "ask": ask_password}
    uids = [args.series] if args.series else [s.uid for s in pacs.series(args.server, args.study, **common)]
    for uid in uids:
        folder = pacs.retrieve(args.server, args.study, uid, refresh=args.refresh,
                               progress=progress_bar(not args.no_progress, f"series {uid[-12:]}"), **common)
        if args.out:
            folder = _copy_out(folder, Path(args.out))
        print(f"{folder}  ({sum(1 for _ in folder.iterdir())} files)")
    return 0


def _send(args, pacs) -> int:
    import volumen

    items: list = []
    for f in args.files:
        p = Path(f)
        items += sorted(q for q in p.rglob("*") if q.is_file()) if p.is_dir() else [p]
    if args.labels or args.picture:
        if not args.scan:
            raise ValueError("--labels and --picture need --scan (the DICOM series they belong to)")
        scan = load_from_args(_Reading(), path=args.scan)
        if args.labels:
            made = pacs.make_seg(volumen.load_labels(args.labels, like=scan), scan)
        else:
            made = pacs.make_capture(args.picture, scan)
        if args.save:
            made.save_as(args.save, enforce_file_format=True)
        items.append(made)
    if not items:
        raise ValueError("nothing to send: give DICOM files, or --scan with --labels or --picture")
    n = pacs.send(args.server, items, protocol=args.protocol, ask=ask_password)
    print(f"stored {n} instance(s) on {pacs.resolve_server(args.server, protocol=args.protocol).label}")
    return 0


class _Reading:
    """The reading options of ``load_from_args`` at their defaults (``send`` has none of its own)."""

    series = shape = dtype = spacing = byte_order = nonfinite = resample = None
    no_progress = False


def run(args):
    import volumen.pacs as pacs

    if args.action == "echo":
        seconds = pacs.echo(args.server, protocol=args.protocol, ask=ask_password)
        srv = pacs.resolve_server(args.server, protocol=args.protocol)
        print(f"{srv.label} answers {'C-ECHO' if srv.kind == 'dimse' else 'DICOMweb'} in {seconds * 1000:.0f} ms")
        return 0
    return {"find": _find, "get": _get, "send": _send}[args.action](args, pacs)
