"""``--device``, ``--technique`` and one flag per technique option, generated from ``volumen.render``'s vocabulary.

Each option field of a technique becomes ``--TECHNIQUE-FIELD`` (``--slicing-precision``,
``--mesh-shading``...): a ``Literal`` field takes its choices, a bool field is
``--x/--no-x``, an int field a number. Nothing is listed here by hand, so a new
option or technique appears on the command line by itself.
"""

from __future__ import annotations

import argparse

__all__ = ["add_technique_options", "technique_from_args", "settings_technique"]


def _flags():
    """(technique, field, flag, dest, kind) for every technique option."""
    from volumen.render import TECHNIQUES, option_choices

    for name in TECHNIQUES:
        for field, kind in option_choices(name).items():
            yield name, field, f"--{name}-{field.replace('_', '-')}", f"{name}_{field}", kind


def add_technique_options(p: argparse.ArgumentParser) -> None:
    """Add ``--device``, ``--technique`` and the technique option flags to ``p``."""
    from volumen.render import DEVICES, TECHNIQUES

    g = p.add_argument_group("device and technique")
    g.add_argument("--device", choices=DEVICES, help="where the picture is computed: cpu (Numba), cuda (NVIDIA GPU), "
                   "gl (OpenGL), auto (the fastest here: cuda, else gl on a hardware OpenGL renderer, else cpu; "
                   "it says which and why); default: cpu for raycast, gl for the others")
    g.add_argument("--technique", choices=list(TECHNIQUES), help="; ".join(
        f"{n} ({', '.join(t.devices)}): {t.description}" for n, t in TECHNIQUES.items()) + " (default raycast)")
    for name, field, flag, dest, kind in _flags():
        if isinstance(kind, tuple):
            g.add_argument(flag, dest=dest, choices=kind, help=f"{name} option {field}")
        elif kind is bool:
            g.add_argument(flag, dest=dest, action=argparse.BooleanOptionalAction, help=f"{name} option {field}")
        else:
            g.add_argument(flag, dest=dest, type=kind, help=f"{name} option {field} ({kind.__name__})")


def settings_technique(base: dict | None):
    """``(device, Technique)`` recorded in a settings dict (``backend`` of volumen 0.1 read too), or
    ``(None, None)`` when it names none."""
    from volumen.render import Technique, legacy_backend

    if not base:
        return None, None
    if "technique" in base:
        return base.get("device"), Technique.from_dict(base["technique"])
    if "backend" in base:
        return legacy_backend(base["backend"])
    return None, None


def technique_from_args(args: argparse.Namespace, base: dict | None = None):
    """``(device, Technique)``: the flags over the settings ``base``; device resolved (``auto`` to a name).

    An option flag of another technique than the chosen one is an error naming both.
    """
    from volumen.render import Technique, choose_device

    base_device, base_tech = settings_technique(base)
    name = args.technique or (base_tech.name if base_tech else "raycast")
    given = {}
    for tech, field, flag, dest, _ in _flags():
        value = getattr(args, dest, None)
        if value is None:
            continue
        if tech != name:
            raise ValueError(f"{flag} is an option of --technique {tech}, not {name}")
        given[field] = value
    options = base_tech.options if base_tech is not None and base_tech.name == name else None
    technique = Technique(name, options, **given)
    device = args.device or (base_device if base_tech is not None and base_tech.name == name else None)
    chosen, why = choose_device(device, name)
    if device == "auto":
        print(f"device auto: {chosen} ({why})")
    return chosen, technique
