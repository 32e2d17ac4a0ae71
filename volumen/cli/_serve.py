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

from ._common import add_load_options, load_from_args

DEFAULT_PORT = 8765


def register(sub):
    from volumen.core import MODES, PRESETS, SHADINGS

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
    p.add_argument("--settings", help="scene and camera to open with (a `volumen render --save-settings` file)")
    p.add_argument("--preset", choices=PRESETS, help="transfer function preset to open with")
    p.add_argument("--mode", choices=MODES, help="mode to open with (default composite)")
    p.add_argument("--shading", choices=[s for s in SHADINGS if s != "pathtrace"],
                   help="shading to open with (default headlight)")
    add_load_options(p)
    return p


def _scene_and_camera(args, volume):
    from volumen.core import Camera, Scene, Shading, TransferFunction
    from volumen.render import default_transfer

    if args.settings:
        try:
            base = json.loads(Path(args.settings).read_text())
            scene = Scene.from_dict(base["scene"], volume=volume)
            camera = Camera.from_dict(base["camera"])
        except (OSError, KeyError, json.JSONDecodeError) as exc:
            raise ValueError(f"cannot read settings {args.settings}: {exc}") from None
    else:
        scene, camera = Scene(volume=volume, transfer=default_transfer(volume, "composite")), Camera.orbit(volume)
    if args.preset:
        scene = scene.with_(transfer=TransferFunction.preset(args.preset, value_range=volume.value_range()))
    if args.mode:
        scene = scene.with_(mode=args.mode)
    if args.shading:
        scene = scene.with_(shading=Shading(mode=args.shading))
    return scene.with_(volume_ref=""), camera


def _ssl(args):
    if not (args.certfile or args.keyfile):
        return None
    if not (args.certfile and args.keyfile):
        raise ValueError("https needs both --certfile and --keyfile")
    import ssl

    ctx = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH)
    ctx.load_cert_chain(args.certfile, args.keyfile)
    return ctx


def run(args):
    from volumen.web import ViewerServer, is_loopback

    volume = load_from_args(args, args.path)
    scene, camera = _scene_and_camera(args, volume)
    try:
        server = ViewerServer(volume, scene, camera, host=args.host, port=args.port, budget_mb=args.budget,
                              ssl_context=_ssl(args))
    except OSError as exc:
        raise ValueError(f"cannot listen on {args.host} port {args.port}: {exc.strerror or exc} "
                         "(pick another with --port, or 0 for a free one)") from None
    print(server.url, flush=True)
    if not is_loopback(args.host):
        print(f"volumen serve: warning: listening on {args.host}: the scan is reachable from the network by "
              "anyone with the URL", file=sys.stderr, flush=True)
    logging.basicConfig(level=logging.INFO, format="volumen serve: %(message)s", stream=sys.stderr)
    if not args.no_browser:
        import webbrowser

        webbrowser.open(server.url)
    server.run()
    return 0
