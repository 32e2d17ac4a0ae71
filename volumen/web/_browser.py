"""Headless Chromium driven over the DevTools protocol: the viewer's page in a real browser, read back.

Debian's ``chromium`` runs WebGL2 headless on SwiftShader (Google's software Vulkan, through ANGLE), with no
GPU. :class:`Chromium` starts it with a fresh profile on a free DevTools port (read from the profile's
``DevToolsActivePort``), opens one page and talks to it over a websocket (aiohttp's client): evaluate
script (awaiting promises, values returned as JSON), add script to every new document (the WebXR emulator),
set the window's size, send mouse events. It stops the browser and deletes the profile on :meth:`close`.
Used by the browser tests and ``volumen bench web``; nothing here reaches past this machine.
"""

from __future__ import annotations

import asyncio
import itertools
import json
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from volumen.errors import VolumenError

__all__ = ["Chromium", "BrowserUnavailable", "find_chromium", "FLAGS", "MIN_WINDOW"]

#: the smallest window started (CSS px): a window much smaller gets its frames throttled to about one a second
MIN_WINDOW = (800, 600)

#: a browser without network, GPU, sandbox (containers) or first-run chores; WebGL2 on SwiftShader
FLAGS = ("--headless=new", "--no-sandbox", "--enable-unsafe-swiftshader", "--use-angle=swiftshader",
         "--ignore-gpu-blocklist", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", "--no-first-run", "--no-default-browser-check", "--disable-extensions",
         "--mute-audio", "--hide-scrollbars", "--force-device-scale-factor=1", "--no-proxy-server",
         "--disable-renderer-backgrounding", "--disable-background-timer-throttling",
         "--disable-backgrounding-occluded-windows", "--remote-debugging-port=0")


class BrowserUnavailable(VolumenError, RuntimeError):
    """No Chromium here, or it did not start; the message says which."""


def find_chromium() -> str:
    """Path of Debian's ``chromium`` (or ``chromium-browser``); raises :class:`BrowserUnavailable`."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        raise BrowserUnavailable("Chromium is not installed (Debian package 'chromium'; `make test` installs it "
                                 "as root)")
    return exe


class ScriptError(RuntimeError):
    """A script evaluated in the page threw; the message is the page's."""


class Chromium:
    """One headless Chromium with one page.

    Parameters
    ----------
    size : (width, height)
        The page's viewport in CSS pixels (device scale 1). The window itself is at least
        :data:`MIN_WINDOW`: headless Chromium draws a smaller window's frames about once a second.
    start_timeout : float, s
    """

    def __init__(self, size=(800, 600), start_timeout: float = 60.0):
        self.exe = find_chromium()
        self.profile = Path(tempfile.mkdtemp(prefix="volumen-chromium-"))
        self.log = self.profile / "chromium.log"
        self.console: list[str] = []
        w, h = max(size[0], MIN_WINDOW[0]), max(size[1], MIN_WINDOW[1])
        with open(self.log, "wb") as log:
            self.proc = subprocess.Popen([self.exe, *FLAGS, f"--window-size={w},{h}",
                                          f"--user-data-dir={self.profile / 'profile'}", "about:blank"],
                                         stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
        self._ids = itertools.count(1)
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, name="volumen-cdp", daemon=True)
        self._thread.start()
        try:
            port = self._port(start_timeout)
            self._run(self._connect(port), start_timeout)
            self.set_size(*size)
        except BaseException:
            self.close()
            raise

    def _port(self, timeout: float) -> int:
        marker = self.profile / "profile" / "DevToolsActivePort"
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                raise BrowserUnavailable(f"Chromium exited ({self.proc.returncode}) at start: "
                                         f"{self.log.read_text(errors='replace')[-500:]}")
            if marker.exists():
                text = marker.read_text().split()
                if text:
                    return int(text[0])
            time.sleep(0.05)
        raise BrowserUnavailable(f"Chromium did not open its DevTools port within {timeout:.0f} s")

    def _run(self, coro, timeout: float | None):
        return asyncio.run_coroutine_threadsafe(coro, self._loop).result(timeout)

    async def _connect(self, port: int) -> None:
        import aiohttp

        self._session = aiohttp.ClientSession()
        async with self._session.get(f"http://127.0.0.1:{port}/json/list") as r:
            targets = await r.json()
        page = next(t for t in targets if t["type"] == "page")
        self._ws = await self._session.ws_connect(page["webSocketDebuggerUrl"], max_msg_size=0)
        self._waiting: dict[int, asyncio.Future] = {}
        self._reader = asyncio.create_task(self._read())
        for domain in ("Page", "Runtime"):
            await self._send(f"{domain}.enable")

    async def _read(self) -> None:
        async for msg in self._ws:
            data = json.loads(msg.data)
            fut = self._waiting.pop(data.get("id"), None)
            if fut is not None and not fut.done():
                fut.set_result(data)
            elif data.get("method") == "Runtime.consoleAPICalled":
                args = data["params"].get("args", [])
                self.console.append(" ".join(str(a.get("value", a.get("description", ""))) for a in args))
            elif data.get("method") == "Runtime.exceptionThrown":
                d = data["params"]["exceptionDetails"]
                self.console.append(f"exception: {d.get('exception', {}).get('description', d.get('text'))}")
        for fut in self._waiting.values():
            if not fut.done():
                fut.set_exception(BrowserUnavailable("Chromium closed the DevTools connection"))

    async def _send(self, method: str, **params) -> dict:
        i = next(self._ids)
        fut = asyncio.get_running_loop().create_future()
        self._waiting[i] = fut
        await self._ws.send_json({"id": i, "method": method, "params": params})
        reply = await fut
        if "error" in reply:
            raise ScriptError(f"{method}: {reply['error'].get('message')}")
        return reply.get("result", {})

    def call(self, method: str, timeout: float = 60.0, **params) -> dict:
        """Send one DevTools command and return its result."""
        return self._run(self._send(method, **params), timeout)

    def evaluate(self, expression: str, timeout: float = 120.0):
        """The JSON value of ``expression`` in the page (a promise is awaited); :class:`ScriptError` when it
        throws."""
        r = self.call("Runtime.evaluate", timeout=timeout, expression=expression, awaitPromise=True,
                      returnByValue=True)
        if "exceptionDetails" in r:
            d = r["exceptionDetails"]
            raise ScriptError(d.get("exception", {}).get("description") or d.get("text", "script error"))
        return r["result"].get("value")

    def version(self) -> str:
        """The browser's product and version (``Chrome/150.0...``; the page's user agent may be an emulator's)."""
        return self.call("Browser.getVersion").get("product", "Chromium")

    def add_script(self, source: str) -> None:
        """Run ``source`` in every document opened from now on, before the page's own scripts."""
        self.call("Page.addScriptToEvaluateOnNewDocument", source=source)

    def set_size(self, width: int, height: int) -> None:
        """The page's viewport in CSS pixels (device scale 1)."""
        self.call("Emulation.setDeviceMetricsOverride", width=int(width), height=int(height), deviceScaleFactor=1,
                  mobile=False)

    def open(self, url: str, ready: str = "document.body && document.body.dataset.ready", timeout: float = 120.0):
        """Navigate to ``url`` and wait until ``ready`` evaluates to ``"yes"`` (raises on ``"error"``)."""
        self.call("Page.navigate", url=url)
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            state = self.evaluate(ready) if self.proc.poll() is None else "closed"
            if state == "yes":
                return
            if state in ("error", "closed"):
                raise ScriptError(f"the page failed to start ({state}): {self.console[-5:]}")
            time.sleep(0.1)
        raise TimeoutError(f"the page was not ready within {timeout:.0f} s: {self.console[-5:]}")

    def mouse(self, kind: str, x: float, y: float, button: str = "left", modifiers: int = 0) -> None:
        """One mouse event (``kind``: pressed, moved, released) at CSS pixel (x, y) of the page."""
        self.call("Input.dispatchMouseEvent", type=f"mouse{kind.capitalize()}", x=x, y=y, button=button,
                  buttons=0 if kind == "released" else {"left": 1, "right": 2, "middle": 4}[button],
                  clickCount=1, modifiers=modifiers)

    def close(self) -> None:
        """Stop the browser and delete its profile."""
        try:
            if getattr(self, "_ws", None) is not None:
                self._run(self._ws.close(), 10)
                self._run(self._session.close(), 10)
        except Exception:  # noqa: BLE001 - closing a connection to a browser that may already be gone
            pass
        finally:
            self._loop.call_soon_threadsafe(self._loop.stop)
            self._thread.join(10)
            if self.proc.poll() is None:
                self.proc.terminate()
                try:
                    self.proc.wait(10)
                except subprocess.TimeoutExpired:
                    self.proc.kill()
                    self.proc.wait(10)
            shutil.rmtree(self.profile, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
