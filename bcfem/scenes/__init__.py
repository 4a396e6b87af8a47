"""The scene registry: name -> module with ``Params``, ``build`` and the CLI texts,
and name -> module of its studies (``SWEEP``, ``FIT_TARGETS``, ``fit``).

Modules are imported on first use, so ``bcfem run crater --help`` loads only the crater.
"""

import importlib
from collections.abc import Mapping


class _Lazy(Mapping):
    """A read-only name -> module mapping that imports each module when first looked up."""

    def __init__(self, paths: dict[str, str]):
        self._paths = paths

    def __getitem__(self, name: str):
        return importlib.import_module(self._paths[name])

    def __iter__(self):
        return iter(self._paths)

    def __len__(self) -> int:
        return len(self._paths)


REGISTRY = _Lazy({"blister-rigid": "bcfem.scenes.blister_rigid", "blister-3d": "bcfem.scenes.blister_3d",
                  "blister-soft": "bcfem.scenes.blister_soft",
                  "crater": "bcfem.scenes.crater", "crater-cell": "bcfem.scenes.crater_cell",
                  "crater-sector": "bcfem.scenes.crater_sector",
                  "crater-double": "bcfem.scenes.crater_double", "droplet-soft": "bcfem.scenes.droplet_soft"})
STUDIES = _Lazy({"blister-rigid": "bcfem.scenes.blister_studies", "crater": "bcfem.scenes.crater",
                 "crater-double": "bcfem.scenes.crater_double"})
