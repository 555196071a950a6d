"""Type stubs of the extension module glassdb._glassdb (python/src)."""

from collections.abc import Mapping, Sequence
from os import PathLike
from typing import Any, Literal, overload

import numpy as np
import numpy.typing as npt

_Path = str | PathLike[str]
_F32Image = npt.NDArray[np.float32]

__version__: str

class Registry:
    """A glass registry: one table of glasses per colour basis, the first the default."""

    @staticmethod
    def load(path: _Path | None = None) -> Registry:
        """A registry JSON, validated; without a path, the bundled registry."""
    @staticmethod
    def build(
        catalog: _Path,
        spaces: Sequence[str] | None = None,
        *,
        method: str = "colorimetric",
        observer: str = "cie1931",
        illuminant: _Path | None = None,
        lights: Sequence[str | tuple[str, _Path]] | None = None,
        white_balance: str | None = None,
        extrapolate: bool = False,
        tol: float | None = None,
        max_degree: int = 12,
        per_channel: bool = False,
        masks: Sequence[_Path] | None = None,
    ) -> Registry:
        """A registry built from a catalog as `glassdb registry build` builds it; `lights`
        (`"NAME=ILLUMINANT"` or (name, illuminant or SPD path)) as its `--light`."""
    def spaces(self) -> list[str]:
        """The colour bases of its tables, the default first."""
    def ids(self, space: str | None = None) -> list[int]:
        """The glass ids of a table, sorted."""
    def glass(self, id: int, space: str | None = None) -> dict[str, Any]:
        """The glass's registry record, plus `tau_v`, `rho_v` and `build_up`."""
    @overload
    def eval(
        self, id: int, cos_theta: float, side: Literal["front", "back"] = "front", space: str | None = None
    ) -> tuple[tuple[float, float, float], tuple[float, float, float]]: ...
    @overload
    def eval(
        self,
        id: int,
        cos_theta: npt.NDArray[np.float64],
        side: Literal["front", "back"] = "front",
        space: str | None = None,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def to_json(self) -> str:
        """The registry JSON, as `glassdb registry build` writes it."""
    def save(self, path: _Path) -> None:
        """Writes the registry JSON (validated, atomically)."""
    @property
    def sha256(self) -> str:
        """SHA-256 of its JSON."""

class Pass:
    """A pass as `compose` reads it."""

    @property
    def pixels(self) -> _F32Image:
        """float32 (H, W, 3), or (H, W, 4) with alpha; linear, premultiplied."""
    @property
    def layer(self) -> str | None: ...
    @property
    def space(self) -> str | None: ...
    @property
    def data_window(self) -> tuple[int, int, int, int]: ...
    @property
    def display_window(self) -> tuple[int, int, int, int]: ...

def compose(
    trans: _F32Image | Mapping[str, _F32Image],
    refl: _F32Image | Sequence[_F32Image] | Mapping[str, _F32Image] | Sequence[Mapping[str, _F32Image]],
    mask: npt.NDArray[np.uint8] | Mapping[str, npt.NDArray[np.float32]],
    registry: Registry | None = None,
    planes: _Path | None = None,
    space: str | None = None,
    sides: Mapping[int, Literal["front", "back"]] | None = None,
    unknown: Literal["error", "passthrough"] = "error",
    light_groups: Sequence[str] | str | None = None,
    surfaces: int | None = None,
) -> _F32Image:
    """The composite, bit for bit as `compose` writes it to a float EXR; with `light_groups`
    (`trans` and each `refl` then dicts {group: array}), the sum of the groups' composites,
    bit for bit the beauty `compose --light-groups` writes. A unit (an insulated glass) in the
    mask is refused (no pane-group passes from arrays) unless `surfaces=1`."""

def read_passes(path: _Path, layer: str | None = None) -> list[Pass]:
    """The passes of a file as `compose` reads them."""

def cryptomatte_mask(
    path: _Path,
    glass: Sequence[tuple[str, int]],
    cos: str = "facing",
    plane: str | None = None,
    layer: str | None = None,
    aovs: Literal["glass-only", "every-material"] = "glass-only",
) -> dict[str, npt.NDArray[np.float32]]:
    """The mask `compose --mask-cryptomatte` builds, as float32 (H, W) arrays."""

def stack(
    layers: Sequence[_Path],
    gaps: Sequence[str] | None = None,
    angles: Sequence[float] | str | None = None,
    space: str = "srgb",
    spectra: bool = False,
    per_channel: bool = False,
    combine: Literal["per-wavelength", "per-band"] = "per-wavelength",
) -> dict[str, Any]:
    """What `glassdb stack --json` prints."""

def spectral(
    path: _Path,
    space: str | None = None,
    illuminant: str | None = None,
    observer: str | None = None,
    method: Literal["colorimetric", "paper", "luminous"] = "colorimetric",
    cmf: str | None = None,
    percent: bool = False,
    extrapolate: bool = False,
) -> dict[str, Any]:
    """What `glassdb spectral --json` prints."""
