"""The ``--labels`` options shared by ``info``, ``slices``, ``mesh`` and ``render``: a segmentation on the scan's grid.

``--labels PATH`` reads anything :func:`volumen.load_labels` reads (``phantom:organs`` gives the
organ phantom's exact labels); ``--names TABLE`` names a plain label map's values; ``--show a,b``
keeps only those structures.
"""

from __future__ import annotations

from urllib.parse import parse_qsl

__all__ = ["add_label_options", "labels_from_args", "shown_values", "add_label_render_options",
           "label_layer_from_args"]


def add_label_options(p, required: bool = False) -> None:
    g = p.add_argument_group("labels (segmentations)")
    g.add_argument("--labels", required=required,
                   help="segmentation: label map (NIfTI/NRRD), .seg.nrrd, DICOM SEG, folder of masks, "
                        "or phantom:organs")
    g.add_argument("--names", help="names table of a plain label map (JSON, CSV, ITK-SNAP, Slicer colour table)")
    g.add_argument("--show", help="comma-separated structure names (or values) to keep; default all")


def labels_from_args(args, volume):
    """The ``--labels`` segmentation on ``volume``'s grid, or None when not given."""
    if not getattr(args, "labels", None):
        return None
    ref = str(args.labels)
    if ref.startswith("phantom:organs"):
        from volumen.data import organ_phantom
        from volumen.io import labels_on_grid

        params = {k: int(v) for k, v in parse_qsl(ref.partition("?")[2])}
        return labels_on_grid(organ_phantom(**params)[1], volume)
    from volumen.io import load_labels

    return load_labels(ref, names=args.names, like=volume)


def shown_values(args, labels) -> list[int]:
    """Label values named by ``--show`` (all when not given); KeyError naming the valid structures."""
    if not getattr(args, "show", None):
        return labels.values
    try:
        return [labels.value_of(n.strip()) for n in args.show.split(",") if n.strip()]
    except KeyError as e:
        raise ValueError(f"--show: {e.args[0]}") from None


def add_label_render_options(p) -> None:
    """``--labels`` plus how the ray caster draws the structures."""
    add_label_options(p)
    g = p.add_argument_group("labels in the picture")
    g.add_argument("--label-opacity", type=float, default=1.0,
                   help="opacity per voxel step of the shown structures, 0..1 (default 1)")
    g.add_argument("--label-style", choices=["solid", "textured"], default="solid",
                   help="solid colours, or the scan's transfer function tinted by each structure (default solid)")
    g.add_argument("--label-scan", choices=["preset", "hidden"], default="preset",
                   help="unlabelled voxels: the scan's transfer function, or hidden (default preset)")


def label_layer_from_args(args, volume):
    """The scene's :class:`~volumen.core.LabelLayer` from the flags, or None without ``--labels``."""
    from volumen.core import LabelLayer

    labels = labels_from_args(args, volume)
    if labels is None:
        return None
    if not 0.0 <= args.label_opacity <= 1.0:
        raise ValueError(f"--label-opacity must lie in 0..1, got {args.label_opacity}")
    return LabelLayer(labels, show=tuple(shown_values(args, labels)), opacity=args.label_opacity,
                      textured=args.label_style == "textured", scan=args.label_scan)
