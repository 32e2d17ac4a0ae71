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


def test_an_angle_placed_by_its_arm_and_second_point_and_moved(make_window, qtbot):
    """The first arm dragged (first point to vertex), the second point dragged after the next press: the degrees
    beside the vertex follow the drag and end within 0.5 deg of the angle between the pixel vectors; a drag of the
    vertex changes it as the analytic answer says; the coronal slice that holds it shows it too."""
    win = make_window()
    ax = win.slices["axial"]
    set_tool(win, "angle")
    cx, cy = np.rint(ax.world_to_widget(win.state.crosshair)).astype(int)
    first, vertex, second = (int(cx) + 40, int(cy)), (int(cx), int(cy)), (int(cx) + 30, int(cy) - 30)
    _drag(qtbot, ax, first, vertex)
    assert len(win.state.measurements) == 0 and ax.measure_tool.arm is not None  # half an angle, drawn, not kept
    seen = _drag(qtbot, ax, (int(cx) + 40, int(cy) - 5), second)
    (angle,) = win.state.measurements
    dz, dy, dx = win.state.volume.spacing
    assert dx == pytest.approx(dy)  # square pixels in mm: the picture's angle is the world's
    assert abs(angle.degrees - 45.0) < 0.5
    degrees = [float(c[0].rstrip("\u00b0")) for c in seen]
    assert degrees == sorted(degrees) and degrees[0] < degrees[-1]  # the value followed the drag
    text, (tx, ty) = ax.measure_tool.captions[0]
    assert text == f"{angle.degrees:.1f}\u00b0" and abs(tx - (vertex[0] + 6)) < 2  # beside the vertex
    win.slices["coronal"].repaint()
    assert [c for c, _ in win.slices["coronal"].measure_tool.captions] == [text]

    set_tool(win, None)
    _drag(qtbot, ax, vertex, (int(cx), int(cy) - 30))  # the vertex moved up: first arm at 45 deg below, second level
    (moved,) = win.state.measurements
    want = np.degrees(np.arctan2(30, 40))  # the vertex (0, -30) px: arms (40, 30) and (30, 0)
    assert abs(moved.degrees - want) < 0.5
    qtbot.mouseClick(ax, Qt.RightButton, pos=QPoint(int(cx), int(cy) - 30))
    assert len(win.state.measurements) == 0


def test_a_point_shows_its_world_position_and_the_scans_value(make_window, qtbot, tmp_path):
    """A click with the point tool: the point at the click's world position, its caption the coordinates in mm and
    the value of the scan's voxel there; dragged, it moves; saved and read back with the session; in the SR."""
    from volumen.core import hu_offset
    from volumen.measure import point_value

    win = make_window()
    ax = win.slices["axial"]
    set_tool(win, "point")
    cx, cy = np.rint(ax.world_to_widget(win.state.crosshair)).astype(int)
    qtbot.mouseClick(ax, Qt.LeftButton, pos=QPoint(int(cx) + 12, int(cy) - 7))
    ax.repaint()
    (pt,) = win.state.measurements
    assert np.allclose(pt.position, ax.world_at(int(cx) + 12, int(cy) - 7), atol=1e-6)
    vol = win.state.volume
    i, j, k = np.rint(vol.world_to_index(np.array([pt.position]))[0]).astype(int)
    value, units = point_value(vol, pt.position)
    assert value == pytest.approx(float(np.asarray(vol.data)[k, j, i]) - (hu_offset(vol) or 0), abs=1e-6)
    text = ax.measure_tool.captions[0][0]
    assert text.startswith(" ".join(f"{c:.1f}" for c in pt.position) + " mm")
    set_tool(win, None)
    _drag(qtbot, ax, (int(cx) + 12, int(cy) - 7), (int(cx) + 32, int(cy) - 7))
    (moved,) = win.state.measurements
    assert np.linalg.norm(np.subtract(moved.position, pt.position)) == pytest.approx(20 * _mm_per_px(ax), abs=1e-6)
    win.save_session(tmp_path / "s.json")
    again = make_window()
    assert again.load_session(tmp_path / "s.json", volume=vol)
    assert again.state.measurements == win.state.measurements


def test_a_free_hand_polygon_traced_with_the_mouse(make_window, qtbot):
    """The polygon tool traces the drag's path: a rectangle's outline traced in 5 px steps is a polygon of its area
    (40 x 30 px in mm², to 1e-6) whose mean is numpy's over the same voxels (0.5 %); a vertex dragged moves it."""
    win = make_window()
    ax = win.slices["axial"]
    set_tool(win, "polygon")
    cx, cy = np.rint(ax.world_to_widget(win.state.crosshair)).astype(int)
    corners = [(cx - 20, cy - 15), (cx + 20, cy - 15), (cx + 20, cy + 15), (cx - 20, cy + 15), (cx - 20, cy - 15)]
    qtbot.mousePress(ax, Qt.LeftButton, pos=QPoint(*corners[0]))
    for a, b in zip(corners, corners[1:], strict=False):
        n = int(max(abs(b[0] - a[0]), abs(b[1] - a[1])) // 5)
        for t in np.linspace(0, 1, n + 1)[1:]:
            qtbot.mouseMove(ax, pos=QPoint(*np.rint(np.add(a, t * np.subtract(b, a))).astype(int)))
    qtbot.mouseRelease(ax, Qt.LeftButton, pos=QPoint(*corners[-1]))
    ax.repaint()
    (region,) = win.state.measurements
    k = _mm_per_px(ax)
    assert region.shape.kind == "polygon"
    assert region.area_mm2 == pytest.approx(40 * 30 * k * k, rel=1e-6)
    box, mask = measure.region_voxels(win.state.volume, region.plane, region.shape)
    values = np.asarray(win.state.volume.data)[box][mask].astype(float)
    from volumen.core import hu_offset

    assert region.mean == pytest.approx(values.mean() - (hu_offset(win.state.volume) or 0), rel=0.005)
    assert ax.measure_tool.captions[0][0].startswith("mean ")

    set_tool(win, None)  # the corner vertex dragged 10 px right; its neighbours 5 px away along the edges stay:
    _drag(qtbot, ax, corners[2], (corners[2][0] + 10, corners[2][1]))  # a triangle of 10 x 5 px / 2 is added
    (moved,) = win.state.measurements
    assert moved.area_mm2 == pytest.approx((40 * 30 + 10 * 5 / 2) * k * k, rel=1e-6)
