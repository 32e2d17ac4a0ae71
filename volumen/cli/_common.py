"""Options shared by several sub-commands: reading a volume (files, phantoms, archive references), choosing a window,
asking for an archive password, a progress bar."""

from __future__ import annotations

import argparse
import math
import re
import sys

# a negative number or a comma-separated list starting with one: "-60,30,80", "-1.5e2"
_NEGATIVE_VALUE = re.compile(r"^-(\d|\.\d)[\d.eE+\-,x]*$")


def join_negative_values(argv: list[str]) -> list[str]:
    """``["--end", "-60,30,80"]`` -> ``["--end=-60,30,80"]``: argparse would take the value for an option.

    Only a ``--long`` option without ``=`` followed by a token that reads as a
    negative number (or a comma list starting with one) is joined.
    """
    out: list[str] = []
    for tok in argv:
        prev = out[-1] if out else ""
        if _NEGATIVE_VALUE.match(tok) and prev.startswith("--") and "=" not in prev and len(prev) > 2:
            out[-1] = f"{prev}={tok}"
        else:
            out.append(tok)
    return out


def add_load_options(p: argparse.ArgumentParser) -> None:
    """Options of :func:`volumen.load` (DICOM series choice, raw geometry, NaN policy)."""
    g = p.add_argument_group("reading")
    g.add_argument("--series", help="DICOM SeriesInstanceUID to load when a folder holds several")
    g.add_argument("--resample", action="store_true", default=None, help="make non-uniform slice spacing uniform")
    g.add_argument("--nonfinite", choices=["zero", "min", "error", "keep"], default=None,
                   help="what to do with NaN/inf values (default: replace by 0 with a warning)")
    g.add_argument("--shape", help="raw files: NZ,NY,NX")
    g.add_argument("--dtype", help="raw files: numpy dtype, e.g. int16")
    g.add_argument("--spacing", help="raw files: DZ,DY,DX in mm")
    g.add_argument("--byte-order", choices=["little", "big"], help="raw files: byte order")


def finite_float(text: str) -> float:
    """An argument's number, refused (one line, the option named by argparse) unless finite."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{text!r} is not a finite number")
    return value


finite_float.__name__ = "finite number"  # argparse's words: "invalid finite number value: 'nan'"


def count(text: str) -> int:
    """An argument's whole number, refused (one line) where negative."""
    value = int(text)
    if value < 0:
        raise ValueError(f"{text!r} is negative")
    return value


count.__name__ = "whole number of 0 or more"  # argparse's words: "invalid whole number of 0 or more value: '-5'"


def _floats(text: str | None, n: int, what: str):
    if text is None:
        return None
    parts = text.replace("x", ",").split(",")
    try:
        vals = [float(t) for t in parts]
    except ValueError:
        raise ValueError(f"{what} must be {n} comma-separated numbers, got {text!r}") from None
    if len(vals) != n or not all(math.isfinite(v) for v in vals):
        raise ValueError(f"{what} must be {n} comma-separated numbers, got {text!r}")
    return vals


#: a reader's warnings said on the terminal before the rest are only counted (``volumen info`` lists every one)
SAID_WARNINGS = 5


def load_from_args(args: argparse.Namespace, path=None, *, quiet: bool = False):
    """Load ``path`` (default ``args.input``) with the reading options, or a phantom for ``phantom:NAME``; the
    reader's warnings about it are said on stderr (:func:`say_warnings`) unless ``quiet``."""
    volume = _load(args, path if path is not None else args.input)
    if not quiet:
        say_warnings(volume, getattr(args, "command", None))
    return volume


def say_warnings(volume, command: str | None) -> None:
    """One line on stderr per warning the reader left in ``volume.meta["warnings"]`` (a 4-D file drawn from its
    first volume, NaN replaced, a gantry tilt, uneven slices, an assumed spacing, skipped files), at most
    :data:`SAID_WARNINGS` and then how many more: a picture drawn from what the file did not quite say is not
    handed over as if it had."""
    said = list((volume.meta or {}).get("warnings", []))
    who = f"volumen {command}" if command else "volumen"
    for w in said[:SAID_WARNINGS]:
        print(f"{who}: warning: {w}", file=sys.stderr)
    if len(said) > SAID_WARNINGS:
        print(f"{who}: warning: {len(said) - SAID_WARNINGS} more (volumen info lists them)", file=sys.stderr)


def _load(args: argparse.Namespace, path):
    import volumen

    if str(path).startswith("phantom:"):
        return load_phantom(str(path))
    opts = {"nonfinite": args.nonfinite or "zero", "resample": bool(args.resample)}
    if args.series:
        opts["series"] = args.series
    if args.shape:
        opts["shape"] = tuple(int(v) for v in _floats(args.shape, 3, "--shape"))
    if args.dtype:
        opts["dtype"] = args.dtype
    if args.spacing:
        opts["spacing"] = tuple(_floats(args.spacing, 3, "--spacing"))
    if args.byte_order:
        opts["byte_order"] = args.byte_order
    if str(path).startswith(("dicomweb://", "dimse://")):  # retrieved into the cache, then read from there
        from volumen.pacs import load as load_archived

        return load_archived(str(path), progress=progress_bar(not getattr(args, "no_progress", False)),
                             ask=ask_password, **opts)
    return volumen.load(path, **opts)


def load_phantom(ref: str):
    """``phantom:NAME`` or ``phantom:NAME?size=64&noise=0`` -> the built-in phantom with those parameters."""
    from urllib.parse import parse_qsl

    from volumen.data import phantom

    name, _, query = ref.split(":", 1)[1].partition("?")
    params = {}
    for key, val in parse_qsl(query, strict_parsing=bool(query)):
        try:
            params[key] = int(val)
        except ValueError:
            try:
                params[key] = float(val)
            except ValueError:
                params[key] = val
    try:
        if name == "organs":  # the abdomen with ground-truth labels (its labels: --labels phantom:organs)
            from volumen.data import organ_phantom

            return organ_phantom(**params)[0]
        return phantom(name, **params)
    except TypeError as exc:
        raise ValueError(str(exc)) from None


#: what ``--shift`` does, in the commands that take it
SHIFT_HELP = ("move the transfer function along the values by this much (data units; e.g. 1000 for a CT stored in "
              "scanner units, HU + 1000, that is not recognised as one), as the browser page's shift slider")


#: what ``--window`` takes, in every command's help
WINDOW_HELP = "grey window: LEVEL,WIDTH in the data's units, or a CT window: bone, soft-tissue, lung, brain (HU)"


def parse_window(text: str | None, volume=None):
    """``--window``: ``LEVEL,WIDTH`` or a CT window's name (:func:`volumen.core.named_window`: moved onto a CT's
    stored values, refused for another modality) -> a :class:`volumen.core.Window`; None for None."""
    if text is None:
        return None
    from volumen.core import WINDOW_PRESETS, Window, named_window
    from volumen.errors import UnknownChoiceError

    if not any(c.isdigit() for c in text):
        return named_window(text, volume)
    try:
        level, width = _floats(text, 2, "--window")
    except ValueError:
        raise UnknownChoiceError("--window", text, [*WINDOW_PRESETS, "LEVEL,WIDTH"]) from None
    return Window(level=level, width=width)


def parse_point(text: str | None):
    """``X,Y,Z`` in world RAS+ mm."""
    vals = _floats(text, 3, "point")
    return None if vals is None else tuple(vals)


def ask_password(label: str, user: str) -> str | None:
    """Prompt on the terminal (never echoed); None when there is no terminal."""
    if not sys.stdin.isatty():
        return None
    import getpass

    return getpass.getpass(f"password of {user} on {label}: ")


def progress_bar(enabled: bool = True, what: str = "retrieving"):
    """A ``progress(done, total)`` callback drawing a tqdm bar on stderr (None when disabled)."""
    if not enabled:
        return None
    from tqdm import tqdm

    bar = None

    def progress(done: int, total: int) -> None:
        nonlocal bar
        if bar is None:
            bar = tqdm(total=total, unit="file", desc=what, file=sys.stderr, leave=False)
        bar.n = done
        bar.refresh()
        if done >= total:
            bar.close()

    return progress
