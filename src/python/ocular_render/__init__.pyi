"""Type stubs of ocular_render (the extension module _ocular_render)."""

from os import PathLike
from typing import Any, Dict, Literal, Optional, Sequence, Tuple, TypedDict, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, PathLike[str]]
_F32 = npt.NDArray[np.float32]
_F64 = npt.NDArray[np.float64]
_Method = Literal["splat", "reference", "slices"]

class Refraction:
    """A spectacle prescription at a vertex distance (what `ocular eye refract` prints), and
    the eye's power vector at its entrance pupil beside it (D)."""

    sphere_d: float
    cylinder_d: float
    """Minus-cylinder form: ≤ 0."""
    axis_deg: float
    """1 to 180 degrees."""
    vertex_mm: float
    """Where the prescription's lens sits in front of the cornea (0: a contact lens)."""
    pupil_m_d: float
    """The eye as given (its correction included) at its entrance pupil: M."""
    pupil_j0_d: float
    pupil_j45_d: float
    pupil_mm: float
    wavelength_nm: float
    field_deg: Optional[Tuple[float, float]]
    def rx(self) -> str:
        """"S C x A" at vertex_mm, as Eye.from_rx and Eye.with_correction take it."""

class Eye:
    """A physical eye model (Navarro-based), optionally with the record of its fit."""

    @staticmethod
    def preset(name: str) -> Eye:
        """A shipped eye: one of eye_presets() (healthy, myopia, astigmatism, …)."""
    @staticmethod
    def load(path: _Path) -> Eye:
        """An eye file (TOML) as `ocular eye estimate` and Eye.save write it."""
    @staticmethod
    def from_rx(
        rx: str,
        pupil_mm: float = 4.0,
        wavelength_nm: Optional[float] = None,
        vertex_mm: float = 12.0,
        max_time_s: Optional[float] = None,
    ) -> Eye:
        """Fits an eye to a spectacle prescription "S C x A" at vertex_mm (0 to 16) over a
        pupil (mm, 1 to 9), as `ocular eye estimate --rx` does; wavelength_nm None: 549 nm."""
    @staticmethod
    def from_zernike(
        coefficients_um: Union[Sequence[float], _F64],
        pupil_mm: float,
        wavelength_nm: float,
        max_time_s: Optional[float] = None,
    ) -> Eye:
        """Fits an eye to OSA/ANSI Zernike coefficients (µm, j = 0, 1, …; up to order 10)."""
    def save(self, path: _Path) -> None:
        """Writes the eye file (TOML) atomically."""
    def to_toml(self) -> str: ...
    def with_correction(self, rx: str, vertex_mm: float = 12.0) -> Eye:
        """The eye behind a spectacle lens "S C x A" at vertex_mm (0: contact lens)."""
    def refraction(
        self,
        pupil_mm: float = 4.0,
        wavelength_nm: float = 549.0,
        field_deg: Optional[Tuple[float, float]] = None,
        vertex_mm: float = 12.0,
    ) -> Refraction:
        """The spectacle prescription at vertex_mm (0 to 16; 0: contact lens) that corrects
        the eye for a distant object, as `ocular eye refract` prints it, with the eye's
        minimum-RMS power vector at its entrance pupil (on axis or at field (H, V) degrees)."""
    def wavefront(
        self,
        pupil_mm: float = 4.0,
        wavelength_nm: float = 555.0,
        field_deg: Optional[Tuple[float, float]] = None,
        focus_m: Optional[float] = None,
        order: int = 6,
    ) -> _F64:
        """OSA/ANSI Zernike coefficients (µm) over the entrance pupil."""
    @property
    def accommodation_max_d(self) -> Optional[float]: ...
    @property
    def converged(self) -> Optional[bool]: ...

def eye_presets() -> list[str]: ...
def scenes() -> list[str]: ...
def psf(
    eye: Eye,
    pupil_mm: float,
    wavelength_nm: float,
    *,
    focus_d: float = 0.0,
    object_d: Optional[float] = None,
    size: int = 256,
    pitch_arcmin: float = 0.25,
) -> _F64:
    """(size, size) PSF normalised to sum 1; optical axis at (size//2, size//2), row 0 on top."""

class LastFrame(TypedDict):
    focus_d: float
    focus_from: str
    focus_reached_d: float
    pupil_mm: float
    pupil_from: str
    method: str
    seconds: float
    kernels_reused: bool
    accommodation_max_d: Optional[float]

class Stats(TypedDict):
    frames: int
    kernel_preparations: int

class Renderer:
    """One Vulkan device and the caches of the current eye state."""

    def __init__(
        self,
        device: Union[None, int, str] = None,
        *,
        cache_dir: Optional[_Path] = None,
        kernel_cache: bool = True,
    ) -> None: ...
    @property
    def device(self) -> str: ...
    @property
    def last_frame(self) -> Optional[LastFrame]: ...
    @property
    def stats(self) -> Stats: ...
    def render(
        self,
        eye: Eye,
        color: _F32,
        depth: _F32,
        *,
        fov_y_deg: float,
        focus_m: Optional[float] = None,
        focus_d: Optional[float] = None,
        focus_at: Optional[Tuple[int, int]] = None,
        pupil_mm: Optional[float] = None,
        luminance_cdm2: Optional[float] = None,
        age: float = 30.0,
        method: _Method = "splat",
        layers: int = 1,
        off_axis: bool = False,
        exposure_ev: Optional[float] = None,
        quality: Literal["exact", "balanced", "fast"] = "balanced",
    ) -> _F32:
        """color (H, W, 3) or (L, H, W, 3) float32, depth (H, W) or (L, H, W) float32 metres
        → (H, W, 3) float32, as `ocular render --color --depth` renders them."""
    def render_scene(
        self,
        scene: str,
        eye: Eye,
        *,
        size: Optional[Tuple[int, int]] = None,
        time_s: float = 0.0,
        focus_m: Optional[float] = None,
        focus_d: Optional[float] = None,
        focus_at: Optional[Tuple[int, int]] = None,
        pupil_mm: Optional[float] = None,
        luminance_cdm2: Optional[float] = None,
        age: float = 30.0,
        method: _Method = "splat",
        layers: int = 1,
        off_axis: bool = False,
        exposure_ev: Optional[float] = None,
        quality: Literal["exact", "balanced", "fast"] = "balanced",
        headset: Optional[Literal["quest3", "vive-pro"]] = None,
    ) -> _F32:
        """A shipped scene or scene .toml file as the eye sees it (size is (W, H); headset
        instead of size: that headset's panel and vertical field)."""
    def render_scene_pair(
        self,
        scene: str,
        left: Eye,
        right: Optional[Eye] = None,
        *,
        ipd_mm: float = 63.0,
        size: Optional[Tuple[int, int]] = None,
        time_s: float = 0.0,
        focus_m: Optional[float] = None,
        focus_d: Optional[float] = None,
        focus_at: Optional[Tuple[int, int]] = None,
        pupil_mm: Optional[float] = None,
        luminance_cdm2: Optional[float] = None,
        age: float = 30.0,
        exposure_ev: Optional[float] = None,
        quality: Literal["exact", "balanced", "fast"] = "balanced",
        headset: Optional[Literal["quest3", "vive-pro"]] = None,
    ) -> Tuple[_F32, _F32]:
        """A scene through two eyes converging on the focus point and sharing one
        accommodation and pupil, as `ocular render --binocular`: (left, right)."""
    @property
    def last_pair(self) -> Optional[Dict[str, Any]]:
        """How the last pair was rendered: the driving eye, the shared accommodation, and
        per eye (left, right) its focus, far point, demand and defocus at the target."""
    def rasterize(
        self, scene: str, *, size: Optional[Tuple[int, int]] = None, time_s: float = 0.0
    ) -> Tuple[_F32, _F32, float]:
        """(color, depth, fov_y_deg) of a scene: what render() takes."""

def psnr(image: _F32, reference: _F32, data_range: float = 1.0) -> float: ...
@overload
def ssim(
    image: _F32, reference: _F32, data_range: float = 1.0, full: Literal[False] = False
) -> float: ...
@overload
def ssim(
    image: _F32, reference: _F32, data_range: float = 1.0, *, full: Literal[True]
) -> Tuple[float, _F32]: ...
@overload
def flip(
    image: _F32,
    reference: _F32,
    ppd: float = 67.02064327658225,
    hdr: bool = False,
    full: Literal[False] = False,
) -> float:
    """FLIP's mean error in [0, 1] (LDR, or HDR-FLIP with hdr=True), as `ocular metrics`."""
@overload
def flip(
    image: _F32,
    reference: _F32,
    ppd: float = 67.02064327658225,
    hdr: bool = False,
    *,
    full: Literal[True],
) -> Tuple[float, _F32]: ...
def read_exr(path: _Path) -> _F32:
    """An EXR's colour as (H, W, 3) float32."""
def write_exr(path: _Path, array: _F32) -> None:
    """(H, W, 3) float32 → R, G, B; (H, W) float32 → depth channel Z. Atomic."""
