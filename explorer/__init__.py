"""phong-explorer: per-vertex Phong / Blinn-Phong shading, material presets and an explorer.

``import explorer`` never imports pyvista or VTK.
"""

__version__ = "0.1.0"
