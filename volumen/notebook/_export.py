"""A standalone HTML page with the viewer's canvas: jupyter-rfb's own front end showing one frame.

The page loads the widget's JavaScript (the anywidget module jupyter-rfb ships) with a stand-in for
the Jupyter model and delivers the frame as the ``framebufferdata`` message a kernel would send, so a
browser draws it exactly as in a notebook. Needs no network and no server: open the file. Browser
events the widget would send to Python are collected in ``window.rfbEvents``.
"""

from __future__ import annotations

import base64
import json

import numpy as np

from . import pictures

__all__ = ["export_html"]

_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>volumen</title>
<style>body {{ margin: 0; background: #fff; }} {css}</style></head>
<body><div id="view"></div>
<script type="text/plain" id="rfb-source">{js}</script>
<script type="module">
class Model {{
  constructor(traits) {{ this.traits = traits; this.handlers = {{}}; }}
  get(k) {{ return this.traits[k]; }}
  set(k, v) {{ this.traits[k] = v; for (const f of this.handlers['change:' + k] || []) f(); }}
  save_changes() {{}}
  on(e, f) {{ (this.handlers[e] = this.handlers[e] || []).push(f); }}
  off() {{}}
  send(msg) {{ window.rfbEvents.push(msg); }}
  emit(e, ...args) {{ for (const f of this.handlers[e] || []) f(...args); }}
}}
window.rfbEvents = [];
const source = document.getElementById('rfb-source').textContent;
const url = URL.createObjectURL(new Blob([source], {{ type: 'text/javascript' }}));
const widget = (await import(url)).default();
const model = new Model({traits});
widget.initialize({{ model }});
widget.render({{ model, el: document.getElementById('view') }});
const bytes = Uint8Array.from(atob('{png}'), c => c.charCodeAt(0));
model.emit('msg:custom', {{ type: 'framebufferdata', mimetype: 'image/png', index: 1, timestamp: 0 }},
           [new DataView(bytes.buffer)]);
</script></body></html>
"""


def export_html(frame: np.ndarray) -> str:
    """The page (a str) showing ``frame`` (uint8 (H, W, 3), row 0 at the top) in jupyter-rfb's widget,
    at one CSS pixel per frame pixel, in the page's top-left corner."""
    from jupyter_rfb.widget import CSS, JS

    h, w = frame.shape[:2]
    traits = {"css_width": f"{w}px", "css_height": f"{h}px", "resizable": False, "has_titlebar": False,
              "title": "", "cursor": "default", "_frame_feedback": {}, "_has_visible_views": False}
    png = base64.b64encode(pictures.png_bytes(frame)).decode()
    return _PAGE.format(css=CSS, js=JS.replace("</script", "<\\/script"), traits=json.dumps(traits), png=png)
