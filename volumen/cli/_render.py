"""``volumen render INPUT -o out.png``: one picture, every setting a flag, reproducible from JSON.

``--save-settings s.json`` writes everything that decided the picture (scene,
camera, size, background, reading options, device and technique); ``--settings s.json`` renders it
again bit for bit. Flags given together with ``--settings`` override it.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from ._common import SHIFT_HELP, _floats, add_load_options, finite_float, load_from_args, parse_point
from ._labels_opts import add_label_render_options, label_layer_from_args
from ._technique import add_technique_options, technique_from_args

SETTINGS_VERSION = 1


#: the arguments naming what the command writes (removed again when it fails: ``_contract.OutputFiles``)
OUTPUTS = ("out", "save_settings")


def register(sub):
    from volumen.core import ENVIRONMENTS, INTERPOLATIONS, MODES, PRESETS, SHADINGS, TONEMAPS, VIEWS

    p = sub.add_parser("render", help="render a volume to a PNG (ray casting, texture slicing or a mesh)")
    p.add_argument("input", nargs="?", help="volume file, DICOM folder, phantom:NAME or "
                   "dicomweb://SERVER/STUDY/SERIES (optional with --settings)")
    p.add_argument("-o", "--out", required=True, help="output PNG")
    p.add_argument("--settings", help="scene JSON written by --save-settings; flags given override it")
    p.add_argument("--save-settings", help="write the settings that reproduce this picture to a JSON file")
    add_label_render_options(p)
    o = p.add_argument_group("out of core (chunked OME-Zarr input)")
    o.add_argument("--memory", default="4GB", help="chunk cache bound, e.g. 4GB (default); a Zarr volume is drawn "
                   "brick by brick through it (composite, mip, minip)")
    o.add_argument("--level", type=int, default=0, help="pyramid level drawn (0: full resolution)")
    g = p.add_argument_group("look")
    g.add_argument("--preset", choices=PRESETS, help="transfer function preset")
    g.add_argument("--tf", help="transfer function JSON file (TransferFunction.to_json)")
    g.add_argument("--shift", type=finite_float, help=SHIFT_HELP)
    g.add_argument("--mode", choices=MODES, help="composite (default; a single slice or two frames "
                   "with no --tf, --preset or --labels: mip), mip, minip, average, isosurface")
    g.add_argument("--iso", type=finite_float, help="isosurface threshold in data units (default 300 HU for CT)")
    g.add_argument("--iso-color", help="isosurface colour R,G,B in 0..1")
    g.add_argument("--shading", choices=SHADINGS, help=f"{', '.join(SHADINGS)} (default headlight, none for a colour "
                   "slab: an ultrasound frame drawn as its image; the lit models use --light)")
    g.add_argument("--light", action="append", default=None, metavar="SPEC",
                   help="a light, repeatable: 'pos=X,Y,Z dir=X,Y,Z exp=E color=R,G,B intensity=I "
                        "[kind=point|spot|headlight attach=world|camera radius=R]' (mm, RAS; attach=camera: "
                        "in the camera frame); implies --shading phong unless --shading says otherwise")
    g.add_argument("--background", help="background colour R,G,B in 0..1 (default black)")
    g.add_argument("--shadow-method", choices=["fast", "direct"],
                   help="shadows: illumination volumes (fast, default) or shadow rays per sample (direct)")
    g.add_argument("--sigma-a", type=float, help="scattering: absorption, in units of the TF's extinction")
    g.add_argument("--sigma-s", type=float, help="scattering: scattering, in units of the TF's extinction")
    g.add_argument("--phase-g", type=float, help="scattering: Henyey-Greenstein anisotropy g in (-1, 1)")
    g.add_argument("--pt-samples", type=int, help="pathtrace: samples per pixel")
    g.add_argument("--pt-bounces", type=int, help="pathtrace: scattering events per path (1 = single)")
    g.add_argument("--pt-denoise", action=argparse.BooleanOptionalAction, default=None,
                   help="pathtrace: denoise with Intel Open Image Denoise (default on)")
    g.add_argument("--environment", metavar="KIND|FILE", help=f"light around the volume: {', '.join(ENVIRONMENTS)} "
                   "(default auto: the studio rig's sky and key, fill and rim lights without --light, the uniform "
                   "ambient with), or an equirectangular .hdr / .exr map")
    g.add_argument("--env-intensity", type=float, help="scales the environment (and the studio rig's lights)")
    g.add_argument("--env-rotation", type=float, help="degrees the environment turns about its up axis")
    d = p.add_argument_group("display")
    d.add_argument("--tonemap", choices=TONEMAPS, help="auto (default: aces for the lit models phong, shadows, "
                   "scattering, pathtrace; linear otherwise), linear (values as they are, linear PNG), aces (filmic "
                   "curve, sRGB PNG)")
    d.add_argument("--exposure", type=float, help="stops (EV) applied before the tone curve (default: metered on "
                   "the subject with aces, 0 with linear)")
    c = p.add_argument_group("camera")
    c.add_argument("--view", choices=VIEWS,
                   help="anatomical view (default anterior; a slab or single slice: the view facing it)")
    c.add_argument("--azimuth", type=float, help="degrees about the view's up axis")
    c.add_argument("--elevation", type=float, help="degrees above the view")
    c.add_argument("--zoom", type=float, help="> 1 moves closer")
    c.add_argument("--projection", choices=["perspective", "orthographic"])
    c.add_argument("--size", help="WIDTHxHEIGHT in pixels (default 512x512)")
    s = p.add_argument_group("sampling and clipping")
    s.add_argument("--spv", type=float, help="samples per voxel (default 1)")
    s.add_argument("--reconstruction", choices=INTERPOLATIONS,
                   help="between voxels: linear (trilinear, the default), nearest, or bspline (tricubic B-spline: "
                        "no slice terraces on thick-slice scans, about 3x slower; cpu and cuda devices)")
    s.add_argument("--nearest", action="store_true", default=None, help="same as --reconstruction nearest")
    s.add_argument("--no-jitter", action="store_true", default=None, help="no jittered ray starts")
    s.add_argument("--preintegrate", action="store_true", default=None, help="pre-integrated classification")
    s.add_argument("--adaptive", action=argparse.BooleanOptionalAction, default=None,
                   help="adaptive sampling: longer steps through nearly transparent tissue (composite; faster on "
                        "translucent presets, pictures within a mean 0.005; cpu and cuda devices). Default: on for "
                        "shading none, headlight and phong, off for the models whose light changes along the steps "
                        "(shadows, scattering, pathtrace); --no-adaptive: the exact full-rate picture")
    s.add_argument("--crop", help="crop box XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX (voxel indices; see --crop-space)")
    s.add_argument("--crop-space", choices=["voxel", "world"], help="units of --crop (default voxel)")
    s.add_argument("--clip-plane", action="append", default=None, metavar="SPEC",
                   help="'point=X,Y,Z normal=X,Y,Z' in world mm, repeatable (the side the normal points to is kept)")
    add_technique_options(p)
    add_load_options(p)
    return p


def parse_spec(text: str, keys: dict[str, int | tuple[str, ...]]) -> dict:
    """``'pos=1,2,3 exp=4 kind=spot'`` -> ``{'pos': [1, 2, 3], 'exp': [4], 'kind': 'spot'}``.

    ``keys`` maps each key to the count of numbers it takes, or to the tuple of words it accepts.
    """
    out: dict = {}
    for part in text.replace(";", " ").split():
        if "=" not in part:
            raise ValueError(f"expected KEY=VALUE in {text!r}, got {part!r}")
        key, val = part.split("=", 1)
        if key not in keys:
            raise ValueError(f"unknown key {key!r} in {text!r}; valid: {', '.join(keys)}")
        if isinstance(keys[key], tuple):
            if val not in keys[key]:
                raise ValueError(f"{key}= must be one of {', '.join(keys[key])}; got {val!r}")
            out[key] = val
        else:
            out[key] = _floats(val, keys[key], key)
    return out


def parse_light(text: str):
    """A :class:`volumen.core.Light` from ``'pos=X,Y,Z dir=X,Y,Z exp=E color=R,G,B intensity=I
    kind=point|spot|headlight attach=world|camera radius=R'`` (mm; ``attach=camera`` gives position
    and direction in the camera's right/up/forward frame, an endoscope's flashlight)."""
    from volumen.core import Light

    d = parse_spec(text, {"pos": 3, "dir": 3, "exp": 1, "color": 3, "intensity": 1,
                          "kind": ("point", "spot", "headlight"), "attach": ("world", "camera"), "radius": 1})
    if "pos" not in d and d.get("kind") != "headlight" and d.get("attach") != "camera":
        raise ValueError(f"a light needs pos=X,Y,Z (mm): {text!r}")
    kw = {"position": d["pos"]} if "pos" in d else {}
    for key in ("kind", "attach"):
        if key in d:
            kw[key] = d[key]
    if "radius" in d:
        kw["radius"] = d["radius"][0]
    if "dir" in d:
        kw["direction"] = d["dir"]
    if "exp" in d:
        kw["exponent"] = d["exp"][0]
    if "color" in d:
        kw["color"] = d["color"]
    if "intensity" in d:
        kw["intensity"] = d["intensity"][0]
    return Light(**kw)


def _size(text):
    if text is None:
        return None
    w, h = (int(v) for v in _floats(text, 2, "--size"))
    return (w, h)


def build(args, base: dict | None, volume):
    """(scene, camera, size, background) from the flags over an optional settings dict."""
    from dataclasses import replace

    from volumen.core import (
        Camera,
        Clipping,
        ClipPlane,
        Isosurface,
        Sampling,
        Scene,
        TransferFunction,
        default_camera,
        default_iso,
        fitted_preset,
    )
    from volumen.render import default_look

    scene = Scene.from_dict(base["scene"], volume=volume) if base else Scene(volume=volume)
    scene = replace(scene, volume_ref=_volume_ref(args, base))
    if args.tf:
        try:
            scene = replace(scene, transfer=TransferFunction.from_json(Path(args.tf).read_text()))
        except (OSError, ValueError, TypeError) as exc:
            raise ValueError(f"{args.tf}: not a transfer function JSON file ({exc})") from None
    elif args.preset:
        scene = replace(scene, transfer=fitted_preset(args.preset, volume))
    if base:  # the settings' look, but for the flags named
        if args.mode:
            scene = replace(scene, mode=args.mode)
    else:
        named = bool(args.tf or args.preset or getattr(args, "labels", None))  # the labels composite
        mode, tf, shaded = default_look(volume, args.mode, transfer_named=named)
        scene = replace(scene, mode=mode, transfer=scene.transfer if args.tf or args.preset else tf,
                        shading=replace(scene.shading, mode=shaded))
    if args.shift:  # as the browser page's shift: the inner control points move along the values
        scene = replace(scene, transfer=scene.transfer.shifted(args.shift))
        if scene.mode != "composite":
            print(f"volumen render: warning: --shift moves the transfer function, which --mode {scene.mode} does "
                  "not use", file=sys.stderr)
    if args.iso is not None or args.iso_color or (not base and scene.mode == "isosurface"):
        iso = scene.isosurface
        value = args.iso if args.iso is not None else (iso.value if base else default_iso(volume))
        color = parse_point(args.iso_color) if args.iso_color else iso.color
        scene = replace(scene, isosurface=Isosurface(value=value, color=color))
    if args.light:
        lit = scene.shading.mode if scene.shading.mode not in ("none", "headlight") else "phong"
        scene = replace(scene, lights=tuple(parse_light(t) for t in args.light),
                        shading=replace(scene.shading, mode=lit))
    if args.shading:
        scene = replace(scene, shading=replace(scene.shading, mode=args.shading))
    shade = {k: getattr(args, k) for k in ("shadow_method", "sigma_a", "sigma_s", "phase_g", "pt_samples",
                                           "pt_bounces", "pt_denoise") if getattr(args, k) is not None}
    if shade:
        scene = replace(scene, shading=replace(scene.shading, **shade))
    scene = _look(args, scene)
    samp = {}
    if args.spv is not None:
        samp["samples_per_voxel"] = args.spv
    if args.nearest:
        samp["interpolation"] = "nearest"
    if args.reconstruction:
        samp["interpolation"] = args.reconstruction
    if args.no_jitter:
        samp["jitter"] = False
    if args.preintegrate:
        samp["preintegrate"] = True
    if args.adaptive is not None:
        samp["adaptive"] = args.adaptive
    if samp:
        scene = replace(scene, sampling=replace(scene.sampling, **samp) if base else Sampling(**samp))
    if args.crop or args.clip_plane or args.crop_space:
        clip = scene.clipping
        crop = _floats(args.crop, 6, "--crop") if args.crop else clip.crop
        planes = clip.planes
        if args.clip_plane:
            specs = [parse_spec(t, {"point": 3, "normal": 3}) for t in args.clip_plane]
            planes = tuple(ClipPlane(point=d["point"], normal=d["normal"]) for d in specs)
        scene = replace(scene, clipping=Clipping(crop=crop, crop_space=args.crop_space or clip.crop_space,
                                                 planes=planes))
    cam_flags = {k: getattr(args, k) for k in ("view", "azimuth", "elevation", "zoom", "projection")}
    if base and not any(v is not None for v in cam_flags.values()):
        camera = Camera.from_dict(base["camera"])
    else:
        prev = (base or {}).get("orbit", {})
        orbit = {k: (v if v is not None else prev.get(k)) for k, v in cam_flags.items()}
        orbit = {k: v for k, v in orbit.items() if v is not None}
        camera = default_camera(volume, **orbit)
        cam_flags = orbit
    size = _size(args.size) or (tuple(base["size"]) if base else (512, 512))
    background = parse_point(args.background) if args.background else tuple((base or {}).get("background", (0, 0, 0)))
    return scene, camera, size, background, {k: v for k, v in cam_flags.items() if v is not None}


def _look(args, scene):
    """The scene with the environment and display flags applied."""
    from dataclasses import replace

    from volumen.core import ENVIRONMENTS, Display, Environment

    env = scene.environment
    if args.environment:
        if args.environment in ENVIRONMENTS:
            env = Environment(kind=args.environment, intensity=env.intensity, rotation=env.rotation)
        else:
            env = Environment(kind="map", map=str(Path(args.environment).resolve()), intensity=env.intensity,
                              rotation=env.rotation)
    if args.env_intensity is not None or args.env_rotation is not None:
        env = replace(env, intensity=env.intensity if args.env_intensity is None else args.env_intensity,
                      rotation=env.rotation if args.env_rotation is None else args.env_rotation)
    if env.kind == "map" and env.image is None:
        from volumen.io import read_environment

        env = replace(env, image=read_environment(env.map))
    disp = scene.display
    if args.tonemap is not None or args.exposure is not None:
        disp = Display(tonemap=args.tonemap or disp.tonemap,
                       exposure=args.exposure if args.exposure is not None else disp.exposure)
    return replace(scene, environment=env, display=disp)


def _kind(volume) -> str:
    from volumen.core import is_color_slab, is_ct

    if is_color_slab(volume):
        return "a colour slab"
    return "CT" if is_ct(volume) else (volume.modality or "a scan of unknown modality")


def _for_technique(scene, technique, args, volume):
    """The scene as ``technique`` draws it: the mesh technique draws an isosurface, so a scene of the default
    mode becomes one (at ``--iso``, else the volume's default level) and a mode asked for otherwise is refused."""
    if technique.name != "mesh" or scene.mode == "isosurface":
        return scene
    if args.mode:
        raise ValueError(f"--technique mesh draws an isosurface, not --mode {args.mode}: use --mode isosurface")
    from dataclasses import replace

    from volumen.core import Isosurface, default_iso

    value = args.iso if args.iso is not None else default_iso(volume)
    return replace(scene, mode="isosurface", isosurface=Isosurface(value=value, color=scene.isosurface.color))


def _progressive(scene, device, technique) -> bool:
    """Whether the picture is path traced progressively (pathtrace shading, composite, ray casting on cpu / cuda)."""
    return (scene.shading.mode == "pathtrace" and scene.mode == "composite" and technique.name == "raycast"
            and device in ("cpu", "cuda"))


#: samples per pixel of the first picture written while path tracing
FIRST_SAMPLES = 4


def _path_trace(scene, camera, size, device, out, background):
    """Path trace with a progress bar, writing the (denoised) picture after :data:`FIRST_SAMPLES` samples and
    again when all ``pathtrace.samples`` are taken; returns the last Image."""
    from tqdm import tqdm

    if device == "cuda":
        from volumen.render.cuda import CudaPathTracer as Tracer
    else:
        from volumen.render import PathTracer as Tracer

    total = scene.shading.pathtrace.samples
    pt = Tracer(scene, camera, size)
    steps = [min(FIRST_SAMPLES, total)]
    while sum(steps) < total:
        steps.append(min(max(sum(steps), 1), total - sum(steps)))
    with tqdm(total=total, unit="spp", desc="path tracing", leave=False, disable=None) as bar:
        for i, n in enumerate(steps):
            pt.add(n)
            bar.update(n)
            if i == 0 and len(steps) > 1:
                _write(pt.image(), out, background)  # a first picture to look at
    return pt.image()


def _write(image, out, background) -> None:
    """Save ``image`` as a PNG, atomically: nothing half-written is ever at ``out``."""
    out = Path(out)
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp.png")
    try:
        image.save(tmp, background=background)
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)


def _volume_ref(args, base) -> str:
    if args.input:
        s = str(args.input)
        return s if s.startswith("phantom:") else str(Path(s).resolve())
    return (base or {}).get("scene", {}).get("volume", "")


def run(args):
    import volumen
    from volumen.core import is_chunked
    from volumen.render import render

    base = None
    if args.settings:
        try:
            base = json.loads(Path(args.settings).read_text())
        except (OSError, json.JSONDecodeError) as exc:
            raise ValueError(f"cannot read settings {args.settings}: {exc}") from None
        if base.get("version") != SETTINGS_VERSION or not {"scene", "camera", "size"} <= set(base):
            raise ValueError(f"{args.settings} is not a volumen render settings file (version {SETTINGS_VERSION})")
        for key, val in base.get("load", {}).items():  # reading options recorded with the picture
            if getattr(args, key, None) is None:
                setattr(args, key, val)
    if not args.input and not base:
        raise ValueError("give an INPUT volume or --settings")
    source = args.input or base["scene"]["volume"]
    volume = load_from_args(args, path=source)
    scene, camera, size, background, orbit = build(args, base, volume)
    layer = label_layer_from_args(args, volume)
    if layer is not None:
        scene = scene.with_(labels=layer)
    t0 = time.perf_counter()
    lit_by_ambient_only = not scene.lights and scene.environment.kind == "uniform"  # auto: the studio rig lights it
    if scene.shading.mode in ("phong", "shadows", "scattering", "pathtrace") and lit_by_ambient_only:
        print(f"warning: shading {scene.shading.mode!r} without --light: only the ambient term lights the picture "
              "(add --light 'pos=X,Y,Z dir=...', use --environment studio or --shading headlight)", file=sys.stderr)
    device, technique = technique_from_args(args, base)
    scene = _for_technique(scene, technique, args, volume)
    out_dir = Path(args.out).resolve().parent
    if not out_dir.is_dir():
        raise ValueError(f"{args.out}: folder {out_dir} does not exist")
    if is_chunked(volume.data):  # out of core, at the pyramid level asked for
        if args.level:
            scene = scene.with_(volume=volumen.load(volume.meta["source"], format="zarr", level=args.level))
        image = render(scene, camera, size, device="auto" if args.device == "auto" else device, technique=technique,
                       memory=args.memory)
    elif _progressive(scene, device, technique):
        image = _path_trace(scene, camera, size, device, args.out, background)
    else:
        image = render(scene, camera, size, device=device, technique=technique)
    dt = time.perf_counter() - t0
    _write(image, args.out, background)
    chosen = "" if (args.preset or args.tf or base) else f" (chosen for {_kind(volume)})"
    moved = f" shifted by {args.shift:g}" if args.shift else ""
    look = f", preset {scene.transfer.name}{moved}{chosen}" if scene.transfer.name and scene.mode == "composite" else ""
    spp = f", {image.stats['spp']} samples/pixel{' denoised' if image.stats.get('denoised') else ''}" \
        if "spp" in image.stats else ""
    why = "" if args.mode or base or scene.mode == "composite" else \
        f" at {scene.isosurface.value:g} (the mesh technique's)" if technique.name == "mesh" else " (chosen for a slab)"
    flat = " (chosen for a colour slab)" if not (args.shading or args.light or base) and scene.shading.mode == "none" \
        else ""
    print(f"wrote {args.out} ({size[0]}x{size[1]}, {scene.mode}{why}, shading {scene.shading.mode}{flat}{look}{spp}, "
          f"display {image.display.tonemap if image.display else 'linear'}) in {dt * 1000:.0f} ms")
    if args.save_settings:
        load_opts = {k: getattr(args, k) for k in ("series", "resample", "nonfinite", "shape", "dtype", "spacing",
                                                   "byte_order") if getattr(args, k, None) is not None}
        settings = {"version": SETTINGS_VERSION, "scene": scene.to_dict(), "camera": camera.to_dict(),
                    "size": list(size), "background": list(background), "orbit": orbit, "load": load_opts,
                    "device": device, "technique": technique.to_dict()}
        Path(args.save_settings).write_text(json.dumps(settings, indent=2))
        print(f"wrote {args.save_settings}")
    return 0
