"""``volumen serve [PATH]``: the browser viewer (WebGL2 ray casting, WebXR) of one scan, served to this machine.

The first line on stdout is the URL to open, with its access token (printed once, nowhere else). The server
binds 127.0.0.1 unless ``--host`` says otherwise; a host other than a loopback address is warned about in one
line (the scan is then reachable from the network). WebXR needs a secure origin: ``https`` (``--certfile`` and
``--keyfile``) on any host but ``localhost``. Ctrl-C stops it.
"""

from __future__ import annotations

import json
import logging
import sys
from pathlib import Path

from ._common import _floats, add_load_options, load_from_args

DEFAULT_PORT = 8765


def register(sub):
    from volumen.core import MODES, PRESETS, SHADINGS, TONEMAPS, VIEWS

    p = sub.add_parser("serve", help="open a scan in the browser viewer (WebGL2 ray casting, VR headsets)")
    p.add_argument("path", nargs="?", default="phantom:head",
                   help="volume file, DICOM folder or phantom:NAME (default: the head phantom)")
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1, this machine "
                   "only; 0.0.0.0: every network this machine is on, for a headset on the same network)")
    p.add_argument("--port", type=int, default=DEFAULT_PORT, help=f"port (default {DEFAULT_PORT}; 0: a free one)")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser on this machine")
    p.add_argument("--budget", type=float, default=256.0, metavar="MB",
                   help="memory budget of the volume texture on the client in MiB (2 bytes a voxel; default 256): "
                        "a larger scan is resampled to fit, and the page says so")
    p.add_argument("--certfile", help="serve https with this PEM certificate (WebXR on another device needs it)")
    p.add_argument("--keyfile", help="the certificate's private key (PEM)")
    p.add_argument("--screenshot", metavar="PNG", help="open the page in headless Chromium, save it to PNG and exit")
    p.add_argument("--vr", action="store_true", help="with --screenshot: the two eyes of an emulated headset "
                   "(iwer, `make web-deps`)")
    p.add_argument("--size", default="1280x800", metavar="WxH", help="with --screenshot: the browser window's "
                   "size in CSS pixels (default 1280x800)")
    p.add_argument("--measurements", metavar="FILE", help="measurements the page opens with: a DICOM SR, a session "
                   "or a measurements JSON of this scan (`volumen measure export`)")
    p.add_argument("--report", metavar="FOLDER", help="a vessel profile the page plots under its slices: the "
                   "report folder of `volumen measure vessel` or `volumen fly --report` of this scan")
    p.add_argument("--profile", metavar="JSON", help="the same from its report.json")
    p.add_argument("--settings", help="scene and camera to open with (a `volumen render --save-settings` file)")
    p.add_argument("--preset", choices=PRESETS, help="transfer function preset to open with")
    p.add_argument("--shift", type=float, default=0.0, help="move the preset along the values by this much (data "
                   "units; e.g. 1000 for a CT stored in scanner units, HU + 1000); the page's shift slider starts "
                   "there")
    p.add_argument("--mode", choices=MODES, help="mode to open with (default composite)")
    p.add_argument("--shading", choices=[s for s in SHADINGS if s != "pathtrace"],
                   help="shading to open with (default headlight)")
    p.add_argument("--tonemap", choices=TONEMAPS, help="display transform: auto (default: aces for phong, shadows "
                   "and scattering, linear otherwise), linear, aces")
    p.add_argument("--exposure", type=float, help="stops (EV) before the tone curve (default: metered on each "
                   "picture with aces, 0 with linear)")
    p.add_argument("--view", choices=VIEWS, help="anatomical view to open with (default anterior; a slab or single "
                   "slice: the view facing it)")
    p.add_argument("--azimuth", type=float, default=0.0, help="degrees about the view's up axis")
    p.add_argument("--elevation", type=float, default=0.0, help="degrees above the view")
    p.add_argument("--zoom", type=float, default=1.0, help="> 1 moves closer")
    add_load_options(p)
    return p


def _scene_and_camera(args, volume):
    from volumen.core import Camera, Display, Isosurface, Scene, Shading, default_camera, default_iso, fitted_preset
    from volumen.render import default_look

    if args.settings:
        try:
            base = json.loads(Path(args.settings).read_text())
            scene = Scene.from_dict(base["scene"], volume=volume)
            camera = Camera.from_dict(base["camera"])
        except (OSError, KeyError, json.JSONDecodeError) as exc:
            raise ValueError(f"cannot read settings {args.settings}: {exc}") from None
    else:
        mode, tf, _ = default_look(volume, transfer_named=bool(args.preset))  # the page refuses colour volumes
        scene = Scene(volume=volume, transfer=tf, mode=mode, isosurface=Isosurface(value=default_iso(volume)))
        camera = default_camera(volume, view=args.view, azimuth=args.azimuth, elevation=args.elevation, zoom=args.zoom)
    if args.preset:
        scene = scene.with_(transfer=fitted_preset(args.preset, volume))
    if args.shift:
        scene = scene.with_(transfer=scene.transfer.shifted(args.shift))
    if args.mode:
        scene = scene.with_(mode=args.mode)
    if args.shading:
        scene = scene.with_(shading=Shading(mode=args.shading))
    if args.tonemap is not None or args.exposure is not None:
        ev = scene.display.exposure if args.exposure is None else args.exposure
        scene = scene.with_(display=Display(tonemap=args.tonemap or scene.display.tonemap, exposure=ev))
    if scene.shading.mode in ("phong", "shadows", "scattering") and not scene.lights:
        scene = scene.with_(lights=(_key_light(volume, camera),))
    return scene.with_(volume_ref=""), camera


def _key_light(volume, camera):
    """A white point light in front of the volume, above and to the right of the camera's view: the lit models
    need one, and the page adds, moves and deletes others."""
    import numpy as np

    from volumen.core import Light

    r, u, f = camera.basis()
    return Light(position=tuple(np.asarray(volume.center) + volume.diagonal * (0.6 * r + 0.7 * u - 0.5 * f)),
                 kind="point")


def _ssl(args):
    if not (args.certfile or args.keyfile):
        return None
    if not (args.certfile and args.keyfile):
        raise ValueError("https needs both --certfile and --keyfile")
    import ssl

    ctx = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH)
    ctx.load_cert_chain(args.certfile, args.keyfile)
    return ctx


def _screenshot(server, args) -> int:
    from volumen.web._screenshot import screenshot

    w, h = (int(v) for v in _floats(args.size, 2, "--size"))
    server.start()
    try:
        out = screenshot(server, args.screenshot, (w, h), vr=args.vr)
    finally:
        server.stop()
    print(f"wrote {out}")
    return 0


def run(args):
    from volumen.web import ViewerServer, certificate_names, is_loopback

    volume = load_from_args(args, args.path)
    scene, camera = _scene_and_camera(args, volume)
    shown = []
    if args.measurements:
        from volumen.measure import load_measurements

        shown = load_measurements(args.measurements, volume=volume).to_dicts()
    if args.report and args.profile:
        raise ValueError("give --report or --profile, not both")
    plotted = None
    if args.report or args.profile:
        from volumen.web._profile_route import read_profile

        plotted = read_profile(args.report or args.profile, volume)
    try:
        server = ViewerServer(volume, scene, camera, host=args.host, port=args.port, budget_mb=args.budget,
                              ssl_context=_ssl(args), shift=args.shift,
                              names=certificate_names(args.certfile) if args.certfile else ())
    except OSError as exc:
        raise ValueError(f"cannot listen on {args.host} port {args.port}: {exc.strerror or exc} "
                         "(pick another with --port, or 0 for a free one)") from None
    server.handlers.opening = shown
    server.handlers.profile = plotted
    print(server.url, flush=True)
    if not is_loopback(args.host):
        print(f"volumen serve: warning: listening on {args.host}: the scan is reachable from the network by "
              "anyone with the URL", file=sys.stderr, flush=True)
    if args.screenshot:
        return _screenshot(server, args)
    logging.basicConfig(level=logging.INFO, format="volumen serve: %(message)s", stream=sys.stderr)
    if not args.no_browser:
        import webbrowser

        webbrowser.open(server.url)
    server.run()
    return 0
