"""phong-explorer: per-vertex Phong / Blinn-Phong shading and an interactive material explorer.

``import explorer`` is light: the engine needs numpy and numba only; the renderer and the GUI
import VTK when they are used.
"""

from explorer.core.errors import ExplorerError, ValidationError
from explorer.core.lights import DirectionalLight, PointLight, SpotLight
from explorer.core.material import Material
from explorer.core.scene import Scene, Viewer, load_scene
from explorer.core.version import __version__
from explorer.shading.plan import make_plan
from explorer.shading.shader import Shader, shade

__all__ = [
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
