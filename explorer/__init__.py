"""phong-explorer: per-vertex Phong / Blinn-Phong shading and an interactive material explorer.

``import explorer`` is light: the engine needs numpy and numba only; the renderer and the GUI
import VTK when they are used.
"""

__version__ = "0.1.0"

from .engine import Shader, shade  # noqa: E402
from .errors import ExplorerError, ValidationError  # noqa: E402
from .lights import DirectionalLight, PointLight, SpotLight  # noqa: E402
from .material import Material  # noqa: E402
from .plan import make_plan  # noqa: E402
from .scene import Scene, Viewer, load_scene  # noqa: E402

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
