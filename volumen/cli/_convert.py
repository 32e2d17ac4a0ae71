"""``volumen convert IN OUT``: read any supported format, write NIfTI, NRRD, MHA/MHD, NPY/NPZ or an OME-Zarr
pyramid (``scan.ome.zarr``)."""

from __future__ import annotations

from ._common import add_load_options, load_from_args

#: the arguments naming what the command writes (removed again when it fails: ``_contract.OutputFiles``)
OUTPUTS = ("output",)


def register(sub):
    p = sub.add_parser("convert", help="convert a volume to .nii/.nii.gz/.nrrd/.mha/.mhd/.npy/.npz/.ome.zarr")
    p.add_argument("input", help="volume file, DICOM folder, or phantom:NAME")
    p.add_argument("output", help="output file; the suffix picks the format")
    p.add_argument("--chunks", type=int, default=64, help="OME-Zarr: chunk edge in voxels (default 64)")
    p.add_argument("--zarr-format", type=int, choices=(2, 3), default=3,
                   help="OME-Zarr: 3 (OME-NGFF 0.5, default) or 2 (0.4)")
    add_load_options(p)
    return p


def run(args):
    import volumen

    vol = load_from_args(args)
    opts = dict(chunks=args.chunks, zarr_format=args.zarr_format) if str(args.output).rstrip("/").endswith(".zarr") \
        else {}
    volumen.save(vol, args.output, **opts)
    z, y, x = vol.shape
    print(f"wrote {args.output} ({x} x {y} x {z} voxels, {vol.dtype})")
    return 0
