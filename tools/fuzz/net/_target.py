"""The viewer server the request fuzzer attacks, in a process of its own (so a crash or its memory is seen).

``python -m tools.fuzz.net._target TOKEN`` serves a small head phantom whose name and source path hold a
patient's identity (:data:`IDENTITY`: what no log line may show), with the limits of :data:`LIMITS`; it
prints its port on stdout and logs every logger at DEBUG on stderr (the campaign searches it for the token,
the identity and tracebacks).
"""

from __future__ import annotations

import logging
import sys

__all__ = ["IDENTITY", "LIMITS", "main"]

#: the served volume's name, source folder and file: none may reach a log line or an answer
IDENTITY = ("Doe^Jane", "SECRET123_19700101", "/data/Doe^Jane_SECRET123_19700101/scan.nii.gz")
#: the limits of the server under attack (short deadlines: a campaign waits on none for long)
LIMITS = {"max_connections": 32, "header_timeout": 2.0, "body_timeout": 2.0, "keepalive_timeout": 1.0,
          "workers": 2, "queue": 8, "cached_volumes": 2, "frame_mb": 64.0}


def _volume():
    from volumen.data import phantom

    vol = phantom("head", size=24)
    return vol.with_data(vol.data, name=IDENTITY[0], meta={"source": IDENTITY[2]})


def main(argv=None) -> int:
    from volumen.core import Camera, Scene
    from volumen.web import ViewerServer
    from volumen.web._serve_limits import ServeLimits

    token = (argv or sys.argv[1:])[0]
    logging.basicConfig(level=logging.DEBUG, stream=sys.stderr, format="%(name)s %(levelname)s %(message)s")
    vol = _volume()
    scene = Scene(volume=vol)
    camera = Camera.orbit(vol)
    server = ViewerServer(vol, scene, camera, token=token, limits=ServeLimits(**LIMITS))
    print(server.port, flush=True)
    server.run()
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
