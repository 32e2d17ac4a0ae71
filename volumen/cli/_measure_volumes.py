"""``volumen measure volumes LABELS``: the volume of every structure of a segmentation, in ml, as a table (or CSV /
JSON with ``-o``): its voxel count times one voxel's volume (``volumen.measure.label_volumes``)."""

from __future__ import annotations

__all__ = ["register", "run", "OUTPUTS"]

OUTPUTS = ("out",)


def register(acts):
    p = acts.add_parser("volumes", help="the volume (ml) of every structure of a segmentation")
    p.add_argument("labels", help="a label map, a .seg.nrrd, a DICOM SEG or a folder of masks (volumen.load_labels)")
    p.add_argument("--scan", help="the scan the labels belong to (they are put on its grid first)")
    p.add_argument("-o", "--out", help="also write the table: .csv or .json")
    return p


def run(args):
    import volumen
    from volumen.measure import label_volumes, save_measurements

    scan = volumen.load(args.scan) if args.scan else None
    found = label_volumes(volumen.load_labels(args.labels, like=scan), scan=scan)
    if not found:
        raise ValueError(f"{args.labels}: holds no structure (every voxel is 0)")
    width = max(len(m.label or str(m.value)) for m in found)
    for m in found:
        print(f"{(m.label or str(m.value)).ljust(width)}  {m.ml:10.2f} ml  {m.voxels:9d} voxels")
    if args.out:
        if not str(args.out).lower().endswith((".csv", ".json")):
            raise ValueError(f"-o {args.out}: the suffix says the format: .csv or .json")
        save_measurements(found, args.out)
    return 0
