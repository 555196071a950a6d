"""glassdb: architectural glass optical data and a physically based glazing compositor.

The library the ``glassdb`` and ``compose`` commands run, for Python pipelines (Nuke, Houdini,
Blender, farm submitters, notebooks). numpy arrays in and out; the GIL is released while
glassdb computes; errors are the classes of ``glassdb._errors`` with the command's message.

- ``Registry.load(path=None)``, ``Registry.build(catalog, spaces=...)``: glass tables;
  ``.ids()``, ``.glass(id)``, ``.eval(id, cos_theta)``.
- ``compose(trans, refl, mask, registry=...)``: the composite, bit for bit as ``compose``
  writes it to a float EXR.
- ``read_passes(path)``, ``cryptomatte_mask(path, glass=...)``: passes and masks as
  ``compose`` reads them.
- ``stack(layers, angles=...)``, ``spectral(path, ...)``: ``glassdb stack --json`` and
  ``glassdb spectral --json`` as dicts.
"""

from ._errors import (
    GlassdbError,
    InternalError,
    InvalidInput,
    IoError,
    LimitExceeded,
    Unsupported,
)
from ._glassdb import (
    Pass,
    Registry,
    __version__,
    compose,
    cryptomatte_mask,
    read_passes,
    spectral,
    stack,
)

__all__ = [
    "GlassdbError",
    "InternalError",
    "InvalidInput",
    "IoError",
    "LimitExceeded",
    "Pass",
    "Registry",
    "Unsupported",
    "__version__",
    "compose",
    "cryptomatte_mask",
    "read_passes",
    "spectral",
    "stack",
]
