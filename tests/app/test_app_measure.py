"""Rulers and regions on the slice views, placed, moved and deleted by simulated mouse input (offscreen): the value
drawn beside each, updated while dragging, shown on every plane that cuts it, kept in the session."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

from volumen import measure
from volumen.app._measure_menu import set_tool


def _mm_per_px(view) -> float:
    """Millimetres per widget pixel of a slice view, from its drawn rectangle and the slice's physical width."""
    g = view.geometry_
    return g.cols * g.col_mm / view.image_rect().width()


def _drag(qtbot, view, a, b, steps=4, button=Qt.LeftButton):
    """Press at ``a``, move in ``steps`` to ``b`` (values read after each move), release; widget px."""
    qtbot.mousePress(view, button, pos=QPoint(*a))
    seen = []
    for t in np.linspace(0, 1, steps + 1)[1:]:
        qtbot.mouseMove(view, pos=QPoint(*np.rint(np.add(a, t * np.subtract(b, a))).astype(int)))
        view.repaint()
        seen.append([c for c, _ in view.measure_tool.captions])
    qtbot.mouseRelease(view, button, pos=QPoint(*b))
    view.repaint()
    return seen


def test_a_ruler_placed_moved_and_deleted_with_the_mouse(make_window, qtbot):
    win = make_window()
    ax = win.slices["axial"]
    set_tool(win, "ruler")
    cx, cy = np.rint(ax.world_to_widget(win.state.crosshair)).astype(int)  # the row of the coronal slice
    a, b = (int(cx) - 40, int(cy)), (int(cx) + 30, int(cy))
    seen = _drag(qtbot, ax, a, b)
    (ruler,) = win.state.measurements
    k = _mm_per_px(ax)
    voxel = min(win.state.volume.spacing)
    assert abs(ruler.mm - 70 * k) < 0.5 * voxel
    lengths = [float(c[0].split()[0]) for c in seen]
    assert lengths == sorted(lengths) and lengths[0] < lengths[-1]  # the value followed the drag
    assert ax.measure_tool.captions[0][0] == f"{ruler.mm:.1f} mm"

    for plane in ("coronal", "sagittal"):  # the coronal slice holds it, the sagittal one is crossed by it
        win.slices[plane].repaint()
        assert [c for c, _ in win.slices[plane].measure_tool.captions] == [f"{ruler.mm:.1f} mm"], plane

    set_tool(win, None)  # a handle is grabbed in any mode
    _drag(qtbot, ax, b, (b[0] + 20, b[1]))
    (moved,) = win.state.measurements
    assert abs(moved.mm - 90 * k) < 0.5 * voxel
    qtbot.mouseClick(ax, Qt.RightButton, pos=QPoint(b[0] + 20, b[1]))
    assert len(win.state.measurements) == 0


def test_a_rectangle_shows_its_statistics_over_the_scans_voxels(make_window, qtbot):
    win = make_window()
    ax = win.slices["axial"]
    set_tool(win, "rectangle")
    cx, cy = np.rint(ax.world_to_widget(win.state.crosshair)).astype(int)
    _drag(qtbot, ax, (int(cx) + 20, int(cy) + 15), (int(cx) - 20, int(cy) - 15))  # up and left: the box still spans
    (region,) = win.state.measurements
    k = _mm_per_px(ax)
    assert region.area_mm2 == pytest.approx(40 * 30 * k * k, rel=1e-6)
    box, mask = measure.region_voxels(win.state.volume, region.plane, region.shape)
    values = np.asarray(win.state.volume.data)[box][mask]
    dz, dy, dx = win.state.volume.spacing
    assert abs(region.voxels - region.area_mm2 / (dx * dy)) < (40 + 30) * k / min(dx, dy) + 1  # one edge row
    assert region.mean == pytest.approx(values.mean(), rel=0.005)
    assert ax.measure_tool.captions[0][0].startswith("mean ")


def test_measurements_stay_with_the_session_and_another_scans_are_refused(make_window, qtbot, tmp_path):
    win = make_window()
    ax = win.slices["axial"]
    set_tool(win, "ellipse")
    cx, cy = np.rint(ax.world_to_widget(win.state.crosshair)).astype(int)
    _drag(qtbot, ax, (int(cx) - 20, int(cy) - 10), (int(cx) + 10, int(cy) + 20))
    win.save_session(tmp_path / "s.json")
    again = make_window()
    assert again.load_session(tmp_path / "s.json", volume=win.state.volume)
    assert again.state.measurements == win.state.measurements

    d = json.loads((tmp_path / "s.json").read_text())
    d["measurements"][0]["scan"]["source"] = "another-scan.nii.gz"
    (tmp_path / "other.json").write_text(json.dumps(d))
    assert not again.load_session(tmp_path / "other.json", volume=win.state.volume)
    assert "another-scan.nii.gz" in again.last_error[1] and "\n" not in again.last_error[1]
    assert again.state.measurements == win.state.measurements  # nothing lost


def test_a_3d_ruler_between_two_clicks_on_the_picture(make_window, qtbot):
    """Two clicks in the 3-D view pick the first visible surface under each (checked against the depth of the
    CPU's whole unjittered picture at those pixels, within a voxel) and draw the ruler over the rendering with its
    length."""
    from dataclasses import replace

    from volumen.measure._pick import pixel_ray
    from volumen.render import render

    win = make_window()
    set_tool(win, "ruler3d")
    v = win.view3d
    clicks = [(62, 70), (101, 84)]
    for x, y in clicks:
        qtbot.mouseClick(v, Qt.LeftButton, pos=QPoint(x, y))
    (ruler,) = win.state.measurements
    st, size = win.state, v.view_size
    whole = render(st.scene.with_(sampling=replace(st.scene.sampling, jitter=False)), st.camera, size, device="cpu")
    voxel = max(st.volume.spacing)
    for (x, y), end in zip(clicks, (ruler.start, ruler.end), strict=True):
        origin, direction = pixel_ray(st.camera, size, x + 0.5, y + 0.5)  # the whole picture's pixel centre
        seen = origin + whole.depth[y, x] * direction
        assert np.linalg.norm(np.subtract(end, seen)) < voxel, (x, y)
    v.repaint()
    assert [c for c, _ in v.ruler3d.captions] == [f"{ruler.mm:.1f} mm"]
    assert ruler.mm > 10


def test_measurements_exported_and_imported_again(make_window, qtbot, tmp_path):
    """Export writes the measurements (JSON here: the phantom is no DICOM series for an SR) and import adds them
    back; a file of another scan's measurements is refused in one line and nothing is lost."""
    from volumen.app._measure_menu import export, import_measurements
    from volumen.errors import MeasurementError

    win = make_window()
    ax = win.slices["axial"]
    set_tool(win, "ruler")
    cx, cy = np.rint(ax.world_to_widget(win.state.crosshair)).astype(int)
    _drag(qtbot, ax, (int(cx) - 30, int(cy)), (int(cx) + 25, int(cy) + 10))
    made = list(win.state.measurements)
    export(win, tmp_path / "m.json")
    win.state.set_measurements([])
    assert import_measurements(win, tmp_path / "m.json") == 1 and list(win.state.measurements) == made
    other = measure.Measurements([measure.Distance((0, 0, 0), (1, 0, 0), scan=measure.Scan(source="other.nii"))])
    measure.save_measurements(other, tmp_path / "other.json")
    with pytest.raises(MeasurementError) as err:
        import_measurements(win, tmp_path / "other.json")
    assert "other.nii" in str(err.value) and "\n" not in str(err.value)
    assert list(win.state.measurements) == made
