"""The profile's picture: diameters and area against the distance along the path, the stretched CPR above.

:func:`profile_figure` draws, with matplotlib (imported here, the Agg canvas: no window):

* above (given the volume): the stretched curved planar reformation along the profile's centerline
  (:func:`volumen.endoscopy.curved_reformation`), turned so that the distance along the path runs left to
  right under the plots' axis, through the vessel's window (:func:`volumen.endoscopy.vessel_window`);
* below: the equivalent, minimum and maximum diameters (mm) and, on the right axis, the area (mm^2);
  the stenosis (red) and the maximum (orange) marked by a line across both panels with their numbers
  (dashed where not flagged),
  the branch points by grey dotted lines.

:func:`summary_html` is the notebook's view: the summary as a table and the plot as an inline PNG.
"""

from __future__ import annotations

import base64
import html
import io

import numpy as np

__all__ = ["profile_figure", "summary_html", "figure_png"]

STENOSIS_COLOR, MAXIMUM_COLOR, BRANCH_COLOR = "#d62728", "#ff7f0e", "#7f7f7f"


def _cpr_panel(ax, volume, profile) -> None:
    from ..endoscopy import curved_reformation, vessel_window

    cpr = curved_reformation(volume, profile.centerline, kind="stretched")
    window = vessel_window(cpr, float(np.median(profile.sections.inscribed_radius)))
    finite = cpr.values[np.isfinite(cpr.values)]
    if window is None and finite.size:
        window = tuple(np.percentile(finite, [1.0, 99.5]))
    across = (np.arange(cpr.values.shape[1] + 1) - 0.5) * cpr.pixel
    arc = cpr.arc
    edges = np.concatenate([[arc[0]], 0.5 * (arc[1:] + arc[:-1]), [arc[-1]]])
    ax.pcolormesh(edges, across, np.nan_to_num(cpr.values.T, nan=window[0] if window else 0.0), cmap="gray",
                  vmin=window[0] if window else None, vmax=window[1] if window else None, shading="flat")
    ax.set_ylim(across[-1], across[0])
    ax.set_yticks([])
    ax.set_title("stretched CPR along the path")


def _marks(axes, profile) -> None:
    for a in profile.branch_arcs:
        for ax in axes:
            ax.axvline(a, color=BRANCH_COLOR, linestyle=":", linewidth=1.0)
    for lesion, color in ((profile.stenosis, STENOSIS_COLOR), (profile.maximum, MAXIMUM_COLOR)):
        for ax in axes:
            ax.axvline(lesion.arc, color=color, linewidth=1.2, linestyle="-" if lesion.flagged else "--")


def _label(lesion) -> str:
    flag = "" if lesion.flagged else ", not flagged"
    if lesion.kind == "stenosis":
        return f"stenosis {lesion.percent:.0f} % ({lesion.diameter:.1f} of {lesion.reference:.1f} mm{flag})"
    return f"maximum {lesion.diameter:.1f} mm" + (" (aneurysm)" if lesion.flagged else flag)


def profile_figure(profile, volume=None):
    """A matplotlib ``Figure`` of ``profile`` (see the module docstring); the CPR panel only with ``volume``."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 6.5 if volume is not None else 4.0), dpi=100, layout="constrained")
    if volume is not None:
        top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[1.0, 1.4])
        _cpr_panel(top, volume, profile)
        axes = [top, bottom]
    else:
        bottom = fig.subplots(1, 1)
        axes = [bottom]
    arc, s = profile.centerline.arc, profile.sections
    bottom.plot(arc, s.diameter, color="k", label="equivalent diameter")
    bottom.plot(arc, s.min_diameter, color="#1f77b4", linewidth=0.8, label="minimum diameter")
    bottom.plot(arc, s.max_diameter, color="#2ca02c", linewidth=0.8, label="maximum diameter")
    bottom.set_xlabel("distance along the path (mm)")
    bottom.set_ylabel("diameter (mm)")
    bottom.set_xlim(arc[0], arc[-1])
    bottom.set_ylim(0.0, 1.1 * float(np.max(s.max_diameter)))
    area = bottom.twinx()
    area.plot(arc, s.area, color="#9467bd", linewidth=0.8, linestyle="--", label="area")
    area.set_ylabel("area (mm²)", color="#9467bd")
    area.set_ylim(0.0, 1.1 * float(np.max(s.area)))
    _marks(axes, profile)
    handles = bottom.get_legend_handles_labels()[0] + area.get_legend_handles_labels()[0]
    bottom.legend(handles=handles, loc="upper left", fontsize=8)
    for lesion, color in ((profile.stenosis, STENOSIS_COLOR), (profile.maximum, MAXIMUM_COLOR)):
        y = lesion.diameter if lesion.kind == "maximum" else s.diameter[lesion.index]
        bottom.annotate(_label(lesion), (lesion.arc, y), xytext=(4, -14 if lesion.kind == "stenosis" else 4),
                        textcoords="offset points", color=color, fontsize=8)
    bottom.set_title(f"length {profile.length:.1f} mm, tortuosity {profile.tortuosity:.2f}")
    return fig


def figure_png(fig) -> bytes:
    """The figure as PNG bytes."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()


def summary_html(profile) -> str:
    """The notebook's view: the summary's numbers as a table, then the plot (an inline PNG)."""
    rows = "".join(f"<tr><th style='text-align:left'>{html.escape(k)}</th><td>{html.escape(_text(v))}</td></tr>"
                   for k, v in profile.summary().items())
    png = base64.b64encode(figure_png(profile_figure(profile))).decode("ascii")
    return f"<table>{rows}</table><img src='data:image/png;base64,{png}'/>"


def _text(value) -> str:
    if isinstance(value, dict):
        return ", ".join(f"{k} {_text(v)}" for k, v in value.items() if k != "kind")
    if isinstance(value, list):
        return ", ".join(_text(v) for v in value) or "none"
    return str(value)
