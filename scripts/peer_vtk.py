#!/usr/bin/env python3
"""Peer benchmark: VTK's GPU ray-cast volume mapper on a signed-orbital cube file.

    python3 scripts/peer_vtk.py CUBE [--size 800x600] [--frames 20]
                                [--sample-distance D] [--save out.png]

Reads a Gaussian cube (plain or .gz), builds a vtkImageData (bohr, the cube's
own origin and axes), and renders it offscreen with vtkGPUVolumeRayCastMapper:
composite blending, trilinear interpolation, no shading, colour red for
psi > 0 and blue for psi < 0, opacity proportional to psi^2. The sample
distance is fixed (automatic adjustment off); by default it is half the
smallest grid spacing. One warm-up frame (volume upload, shader build) is
timed separately, then N frames, each after a small camera rotation, are
timed as Render() followed by WaitForCompletion() (glFinish), so the GPU or
the software rasteriser has finished the frame.

Headless machines: with no DISPLAY the script selects VTK's EGL render window
(PyPI wheels of VTK >= 9.4 carry it; Mesa's libEGL then gives llvmpipe).
Where EGL is unavailable, run it under an X server instead:
    xvfb-run -a -s '-screen 0 1280x1024x24' python3 scripts/peer_vtk.py CUBE

The last stdout line of interest is `vtk_ms_per_frame=<float>`.
"""

from __future__ import annotations

import argparse
import gzip
import math
import os
import sys
import time

import numpy as np

BOHR_PER_ANGSTROM = 1.0 / 0.529177210903

if not os.environ.get("DISPLAY") and "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ:
    os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"

import vtk  # noqa: E402
from vtk.util import numpy_support  # noqa: E402


# --------------------------------------------------------------------------- cube reading

def read_cube(path: str, orbital: int = 0):
    """Return (values[nx,ny,nz] float32, origin[3], axes[3,3] rows = step vectors, atoms).

    Lengths in bohr. Handles Å axes (negative counts), the NAtoms < 0 orbital
    line (values of several orbitals interleaved; `orbital` picks one) and gzip.
    """
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rt") as fh:
        text = fh.read()
    lines = text.splitlines()
    head = lines[2].split()
    natoms = int(head[0])
    origin = np.array([float(v) for v in head[1:4]])
    nval = int(head[4]) if len(head) > 4 else 1
    counts, axes = [], []
    for i in range(3):
        parts = lines[3 + i].split()
        counts.append(int(parts[0]))
        axes.append([float(v) for v in parts[1:4]])
    axes = np.array(axes)
    if any(c < 0 for c in counts):
        axes *= BOHR_PER_ANGSTROM
        origin = origin * BOHR_PER_ANGSTROM
    n = [abs(c) for c in counts]
    atoms = []
    for i in range(abs(natoms)):
        parts = lines[6 + i].split()
        atoms.append((int(float(parts[0])), np.array([float(v) for v in parts[2:5]])))
    # Fortran-style exponents (1.0D-03) are read as E.
    rest = "\n".join(lines[6 + abs(natoms):]).translate(str.maketrans("Dd", "Ee"))
    tokens = rest.split()
    nper = nval
    if natoms < 0:
        m = int(tokens[0])
        tokens = tokens[1 + m:]
        nper = m
    data = np.array(tokens, dtype=np.float64)
    expected = n[0] * n[1] * n[2] * nper
    if data.size < expected:
        raise SystemExit(f"{path}: {data.size} values, expected {expected}")
    data = data[:expected].reshape(n[0], n[1], n[2], nper)[..., orbital]
    return data.astype(np.float32), origin, axes, atoms


def to_image_data(values, origin, axes) -> vtk.vtkImageData:
    nx, ny, nz = values.shape
    lengths = np.linalg.norm(axes, axis=1)
    image = vtk.vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.SetOrigin(*origin)
    image.SetSpacing(*lengths)
    direction = (axes / lengths[:, None]).T  # columns = unit axis directions
    if not np.allclose(direction, np.eye(3)):
        image.SetDirectionMatrix(*direction.ravel())
    # VTK stores x fastest; the cube stores z fastest.
    flat = np.ascontiguousarray(values.ravel(order="F"))
    arr = numpy_support.numpy_to_vtk(flat, deep=True, array_type=vtk.VTK_FLOAT)
    arr.SetName("psi")
    image.GetPointData().SetScalars(arr)
    return image


# --------------------------------------------------------------------------- rendering

def transfer_functions(vmax: float, peak_opacity: float, points: int = 65):
    colour = vtk.vtkColorTransferFunction()
    colour.AddRGBPoint(-vmax, 0.10, 0.25, 1.00)
    colour.AddRGBPoint(-0.005 * vmax, 0.10, 0.25, 1.00)
    colour.AddRGBPoint(0.005 * vmax, 1.00, 0.15, 0.10)
    colour.AddRGBPoint(vmax, 1.00, 0.15, 0.10)
    opacity = vtk.vtkPiecewiseFunction()
    for v in np.linspace(-vmax, vmax, points):
        opacity.AddPoint(float(v), float(peak_opacity * (v / vmax) ** 2))
    return colour, opacity


def renderer_string(window) -> str:
    caps = window.ReportCapabilities() or ""
    for line in caps.splitlines():
        if "renderer string" in line.lower():
            return line.split(":", 1)[1].strip()
    return "unknown"


def ray_box_length(origin, direction, lo, hi) -> float:
    """Length of the segment of the ray origin + t*direction (t>0) inside the box [lo, hi]."""
    tmin, tmax = -math.inf, math.inf
    for o, d, a, b in zip(origin, direction, lo, hi):
        if abs(d) < 1e-12:
            if o < a or o > b:
                return 0.0
            continue
        t0, t1 = (a - o) / d, (b - o) / d
        tmin, tmax = max(tmin, min(t0, t1)), min(tmax, max(t0, t1))
    return max(0.0, tmax - max(tmin, 0.0))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("cube")
    ap.add_argument("--size", default="800x600", help="WxH (default 800x600)")
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--sample-distance", type=float, default=None,
                    help="bohr along the ray (default: half the smallest grid spacing)")
    ap.add_argument("--orbital", type=int, default=0, help="which orbital of a multi-orbital cube")
    ap.add_argument("--peak-opacity", type=float, default=0.9,
                    help="opacity per unit distance at |psi| = 0.75 max|psi| (default 0.9)")
    ap.add_argument("--degrees", type=float, default=2.0, help="azimuth step per frame (default 2)")
    ap.add_argument("--elevation", type=float, default=60.0,
                    help="initial camera elevation from the cube's +z axis, degrees (default 60)")
    ap.add_argument("--zoom", type=float, default=1.5,
                    help="camera zoom after fitting the volume's bounding sphere (default 1.5)")
    ap.add_argument("--eye", default=None,
                    help="camera position x,y,z in bohr (with --target and --fov: replaces --elevation/--zoom)")
    ap.add_argument("--target", default=None, help="camera focal point x,y,z in bohr")
    ap.add_argument("--fov", type=float, default=30.0, help="vertical view angle, degrees (with --eye)")
    ap.add_argument("--readback", action="store_true",
                    help="also read the RGBA pixels back after every frame")
    ap.add_argument("--save", default=None, help="write the last frame as PNG")
    args = ap.parse_args(argv)
    width, height = (int(v) for v in args.size.lower().split("x"))

    t0 = time.perf_counter()
    values, origin, axes, atoms = read_cube(args.cube, args.orbital)
    t_read = time.perf_counter() - t0
    image = to_image_data(values, origin, axes)
    spacing = np.array(image.GetSpacing())
    sample_distance = args.sample_distance or 0.5 * float(spacing.min())
    absmax = float(np.abs(values).max())
    # Full opacity scale reached at 75% of the largest |psi|, so the lobes read clearly.
    vmax = 0.75 * absmax

    colour, opacity = transfer_functions(absmax, args.peak_opacity * (absmax / vmax) ** 2)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(colour)
    prop.SetScalarOpacity(opacity)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()
    prop.SetScalarOpacityUnitDistance(1.0)

    mapper = vtk.vtkGPUVolumeRayCastMapper()
    mapper.SetInputData(image)
    mapper.SetBlendModeToComposite()
    mapper.SetAutoAdjustSampleDistances(False)
    mapper.SetLockSampleDistanceToInputSpacing(False)
    mapper.SetSampleDistance(sample_distance)
    mapper.SetUseJittering(False)

    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    ren = vtk.vtkRenderer()
    ren.SetBackground(0.0, 0.0, 0.0)
    ren.AddVolume(volume)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(width, height)
    window.SetMultiSamples(0)
    window.AddRenderer(ren)

    ren.ResetCamera()
    cam = ren.GetActiveCamera()
    if args.eye and args.target:
        # The exact camera another renderer used (e.g. `orbcloud bench render` prints it).
        cam.SetPosition(*[float(v) for v in args.eye.split(",")])
        cam.SetFocalPoint(*[float(v) for v in args.target.split(",")])
        cam.SetViewUp(0.0, 1.0, 0.0)
        cam.SetViewAngle(args.fov)
    else:
        cam.Elevation(args.elevation)
        cam.OrthogonalizeViewUp()
        cam.Azimuth(30.0)
        ren.ResetCamera()
        cam.Zoom(args.zoom)
    ren.ResetCameraClippingRange()

    def finish():
        if hasattr(window, "WaitForCompletion"):
            window.WaitForCompletion()
        if args.readback:
            window.GetRGBACharPixelData(0, 0, width - 1, height - 1, 0)

    t0 = time.perf_counter()
    window.Render()
    finish()
    t_first = time.perf_counter() - t0

    bounds = np.array(image.GetBounds()).reshape(3, 2)
    lo, hi = bounds[:, 0], bounds[:, 1]
    diag = float(np.linalg.norm(hi - lo))
    pos = np.array(cam.GetPosition())
    dop = np.array(cam.GetDirectionOfProjection())
    centre_len = ray_box_length(pos, dop, lo, hi)

    times = []
    for _ in range(args.frames):
        cam.Azimuth(args.degrees)
        ren.ResetCameraClippingRange()
        t0 = time.perf_counter()
        window.Render()
        finish()
        times.append(time.perf_counter() - t0)

    if args.save:
        grab = vtk.vtkWindowToImageFilter()
        grab.SetInput(window)
        grab.SetInputBufferTypeToRGB()
        grab.ReadFrontBufferOff()
        grab.Update()
        writer = vtk.vtkPNGWriter()
        writer.SetFileName(args.save)
        writer.SetInputConnection(grab.GetOutputPort())
        writer.Write()

    ms = np.array(times) * 1000.0
    nx, ny, nz = values.shape
    print(f"vtk_version={vtk.vtkVersion.GetVTKVersion()}")
    print(f"render_window={window.GetClassName()}")
    print(f"opengl_renderer={renderer_string(window)}")
    print(f"llvmpipe_threads={os.environ.get('LP_NUM_THREADS', 'default')} cpus={os.cpu_count()} "
          f"loadavg={' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    print(f"cube={args.cube} grid={nx}x{ny}x{nz} spacing_bohr={' '.join(f'{s:.4f}' for s in spacing)} "
          f"extent_bohr={' '.join(f'{e:.3f}' for e in hi - lo)} read_s={t_read:.2f}")
    print(f"mapper={mapper.GetClassName()} blend=composite interpolation=linear shade=off "
          f"jitter=off auto_adjust=off readback={'on' if args.readback else 'off'}")
    print(f"sample_distance_bohr={sample_distance:.5f} samples_per_ray_centre={centre_len / sample_distance:.0f} "
          f"samples_per_ray_max={diag / sample_distance:.0f}")
    print(f"size={width}x{height} frames={args.frames} degrees_per_frame={args.degrees} "
          f"elevation={args.elevation} zoom={args.zoom} first_frame_ms={t_first * 1000:.1f}")
    print(f"frame_ms min={ms.min():.1f} median={np.median(ms):.1f} max={ms.max():.1f}")
    print(f"vtk_ms_per_frame={ms.mean():.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
