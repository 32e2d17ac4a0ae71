"""The endoscopy panel's profile on the torso phantom's aorta: the lumen's diameter along the path drawn under the
flight, and the current cross-section's numbers following the eye."""

from __future__ import annotations

import numpy as np


def test_the_panel_shows_the_profile_and_the_section_under_the_eye(torso_flight):
    """After the centerline the profile (:func:`volumen.analysis.measure`, whose accuracy tests/analysis measures)
    is the panel's; flying forward, the numbers shown are those of the section nearest the eye (its projection
    onto the profile's centerline), and the plot's eye line moves with it (its x within 2 pixels of the eye's
    share of the path's length)."""
    from PySide6.QtGui import QColor

    from volumen.app._endo_profile import EYE, PAD, section_text

    _, _, panel = torso_flight
    p = panel.model.profile
    view = panel.profile_view
    assert p is not None and view.plot.profile is p
    print(p)
    panel.start_guided()
    shown = []
    for _ in range(3):
        panel.model.guided.advance(1.0)
        panel._show_pose()
        eye = np.asarray(panel.model.pose.position, float)
        arc, _ = p.centerline.project(eye)
        k = int(np.argmin(np.abs(p.centerline.arc - arc)))
        assert view.label.text() == section_text(p, k)
        assert f"diameter {p.sections.diameter[k]:.1f} mm" in view.label.text()
        img = view.plot.grab().toImage()
        row = [QColor(img.pixel(x, 2)) for x in range(img.width())]
        cols = [x for x, c in enumerate(row) if (c.red(), c.green(), c.blue()) == (EYE.red(), EYE.green(), EYE.blue())]
        expected = PAD + (img.width() - 2 * PAD) * arc / p.length
        assert cols and abs(np.mean(cols) - expected) <= 2.0
        shown.append(arc)
    print("eye at", np.round(shown, 1), "mm:", view.label.text())
    assert np.all(np.diff(shown) > 0)
    panel.stop()
