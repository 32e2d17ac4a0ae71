"""The same scene through VTK's ``vtkFixedPointVolumeRayCastMapper``: the CPU peer we measure against.

Only what both renderers share is translated: the volume (axis-aligned, its
origin and spacing), the transfer function's colour and opacity points (data
units), the opacity unit distance (our reference step, one voxel), the sample
distance, trilinear interpolation, Phong coefficients with VTK's headlight, the
camera (position, focal point, view up, vertical view angle) and the image size.
VTK is imported only here, only when asked for.
"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["vtk_available", "VtkScene"]


def vtk_available() -> bool:
    """True when the ``vtk`` package imports (the ``bench`` extra)."""
    try:
        import vtk  # noqa: F401
    except ImportError:
        return False
    return True


class VtkScene:
    """A VTK render window set up like ``(scene, camera, size)``; :meth:`render` returns RGB float (H, W, 3).

    Parameters
    ----------
    scene : volumen.core.Scene
        Composite mode only; shading ``none`` or ``headlight``.
    camera : volumen.core.Camera
        Perspective.
    size : (width, height) pixels
    threads : int, optional
        Mapper threads (default: all CPUs).
    """

    def __init__(self, scene, camera, size, threads: int | None = None):
        import vtk
        from vtk.util import numpy_support

        vol = scene.volume
        if scene.mode != "composite" or scene.shading.mode not in ("none", "headlight"):
            raise ValueError("the VTK peer renders composite mode with shading none or headlight only")
        m = np.asarray(vol.affine, float)[:3, :3]
        if not (np.allclose(m, np.diag(np.diag(m))) and np.all(np.diag(m) > 0)):
            # vtkImageData here has no direction: permuted, flipped or oblique axes would be drawn wrongly
            raise ValueError("the VTK peer takes volumes whose voxel axes i, j, k point +x, +y, +z (RAS) only")
        img = vtk.vtkImageData()
        nz, ny, nx = vol.shape
        img.SetDimensions(nx, ny, nz)
        img.SetSpacing(vol.spacing[2], vol.spacing[1], vol.spacing[0])
        img.SetOrigin(*vol.origin)
        data = np.ascontiguousarray(vol.data)
        self._scalars = numpy_support.numpy_to_vtk(data.ravel(), deep=False)  # x fastest = C order [z, y, x]
        img.GetPointData().SetScalars(self._scalars)
        self._data = data  # keep the buffer alive

        mapper = vtk.vtkFixedPointVolumeRayCastMapper()
        mapper.SetInputData(img)
        mapper.SetNumberOfThreads(threads or os.cpu_count() or 1)
        mapper.SetAutoAdjustSampleDistances(0)
        mapper.SetLockSampleDistanceToInputSpacing(0)
        ds0 = min(vol.spacing)
        mapper.SetSampleDistance(ds0 / scene.sampling.samples_per_voxel)
        mapper.SetImageSampleDistance(1.0)

        tf = scene.transfer
        ctf = vtk.vtkColorTransferFunction()
        for v, r, g, b in tf.color:
            ctf.AddRGBPoint(v, r, g, b)
        otf = vtk.vtkPiecewiseFunction()
        for v, a in tf.opacity:
            otf.AddPoint(v, a)
        prop = vtk.vtkVolumeProperty()
        prop.SetColor(ctf)
        prop.SetScalarOpacity(otf)
        prop.SetScalarOpacityUnitDistance(ds0)
        prop.SetInterpolationTypeToLinear()
        sh = scene.shading
        if sh.mode == "headlight":
            prop.ShadeOn()
            prop.SetAmbient(sh.phong.ambient)
            prop.SetDiffuse(sh.phong.diffuse)
            prop.SetSpecular(sh.phong.specular)
            prop.SetSpecularPower(sh.phong.shininess)
        else:
            prop.ShadeOff()
        actor = vtk.vtkVolume()
        actor.SetMapper(mapper)
        actor.SetProperty(prop)

        ren = vtk.vtkRenderer()
        ren.AddVolume(actor)
        ren.SetBackground(0, 0, 0)
        cam = ren.GetActiveCamera()
        cam.SetPosition(*camera.position)
        cam.SetFocalPoint(*camera.target)
        cam.SetViewUp(*camera.up)
        cam.SetViewAngle(camera.fov)
        ren.ResetCameraClippingRange()
        win = vtk.vtkRenderWindow()
        win.SetOffScreenRendering(1)
        win.AddRenderer(ren)
        win.SetSize(int(size[0]), int(size[1]))
        self._win, self._ren, self._vtk = win, ren, vtk

    def render_only(self) -> None:
        """One full frame (the mapper casts every ray again)."""
        self._ren.GetActiveCamera().Modified()
        self._win.Render()

    def render(self) -> np.ndarray:
        """Render and read back: float RGB in [0, 1], ``(H, W, 3)``, row 0 at the top."""
        from vtk.util import numpy_support

        self.render_only()
        grab = self._vtk.vtkWindowToImageFilter()
        grab.SetInput(self._win)
        grab.ReadFrontBufferOff()
        grab.Update()
        out = grab.GetOutput()
        w, h, _ = out.GetDimensions()
        rgb = numpy_support.vtk_to_numpy(out.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]
        return rgb[::-1].astype(np.float32) / 255.0
