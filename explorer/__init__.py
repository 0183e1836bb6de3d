"""phong-explorer: per-vertex Phong / Blinn-Phong shading and an interactive material explorer.

``import explorer`` is light: the names below are loaded on first use (PEP 562, as SciPy's and
scikit-image's lazy loading), so ``import explorer`` itself imports neither numpy nor numba,
and the ``phong-explorer`` command starts inside its own error handling (a Ctrl-C while the
engine loads ends with one line, not a traceback). The engine needs numpy and numba only; the
renderer and the GUI import VTK when they are used.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from explorer.core.version import __version__

#: public name -> the module that defines it
_EXPORTS = {
    "DirectionalLight": "explorer.core.lights",
    "ExplorerError": "explorer.core.errors",
    "Material": "explorer.core.material",
    "PointLight": "explorer.core.lights",
    "Scene": "explorer.core.scene",
    "Shader": "explorer.shading.shader",
    "SpotLight": "explorer.core.lights",
    "ValidationError": "explorer.core.errors",
    "Viewer": "explorer.core.scene",
    "load_scene": "explorer.core.scene",
    "make_plan": "explorer.shading.plan",
    "shade": "explorer.shading.shader",
}

__all__ = [  # (a literal, for static tools; a test checks it against _EXPORTS)
    "DirectionalLight",
    "ExplorerError",
    "Material",
    "PointLight",
    "Scene",
    "Shader",
    "SpotLight",
    "ValidationError",
    "Viewer",
    "__version__",
    "load_scene",
    "make_plan",
    "shade",
]

if TYPE_CHECKING:  # what static tools and editors see
    from explorer.core.errors import ExplorerError, ValidationError
    from explorer.core.lights import DirectionalLight, PointLight, SpotLight
    from explorer.core.material import Material
    from explorer.core.scene import Scene, Viewer, load_scene
    from explorer.shading.plan import make_plan
    from explorer.shading.shader import Shader, shade


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'explorer' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})
