"""``volumen mesh INPUT --iso 300 | --mask MASK -o out.stl``: a surface mesh file (STL, OBJ, PLY)."""

from __future__ import annotations

from pathlib import Path

from ._common import add_load_options, load_from_args
from ._labels_opts import add_label_options, labels_from_args, shown_values

#: the arguments naming what the command writes (removed again when it fails: ``_contract.OutputFiles``)
OUTPUTS = ("out",)


def register(sub):
    p = sub.add_parser("mesh", help="extract a surface mesh (marching cubes) and write STL, OBJ or PLY "
                                       "(--labels: a coloured scene, .glb)")
    p.add_argument("input", help="volume file, DICOM folder, or phantom:NAME")
    p.add_argument("-o", "--out", required=True, help="output mesh file: .stl, .obj or .ply (world RAS+ mm)")
    what = p.add_argument_group("surface (neither: the level the 3-D views start with; or --labels)")
    what.add_argument("--iso", type=float, help="iso level in the data's units (HU for CT), e.g. 300 for bone "
                      "(default: bone for a CT, else the middle of the display range; a 0/1 mask: its boundary)")
    what.add_argument("--mask", help="mask volume on the same grid: its boundary is meshed "
                                     "(with --iso: only the isosurface inside the mask)")
    p.add_argument("--smooth", type=int, default=10, help="Taubin smoothing iterations (default 10; 0: none)")
    p.add_argument("--target-triangles", type=int, help="decimate to about this many triangles")
    p.add_argument("--largest", action="store_true", help="keep only the largest connected piece")
    p.add_argument("--step", type=int, default=1, help="marching-cubes step in voxels (default 1)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--check", action="store_true", help="print whether the mesh is closed: open and "
                   "non-manifold edges, pieces and genus (equal positions welded, as an STL reader does)")
    add_load_options(p)
    add_label_options(p)
    return p


def _label_scene(args, volume, out: Path) -> int:
    """``--labels``: one coloured, smoothed (and decimated) mesh per structure in one scene file."""
    from volumen.surface import label_meshes, write_label_scene

    labels = labels_from_args(args, volume)
    meshes = label_meshes(labels, shown_values(args, labels), smooth_iterations=args.smooth,
                          target_triangles=args.target_triangles)
    path = write_label_scene(meshes, labels, out)
    print(f"{path}: {len(meshes)} structures")
    for v, m in meshes.items():
        print(f"  {labels.names[v]:<24} {m.n_faces:>8} triangles  area {m.area():.1f} mm^2")
    return 0


def _default_level(volume) -> tuple[float | None, str]:
    """With neither ``--iso`` nor ``--mask``: ``(level, what the output line says of it)``. A 0/1 mask's boundary
    (None: ``extract_mesh`` meshes it), else the level the 3-D views start with (``core.default_iso``: bone in a
    CT, the middle of the display range otherwise)."""
    from volumen.core import default_iso, hu_offset
    from volumen.surface import is_mask

    if is_mask(volume):
        return None, ", chosen: the mask's boundary"
    return default_iso(volume), (", chosen for a CT: bone" if hu_offset(volume) is not None
                                 else ", chosen: the middle of the display range")


def run(args):
    from tqdm import tqdm

    from volumen.core import value_text, values_of
    from volumen.surface import MESH_FORMATS, extract_mesh, write_mesh

    if args.labels:
        if args.check:
            raise ValueError("--check checks one surface (--iso or --mask), not a --labels scene")
        return _label_scene(args, load_from_args(args), Path(args.out))
    if args.step < 1:
        raise ValueError(f"--step must be >= 1, got {args.step}")
    out = Path(args.out)
    if out.suffix.lower() not in MESH_FORMATS:  # before any work
        raise ValueError(f"{out}: the suffix picks the mesh format; use one of {', '.join(MESH_FORMATS)}")
    if not out.resolve().parent.is_dir():
        raise ValueError(f"{out}: folder {out.resolve().parent} does not exist")
    volume = load_from_args(args)
    mask = load_from_args(args, path=args.mask) if args.mask else None
    if mask is not None and mask.shape != volume.shape:
        raise ValueError(f"--mask {args.mask} has shape {mask.shape}, the volume {volume.shape}: "
                         "they must share a grid")
    iso, chosen = (args.iso, "") if args.iso is not None or mask is not None else _default_level(volume)
    with tqdm(total=100, desc="mesh", unit="%", disable=args.quiet, leave=False) as bar:
        def progress(fraction: float) -> None:
            bar.update(max(0, int(round(100 * fraction)) - bar.n))

        mesh = extract_mesh(volume, iso=iso, mask=mask, smooth_iterations=args.smooth,
                            target_triangles=args.target_triangles, largest_only=args.largest, step=args.step,
                            progress=progress)
    path = write_mesh(mesh, out)
    print(f"{path}: {mesh.n_vertices} vertices, {mesh.n_faces} triangles, "
          f"area {mesh.area():.1f} mm^2 (level {value_text(mesh.meta.get('level', iso), **values_of(volume))}{chosen})")
    if args.check:
        from volumen.surface import check_mesh

        print(check_mesh(mesh).line())
    return 0
