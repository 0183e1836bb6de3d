"""Pictures: cameras, the VTK plotter factory and mesh builder, the off-screen renderer, the
per-pixel reference, live per-pixel frames, image files and mesh exports.

May import: :mod:`explorer.core`, :mod:`explorer.geometry`, :mod:`explorer.shading`, and VTK /
PyVista / trimesh inside the functions that draw, read or write (so importing this package
stays cheap).
"""
