"""``volumen convert IN OUT``: read any supported format, write NIfTI, NRRD, MHA/MHD or NPY/NPZ."""

from __future__ import annotations

from ._common import add_load_options, load_from_args


def register(sub):
    p = sub.add_parser("convert", help="convert a volume to .nii/.nii.gz/.nrrd/.mha/.mhd/.npy/.npz")
    p.add_argument("input", help="volume file, DICOM folder, or phantom:NAME")
    p.add_argument("output", help="output file; the suffix picks the format")
    add_load_options(p)
    return p


def run(args):
    import volumen

    vol = load_from_args(args)
    volumen.save(vol, args.output)
    z, y, x = vol.shape
    print(f"wrote {args.output} ({x} x {y} x {z} voxels, {vol.dtype})")
    for w in vol.meta.get("warnings", []):
        print(f"warning: {w}")
    return 0
