"""ocular_render: the eye, its PSFs and the renderer of ocular, from NumPy.

Eyes come from presets, eye files, spectacle prescriptions or Zernike wavefronts
(:class:`Eye`); :func:`psf` computes one point-spread function through an eye;
:class:`Renderer` owns one Vulkan device and renders colour + depth arrays (or shipped scenes)
as the eye sees them, reusing its kernels, pipelines and PSF texture from frame to frame while
the eye's state holds. :func:`psnr`, :func:`ssim` and :func:`flip` compare images as
``ocular compare`` and ``ocular metrics`` do.

Arrays: colour is (H, W, 3) float32 linear RGB (cd/m²), depth (H, W) float32 metres along the
view axis (0 or +inf: background); row 0 is the top. Bad arguments raise ValueError (TypeError
for a wrong type) with the one-line message the ``ocular`` CLI prints; a missing Vulkan driver
raises RuntimeError saying what to install. See docs/python.md.
"""

from ._ocular_render import (
    Eye,
    Refraction,
    Renderer,
    __version__,
    eye_presets,
    flip,
    psf,
    psnr,
    read_exr,
    scenes,
    ssim,
    write_exr,
)

__all__ = [
    "Eye",
    "Refraction",
    "Renderer",
    "__version__",
    "eye_presets",
    "flip",
    "psf",
    "psnr",
    "read_exr",
    "scenes",
    "ssim",
    "write_exr",
]
